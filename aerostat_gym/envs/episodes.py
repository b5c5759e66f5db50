"""The episode start: trim table, turbulence bank, perturbation and domain randomisation.

Everything random at an episode start is drawn from the one generator passed in, in a fixed
order, so a seed fixes the episode and environment i of a batch matches a single environment
seeded the same way.
"""

from __future__ import annotations

import weakref
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..analysis.directional import WEATHERCOCK_OFFSETS_DEG, weathercock_stable
from ..analysis.trim import Equilibrium, TrimError, find_equilibrium, largest_trim_tension
from ..checks import is_number
from ..params import InertiaError, ParameterError, Params, apply_overrides, dumps_toml
from ..physics.core import euler_angles, rotation_matrix
from ..physics.packing import pack_params
from ..physics.state import S_Z, StateLayout
from ..physics.wind import (
    mean_wind,
    set_advection,
    set_field,
    set_field_scale,
    set_gust,
    set_periodic,
    set_row_decorrelation,
)
from ..sim import Model
from ..wind.field import decorrelation_at, pair_decorrelations
from ..wind.presets import TurbulenceConfig
from ..wind.synthesis import check_field_size, fft_length, veers_field
from .config import TaskConfig, TaskError, get_parameter, perturbation

#: [m/s] step of the trim table: the trims are computed once per parameter set by continuation
#: in wind speed on this grid (0.7 s for 3-15 m/s on the baseline) and episodes draw their speed
#: among its points, which is what makes a reset cheap; a fixed speed off the grid (the task's
#: single ``wind_speed`` or a reset option) is trimmed exactly from its nearest table trim (a
#: few ms, the first time the environment meets that speed)
WIND_GRID = 0.1
#: [m/s] a speed this close to a grid point is that grid point (binary fractions of 0.1)
GRID_TOL = 1e-9
FIELD_DXI = 1.0  # [m] along-wind step of the turbulence bank (0.07-0.33 s at 15-3 m/s)
#: [s] the bank's fields are sized to serve this long a stretch at the task's top speed, twice
#: over (random start offsets); they are periodic and read modulo their length, so episodes of
#: any length are served and a field repeats no sooner than 2 FIELD_PERIOD_HORIZON seconds
FIELD_PERIOD_HORIZON = 120.0
#: the most banks kept alive by the cache at once (each is freed with its last environment)
MAX_CACHED_BANKS = 4
#: draws of the randomised parameters per episode start before the start is an error
MAX_REDRAWS = 20
#: further draws allowed for moments of inertia no body has (cheap: refused before any trim;
#: a randomisation is made only where at least 5 % of the inertia draws are bodies, so 1000
#: redraws all fail with probability below 0.95^1000 ~ 5e-23)
MAX_INERTIA_REDRAWS = 1000
#: further draws allowed, with ``weathercock=True``, for aerostats that do not weathervane
#: (each costs a trim; the task is made only where at least MIN_WEATHERCOCK_ACCEPTANCE of the
#: draws weathervane, so 1000 redraws all fail with probability below 0.95^1000)
MAX_WEATHERCOCK_REDRAWS = 1000
#: the smallest share of weathercock-stable draws a task with ``weathercock=True`` is made with
MIN_WEATHERCOCK_ACCEPTANCE = 0.05
#: draws per wind speed (the range's ends and middle) of the door's acceptance estimate
WEATHERCOCK_ACCEPTANCE_DRAWS = 100


# --- trims, shared between environments with the same parameters -------------------------------

#: the most trim tables kept by the cache (one per parameter set and wind range; a process that
#: walks through many parameter sets, such as a sweep, evicts the oldest first)
MAX_CACHED_TRIMS = 16
#: the most off-grid nominal trims an environment remembers (reset options at fixed speeds)
MAX_OFF_GRID_TRIMS = 64
_TRIMS: dict = {}


def _remembered(cache: dict, key, make, limit: int):
    """``cache[key]``, made by ``make()`` the first time; a cache holding ``limit`` entries
    forgets its oldest first (dicts keep insertion order)."""
    if key not in cache:
        while len(cache) >= limit:
            del cache[next(iter(cache))]
        cache[key] = make()
    return cache[key]


class TrimTable:
    """Exact trims of the task's wind range, computed once per parameter set by continuation in
    wind speed and shared by every environment in the process.

    ``speeds`` holds the points of the :data:`WIND_GRID` inside [lo, hi] and, where an end of
    the range is off the grid, that end itself (so the range's largest trim tension is
    checked); episodes draw their speed uniformly among the grid points (``draws``, indices
    into ``speeds``), or take ``lo`` when the range is a single speed. A range of two speeds
    with no grid point between them is a :class:`TaskError` naming the grid.
    """

    def __init__(self, params: Params, lo: float, hi: float):
        self.params = params
        grid = _grid_points(lo, hi)
        if lo == hi:
            self.speeds = grid if grid.size else np.array([float(lo)])
        elif not grid.size:
            raise TaskError(f"wind_speed ({lo:g}, {hi:g}) holds no point of the "
                            f"{WIND_GRID:g} m/s grid that episode speeds are drawn on (nearest: "
                            f"{_grid_speed(np.floor(lo / WIND_GRID)):g} and "
                            f"{_grid_speed(np.ceil(hi / WIND_GRID)):g} m/s); widen the range "
                            f"to hold one, or pass a single number to fix the speed exactly")
        else:
            ends = ([float(lo)] if grid[0] - lo > GRID_TOL else [],
                    [float(hi)] if hi - grid[-1] > GRID_TOL else [])
            self.speeds = np.concatenate([ends[0], grid, ends[1]])
        on_grid = np.isin(self.speeds, grid)
        self.draws = np.flatnonzero(on_grid) if on_grid.any() else np.array([0])
        self.key = key = (dumps_toml(params), tuple(self.speeds.tolist()))
        # winch-end tension (the winch's load) and the largest (the tether's, top end) per speed
        self.states, self.tensions, self.largest_tensions = _remembered(
            _TRIMS, key, lambda: _build_trims(params, self.speeds), MAX_CACHED_TRIMS)
        #: nominal trims at off-grid speeds already asked for (reset options), by speed
        self.off_grid: dict[float, np.ndarray] = {}

    def off_grid_trim(self, speed: float) -> np.ndarray:
        """The nominal trim at an off-grid ``speed``, continued from the nearest table trim
        the first time and remembered (at most :data:`MAX_OFF_GRID_TRIMS` speeds, the oldest
        forgotten first), so an episode reset at the same speed again costs no trim."""
        return _remembered(self.off_grid, speed, lambda: _continued_trim(self.params, self, speed),
                           MAX_OFF_GRID_TRIMS).copy()

    def equilibrium(self, k: int) -> Equilibrium:
        return Equilibrium(self.states[k].copy(), float(self.speeds[k]), self.params, 0.0, 0, {})

    def index(self, speed: float) -> int | None:
        """Index of ``speed`` in the table (within :data:`GRID_TOL`), or None."""
        k = self.nearest(speed)
        return k if abs(self.speeds[k] - speed) <= GRID_TOL else None

    def nearest(self, speed: float) -> int:
        """Index of the table speed nearest ``speed`` (the continuation's start)."""
        return int(np.argmin(np.abs(self.speeds - speed)))

    def contains(self, speed: float) -> bool:
        """Whether ``speed`` lies in the table's range (NaN does not)."""
        return self.speeds[0] - GRID_TOL <= speed <= self.speeds[-1] + GRID_TOL


def _grid_speed(i) -> float:
    """Grid point i [m/s], rounded so that 3.0 is 3.0 (not 30 * 0.1 = 3.0000000000000004)."""
    return float(np.round(i * WIND_GRID, 10))


def _grid_points(lo: float, hi: float) -> np.ndarray:
    """The :data:`WIND_GRID` points in [lo, hi] (an end within :data:`GRID_TOL` of a point
    counts as that point)."""
    first = int(np.ceil(lo / WIND_GRID - GRID_TOL / WIND_GRID))
    last = int(np.floor(hi / WIND_GRID + GRID_TOL / WIND_GRID))
    return np.round(np.arange(first, last + 1) * WIND_GRID, 10)


def _build_trims(params: Params, speeds: np.ndarray):
    model = Model(params, 0.0)
    eq = find_equilibrium(params, float(speeds[0]))
    states, ends = [], []
    for s in speeds:
        eq = find_equilibrium(params, float(s), guess=eq, max_step=WIND_GRID)
        states.append(eq.x)
        ends.append(model.end_tensions(eq.x))
    top, winch = np.array(ends).T
    return np.array(states), winch, largest_trim_tension(top, winch)


# --- turbulence bank ---------------------------------------------------------------------------

#: Banks in use, by (config, size, seed, length): weak references, so a bank is freed with the
#: last environment that holds it; at most MAX_CACHED_BANKS distinct banks are findable.
_BANKS: weakref.WeakValueDictionary = weakref.WeakValueDictionary()


def turbulence_bank(cfg: TurbulenceConfig, size: int, seed: int, length: float) -> np.ndarray:
    """``size`` frozen turbulence fields on an along-wind grid of step FIELD_DXI [m], shape
    (size, n_heights, n_xi, 3); shared by every environment in the process that asks for the
    same (config, size, seed, length) while one of them holds it.

    The field is generated in space (Taylor's frozen turbulence): the von Karman / Dryden
    spectra and the IEC coherence depend on frequency and wind speed only through the
    wavenumber f / U, so a field synthesised at U = 1 m/s with time step FIELD_DXI is the
    spatial field, valid for any mean speed once read with time step FIELD_DXI / U_a. The
    inverse-FFT synthesis makes each field exactly periodic with its length n_xi FIELD_DXI,
    which is why the environments read it modulo that length (a seamless wrap).
    """
    samples = length / FIELD_DXI + 1.0
    check_bank_size(cfg, size, samples)
    n = fft_length(samples)
    key = (cfg, size, seed, n)
    bank = _BANKS.get(key)
    if bank is None:
        rng = np.random.default_rng(seed)
        spatial = cfg.replace(dt=FIELD_DXI)
        bank = np.stack([veers_field(spatial, 1.0, n, rng) for _ in range(size)])
        if len(_BANKS) >= MAX_CACHED_BANKS:  # still held by live environments: not shared
            return bank
        _BANKS[key] = bank
    return bank


def check_bank_size(cfg: TurbulenceConfig, size: int, samples: float) -> None:
    """A bank above :data:`~aerostat_gym.wind.synthesis.MAX_FIELD_BYTES` is a TaskError naming
    the grid's settings and the memory it would take, raised before anything is allocated."""
    detail = (f" along the wind (every {FIELD_DXI:g} m over twice downwind_extent = "
              f"{cfg.downwind_extent:g} m + upwind_extent = {cfg.upwind_extent:g} m + "
              f"{FIELD_PERIOD_HORIZON:g} s at the top wind)")
    try:
        check_field_size(cfg, samples, size, detail)
    except ValueError as exc:
        raise TaskError(f"turbulence bank (wind_bank_size = {size}): {exc}; raise dz, lower "
                        "the extents or wind_bank_size") from None


def cached_bank_bytes() -> int:
    """Bytes held by the banks the cache can still find (all of them belong to live envs)."""
    return sum(b.nbytes for b in list(_BANKS.values()))


def field_length_needed(cfg: TurbulenceConfig, u_max: float,
                        horizon: float = FIELD_PERIOD_HORIZON) -> float:
    """Along-wind extent [m] of a bank field: what one stretch of ``horizon`` seconds at speeds
    up to u_max reads, plus as much again for random start offsets."""
    return 2.0 * (u_max * horizon + cfg.downwind_extent + cfg.upwind_extent) + 100.0


# --- episode start -----------------------------------------------------------------------------


@dataclass
class Episode:
    """What one episode start produced (the batch copies it into its arrays)."""

    x0: np.ndarray
    x_trim: np.ndarray
    tension_trim: float
    p: np.ndarray
    wp: np.ndarray
    field_index: int
    wind_speed: float
    params: Params
    info: dict


def reset_options(options) -> dict:
    """``reset``'s options as a dict (None: none); anything but a mapping is a TaskError."""
    if options is not None and not isinstance(options, Mapping):
        raise TaskError(f"reset options must be a dict such as {{'wind_speed': 10.0}}, got "
                        f"{options!r}")
    return dict(options or {})


def sample_episode(task: TaskConfig, trims: TrimTable, bank_shape, rng: np.random.Generator,
                   options: dict | None = None,
                   decorrelation: np.ndarray | None = None) -> Episode:
    """Draw one episode start: wind speed, parameters, trim, turbulence offset, perturbation.

    ``options`` (from ``reset(options=...)``) may fix ``wind_speed`` (exactly, inside the
    task's range) and ``perturbation`` (a preset name or dict) for this episode.
    ``decorrelation`` is the bank's, per pair of adjacent rows
    (:func:`aerostat_gym.wind.field.pair_decorrelations`); the episode takes the pair around
    its trim's CM, where the aerostat flies.
    """
    opts = reset_options(options)
    unknown = sorted(set(opts) - {"wind_speed", "perturbation"})
    if unknown:
        raise TaskError(f"unknown reset option(s) {unknown}; known: ['perturbation', 'wind_speed'] "
                        "(and, on the single environment alone, 'snapshot')")
    pert = (perturbation(opts["perturbation"], trims.params.tether.length,
                         float(trims.speeds[-1]))
            if "perturbation" in opts else task.resolved["perturbation"])
    U = _episode_speed(trims, opts.get("wind_speed"), rng)
    params, x_trim = _parameters(task, trims, U, rng)
    k = trims.index(U)
    tension = (trims.tensions[k] if params is trims.params and k is not None
               else Model(params, U).end_tensions(x_trim)[1])
    cfg = task.resolved["turbulence"]
    wp = mean_wind(params.wind, U)
    ua = set_advection(wp, cfg.reference_height, cfg.min_advection_speed)
    field_index, offset = _field(cfg, bank_shape, ua, wp, rng)
    if decorrelation is not None and not cfg.is_off:
        height = x_trim[StateLayout(params.tether.n_elements).at(S_Z)]
        set_row_decorrelation(wp, decorrelation_at(decorrelation, cfg.z_min, cfg.dz, height))
    x0, info = _perturb(x_trim, params, pert, wp, ua, rng)
    mix = task.resolved.get("turbulence_mix")
    if mix is not None:  # drawn last: the rest of the episode is the single-class task's
        cfg = cfg.replace(intensity=mix[0][int(rng.choice(len(mix[0]), p=mix[1]))])
        info["turbulence_class"] = cfg.intensity
        if cfg.is_off:  # calm air: the field is set (the bank's grid) and read at zero scale
            set_field_scale(wp, (0.0, 0.0, 0.0))
    sigmas = _intensity(cfg, wp)
    info.update({"wind_speed": U, "field_index": field_index, "field_offset_m": offset,
                 "turbulence_sigma_m_s": sigmas})
    return Episode(x0, x_trim, float(tension), pack_params(params), wp, field_index, U, params,
                   info)


def _episode_speed(trims: TrimTable, fixed, rng) -> float:
    """The episode's mean wind speed [m/s]: a grid point of the table drawn uniformly, or the
    reset option ``fixed``, exactly, where it lies in the task's range (no draw then: a
    seed's episode at a fixed speed is the one it always was)."""
    if fixed is None:
        return float(trims.speeds[trims.draws[int(rng.integers(len(trims.draws)))]])
    if not is_number(fixed):
        raise TaskError(f"reset option wind_speed must be a number [m/s], got {fixed!r}")
    if not trims.contains(fixed):  # NaN and infinities too
        raise TaskError(f"reset option wind_speed={fixed!r} is outside the task's range "
                        f"[{trims.speeds[0]}, {trims.speeds[-1]}] m/s")
    k = trims.index(fixed)
    return float(fixed) if k is None else float(trims.speeds[k])


def _continued_trim(params: Params, trims: TrimTable, U: float) -> np.ndarray:
    """Trim state of ``params`` at wind speed U, continued from the table's nearest trim (a few
    ms off the grid, where the nominal trim is; TrimError where none is found)."""
    return find_equilibrium(params, U, guess=trims.equilibrium(trims.nearest(U)),
                            max_step=WIND_GRID).x


def _parameters(task: TaskConfig, trims: TrimTable, U: float, rng) -> tuple[Params, np.ndarray]:
    """Nominal parameters and trim (the table's, or trimmed exactly at an off-grid U), or
    randomised ones re-trimmed from the nominal trim.

    The randomised parameters are drawn independently and uniformly in their ranges; a draw
    whose moments of inertia no body has (a triangle inequality broken, about 10 % of the
    default draws) is drawn again, so the episode's aerostat is uniform over the ranges'
    physical part. A draw that loads but does not trim is drawn again too, a bounded number of
    times (:data:`MAX_REDRAWS`). With ``weathercock=True`` so is a draw that does not weathervane
    at its trim (:func:`~aerostat_gym.analysis.directional.weathercock_stable`): the episode's
    aerostat is then uniform over the ranges' weathercock-stable part."""
    spec = task.resolved["randomize"]
    if not spec:
        k = trims.index(U)
        if k is not None:
            return trims.params, trims.states[k].copy()
        try:  # between two table trims of the same parameters: a failure is not expected
            return trims.params, trims.off_grid_trim(U)
        except TrimError as exc:
            raise TaskError(f"wind_speed {U} m/s: no trim for these parameters: {exc}") from None
    last = None
    failures = no_body = divergent = 0
    while (failures < MAX_REDRAWS and no_body < MAX_INERTIA_REDRAWS
           and divergent < MAX_WEATHERCOCK_REDRAWS):
        try:
            params = _drawn(trims.params, spec, rng)
            x_trim = _continued_trim(params, trims, U)
        except InertiaError as exc:
            no_body, last = no_body + 1, exc
            continue
        except (ParameterError, TrimError) as exc:
            failures, last = failures + 1, exc
            continue
        if not task.weathercock or weathercock_stable(Model(params, U), x_trim):
            return params, x_trim
        divergent, last = divergent + 1, "the static yaw moment does not restore"
    raise TaskError(f"randomize {spec} gave no feasible aerostat in "
                    f"{failures + no_body + divergent} draws at U = {U} m/s (last: {last}); "
                    "narrow the ranges")


def _drawn(base: Params, spec: Mapping[str, float], rng) -> Params:
    """One draw of the randomised parameters: each uniform within its relative half-range."""
    return apply_overrides(base, {key: get_parameter(base, key) * (1.0 + rng.uniform(-rel, rel))
                                  for key, rel in spec.items()})


def weathercock_acceptance(trims: TrimTable, spec: Mapping[str, float]) -> tuple[float, float]:
    """(share, wind speed): the smallest share of weathercock-stable aerostats among
    :data:`WEATHERCOCK_ACCEPTANCE_DRAWS` draws of ``spec`` at the table's lowest, middle and
    highest speed, and the speed where it is smallest. Fixed seed; each draw is judged at the
    nominal trim (the door's estimate; an episode judges a draw at its own trim); draws no body
    can have are left out, as an episode start redraws them."""
    rng = np.random.default_rng(0)
    worst = (1.0, float(trims.speeds[0]))
    for k in sorted({0, len(trims.speeds) // 2, len(trims.speeds) - 1}):
        U, stable, bodies = float(trims.speeds[k]), 0, 0
        for _ in range(WEATHERCOCK_ACCEPTANCE_DRAWS):
            try:
                params = _drawn(trims.params, spec, rng)
            except ParameterError:
                continue
            bodies += 1
            stable += weathercock_stable(Model(params, U), trims.states[k])
        worst = min(worst, (stable / max(bodies, 1), U))
    return worst


def check_weathercock_draws(task: TaskConfig, trims: TrimTable) -> None:
    """TaskError where ``weathercock=True`` would redraw nearly every randomised aerostat: fewer
    than :data:`MIN_WEATHERCOCK_ACCEPTANCE` of the draws weathervane at some speed of the
    range (measured once per parameter set, randomisation and range)."""
    spec = task.resolved["randomize"]
    if not (task.weathercock and spec):
        return
    key = (trims.key, tuple(sorted(spec.items())))
    share, U = _remembered(_WEATHERCOCK, key, lambda: weathercock_acceptance(trims, spec),
                           MAX_CACHED_TRIMS)
    if share < MIN_WEATHERCOCK_ACCEPTANCE:
        raise TaskError(
            f"weathercock=True: only {100 * share:.1f} % of the draws of randomize {spec} "
            f"weathervane at {U:g} m/s (their static yaw moment restores at yaw offsets up to "
            f"{WEATHERCOCK_OFFSETS_DEG[-1]:g} deg); at least "
            f"{100 * MIN_WEATHERCOCK_ACCEPTANCE:.0f} % must. Narrow the ranges of the fin lift "
            "slope and the hull efficiency (fins.CL_alpha, hull.eta_k), or set weathercock=False")


#: door estimates of the weathercock-stable share, by (trim table, randomisation)
_WEATHERCOCK: dict = {}


def _field(cfg, bank_shape, ua, wp, rng) -> tuple[int, float]:
    """Pick a bank field and a start offset; record its grid in wp (time step dxi / U_a) and
    mark it periodic: an episode longer than the field reads it round again."""
    if cfg.is_off:
        return 0, 0.0
    n_fields, nz, n_xi, _ = bank_shape
    index = int(rng.integers(n_fields))
    span = (n_xi - 1) * FIELD_DXI
    lo = cfg.downwind_extent
    # offsets from which a FIELD_PERIOD_HORIZON stretch needs no wrap (any offset is valid)
    hi = max(span - ua * FIELD_PERIOD_HORIZON - cfg.upwind_extent, lo)
    offset = float(rng.uniform(lo, hi))
    set_field(wp, cfg.z_min, cfg.dz, -offset / ua, FIELD_DXI / ua, cfg.downwind_extent,
              cfg.upwind_extent)
    set_periodic(wp)
    return index, offset


# --- per-episode turbulence intensity (issue 13) -------------------------------------------------


#: id -> bank already normalised; weak, so that a bank is still freed with its last
#: environment (a dead bank's entry goes with it, so an id is never matched stale)
_UNIT_BANKS: weakref.WeakValueDictionary = weakref.WeakValueDictionary()
#: id -> 1 - rho of each pair of adjacent rows of a normalised bank (pair_decorrelations),
#: computed once with the normalisation (about 50 ms for the default bank) and dropped with it
_DECORRELATIONS: dict[int, np.ndarray] = {}


def unit_bank(cfg: TurbulenceConfig, size: int, seed: int, length: float) -> np.ndarray:
    """The turbulence bank of ``cfg``'s class with unit-variance fields: :func:`turbulence_bank`
    of :meth:`TurbulenceConfig.unit`, normalised once by :func:`normalise_bank` (a bank shared
    through the cache is never rescaled again, so every environment reads the same bits)."""
    bank = turbulence_bank(cfg.unit(), size, seed, length)
    if _UNIT_BANKS.get(id(bank)) is not bank:
        normalise_bank(bank)
        _UNIT_BANKS[id(bank)] = bank
        _DECORRELATIONS[id(bank)] = pair_decorrelations(bank)
        weakref.finalize(bank, _DECORRELATIONS.pop, id(bank), None)
    return bank


def bank_decorrelation(bank: np.ndarray) -> np.ndarray:
    """1 - rho of each pair of adjacent rows of a bank from :func:`unit_bank` (rows - 1, 3),
    as computed when the bank was normalised."""
    return _DECORRELATIONS[id(bank)]


def normalise_bank(bank: np.ndarray) -> np.ndarray:
    """Scale every field of a bank, per height row and component, to unit mean square, in
    place; returns the bank.

    A Veers field's variance is itself random (Gaussian Fourier coefficients: the eight fields
    of the default bank range 0.46-1.40 in variance). Scaling a row by a constant leaves its
    spectral shape and its coherence with every other row unchanged, so the fields stay valid
    samples of the spectrum, and each episode's sigma is then the one its class asks for.
    """
    n = bank.shape[2]
    if n == 0:
        return bank
    for field in bank:  # one field at a time: no temporary the size of the bank
        rms = np.sqrt(np.einsum("kjc,kjc->kc", field, field) / n)
        field /= np.where(rms > 0.0, rms, 1.0)[:, None, :]
    return bank


def _intensity(cfg: TurbulenceConfig, wp: np.ndarray) -> tuple[float, float, float]:
    """Scale the bank's unit-variance field to this episode's mean wind (in place in wp) and
    return (sigma_u, sigma_v, sigma_w) [m/s]: the class's sigmas at the episode's U(h) for a
    wind-scaled class, the explicit ones for a 'fixed' config. Exact, because no intensity
    model's spectral shape changes with U (:meth:`TurbulenceConfig.unit`)."""
    if cfg.is_off:
        return (0.0, 0.0, 0.0)
    sigmas = cfg.for_wind(wp).sigmas
    set_field_scale(wp, sigmas)
    return tuple(float(s) for s in sigmas)


def _perturb(x_trim, params, pert, wp, ua, rng) -> tuple[np.ndarray, dict]:
    """Initial state: the trim swung rigidly about the winch (no element stretched), then the
    aerostat pitched about its confluence point (the top element keeps its length); and a
    1 - cos gust along the wind with probability gust_probability."""
    lay = StateLayout(params.tether.n_elements)
    x = x_trim.copy()
    draw = (lambda: 1.0) if pert["fixed"] else (lambda: rng.uniform(-1.0, 1.0))
    swing = draw() * pert["swing"]
    lateral = draw() * pert["lateral"]
    pitch = draw() * pert["pitch"]
    # the swing pivots on the winch, wherever the configuration puts it: positions are taken
    # relative to the anchor, rotated, and put back (exact for an anchor at the origin)
    anchor = np.array(params.tether.anchor_position, float)
    height = x[lay.at(S_Z)] - anchor[2]
    Rs = rotation_matrix(0.0, swing / height, 0.0) @ rotation_matrix(-lateral / height, 0.0, 0.0)
    nodes = x[lay.node_pos].reshape(-1, 3) - anchor
    x[lay.node_pos] = (nodes @ Rs.T + anchor).ravel()
    R = Rs @ rotation_matrix(*x[lay.euler])
    leash = np.array(params.derived.leash_position)
    conf = anchor + Rs @ (x[lay.cm_pos] - anchor) + R @ leash
    phi, theta, psi = euler_angles(R)
    theta += pitch
    x[lay.euler] = (phi, theta, psi)
    x[lay.cm_pos] = conf - rotation_matrix(phi, theta, psi) @ leash
    info = {"swing_m": swing, "lateral_m": lateral, "pitch_rad": pitch,
            "gust_amplitude_m_s": 0.0, "gust_duration_s": 0.0, "gust_onset_s": 0.0}
    if rng.uniform() < pert["gust_probability"]:
        amp = rng.uniform(*pert["gust_amplitude"])
        dur = rng.uniform(*pert["gust_duration"])
        onset = rng.uniform(*pert["gust_onset"])
        set_gust(wp, (amp, 0.0, 0.0), dur * ua, onset)
        info.update(gust_amplitude_m_s=amp, gust_duration_s=dur, gust_onset_s=onset)
    return x, info

