"""Reel-out / reel-in manoeuvre from the trim, plotted into a PNG.

    python scripts/winch_manoeuvre.py [--wind 10] [--distance 50] [--integrator rk4]
                                      [--out winch_manoeuvre.png] [--set winch.max_speed=1.5]

A thin shim over :func:`aerostat_gym.analysis.manoeuvre.reel_manoeuvre` (tested in tests/test_winch.py):
from the trim at the configured length, reel out ``distance`` metres at the winch's speed limit,
hold, reel back in and let the aerostat settle; plot length, reel speed, winch tension and
aerostat altitude.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from aerostat_gym.analysis.manoeuvre import plot_manoeuvre, reel_manoeuvre
from aerostat_gym.cli.common import add_config, params_from_args, run_script, script_description
from aerostat_gym.params import ParameterError


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--wind", type=float, default=10.0, help="mean wind speed [m/s]")
    ap.add_argument("--distance", type=float, default=50.0, help="reel-out distance [m]")
    ap.add_argument("--speed", type=float, default=None, help="reel speed [m/s] (default: limit)")
    ap.add_argument("--hold", type=float, default=30.0, help="hold at the long length [s]")
    ap.add_argument("--settle", type=float, default=300.0, help="time after reel-in [s]")
    ap.add_argument("--integrator", choices=("rk4", "semi-implicit"), default="rk4")
    add_config(ap, json=False)
    ap.add_argument("--out", default="winch_manoeuvre.png", help="output PNG")
    args = ap.parse_args(argv)
    try:
        params = params_from_args(args)
        res = reel_manoeuvre(params, args.wind, args.distance, args.speed, args.hold,
                             args.settle, args.integrator)
    except (ParameterError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    tr = res.trajectory
    plot_manoeuvre(res, args.out)
    dpos = np.linalg.norm(tr.cm_pos[-1] - tr.cm_pos[0])
    print(f"status {tr.status}; peak length {tr.length.max():.2f} m; final length "
          f"{tr.length[-1]:.3f} m (start {tr.length[0]:.3f} m); final aerostat offset from the "
          f"trim {dpos:.3f} m; winch tension {tr.load_cell.min():.0f}-{tr.load_cell.max():.0f} N; "
          f"events {[e['event'] for e in tr.events]}")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(run_script(main))
