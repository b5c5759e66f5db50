"""Reproduce [LN02] Figure 8: linear vs nonlinear response, L = 300 m, U = 10 m/s, the aerostat
perturbed by 0.1 m in x, y, z and 0.01 rad in roll, pitch, yaw, 80 s.

Usage: python scripts/reproduce_figure8.py --out DIR [--config FILE]
Writes DIR/figure8.png, figure8.json, figure8_nrms.csv, figure8_relaxed_tether.png and
figure8_amplitude_scan.csv (normalised RMS difference against the perturbation amplitude).
"""

from __future__ import annotations

import argparse

from aerostat_gym.analysis.figures import write_figure8
from aerostat_gym.params import load_params


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", required=True, help="output folder")
    ap.add_argument("--config", help="parameter TOML (default: the shipped baseline)")
    args = ap.parse_args(argv)
    data = write_figure8(args.out, load_params(args.config))
    print("normalised RMS difference (linear vs nonlinear), tether nodes at trim:")
    for name, v in data["nrms"].items():
        print(f"  {name:6s} {100 * v:6.2f} %")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
