"""Throughput of the Monte Carlo study, serial against Ray, and the cost of starting Ray.

Figures (parameter sets per second) depend on the machine and on what else runs on it; the
report states the CPU count and that the figures come from one run.
"""

from __future__ import annotations

import os
import time

import numpy as np

from ..params import Params
from .cluster import start_ray, stop_ray
from .montecarlo import check_speeds, evaluate_sample, run_ray, run_serial, studies_identical
from .ranges import ParameterRange


def _first_task_s(ray) -> float:
    """Seconds for one empty task round trip on a fresh session (a worker process starts)."""
    t0 = time.perf_counter()
    ray.get(ray.remote(num_cpus=1)(lambda: None).remote())
    return time.perf_counter() - t0


def _rates(n: int, studies: list) -> dict:
    rates = np.array([n / st.seconds for st in studies])
    return {"median": float(np.median(rates)), "min": float(rates.min()),
            "max": float(rates.max()), "runs": rates.tolist()}


def throughput(base: Params, ranges: list[ParameterRange], n: int, seed: int, speeds,
               workers: int = 2, batch_size: int | None = None, repeats: int = 3) -> dict:
    """Time the same ``n`` parameter sets serially and as Ray tasks on ``workers`` CPUs.

    Parameters
    ----------
    base : base parameter set.
    ranges : the uncertain parameters.
    n : parameter sets per run.
    seed : sampling seed (both paths draw the same sets).
    speeds : wind speeds of the sweep [m/s].
    workers : CPUs of the local Ray instance.
    batch_size : parameter sets per Ray task (default: about four batches per CPU).
    repeats : serial and warm Ray runs, alternated so that a change in the machine's load
        affects both alike.

    Returns
    -------
    dict: Ray import, init and first-task seconds; sets/s of the first Ray run (cold workers:
    each imports the package and loads the compiled kernels); median, min and max sets/s of
    the serial and warm Ray runs; whether every Ray run equals the serial one bit for bit.
    """
    if repeats < 1:
        raise ValueError(f"--repeats must be >= 1, got {repeats}")
    evaluate_sample(base, ranges, [r.nominal for r in ranges], check_speeds(speeds))
    start = start_ray("the serial-vs-Ray benchmark", None, workers)
    serial, warm = [], []
    try:
        first_task = _first_task_s(start.ray)
        cold = run_ray(base, ranges, n, seed, speeds, batch_size=batch_size)
        for _ in range(repeats):
            serial.append(run_serial(base, ranges, n, seed, speeds))
            warm.append(run_ray(base, ranges, n, seed, speeds, batch_size=batch_size))
    finally:
        stop_ray(start)
    s_rate, w_rate = _rates(n, serial), _rates(n, warm)
    return {
        "samples": n, "workers": workers, "machine_cpus": os.cpu_count(), "repeats": repeats,
        "batch_size": cold.meta["batch_size"],
        "serial_sets_per_s": s_rate, "ray_warm_sets_per_s": w_rate,
        "ray_cold_sets_per_s": n / cold.seconds,
        "speedup_median": w_rate["median"] / s_rate["median"],
        "ray_import_s": start.import_s, "ray_init_s": start.init_s,
        "ray_first_task_s": first_task,
        "ray_startup_s": start.import_s + start.init_s + first_task,
        "identical_to_serial": all(studies_identical(serial[0], st) for st in [cold, *warm]),
    }


def _rate_text(r: dict) -> str:
    return f"{r['median']:6.2f} sets/s (median; {r['min']:.2f}-{r['max']:.2f})"


def format_throughput(res: dict) -> str:
    """The throughput figures as text."""
    return "\n".join([
        f"Monte Carlo throughput, {res['samples']} parameter sets per run, {res['repeats']} "
        f"alternated runs each, machine with {res['machine_cpus']} CPUs (shared: figures vary "
        "with the load)",
        f"  serial (this process)        {_rate_text(res['serial_sets_per_s'])}",
        f"  Ray, {res['workers']} workers, warm        {_rate_text(res['ray_warm_sets_per_s'])}"
        f"; speed-up {res['speedup_median']:.2f}x",
        f"  Ray, {res['workers']} workers, first run   {res['ray_cold_sets_per_s']:6.2f} sets/s "
        "(workers import the package and load the compiled kernels)",
        f"  Ray start-up: import {res['ray_import_s']:.2f} s + ray.init {res['ray_init_s']:.2f} s"
        f" + first task {res['ray_first_task_s']:.2f} s = {res['ray_startup_s']:.2f} s",
        f"  batch size {res['batch_size']}; Ray results identical to serial: "
        f"{res['identical_to_serial']}",
    ])
