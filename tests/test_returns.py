"""Seeded returns per registered task: the batched evaluation equals the single environment."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import aerostat_gym  # noqa: F401
from aerostat_gym.agents.returns import format_returns, returns_table, task_returns


def test_task_returns_equal_single_env_episodes():
    """task_returns for the braked winch equals the sum of a single environment's rewards over
    the same task and seeds (the vector env's slot i seeded s is the single env seeded s)."""
    got = task_returns("passive", "TetheredAerostatDamping-v0", seeds=[1000, 1001])
    for seed, value in zip([1000, 1001], got, strict=True):
        env = gym.make("TetheredAerostatDamping-v0")
        env.reset(seed=seed)
        total, done = 0.0, False
        while not done:
            _, r, term, trunc, _ = env.step(np.zeros(1, np.float32))
            total += r
            done = term or trunc
        assert value == pytest.approx(total, rel=1e-12)


def test_returns_table_pairs_with_the_reference():
    rows = returns_table(["passive", "tension"], tasks=["TetheredAerostatDamping-v0"],
                         seeds=[1000, 1001, 1002])
    assert [r["policy"] for r in rows] == ["passive", "tension"]
    assert rows[0]["minus_passive"] == 0.0
    tension = task_returns("tension", "TetheredAerostatDamping-v0", seeds=[1000, 1001, 1002])
    passive = task_returns("passive", "TetheredAerostatDamping-v0", seeds=[1000, 1001, 1002])
    assert rows[1]["minus_passive"] == pytest.approx(np.mean(tension - passive), rel=1e-12)
    text = format_returns(rows)
    assert "(reference)" in text and "`TetheredAerostatDamping-v0` | tension" in text


def test_unknown_task_is_refused():
    with pytest.raises(ValueError, match="unknown task"):
        task_returns("passive", "Pendulum-v1")
