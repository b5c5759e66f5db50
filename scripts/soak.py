"""Reliability soak: random-action env steps over the configuration grid of
:mod:`aerostat_gym.bench.soak`, then the memory check; prints the counts.

    PYTHONPATH=$PWD python scripts/soak.py --steps 1000000
"""

from __future__ import annotations

import argparse

from aerostat_gym.bench.soak import format_report, memory_check, run_soak
from aerostat_gym.cli.common import positive_int, run_script, script_description, seed_int


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--steps", type=positive_int, default=1_000_000, help="total env steps")
    ap.add_argument("--num-envs", type=positive_int, default=8,
                    help="vector env size per configuration")
    ap.add_argument("--seed", type=seed_int, default=0)
    ap.add_argument("--no-memory", action="store_true", help="skip the memory check")
    args = ap.parse_args(argv)

    def progress(k, n, cfg, counts):
        print(f"[{k + 1}/{n}] steps {counts['steps']} exceptions {counts['exceptions']} "
              f"({cfg['integrator']}, {cfg['turbulence']}, wind {cfg['wind_speed']})", flush=True)

    result = run_soak(args.steps, args.num_envs, args.seed, progress=progress)
    memory = None if args.no_memory else memory_check()
    print(format_report(result, memory))
    bad = sum(result["counts"][k] for k in ("exceptions", "nonfinite_obs", "nonfinite_reward",
                                            "obs_outside_space"))
    return 1 if bad or (memory and memory["delta_mb"] > 100) else 0


if __name__ == "__main__":
    raise SystemExit(run_script(main))
