"""Measure the yaw departures described in the README ("Known limitation: yaw departures at
large sideslip").

Usage: python scripts/sideslip_departures.py [--episodes 20] [--stall 16 45] [--config FILE]

Prints (1) the static yaw acceleration against a yaw offset from the trim at 8 m/s (negative:
restoring) for each fin stall angle given, and (2) for the turbulence presets light and
moderate at 3, 5, 10 and 15 m/s, the number of passive-winch episodes (120 s, seeds 100 ...)
in which the sideslip at the aerostat CM exceeds 30 degrees.
"""

from __future__ import annotations

import argparse

from aerostat_gym.agents.sideslip import OFFSETS_DEG, max_sideslip, yaw_curve
from aerostat_gym.cli.common import parse_overrides
from aerostat_gym.params import load_params


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--stall", type=float, nargs="+", default=[16.0, 45.0])
    ap.add_argument("--config", help="parameter TOML or a shipped configuration's name (default: the baseline)")
    ap.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                    help="override one parameter (repeatable)")
    args = ap.parse_args(argv)
    params = load_params(args.config, parse_overrides(args.set) or None)
    print("static yaw acceleration [rad/s^2] at 8 m/s against the yaw offset [deg]:")
    print("  stall " + "".join(f"{d:>8d}" for d in OFFSETS_DEG))
    for stall in args.stall:
        print(f"  {stall:5.0f} " + "".join(f"{v:+8.3f}" for v in yaw_curve(stall, params=params)))
    print(f"passive episodes with sideslip > 30 deg (of {args.episodes}):")
    for turb in ("light", "moderate"):
        counts = "".join(f"  {u:g} m/s: {int((max_sideslip(turb, u, args.episodes, params) > 30.0).sum()):2d}"
                         for u in (3.0, 5.0, 10.0, 15.0))
        print(f"  {turb:9s}{counts}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
