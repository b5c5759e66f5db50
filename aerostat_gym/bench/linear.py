"""Timing of the linear stability sweep, for ``aerostat-gym bench``.

Issue 3 budget: the whole 41-speed sweep of [LN02] Figure 9 (U = 0..20 m/s in 0.5 m/s steps),
trims included, in at most 10 s on a 2-core machine.
"""

from __future__ import annotations

import os
import time

import numpy as np

from ..analysis.modes import wind_sweep
from ..params import Params, load_params

BUDGET_S = 10.0


def bench_sweep(params: Params | None = None, speeds=None, repeats: int = 3) -> dict:
    """Median wall time of :func:`~aerostat_gym.analysis.modes.wind_sweep` (trim by
    continuation, finite-difference linearization, decoupling, both modal tables,
    classification and MAC tracking at every speed).

    Returns
    -------
    dict: ``linear_sweep_s`` (median), ``n_speeds``, ``per_speed_ms``, ``all_stable``,
    ``budget_s``, ``within_budget``, ``cpu_count``. The first (compiling) run is not timed.
    """
    params = params or load_params()
    speeds = np.arange(0.0, 20.0 + 1e-9, 0.5) if speeds is None else np.asarray(speeds, float)
    wind_sweep(params, speeds[:2])  # compile / load the numba cache
    times, sweep = [], None
    for _ in range(max(1, repeats)):
        t0 = time.perf_counter()
        sweep = wind_sweep(params, speeds)
        times.append(time.perf_counter() - t0)
    med = float(np.median(times))
    return {"linear_sweep_s": med, "n_speeds": int(speeds.size),
            "per_speed_ms": 1e3 * med / speeds.size, "all_stable": sweep.all_stable(),
            "budget_s": BUDGET_S, "within_budget": med <= BUDGET_S, "cpu_count": os.cpu_count()}

