"""The task: its configuration (the environment's constructor arguments, validated once) and
the episode start: trim table, turbulence bank, perturbation and domain randomisation.

Everything random at an episode start is drawn from the one generator passed in, in a fixed
order, so a seed fixes the episode and environment i of a batch matches a single environment
seeded the same way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..analysis.trim import Equilibrium, find_equilibrium
from ..params import Params, apply_overrides, dumps_toml, load_params
from ..physics.core import rotation_matrix
from ..physics.layout import StateLayout, pack_params
from ..physics.wind import pack_wind, set_advection, set_field, set_gust
from ..simulation import INTEGRATORS, Model
from ..wind.presets import TurbulenceConfig, resolve_turbulence
from ..wind.synthesis import fft_length, veers_field
from . import spaces

#: Perturbation presets: maximum along-wind swing and lateral displacement of the aerostat [m]
#: (a rigid rotation of aerostat and tether about the winch), pitch kick about the confluence
#: point [rad], and a 1 - cos gust along the wind drawn with this probability. Amplitudes are
#: drawn uniformly in [-max, max]; with "fixed": True they are applied as given (signed).
PERTURBATIONS = {
    "none": {"swing": 0.0, "lateral": 0.0, "pitch": 0.0, "gust_probability": 0.0,
             "fixed": False},
    "displacement": {"swing": 10.0, "lateral": 5.0, "pitch": 0.05, "gust_probability": 0.0},
    "gust": {"swing": 0.0, "lateral": 0.0, "pitch": 0.0, "gust_probability": 1.0},
    "mixed": {"swing": 10.0, "lateral": 5.0, "pitch": 0.05, "gust_probability": 0.5},
}
GUST_DEFAULTS = {"gust_amplitude": (1.0, 4.0), "gust_duration": (5.0, 20.0),
                 "gust_onset": (0.0, 30.0)}
#: Estimated parameters randomised by ``randomize=True`` (relative half-ranges).
DEFAULT_RANDOMIZATION = {
    "aerostat.Ixx": 0.3, "aerostat.Iyy": 0.3, "aerostat.Izz": 0.3, "hull.Cdc": 0.2,
    "hull.eta_k": 0.2, "fins.CL_alpha": 0.2, "tether.Cd_normal": 0.2, "aerostat.mass": 0.03,
}
WIND_GRID = 0.1  # [m/s] episode wind speeds are drawn on this grid, where the trims are exact
FIELD_DXI = 1.0  # [m] along-wind step of the turbulence bank (0.07-0.33 s at 15-3 m/s)
DEFAULT_HORIZON = 120.0  # [s] field coverage when the episode length is not known


class TaskError(ValueError):
    """An invalid environment argument (the message names it and the value)."""


def _range(name, value, lo_min=0.0):
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise TaskError(f"{name} must be a (low, high) pair, got {value!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo_min <= lo <= hi):
        raise TaskError(f"{name} must satisfy {lo_min} <= low <= high (finite), got {value!r}")
    return lo, hi


def _positive(name, value):
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise TaskError(f"{name} must be a finite number > 0, got {value!r}")
    return float(value)


@dataclass(frozen=True)
class TaskConfig:
    """Validated environment arguments (see :class:`aerostat_gym.envs.TetheredAerostatEnv`)."""

    wind_speed: tuple = (3.0, 15.0)
    turbulence: object = "moderate"
    perturbation: object = "mixed"
    tether_length: float | None = None
    n_elements: int | None = None
    integrator: str = "semi-implicit"
    control_step: float = 0.2
    params: object = None
    overrides: dict | None = None
    randomize: object = None
    obs_noise: float = 0.0
    reward_weights: dict | None = None
    observation: str = "standard"
    wind_bank_size: int = 8
    wind_bank_seed: int = 0
    resolved: dict = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self):
        r = self.resolved
        r["wind_speed"] = _range("wind_speed", self.wind_speed)
        try:
            r["turbulence"] = resolve_turbulence(self.turbulence)
        except (TypeError, ValueError) as exc:
            raise TaskError(f"turbulence: {exc}") from None
        r["perturbation"] = _perturbation(self.perturbation)
        if self.integrator not in INTEGRATORS:
            raise TaskError(f"unknown integrator {self.integrator!r}; choose one of {INTEGRATORS}")
        dt = _positive("control_step", self.control_step)
        if dt > 1.0:
            raise TaskError(f"control_step must be <= 1 s (the axial mode is ~3 s), got {dt!r}")
        if self.observation not in ("standard", "full"):
            raise TaskError(f"unknown observation {self.observation!r}; choose 'standard' or "
                            "'full'")
        if not (isinstance(self.obs_noise, (int, float)) and math.isfinite(self.obs_noise)
                and self.obs_noise >= 0):
            raise TaskError(f"obs_noise must be a finite number >= 0, got {self.obs_noise!r}")
        try:
            r["weights"] = spaces.weights_vector(self.reward_weights)
        except ValueError as exc:
            raise TaskError(str(exc)) from None
        if not (isinstance(self.wind_bank_size, int) and self.wind_bank_size >= 1):
            raise TaskError(f"wind_bank_size must be an integer >= 1, got {self.wind_bank_size!r}")
        r["params"] = self._params()
        r["randomize"] = self._randomize(r["params"])

    def _params(self) -> Params:
        p = self.params
        if p is None or isinstance(p, (str, Path)):
            p = load_params(p)
        elif not isinstance(p, Params):
            raise TaskError(f"params must be a Params, a TOML path or None, got {type(p).__name__}")
        over = dict(self.overrides or {})
        if self.tether_length is not None:
            over["tether.length"] = self.tether_length
        if self.n_elements is not None:
            over["tether.n_elements"] = self.n_elements
        return apply_overrides(p, over) if over else p

    def _randomize(self, params: Params) -> dict:
        if self.randomize is None or self.randomize is False:
            return {}
        spec = DEFAULT_RANDOMIZATION if self.randomize is True else self.randomize
        if not isinstance(spec, dict):
            raise TaskError(f"randomize must be None, True or a dict, got {self.randomize!r}")
        for key, rel in spec.items():
            if not (isinstance(rel, (int, float)) and 0 <= rel < 1):
                raise TaskError(f"randomize[{key!r}] must be a relative half-range in [0, 1), "
                                f"got {rel!r}")
            apply_overrides(params, {key: _get(params, key)})  # names an unknown key
        return dict(spec)

    @property
    def params_resolved(self) -> Params:
        return self.resolved["params"]


def _get(params: Params, key: str):
    sec, _, name = key.partition(".")
    try:
        return getattr(getattr(params, sec), name)
    except AttributeError:
        raise TaskError(f"unknown parameter {key!r} in randomize") from None


def _perturbation(spec) -> dict:
    if isinstance(spec, str):
        if spec not in PERTURBATIONS:
            raise TaskError(f"unknown perturbation {spec!r}; choose one of {list(PERTURBATIONS)}"
                            " or pass a dict")
        spec = PERTURBATIONS[spec]
    if not isinstance(spec, dict):
        raise TaskError(f"perturbation must be a preset name or a dict, got {spec!r}")
    out = {**PERTURBATIONS["none"], **GUST_DEFAULTS}
    unknown = sorted(set(spec) - set(out))
    if unknown:
        raise TaskError(f"unknown perturbation key(s) {unknown}; known: {sorted(out)}")
    out.update(spec)
    for k in ("swing", "lateral", "pitch"):
        ok = isinstance(out[k], (int, float)) and math.isfinite(out[k])
        if not ok or (out[k] < 0 and not out["fixed"]):
            raise TaskError(f"perturbation {k} must be a finite number (>= 0 unless fixed), "
                            f"got {out[k]!r}")
    if not isinstance(out["fixed"], bool):
        raise TaskError(f"perturbation fixed must be True or False, got {out['fixed']!r}")
    if not 0 <= out["gust_probability"] <= 1:
        raise TaskError(f"perturbation gust_probability must be in [0, 1], got "
                        f"{out['gust_probability']!r}")
    for k in GUST_DEFAULTS:
        out[k] = _range(f"perturbation {k}", out[k])
    return out


# --- trims, shared between environments with the same parameters -------------------------------

_TRIMS: dict = {}


class TrimTable:
    """Exact trims on the wind-speed grid of the task, computed once per parameter set by
    continuation in wind speed and shared by every environment in the process."""

    def __init__(self, params: Params, lo: float, hi: float):
        self.params = params
        self.speeds = np.round(np.arange(round(lo / WIND_GRID), round(hi / WIND_GRID) + 1)
                               * WIND_GRID, 10)
        key = (dumps_toml(params), float(self.speeds[0]), float(self.speeds[-1]))
        if key not in _TRIMS:
            _TRIMS[key] = _build_trims(params, self.speeds)
        self.states, self.tensions = _TRIMS[key]

    def equilibrium(self, k: int) -> Equilibrium:
        return Equilibrium(self.states[k].copy(), float(self.speeds[k]), self.params, 0.0, 0, {})


def _build_trims(params: Params, speeds: np.ndarray):
    model = Model(params, 0.0)
    eq = find_equilibrium(params, float(speeds[0]))
    states, tensions = [], []
    for s in speeds:
        eq = find_equilibrium(params, float(s), guess=eq, max_step=WIND_GRID)
        states.append(eq.x)
        tensions.append(model.end_tensions(eq.x)[1])
    return np.array(states), np.array(tensions)


# --- turbulence bank ---------------------------------------------------------------------------

_BANKS: dict = {}


def turbulence_bank(cfg: TurbulenceConfig, size: int, seed: int, length: float) -> np.ndarray:
    """``size`` frozen turbulence fields on an along-wind grid of step FIELD_DXI [m], shape
    (size, n_heights, n_xi, 3); cached per (config, size, seed, length).

    The field is generated in space (Taylor's frozen turbulence): the von Karman / Dryden
    spectra and the IEC coherence depend on frequency and wind speed only through the
    wavenumber f / U, so a field synthesised at U = 1 m/s with time step FIELD_DXI is the
    spatial field, valid for any mean speed once read with time step FIELD_DXI / U_a.
    """
    n = fft_length(length / FIELD_DXI + 1.0)
    key = (cfg, size, seed, n)
    if key not in _BANKS:
        rng = np.random.default_rng(seed)
        spatial = cfg.replace(dt=FIELD_DXI)
        _BANKS[key] = np.stack([veers_field(spatial, 1.0, n, rng) for _ in range(size)])
    return _BANKS[key]


def field_length_needed(cfg: TurbulenceConfig, u_max: float, horizon: float) -> float:
    """Along-wind extent [m] a bank field needs to serve one episode at speeds up to u_max,
    plus as much again for random start offsets."""
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


def sample_episode(task: TaskConfig, trims: TrimTable, bank_shape, horizon: float,
                   rng: np.random.Generator, options: dict | None = None) -> Episode:
    """Draw one episode start: wind speed, parameters, trim, turbulence offset, perturbation.

    ``options`` (from ``reset(options=...)``) may fix ``wind_speed`` (snapped to the 0.1 m/s
    grid) and ``perturbation`` (a preset name or dict) for this episode.
    """
    opts = dict(options or {})
    unknown = sorted(set(opts) - {"wind_speed", "perturbation"})
    if unknown:
        raise TaskError(f"unknown reset option(s) {unknown}; known: ['perturbation', 'wind_speed']")
    pert = _perturbation(opts["perturbation"]) if "perturbation" in opts else \
        task.resolved["perturbation"]
    k = _speed_index(trims, opts.get("wind_speed"), rng)
    U = float(trims.speeds[k])
    params, x_trim = _parameters(task, trims, k, rng)
    tension = (trims.tensions[k] if params is trims.params
               else Model(params, U).end_tensions(x_trim)[1])
    cfg = task.resolved["turbulence"]
    w = params.wind
    wp = pack_wind(w.profile, U, w.direction_deg, w.reference_height, w.shear_exponent,
                   w.roughness_length)
    ua = set_advection(wp, cfg.reference_height, cfg.min_advection_speed)
    field_index, offset = _field(cfg, bank_shape, ua, horizon, wp, rng)
    x0, info = _perturb(x_trim, params, pert, wp, ua, rng)
    info.update({"wind_speed": U, "field_index": field_index, "field_offset_m": offset})
    return Episode(x0, x_trim, float(tension), pack_params(params), wp, field_index, U, params,
                   info)


def _speed_index(trims: TrimTable, fixed, rng) -> int:
    if fixed is None:
        return int(rng.integers(len(trims.speeds)))
    k = int(np.argmin(np.abs(trims.speeds - float(fixed))))
    if abs(trims.speeds[k] - float(fixed)) > WIND_GRID / 2 + 1e-9:
        raise TaskError(f"reset option wind_speed={fixed!r} is outside the task's range "
                        f"[{trims.speeds[0]}, {trims.speeds[-1]}] m/s")
    return k


def _parameters(task: TaskConfig, trims: TrimTable, k: int, rng) -> tuple[Params, np.ndarray]:
    """Nominal parameters and trim, or randomised ones re-trimmed from the nominal trim."""
    spec = task.resolved["randomize"]
    if not spec:
        return trims.params, trims.states[k].copy()
    base = trims.params
    over = {key: _get(base, key) * (1.0 + rng.uniform(-rel, rel)) for key, rel in spec.items()}
    params = apply_overrides(base, over)
    eq = find_equilibrium(params, float(trims.speeds[k]), guess=trims.equilibrium(k),
                          max_step=WIND_GRID)
    return params, eq.x


def _field(cfg, bank_shape, ua, horizon, wp, rng) -> tuple[int, float]:
    """Pick a bank field and a start offset; record its grid in wp (time step dxi / U_a)."""
    if cfg.is_off:
        return 0, 0.0
    n_fields, nz, n_xi, _ = bank_shape
    index = int(rng.integers(n_fields))
    span = (n_xi - 1) * FIELD_DXI
    lo = cfg.downwind_extent
    hi = span - ua * horizon - cfg.upwind_extent
    if hi < lo:
        raise TaskError(f"the turbulence bank ({span:.0f} m) is too short for {horizon:.0f} s at "
                        f"U_a = {ua:.1f} m/s")
    offset = float(rng.uniform(lo, hi))
    set_field(wp, cfg.z_min, cfg.dz, -offset / ua, FIELD_DXI / ua, cfg.downwind_extent,
              cfg.upwind_extent)
    return index, offset


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
    height = x[lay.cm_pos][2]
    Rs = _rot_y(swing / height) @ _rot_x(-lateral / height)
    nodes = x[lay.node_pos].reshape(-1, 3)
    x[lay.node_pos] = (nodes @ Rs.T).ravel()
    R = Rs @ rotation_matrix(*x[lay.euler])
    leash = np.array(params.derived.leash_position)
    conf = Rs @ x[lay.cm_pos] + R @ leash
    phi, theta, psi = _euler(R)
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


def _rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _euler(R):
    """Z-Y-X Euler angles (phi, theta, psi) of a body-to-inertial rotation matrix."""
    return (math.atan2(R[2, 1], R[2, 2]), -math.asin(max(-1.0, min(1.0, R[2, 0]))),
            math.atan2(R[1, 0], R[0, 0]))
