"""Speed and accuracy figures printed by ``aerostat-gym bench``.

Every figure is a median over repeats, measured on the machine it runs on, single thread.
"""

from __future__ import annotations

import math
import os
import platform
import time

import numpy as np
from numba import njit

from ..analysis.trim import find_equilibrium
from ..params import Params, load_params
from ..physics.core import rhs
from ..physics.state import S_THETA, S_X
from ..sim import BRAKED, Model, simulate
from .env import bench_env
from .linear import bench_sweep
from .moordyn import compare_with_moordyn
from .wind import bench_wind


@njit(cache=True)
def _rhs_loop(N, t, x, u, p, wp, wf, dx, w):
    acc = 0.0
    for _ in range(N):
        x[0] += 1e-12  # defeat loop-invariant hoisting
        rhs(t, x, u, p, wp, wf, dx, w)
        acc += dx[0]
    return acc


def _median_time(fn, repeats: int) -> float:
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return float(np.median(ts))


def bench_rhs(model: Model, x: np.ndarray, n_calls: int = 200_000, repeats: int = 5) -> float:
    """Median cost of one right-hand-side evaluation [us] from a compiled loop."""
    dx = np.empty_like(x)
    args = (0.0, x.copy(), BRAKED, model.p, model.wp, model.wf, dx, model.work)
    _rhs_loop(10, *args)
    return _median_time(lambda: _rhs_loop(n_calls, *args), repeats) / n_calls * 1e6


def bench_integrator(model: Model, x0: np.ndarray, integrator: str, seconds: float = 60.0,
                     repeats: int = 3) -> dict:
    """Real-time factor (simulated / wall seconds) for one call advancing ``seconds``."""
    x = x0.copy()
    model.advance(x, 0.0, 1.0, BRAKED, integrator)  # compile

    def run():
        y = x0.copy()
        model.advance(y, 0.0, seconds, BRAKED, integrator)

    wall = _median_time(run, repeats)
    dt = model.rk4_dt() if integrator == "rk4" else model.params.simulation.semi_implicit_dt
    return {"real_time_factor": seconds / wall, "wall_s": wall, "dt_s": dt}


def semi_implicit_accuracy(params: Params, wind_speed: float = 10.0, seconds: float = 60.0) -> dict:
    """Semi-implicit against RK4 over ``seconds`` from a perturbed trim: max position error [m]
    and max attitude error [rad] of the aerostat."""
    eq = find_equilibrium(params, wind_speed)
    lay = Model(params).layout
    x = eq.x.copy()
    x[lay.at(S_X)] += 1.0
    x[lay.at(S_THETA)] += 0.02
    a = simulate(params, x, seconds, wind=wind_speed, integrator="rk4", output_dt=0.1)
    b = simulate(params, x, seconds, wind=wind_speed, integrator="semi-implicit", output_dt=0.1)
    return {
        "position_error_max_m": float(np.max(np.linalg.norm(a.cm_pos - b.cm_pos, axis=1))),
        "attitude_error_max_rad": float(np.max(np.abs(a.euler - b.euler))),
        "position_excursion_max_m": float(np.max(np.linalg.norm(a.cm_pos - eq.x[lay.cm_pos], axis=1))),
        "semi_implicit_dt_s": params.simulation.semi_implicit_dt,
        "scenario": f"U = {wind_speed} m/s, trim + 1 m in x and 0.02 rad pitch, {seconds} s",
    }


def machine() -> dict:
    return {"platform": platform.platform(), "processor": platform.processor() or platform.machine(),
            "cpus": os.cpu_count(), "python": platform.python_version()}


def run_bench(quick: bool = False) -> dict:
    """All benchmark figures as a dict (the CLI prints it as text or JSON)."""
    params = load_params()
    wind = 10.0
    eq = find_equilibrium(params, wind)
    model = Model(params, wind)
    x = eq.x.copy()
    x[model.layout.at(S_X)] += 1.0
    out = {"machine": machine(), "case": f"baseline, n = {model.n}, U = {wind} m/s, single thread"}
    out["rhs_us"] = bench_rhs(model, x, n_calls=50_000 if quick else 200_000)
    out["rk4"] = bench_integrator(model, x, "rk4", seconds=20.0 if quick else 60.0)
    out["semi_implicit"] = bench_integrator(model, x, "semi-implicit", seconds=60.0 if quick else 600.0)
    out["semi_implicit_accuracy"] = semi_implicit_accuracy(params, wind)
    out["trim_0_to_25_m_s_s"] = _median_time(lambda: find_equilibrium(params, 25.0), 1 if quick else 3)
    for name, fn in _extra_benches():
        try:
            out[name] = fn(quick)
        except ImportError as exc:
            out[name] = {"skipped": f"{exc} (install the optional extra)"}
    return out


def _extra_benches():
    """Benchmarks of the other layers (peer comparison when MoorDyn is installed, wind, linear
    sweep, environment)."""
    yield "moordyn_comparison", compare_with_moordyn
    yield "wind", lambda quick: bench_wind()
    yield "linear_sweep", lambda quick: bench_sweep()
    yield "environment", bench_env


def format_text(res: dict, indent: int = 0) -> str:
    lines = []
    for k, v in res.items():
        if isinstance(v, dict):
            lines.append(" " * indent + f"{k}:")
            lines.append(format_text(v, indent + 2))
        elif isinstance(v, float):
            lines.append(" " * indent + f"{k}: {v:.4g}" if math.isfinite(v) else f"{k}: {v}")
        else:
            lines.append(" " * indent + f"{k}: {v}")
    return "\n".join(lines)
