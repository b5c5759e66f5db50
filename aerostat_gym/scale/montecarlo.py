"""Monte Carlo stability study over the estimated parameters: the serial path and the Ray path
share one per-sample function, so they give identical numbers for the same seed.

A study draws N parameter sets uniformly from the ranges of :mod:`aerostat_gym.scale.ranges`
(all values drawn up front from ``numpy.random.default_rng(seed)``, so a sample's values do not
depend on how the samples are batched or scheduled). A draw the loader refuses, such as moments
of inertia that break a triangle inequality, is not an aerostat and is redrawn
(:func:`draw_valid`); the study's metadata counts them. Each set is trimmed by continuation in
wind speed and linearized at every speed of the sweep; per speed the study records, for each
Figure 9 mode, whether it is stable, its damping ratio and period, whether every mode of the
linear model (tether harmonics included) is stable, and the largest real part of a non-neutral
eigenvalue. The Table 2 periods are read at 1 m/s, as in the sensitivity table.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..analysis.modes import FIGURE9_MODES, SETS, ModalAnalysis, analyse
from ..analysis.reference import TABLE2, TABLE2_MODES
from ..analysis.trim import TrimError, find_equilibrium
from ..checks import is_whole
from ..params import ParameterError, Params, apply_overrides
from .cluster import start_ray, stop_ray
from .ranges import ParameterRange

#: (set, label) of every mode followed per sample: the modes of [LN02] Figure 9 plus yaw.
MODES = tuple((subset, label) for subset in SETS for label in FIGURE9_MODES[subset])
PERIOD_KEYS = tuple(TABLE2)
#: Wind speed of the Table 2 periods [m/s] (the linear column of [LN02] Table 2).
PERIOD_SPEED = 1.0
#: Default sweep [m/s]: the 0.5 m/s grid of [LN02] Figure 9 without U = 0, where only the
#: tether's material damping acts and every aerostat mode is undamped whatever the parameters.
SWEEP_SPEEDS = tuple(0.5 * k for k in range(1, 41))


@dataclass
class SampleResult:
    """Stability of one parameter set along the wind sweep (nan where not computed).

    Attributes
    ----------
    values : the drawn value of each uncertain parameter.
    stable : (speed, mode) 1.0 stable, 0.0 unstable, nan if the mode was not found or the trim
        failed.
    zeta : (speed, mode) damping ratio.
    period : (speed, mode) period [s] (inf for a real eigenvalue).
    all_stable : (speed,) every mode of the linear model stable (1.0 / 0.0 / nan).
    max_real : (speed,) largest Re(lambda) of a non-neutral mode [1/s].
    periods : the Table 2 periods at :data:`PERIOD_SPEED` [s], in :data:`PERIOD_KEYS` order
        (nan for a mode that is not oscillatory there).
    error : empty, or why the sample stopped (a failed trim, an impossible parameter set).
    """

    values: np.ndarray
    stable: np.ndarray
    zeta: np.ndarray
    period: np.ndarray
    all_stable: np.ndarray
    max_real: np.ndarray
    periods: np.ndarray
    error: str = ""


@dataclass
class Study:
    """All samples of one Monte Carlo run and how it ran.

    Attributes
    ----------
    keys : names of the uncertain parameters.
    ranges : (low, high) of each.
    nominal : baseline value of each.
    speeds : wind speeds of the sweep [m/s].
    seed : the sampling seed.
    samples : one :class:`SampleResult` per parameter set.
    backend : "serial" or "ray".
    seconds : wall time of the evaluation (after Ray start-up).
    meta : Ray start-up figures, workers, batch size.
    """

    keys: list
    ranges: list
    nominal: list
    speeds: np.ndarray
    seed: int
    samples: list
    backend: str
    seconds: float
    meta: dict = field(default_factory=dict)

    def stack(self, name: str) -> np.ndarray:
        """One attribute of every sample stacked along a first axis (sample)."""
        return np.stack([getattr(s, name) for s in self.samples])


#: A study gives up when this many draws per requested set left it short of valid sets.
MAX_DRAWS_PER_SET = 100


def _uniform(rng: np.random.Generator, ranges: list[ParameterRange], rows: int) -> np.ndarray:
    u = rng.uniform(size=(rows, len(ranges)))
    low = np.array([r.low for r in ranges])
    high = np.array([r.high for r in ranges])
    return low + u * (high - low)


#: Most parameter sets one study draws (each keeps its periods, damping ratios and margins at
#: every wind speed: a million sets of the default sweep is about 1 GB).
MAX_SAMPLES = 1_000_000


def check_samples(n) -> None:
    if not is_whole(n) or n > MAX_SAMPLES:
        raise ValueError(f"--samples must be an integer in [1, {MAX_SAMPLES}], got {n!r}")


def draw_values(ranges: list[ParameterRange], n: int, seed: int) -> np.ndarray:
    """(n, len(ranges)) values, each uniform in its range, from ``default_rng(seed)``.

    Parameters
    ----------
    ranges : the uncertain parameters.
    n : number of parameter sets.
    seed : seed of the generator.
    """
    check_samples(n)
    return _uniform(np.random.default_rng(seed), ranges, n)


def draw_valid(base: Params, ranges: list[ParameterRange], n: int,
               seed: int) -> tuple[np.ndarray, list[str]]:
    """n parameter sets uniform in their ranges and conditioned on being valid parameter sets.

    A draw the loader refuses (:class:`ParameterError`: e.g. three independently drawn moments
    of inertia that break a triangle inequality, no mass distribution has them, or a set with
    no net lift) is not an aerostat, so it is redrawn rather than counted: the study is over n
    aerostats that can exist. The first n draws are :func:`draw_values`'s, so a study whose
    draws are all valid is unchanged; the further draws come from the same generator.

    Returns
    -------
    values : (n, len(ranges)) drawn values, in range order.
    rejected : the loader's message for every draw redrawn, in draw order.
    """
    check_samples(n)
    rng = np.random.default_rng(seed)
    kept: list[np.ndarray] = []
    rejected: list[str] = []
    drawn = 0
    while len(kept) < n:
        if drawn >= MAX_DRAWS_PER_SET * n:
            raise ValueError(
                f"only {len(kept)} of {drawn} parameter sets drawn from the ranges are valid "
                f"(first refusal: {rejected[0]}); narrow the ranges")
        rows = _uniform(rng, ranges, n - len(kept))
        drawn += len(rows)
        for row in rows:
            try:
                sample_params(base, ranges, row)
                kept.append(row)
            except ParameterError as exc:
                rejected.append(str(exc))
    return np.array(kept), rejected


def _rejection_meta(rejected: list[str]) -> dict:
    return {"rejected": len(rejected), "rejections": rejected[:5]}


def check_speeds(speeds) -> np.ndarray:
    """Wind speeds of the sweep as a sorted, finite, positive float array."""
    s = np.asarray(speeds, float).ravel()
    if s.size == 0 or not np.all(np.isfinite(s)) or np.any(s <= 0):
        raise ValueError(f"wind speeds must be finite and > 0 (at U = 0 every aerostat mode is "
                         f"undamped), got {list(s)}")
    return np.unique(s)


def sample_params(base: Params, ranges: list[ParameterRange], values: np.ndarray) -> Params:
    """``base`` with every uncertain parameter set to its drawn value, applied in range order.

    Notes
    -----
    With the documented ranges the CM shift (which moves the nose and fin points, and the CB,
    aft by the shift) is applied before the CB position, which then sets the CB relative to the
    CM outright: the two draws are independent uncertainties of the fin arm and of the CB.
    Consecutive plain-field draws (``override`` set) are applied as one override, so that the
    checks between fields see the drawn set, not a half-drawn one (three drawn moments of
    inertia can satisfy the triangle inequalities where the first two with the nominal third
    do not, and the other way round).
    """
    p, pending = base, {}
    for r, v in zip(ranges, values, strict=True):
        if r.override is not None:
            pending[r.override] = float(v)
            continue
        if pending:
            p, pending = apply_overrides(p, pending), {}
        p = r.put(p, float(v))
    return apply_overrides(p, pending) if pending else p


def _empty(values: np.ndarray, n_speeds: int, error: str = "") -> SampleResult:
    grid = np.full((n_speeds, len(MODES)), np.nan)
    return SampleResult(np.asarray(values, float), grid.copy(), grid.copy(), grid.copy(),
                        np.full(n_speeds, np.nan), np.full(n_speeds, np.nan),
                        np.full(len(PERIOD_KEYS), np.nan), error)


def _record(res: SampleResult, k: int, an: ModalAnalysis) -> None:
    for j, (subset, label) in enumerate(MODES):
        m = an.find(subset, label)
        if m is not None:
            res.stable[k, j] = float(m.stable)
            res.zeta[k, j] = m.zeta
            res.period[k, j] = m.period
    res.all_stable[k] = float(an.all_stable())
    res.max_real[k] = max(m.eigenvalue.real for m in an.long + an.lat if not m.neutral)


def table2_periods(an: ModalAnalysis) -> list[float]:
    """Periods [s] of the Table 2 modes, nan where the mode is missing or not oscillatory (a
    real eigenvalue has no period: 2 pi / |lambda| of a divergence is not one)."""
    out = []
    for key in PERIOD_KEYS:
        m = an.find(*TABLE2_MODES[key])
        out.append(m.period if m is not None and m.oscillatory else math.nan)
    return out


def evaluate_sample(base: Params, ranges: list[ParameterRange], values: np.ndarray,
                    speeds: np.ndarray) -> SampleResult:
    """Trim and linearize one parameter set at every speed (the one per-sample function).

    Parameters
    ----------
    base : base parameter set.
    ranges : the uncertain parameters.
    values : drawn value of each, in range order.
    speeds : sorted wind speeds of the sweep [m/s].

    Returns
    -------
    :class:`SampleResult`; a trim failure keeps the speeds done so far and names the speed.
    """
    res = _empty(values, len(speeds))
    try:
        params = sample_params(base, ranges, values)
    except (ParameterError, ValueError) as exc:
        res.error = f"invalid parameter set: {exc}"
        return res
    eq = None
    try:
        for u in sorted(set(speeds.tolist()) | {PERIOD_SPEED}):
            eq = find_equilibrium(params, u, guess=eq)
            an = analyse(params, eq)
            if u == PERIOD_SPEED:
                res.periods[:] = table2_periods(an)
            hit = np.flatnonzero(speeds == u)
            if hit.size:
                _record(res, int(hit[0]), an)
    except TrimError as exc:
        res.error = f"trim failed: {exc}"
    except np.linalg.LinAlgError as exc:
        res.error = f"eigen-decomposition failed at U = {u} m/s: {exc}"
    return res


def evaluate_batch(base: Params, ranges: list[ParameterRange], values: np.ndarray,
                   speeds: np.ndarray) -> list[SampleResult]:
    """:func:`evaluate_sample` over the rows of ``values`` (the body of one Ray task)."""
    return [evaluate_sample(base, ranges, row, speeds) for row in values]


def _study(base, ranges, speeds, seed, samples, backend, seconds, meta) -> Study:
    return Study([r.key for r in ranges], [(r.low, r.high) for r in ranges],
                 [r.nominal for r in ranges], speeds, seed, samples, backend, seconds, meta)


def run_serial(base: Params, ranges: list[ParameterRange], n: int, seed: int,
               speeds=SWEEP_SPEEDS, progress: Callable[[int, int], None] | None = None) -> Study:
    """Evaluate ``n`` parameter sets in this process, in order.

    Parameters
    ----------
    base : base parameter set.
    ranges : the uncertain parameters.
    n : number of parameter sets.
    seed : sampling seed.
    speeds : wind speeds of the sweep [m/s].
    progress : called with (done, n) after every sample.
    """
    speeds = check_speeds(speeds)
    values, rejected = draw_valid(base, ranges, n, seed)
    t0 = time.perf_counter()
    out = []
    for i, row in enumerate(values):
        out.append(evaluate_sample(base, ranges, row, speeds))
        if progress:
            progress(i + 1, n)
    return _study(base, ranges, speeds, seed, out, "serial", time.perf_counter() - t0,
                  _rejection_meta(rejected))


def batch_bounds(n: int, batch_size: int) -> list[tuple[int, int]]:
    """[start, stop) of consecutive batches covering range(n)."""
    if batch_size < 1:
        raise ValueError(f"--batch-size must be >= 1, got {batch_size}")
    return [(i, min(i + batch_size, n)) for i in range(0, n, batch_size)]


def default_batch_size(n: int, cpus: float) -> int:
    """About four batches per CPU (load balance against per-task overhead), at least one set."""
    return max(1, math.ceil(n / max(4 * cpus, 1.0)))


def run_ray(base: Params, ranges: list[ParameterRange], n: int, seed: int,
            speeds=SWEEP_SPEEDS, address: str | None = None, workers: int | None = None,
            batch_size: int | None = None,
            progress: Callable[[int, int], None] | None = None) -> Study:
    """Evaluate ``n`` parameter sets as Ray tasks in batches (one CPU per task).

    Parameters
    ----------
    base : base parameter set.
    ranges : the uncertain parameters.
    n : number of parameter sets.
    seed : sampling seed.
    speeds : wind speeds of the sweep [m/s].
    address : cluster to join; None starts a local instance.
    workers : CPUs of the local instance (default: the machine's cores).
    batch_size : parameter sets per task (default :func:`default_batch_size`).
    progress : called with (done, n) as batches finish.
    """
    speeds = check_speeds(speeds)
    values, rejected = draw_valid(base, ranges, n, seed)
    start = start_ray("running the study on Ray", address, workers,
                      hint="; or run it without Ray with --serial")
    ray = start.ray
    try:
        size = batch_size or default_batch_size(n, start.cpus)
        bounds = batch_bounds(n, size)
        task = ray.remote(num_cpus=1)(evaluate_batch)
        t0 = time.perf_counter()
        base_ref, ranges_ref, speeds_ref = ray.put(base), ray.put(ranges), ray.put(speeds)
        futures = [task.remote(base_ref, ranges_ref, values[a:b], speeds_ref) for a, b in bounds]
        results = _gather(ray, futures, bounds, n, progress)
        seconds = time.perf_counter() - t0
    finally:
        stop_ray(start)
    meta = {"ray_import_s": start.import_s, "ray_init_s": start.init_s, "cpus": start.cpus,
            "batch_size": size, "batches": len(bounds), "address": address or "local",
            **_rejection_meta(rejected)}
    samples = [s for batch in results for s in batch]
    return _study(base, ranges, speeds, seed, samples, "ray", seconds, meta)


def _gather(ray, futures: list, bounds: list, n: int, progress) -> list:
    """Results of ``futures`` in submission order, reporting progress as they complete."""
    index = {f: k for k, f in enumerate(futures)}
    results, pending, done = [None] * len(futures), list(futures), 0
    while pending:
        ready, pending = ray.wait(pending, num_returns=1)
        for f in ready:
            k = index[f]
            results[k] = ray.get(f)
            done += bounds[k][1] - bounds[k][0]
            if progress:
                progress(done, n)
    return results


def studies_identical(a: Study, b: Study) -> bool:
    """True if two studies hold bit-identical samples (nan equal to nan, same errors)."""
    if len(a.samples) != len(b.samples) or a.keys != b.keys:
        return False
    names = ("values", "stable", "zeta", "period", "all_stable", "max_real", "periods")
    if any(not np.array_equal(a.stack(k), b.stack(k), equal_nan=True) for k in names):
        return False
    return [s.error for s in a.samples] == [s.error for s in b.samples]
