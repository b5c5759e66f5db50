"""The shipped policy reproduces from scratch (issue 18): training the shipped configuration
(``agents/hyperparams/ppo.yml`` at the training seed the shipped run records, one torch
thread) in a fresh run directory reaches the shipped policy's score within its 95 % interval. The score is the mean return on the shipped
policy's registered task over the held-out seeds of :data:`RETURN_SEEDS`, with its studentized
bootstrap interval. Slow: the full training (2 M steps, 3-5 minutes on 2 quiet cores)."""

from __future__ import annotations

import json

import pytest

from aerostat_gym.agents.hyperparams import load_hyperparams
from aerostat_gym.agents.protocol_stats import bootstrap_mean_ci
from aerostat_gym.agents.returns import RETURN_SEEDS, task_returns
from aerostat_gym.agents.train import train
from aerostat_gym.resources import shipped_path


@pytest.mark.slow
def test_shipped_policy_reproduces_from_scratch(tmp_path):
    task_id, hp, _ = load_hyperparams("ppo")
    recorded = json.loads(shipped_path("ppo_training", "training_summary.json").read_text())
    assert recorded["task"] == task_id
    run = train("ppo", None, seed=recorded["seed"], run_dir=tmp_path / "run", progress_bar=False, threads=1)
    summary = json.loads((run / "training_summary.json").read_text())
    assert summary["timesteps"] == int(hp["n_timesteps"]) == recorded["timesteps"]
    shipped = bootstrap_mean_ci(task_returns("shipped", task_id))
    again = task_returns(str(run / "ppo_final.zip"), task_id)
    assert len(again) == len(RETURN_SEEDS)
    assert shipped.low <= float(again.mean()) <= shipped.high, (again.mean(), shipped)
