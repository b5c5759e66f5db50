"""Episode ends on generated aerostats in severe turbulence (the semi-implicit step's reach).

    python scripts/generated_aerostats.py --seed 7 --count 16

Each aerostat is the baseline scaled by ``scale_aerostat`` to a random volume (10^-2.5 to 10x),
tether length (30-2000 m), element count (2-29) and trim pitch (-6 to 0 deg), with the step
``scale_aerostat`` writes. It flies 8 environments x 500 control steps of uniform random reel
commands in [-1.5, 1.5] in severe turbulence, at mean winds in the 8 m/s below the highest
(up to 25 m/s) whose trim its tether holds, with randomised parameters. Printed per aerostat:
h x lambda (the step times the tether drag's rate 2 rho Cd d v / mu at v = 12.5 m/s, the
quantity :func:`aerostat_gym.params.tether_drag_step` bounds) and the terminations by reason.
``--toml DIR`` also writes each aerostat's parameter file, ``DIR/generated_SEED_K.toml``, for
the other commands' ``--config`` (``--no-run`` writes them without the runs).
"""

from __future__ import annotations

import argparse
import warnings
from collections import Counter

import numpy as np

import aerostat_gym  # noqa: F401  (registers the environment)
from aerostat_gym.bench.soak import STRESS_PERTURBATION, reeling_ends
from aerostat_gym.cli.common import output_dir, run_script, script_description
from aerostat_gym.envs.batch import held_wind_top
from aerostat_gym.params import (
    TETHER_DRAG_REFERENCE_SPEED,
    dumps_toml,
    load_params,
    tether_drag_step,
)
from aerostat_gym.scaling import scale_aerostat

N_ENVS, STEPS, TOP_WIND, SPAN = 8, 500, 25.0, 8.0


def drag_rate_step(p, speed: float = 12.5) -> float:
    """h x lambda of the tether drag at a normal air speed ``speed`` (lambda grows with the
    speed; tether_drag_step is 2 / lambda at TETHER_DRAG_REFERENCE_SPEED)."""
    t = p.tether
    bound = tether_drag_step(t.diameter, t.density, t.Cd_normal, p.environment.rho_air)
    return p.simulation.semi_implicit_dt * 2.0 / bound * speed / TETHER_DRAG_REFERENCE_SPEED


def run(p, seed: int) -> tuple[Counter, tuple[float, float]]:
    """Terminations by reason of one aerostat's random-reeling run, and its wind range."""
    top = held_wind_top(p, 3.0, TOP_WIND)
    winds = (max(3.0, top - SPAN), top)
    kwargs = {"params": p, "wind_speed": winds, "turbulence": "severe", "randomize": True,
              "perturbation": STRESS_PERTURBATION}
    return reeling_ends(kwargs, N_ENVS, STEPS, seed, amplitude=1.5), winds


def main() -> None:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--seed", type=int, default=7, help="seed of the generated aerostats")
    ap.add_argument("--count", type=int, default=16, help="aerostats to generate")
    ap.add_argument("--toml", metavar="DIR", help="write each aerostat's parameter file here")
    ap.add_argument("--no-run", action="store_true", help="write the files only (with --toml)")
    args = ap.parse_args()
    out = output_dir(args.toml, "--toml") if args.toml else None
    warnings.simplefilter("ignore")  # winch-limit and parameter warnings of extreme aerostats
    rng = np.random.default_rng(args.seed)
    total = Counter()
    for k in range(args.count):
        factor = float(10 ** rng.uniform(-2.5, 1.0))
        length = float(rng.uniform(30.0, 2000.0))
        elements = int(rng.integers(2, 30))
        pitch = float(rng.uniform(-6.0, 0.0))
        p = scale_aerostat(load_params(), factor, length, elements, pitch)
        if out is not None:
            path = out / f"generated_{args.seed}_{k}.toml"
            path.write_text(dumps_toml(p))
            print(f"wrote {path}: {factor:.4f}x the baseline's volume on {length:.0f} m, "
                  f"{elements} elements, trim pitch {pitch:.2f} deg", flush=True)
        if args.no_run:
            continue
        if held_wind_top(p, 3.0, TOP_WIND) <= 3.0:
            print(f"{factor:8.4f}x {length:6.0f} m: the tether holds no wind above 3 m/s")
            continue
        counts, winds = run(p, k)
        total.update(counts)
        print(f"h*lambda {drag_rate_step(p):4.2f}  {factor:8.4f}x {length:6.0f} m n={elements:2d} "
              f"dt={1000 * p.simulation.semi_implicit_dt:4.1f} ms  winds {winds[0]:.1f}-"
              f"{winds[1]:.1f}: {dict(counts) or 'no termination'}", flush=True)
    if not args.no_run:
        print("total", dict(total))


if __name__ == "__main__":
    raise SystemExit(run_script(main))
