"""Realised turbulence intensity at the aerostat against each class's target (README, issue 13).

Usage: python scripts/turbulence_intensity.py [--episodes 20] [--model mil]

For the intensity classes light, moderate and severe at 4, 8, 12 and 16 m/s, prints the
along-wind sigma_u / U(h) at the aerostat's trim CM pooled over the episodes (120 s each, seeds
100 ...) next to the class's target, and the air-inertia force on the baseline hull in one
600 s field of that class.
"""

from __future__ import annotations

import argparse

import numpy as np

from aerostat_gym.agents.intensity import air_inertia_force, realised_intensity
from aerostat_gym.cli.common import run_script, script_description
from aerostat_gym.params import load_params
from aerostat_gym.wind import build_wind
from aerostat_gym.wind.presets import INTENSITY_MODELS

SPEEDS = (4.0, 8.0, 12.0, 16.0)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--model", default="mil", choices=[m for m in INTENSITY_MODELS if m != "fixed"])
    args = ap.parse_args(argv)
    p = load_params()
    print(f"sigma_u / U(h) at the aerostat, realised (target), {args.episodes} episodes x 120 s, "
          f"intensity model {args.model}:")
    print("  class    " + "".join(f"{u:>18.0f} m/s" for u in SPEEDS))
    for cls in ("light", "moderate", "severe"):
        turb = {"preset": cls, "intensity_model": args.model}
        cells = []
        for u in SPEEDS:
            r = realised_intensity(turb, u, args.episodes)
            cells.append(f"{100 * r['realised']:8.2f} % ({100 * r['target']:5.2f} %)")
        print(f"  {cls:9s}" + "".join(f"{c:>22s}" for c in cells))
    print("air-inertia force on the hull held at 300 m, one 600 s field (seed 0): RMS lateral / "
          "peak |F| [N]")
    for cls in ("light", "moderate", "severe"):
        cells = []
        for u in SPEEDS:
            wp, wf = build_wind({"speed": u}, {"preset": cls, "intensity_model": args.model},
                                600.0, np.random.default_rng(0))
            f = air_inertia_force(p, wp, wf, (0.0, 0.0, 300.0), 600.0, 0.05)
            cells.append(f"{f['rms_lateral_n']:6.0f} / {f['peak_n']:5.0f}")
        print(f"  {cls:9s}" + "".join(f"{c:>22s}" for c in cells))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_script(main))
