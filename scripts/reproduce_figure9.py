"""Reproduce [LN02] Figure 9 (periods and damping ratios of the low-frequency longitudinal and
lateral modes for U = 0..20 m/s, L = 300 m, theta_0 = -4 deg) and the tether-length and
trim-pitch families.

Usage: python scripts/reproduce_figure9.py --out DIR [--config FILE] [--no-families]
Writes DIR/figure9.png, figure9.csv, figure9.json, figure9_modes.csv and
family_tether_length.*, family_aerostat_trim_pitch_deg.*.
"""

from __future__ import annotations

import argparse

from aerostat_gym.analysis.figures import write_families, write_figure9
from aerostat_gym.cli.common import add_config, params_from_args, run_script, script_description


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--out", required=True, help="output folder")
    add_config(ap, json=False)
    ap.add_argument("--no-families", action="store_true", help="skip the length / pitch families")
    args = ap.parse_args(argv)
    params = params_from_args(args)
    data = write_figure9(args.out, params)
    print(f"Figure 9: {len(data['wind_speed_m_s'])} speeds in {data['seconds']:.2f} s, "
          f"all modes stable: {data['all_stable']}")
    if not args.no_families:
        fams = write_families(args.out, params)
        for name, fam in fams.items():
            print(f"{name}: " + ", ".join(
                f"{v:g} stable={d['all_stable']} to {d['wind_speed_m_s'][-1]:g} m/s"
                for v, d in fam.items()))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_script(main))
