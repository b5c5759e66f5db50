"""Episode ends of the semi-implicit step on a short tether cut into short elements.

A short element goes slack and snaps taut in severe turbulence; this counts how episodes end
there, so the README's figures can be re-measured (and compared with a finer step):

    python scripts/short_elements.py --length 55 --elements 24
    python scripts/short_elements.py --length 55 --elements 24 --set simulation.semi_implicit_dt=0.0125

Per wind speed: 8 environments x 600 control steps in severe turbulence, once with uniform
random reel commands in [-1, 1] (seed 0) and once braked (command 0); the baseline aerostat
with the given tether (``winch.min_length`` lowered to reach it).
"""

from __future__ import annotations

import argparse
import warnings
from collections import Counter

import aerostat_gym  # noqa: F401  (registers the environment)
from aerostat_gym.bench.soak import STRESS_PERTURBATION, reeling_ends
from aerostat_gym.cli.common import parse_overrides, run_script, script_description

N_ENVS, STEPS = 8, 600


def episode_ends(length: float, elements: int, wind: float, overrides: dict) -> Counter:
    """Terminations by reason over the random and the braked run at one wind speed."""
    kwargs = {"tether_length": length, "n_elements": elements, "wind_speed": wind,
              "turbulence": "severe", "perturbation": STRESS_PERTURBATION,
              "overrides": {"winch.min_length": min(30.0, length), **overrides}}
    return sum((reeling_ends(kwargs, N_ENVS, STEPS, 0, amplitude) for amplitude in (1.0, 0.0)),
               Counter())


def main() -> None:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--length", type=float, default=55.0, help="tether length [m]")
    ap.add_argument("--elements", type=int, default=24, help="tether elements")
    ap.add_argument("--winds", type=float, nargs="+", default=[5.0, 10.0, 15.0, 20.0, 25.0])
    ap.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                    help="parameter override, e.g. simulation.semi_implicit_dt=0.0125")
    args = ap.parse_args()
    overrides = parse_overrides(args.set)
    warnings.simplefilter("ignore")  # the winch-limit warnings of the strong winds
    print(f"{args.length:g} m on {args.elements} elements, severe turbulence, {N_ENVS} envs x "
          f"{STEPS} steps random + braked per wind speed {overrides or ''}")
    for wind in args.winds:
        ends = episode_ends(args.length, args.elements, wind, overrides)
        print(f"{wind:5.1f} m/s  " + (", ".join(f"{k} {v}" for k, v in sorted(ends.items()))
                                      or "no termination"))


if __name__ == "__main__":
    raise SystemExit(run_script(main))
