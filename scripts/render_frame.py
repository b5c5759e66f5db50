"""Write one rendered frame of the environment (side view with the tether, close-up, top view)
to a PNG: the picture at the top of the README.

Usage: python scripts/render_frame.py [--out docs/img/frame.png] [--seed 0] [--steps 60]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import gymnasium as gym
import matplotlib.pyplot as plt
import numpy as np

import aerostat_gym  # noqa: F401  (registers the environment)
from aerostat_gym.cli.common import positive_int, run_script, script_description, seed_int


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=script_description(__doc__),
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--out", default=str(Path(__file__).resolve().parent.parent / "docs" / "img"
                                         / "frame.png"),
                    help="PNG file to write (default: the README's docs/img/frame.png)")
    ap.add_argument("--seed", type=seed_int, default=0, help="episode seed")
    ap.add_argument("--steps", type=positive_int, default=60,
                    help="braked-winch steps before the frame")
    args = ap.parse_args(argv)
    env = gym.make("TetheredAerostat-v0", render_mode="rgb_array")
    env.reset(seed=args.seed, options={"wind_speed": 10.0})
    for _ in range(args.steps):
        env.step(np.zeros(1, np.float32))
    plt.imsave(args.out, env.render())
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(run_script(main))
