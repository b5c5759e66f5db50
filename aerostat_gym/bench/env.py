"""Environment speed figures for ``aerostat-gym bench`` (n = 10, control step 0.1 s, moderate
turbulence): single env through ``gym.make`` with each integrator, the native vector env, and
Gymnasium's ``SyncVectorEnv`` of the same env for comparison. Medians of repeated runs."""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import time

import gymnasium as gym
import numba
import numpy as np

from ..registration import ENV_ID, register

KW = {"control_step": 0.1, "turbulence": "moderate"}


def _median_rate(fn, steps: int, repeats: int) -> float:
    rates = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn(steps)
        rates.append(steps / (time.perf_counter() - t))
    return float(np.median(rates))


def _single(integrator: str, steps: int, repeats: int) -> float:
    env = gym.make(ENV_ID, integrator=integrator, **KW)
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    actions = rng.uniform(-0.3, 0.3, (steps, 1)).astype(np.float32)

    def run(n):
        for k in range(n):
            _, _, term, trunc, _ = env.step(actions[k])
            if term or trunc:
                env.reset()

    run(min(steps, 200))  # compile and warm up
    return _median_rate(run, steps, repeats)


def _vector(make, num_envs: int, steps: int, repeats: int) -> float:
    env = make(num_envs)
    env.reset(seed=0)
    a = np.full((num_envs, 1), 0.1, np.float32)

    def run(n):
        for _ in range(n):
            env.step(a)

    run(2)
    rate = _median_rate(run, steps, repeats) * num_envs
    env.close()
    return rate


@contextlib.contextmanager
def _busy_process():
    """One competing process that keeps a core busy (a pure-Python spin loop) while inside."""
    proc = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        time.sleep(0.2)
        yield
    finally:
        proc.kill()
        proc.wait()


def bench_contention(num_envs: int = 64, steps: int = 100, repeats: int = 5) -> dict:
    """Native vector env speed [env-steps/s] quiet and with one competing busy process, for
    one thread and for every thread of the batched step; ``loaded_over_quiet`` per setting."""
    out = {"case": f"native vector env, N = {num_envs}, median of repeats"}
    for threads in sorted({1, numba.config.NUMBA_NUM_THREADS}):
        make = lambda n, t=threads: gym.make_vec(ENV_ID, num_envs=n, threads=t,  # noqa: E731
                                                 vectorization_mode="vector_entry_point", **KW)
        quiet = _vector(make, num_envs, steps, repeats)
        with _busy_process():
            loaded = _vector(make, num_envs, steps, repeats)
        out[f"threads_{threads}"] = {"quiet": quiet, "loaded": loaded,
                                     "loaded_over_quiet": loaded / quiet}
    out["threading_layer"] = numba.threading_layer()
    return out


def bench_env(quick: bool = False) -> dict:
    register()
    reps = 3 if quick else 5
    n_vec = 256 if quick else 1024
    native = _vector(lambda n: gym.make_vec(ENV_ID, num_envs=n,
                                            vectorization_mode="vector_entry_point", **KW),
                     n_vec, 20 if quick else 100, reps)
    sync = _vector(lambda n: gym.make_vec(ENV_ID, num_envs=n,
                                          vectorization_mode="sync", **KW),
                   64, 20 if quick else 50, reps)
    return {
        "case": "n = 10, control step 0.1 s, moderate turbulence, median of repeats",
        "threads": int(os.environ.get("NUMBA_NUM_THREADS", os.cpu_count() or 1)),
        "single_rk4_steps_per_s": _single("rk4", 2000 if quick else 10000, reps),
        "single_semi_implicit_steps_per_s": _single("semi-implicit", 10000 if quick else 50000,
                                                    reps),
        f"vector_native_N{n_vec}_env_steps_per_s": native,
        "sync_vector_N64_env_steps_per_s": sync,
        "native_over_sync_speedup": native / sync,
        "contention": bench_contention(steps=20 if quick else 100, repeats=reps),
    }
