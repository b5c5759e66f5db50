"""How many of the protocol's pitch fits catch one of the aerostat's fast modes
(:func:`aerostat_gym.agents.pitch_check.pitch_fit_coverage`).

Every named policy in the six recover scenarios at the given speeds and seeds, with the report
suite's sensor noise; the fits guided by the aerostat's linear modes as ``evaluate`` guides them
on any aerostat but the baseline (whose fits it counts unguided). Prints the number of fits, how
many read n/a (damped period more than 1.5 x from both the linear pitching and axial-spring
modes, or no oscillation found) and the largest ratio among the others. Usage::

    PYTHONPATH=. python scripts/pitch_fit_coverage.py [--config TOML] [--scale V L] \\
        [--policies passive lqr modal modal_lqg shipped] [--speeds 5 10 15]
"""

from __future__ import annotations

import argparse

from aerostat_gym.agents.pitch_check import pitch_fit_coverage
from aerostat_gym.cli.common import run_script, script_description
from aerostat_gym.params import load_params
from aerostat_gym.scaling import scale_aerostat


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--config", default=None, help="parameter TOML (default: the baseline)")
    ap.add_argument("--scale", nargs=2, type=float, metavar=("VOLUME_FACTOR", "TETHER_LENGTH"),
                    help="the configuration scaled by aerostat_gym.scaling.scale_aerostat")
    ap.add_argument("--policies", nargs="+",
                    default=["passive", "lqr", "modal", "modal_lqg", "shipped"])
    ap.add_argument("--speeds", nargs="+", type=float, default=[5.0, 10.0, 15.0])
    ap.add_argument("--seeds", nargs="+", type=int, default=[5000, 5001, 5002])
    args = ap.parse_args(argv)
    params = load_params(args.config)
    if args.scale:
        params = scale_aerostat(params, *args.scale)
    out = pitch_fit_coverage(params, args.policies, args.speeds, args.seeds)
    print(f"{out['fits']} pitch fits ({'guided' if out['guided'] else 'unguided'}), "
          f"{out['stray']} n/a, largest ratio to a fast mode among the rest "
          f"{out['worst_ratio']:.3f}")


if __name__ == "__main__":
    raise SystemExit(run_script(main))
