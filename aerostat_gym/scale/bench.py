"""Throughput of the Monte Carlo study, serial against Ray, and the cost of starting Ray.

Figures (parameter sets per second) depend on the machine and on what else runs on it; the
report states the CPU count and that the figures come from one run.
"""

from __future__ import annotations

import os
import time

from ..params import Params
from .cluster import start_ray, stop_ray
from .montecarlo import check_speeds, evaluate_sample, run_ray, run_serial, studies_identical
from .ranges import ParameterRange


def _first_task_s(ray) -> float:
    """Seconds for one empty task round trip on a fresh session (a worker process starts)."""
    t0 = time.perf_counter()
    ray.get(ray.remote(num_cpus=1)(lambda: None).remote())
    return time.perf_counter() - t0


def throughput(base: Params, ranges: list[ParameterRange], n: int, seed: int, speeds,
               workers: int = 2, batch_size: int | None = None) -> dict:
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

    Returns
    -------
    dict: serial sets/s; Ray import, init and first-task seconds; Ray sets/s with cold workers
    (first run: each worker imports the package and loads the compiled kernels) and warm
    workers (second run); whether Ray's numbers equal the serial ones bit for bit.
    """
    evaluate_sample(base, ranges, [r.nominal for r in ranges], check_speeds(speeds))
    serial = run_serial(base, ranges, n, seed, speeds)
    start = start_ray("aerostat-gym montecarlo --bench", None, workers)
    try:
        first_task = _first_task_s(start.ray)
        cold = run_ray(base, ranges, n, seed, speeds, batch_size=batch_size)
        warm = run_ray(base, ranges, n, seed, speeds, batch_size=batch_size)
    finally:
        stop_ray(start)
    return {
        "samples": n, "workers": workers, "machine_cpus": os.cpu_count(),
        "batch_size": cold.meta["batch_size"],
        "serial_s": serial.seconds, "serial_sets_per_s": n / serial.seconds,
        "ray_import_s": start.import_s, "ray_init_s": start.init_s,
        "ray_first_task_s": first_task,
        "ray_startup_s": start.import_s + start.init_s + first_task,
        "ray_cold_s": cold.seconds, "ray_cold_sets_per_s": n / cold.seconds,
        "ray_warm_s": warm.seconds, "ray_warm_sets_per_s": n / warm.seconds,
        "speedup_warm": serial.seconds / warm.seconds,
        "identical_to_serial": studies_identical(serial, cold) and studies_identical(serial, warm),
    }


def format_throughput(res: dict) -> str:
    """The throughput figures as text."""
    return "\n".join([
        f"Monte Carlo throughput, {res['samples']} parameter sets, machine with "
        f"{res['machine_cpus']} CPUs (shared: figures vary with the load)",
        f"  serial (this process)        {res['serial_sets_per_s']:7.2f} sets/s "
        f"({res['serial_s']:.1f} s)",
        f"  Ray, {res['workers']} workers, cold        {res['ray_cold_sets_per_s']:7.2f} sets/s "
        f"({res['ray_cold_s']:.1f} s; workers import the package and load the kernels)",
        f"  Ray, {res['workers']} workers, warm        {res['ray_warm_sets_per_s']:7.2f} sets/s "
        f"({res['ray_warm_s']:.1f} s; speed-up {res['speedup_warm']:.2f}x over serial)",
        f"  Ray start-up: import {res['ray_import_s']:.2f} s + ray.init {res['ray_init_s']:.2f} s"
        f" + first task {res['ray_first_task_s']:.2f} s = {res['ray_startup_s']:.2f} s",
        f"  batch size {res['batch_size']}; Ray results identical to serial: "
        f"{res['identical_to_serial']}",
    ])
