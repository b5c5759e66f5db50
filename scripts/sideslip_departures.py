"""Measure the yaw departures at large sideslip (README, "Large-angle fins, sideslip and the
air-inertia force").

Usage: python scripts/sideslip_departures.py [--episodes 20] [--air-inertia] [--config FILE]

Prints (1) the static yaw acceleration against a yaw offset from the trim at 5, 10 and 15 m/s
(negative: restoring) for the configured fins (the baseline: Viterna-Corrigan post-stall, 45 deg
stall) and for [LN02]'s flat post-stall lift at the 2-D stall angle (16 deg), and (2) for the
wind-scaled intensity classes light, moderate and severe at 3, 5, 10 and 15 m/s, the number of
passive-winch episodes (120 s, seeds 100 ...) in which the sideslip at the aerostat CM exceeds
30 degrees (with ``--air-inertia``: also with the air-inertia force on).
"""

from __future__ import annotations

import argparse

from aerostat_gym.agents.sideslip import OFFSETS_DEG, max_sideslip, yaw_curve
from aerostat_gym.cli.common import add_config, params_from_args, run_script, script_description

FINS = {"configured": None,
        "flat, 16 deg": {"fins.post_stall": "flat", "fins.alpha_stall_deg": 16.0}}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=script_description(__doc__),
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--episodes", type=int, default=20, help="episodes per cell")
    ap.add_argument("--air-inertia", action="store_true",
                    help="repeat the episode counts with the air-inertia force on")
    add_config(ap, json=False)
    args = ap.parse_args(argv)
    params = params_from_args(args)
    print("static yaw acceleration [rad/s^2] against the yaw offset [deg]:")
    print("  fins             U m/s" + "".join(f"{d:>8d}" for d in OFFSETS_DEG))
    for name, over in FINS.items():
        for u in (5.0, 10.0, 15.0):
            curve = yaw_curve(u, over, params=params)
            print(f"  {name:16s} {u:5.0f} " + "".join(f"{v:+8.3f}" for v in curve))
    runs = [("", None)]
    if args.air_inertia:
        runs.append((", air inertia on", {"aerostat.air_inertia": True}))
    for label, over in runs:
        print(f"passive episodes with sideslip > 30 deg at the CM (of {args.episodes}, 120 s"
              f"{label}):")
        for turb in ("light", "moderate", "severe"):
            counts = "".join(
                f"  {u:g} m/s: "
                f"{int((max_sideslip(turb, u, args.episodes, over, params) > 30.0).sum()):2d}"
                for u in (3.0, 5.0, 10.0, 15.0))
            print(f"  {turb:9s}{counts}")
    return 0


if __name__ == "__main__":
    raise SystemExit(run_script(main))
