"""How much of a randomised task's return the aerostats that do not weathervane hold.

``TetheredAerostatRealistic-v0`` draws the fin lift slope and the hull efficiency
independently; where the draw cancels the baseline's modest yaw margin the aerostat does not
turn back into the wind and the light turbulence sails it 80-200 m across it.
``TetheredAerostatRealisticWeathervaning-v0`` redraws those aerostats (``weathercock=True``).
This module measures both on the same seeds; ``scripts/weathercock_tail.py`` prints the table.
"""

from __future__ import annotations

import numpy as np

from ..analysis.directional import WEATHERCOCK_OFFSETS_DEG, static_yaw_acceleration
from ..envs.vector import TetheredAerostatVectorEnv
from ..registration import TASKS
from ..sim import Model
from .protocol_stats import bootstrap_mean_ci

#: seeds of the weathercock study, disjoint from every other seed set of the project
WEATHERCOCK_SEEDS = tuple(range(6000, 6200))
#: the episodes whose share of the summed return the summary gives (the heavy tail)
TAIL_EPISODES = 10
#: [deg] the large yaw offsets at which a weathervaning aerostat may still push off: the
#: baseline's margin there is thin (its 45 deg fin stall is the lowest whole degree at which it
#: restores to 90 deg, README "Large-angle fins"), so near-nominal draws can lose it
LARGE_OFFSETS_DEG = (15.0, 20.0, 30.0, 45.0, 60.0)


def drawn_yaw_curves(task_id: str, seeds, offsets=WEATHERCOCK_OFFSETS_DEG) -> np.ndarray:
    """Static yaw acceleration [rad/s^2] at each offset of ``offsets`` for the aerostat each
    seed of ``task_id`` draws, at its episode's trim (the episode start alone: no step is
    run); shape (seeds, offsets), negative restores."""
    env = TetheredAerostatVectorEnv(num_envs=len(seeds), observation="full", **TASKS[task_id][0])
    env.reset(seed=[int(s) for s in seeds])
    b = env.batch
    curves = [static_yaw_acceleration(Model(ep.params, ep.wind_speed), x, offsets)
              for ep, x in zip(b.episodes, b.trim_state, strict=True)]
    env.close()
    return np.array(curves)


def drawn_weathercock(task_id: str, seeds) -> np.ndarray:
    """Whether the aerostat each seed of ``task_id`` draws weathervanes at its trim."""
    return np.all(drawn_yaw_curves(task_id, seeds) < 0.0, axis=1)


def tail_summary(returns) -> dict:
    """Mean return with its 95 % bootstrap interval, median, worst episode and the share of the
    summed return held by the :data:`TAIL_EPISODES` worst episodes."""
    r = np.asarray(returns, dtype=float)
    worst = np.sort(r)[:TAIL_EPISODES]
    return {**bootstrap_mean_ci(r).as_dict("return"), "median": float(np.median(r)),
            "worst": float(worst[0]), "tail_share": float(worst.sum() / r.sum())}
