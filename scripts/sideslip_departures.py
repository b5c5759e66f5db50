"""Measure the yaw departures described in the README ("Known limitation: yaw departures at
large sideslip").

Usage: python scripts/sideslip_departures.py [--episodes 20] [--stall 16 45]

Prints (1) the static yaw acceleration against a yaw offset from the trim at 8 m/s (negative:
restoring) for each fin stall angle given, and (2) for the turbulence presets light and
moderate at 3, 5, 10 and 15 m/s, the number of passive-winch episodes (120 s, seeds 100 ...)
in which the sideslip at the aerostat CM exceeds 30 degrees.
"""

from __future__ import annotations

import argparse

import numpy as np

from aerostat_gym.analysis.trim import find_equilibrium
from aerostat_gym.envs.spaces import CHANNELS
from aerostat_gym.envs.vector import TetheredAerostatVectorEnv
from aerostat_gym.params import load_params
from aerostat_gym.physics.core import rotation_matrix
from aerostat_gym.sim import Model

OFFSETS_DEG = (5, 10, 15, 20, 30, 45, 60, 80, 100)
WIND = [i for i, c in enumerate(CHANNELS) if c.name in ("wind_x", "wind_y", "wind_z")]


def yaw_curve(stall_deg: float, wind_speed: float = 8.0) -> list[float]:
    """Yaw acceleration dr/dt [rad/s^2] at the trim with psi offset by each of OFFSETS_DEG."""
    p = load_params().replace(**{"fins.alpha_stall_deg": stall_deg})
    eq = find_equilibrium(p, wind_speed)
    model = Model(p, wind=wind_speed)
    lay = model.layout
    out = []
    for deg in OFFSETS_DEG:
        x = eq.x.copy()
        x[lay.euler.start + 2] += np.radians(deg)
        out.append(float(model.rhs(x)[lay.rates.start + 2]))
    return out


def sideslip(euler: np.ndarray, v_rel: np.ndarray) -> np.ndarray:
    """Sideslip [deg] of the body velocity relative to the air, rows of Z-Y-X Euler angles."""
    R = np.array([rotation_matrix(*e) for e in euler])  # body to inertial, one per row
    body = np.einsum("nij,ni->nj", R, v_rel)  # R^T v_rel: body-frame components
    return np.degrees(np.arctan2(np.abs(body[:, 1]), body[:, 0]))


def max_sideslip(turbulence: str, wind_speed: float, episodes: int) -> np.ndarray:
    """Largest sideslip [deg] of each passive-winch episode (120 s, seeds 100, 101, ...)."""
    env = TetheredAerostatVectorEnv(num_envs=episodes, max_episode_steps=600, observation="full",
                                    turbulence=turbulence, perturbation="none")
    obs, _ = env.reset(seed=list(range(100, 100 + episodes)),
                       options={"wind_speed": [wind_speed] * episodes})
    b, lay = env.batch, env.batch.layout
    scale = np.array([CHANNELS[i].scale for i in WIND])
    worst = np.zeros(episodes)
    for _ in range(600):
        obs, *_ = env.step(np.zeros((episodes, 1), np.float32))
        v_rel = b.X[:, lay.cm_vel] - obs[:, WIND] * scale
        worst = np.maximum(worst, sideslip(b.X[:, lay.euler], v_rel))
    env.close()
    return worst


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--stall", type=float, nargs="+", default=[16.0, 45.0])
    args = ap.parse_args(argv)
    print("static yaw acceleration [rad/s^2] at 8 m/s against the yaw offset [deg]:")
    print("  stall " + "".join(f"{d:>8d}" for d in OFFSETS_DEG))
    for stall in args.stall:
        print(f"  {stall:5.0f} " + "".join(f"{v:+8.3f}" for v in yaw_curve(stall)))
    print(f"passive episodes with sideslip > 30 deg (of {args.episodes}):")
    for turb in ("light", "moderate"):
        counts = "".join(f"  {u:g} m/s: {int((max_sideslip(turb, u, args.episodes) > 30.0).sum()):2d}"
                         for u in (3.0, 5.0, 10.0, 15.0))
        print(f"  {turb:9s}{counts}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
