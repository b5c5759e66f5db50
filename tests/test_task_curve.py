"""The learning curve on the training task (aerostat_gym.agents.task_curve): a tiny residual
run's checkpoints against its starting point, which is the named no-learning baseline to the
bit; the paired differences are the means' differences; bad runs are refused at the door."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
import yaml

from aerostat_gym.agents.returns import task_returns
from aerostat_gym.agents.task_curve import run_models, task_curve, zero_residual
from aerostat_gym.agents.train import train
from aerostat_gym.params import default_params, dumps_toml

TASK = "TetheredAerostat-v0"
ENV = {"turbulence": "light", "perturbation": "displacement", "randomize": True,
       "obs_noise": 0.01}
ON_POLICY = {"n_envs": 4, "n_steps": 64, "batch_size": 128, "n_epochs": 2, "gamma": 0.995,
             "normalize": "dict(norm_obs=True, norm_reward=True, epsilon=1.0e-4)",
             "policy_kwargs": {"net_arch": [16, 16]}}
#: the shipped command path: modal_lqg_shaped is this base through it with a zero residual
SHAPED = {"base": "modal_lqg", "scale": 0.1, "lowpass": 1.0, "deadband": 0.03}
SEEDS = (4000, 4001)


def _run(tmp_path_factory, name, project, timesteps=512):
    folder = tmp_path_factory.mktemp(name)
    config = folder / "config.yml"
    config.write_text(yaml.safe_dump({TASK: ON_POLICY, "aerostat_gym": {
        "eval_suite": "damping", "env_kwargs": ENV, **project}}))
    # checkpoints are written at the suite-evaluation frequency: every 256 steps
    return train("ppo", config, timesteps=timesteps, seed=5, run_dir=folder / "run",
                 progress_bar=False, threads=1, eval_freq=256)


@pytest.fixture(scope="module")
def residual_run(tmp_path_factory):
    return _run(tmp_path_factory, "residual", {"residual": SHAPED})


def test_run_models_in_order_with_the_final_models_own_count(residual_run):
    models = run_models(residual_run)
    assert [s for s, _ in models] == [256, 512, 512]
    assert models[-1][1].name == "ppo_final.zip"


def test_curve_against_the_zero_residual(residual_run):
    curve = task_curve(residual_run, SEEDS)
    assert curve["task"] == TASK and curve["env_kwargs"] == ENV
    assert curve["reference"] == "zero residual"
    shaped = task_returns("modal_lqg_shaped", TASK, SEEDS, env_kwargs=ENV)
    assert curve["reference_mean"] == float(shaped.mean())  # the named baseline, to the bit
    final = task_returns(str(residual_run / "ppo_final.zip"), TASK, SEEDS, env_kwargs=ENV)
    last = curve["points"][-1]
    assert last["mean"] == float(final.mean())
    assert last["median_minus_reference"] == float(np.median(final - shaped))
    # a paired difference's estimate is the difference of the means
    for p in curve["points"]:
        assert p["minus_reference"][0] == pytest.approx(p["mean"] - curve["reference_mean"],
                                                        abs=1e-9)


def test_shipped_policy_starts_at_modal_lqg_shaped():
    """The shipped residual with its network at zero is ``modal_lqg_shaped`` to the bit, on
    the training task it was given."""
    task = "TetheredAerostatRealistic-v0"
    start = task_returns(zero_residual("shipped"), task, SEEDS)
    assert np.array_equal(start, task_returns("modal_lqg_shaped", task, SEEDS))


def test_plain_model_has_no_zero_residual(tmp_path_factory):
    run = _run(tmp_path_factory, "plain", {}, timesteps=256)
    assert zero_residual(run / "ppo_final.zip") is None
    curve = task_curve(run, SEEDS)
    assert curve["reference"] == "passive"
    assert curve["reference_mean"] == float(task_returns("passive", TASK, SEEDS,
                                                         env_kwargs=ENV).mean())


def test_bad_runs_are_refused(tmp_path, residual_run):
    with pytest.raises(ValueError, match="not a finished training run"):
        run_models(tmp_path)
    other = tmp_path / "other"
    shutil.copytree(residual_run, other)
    (other / "params.toml").write_text(dumps_toml(default_params(tether__length=250.0)))
    with pytest.raises(ValueError, match="another aerostat"):
        task_curve(other, SEEDS)


def test_script_writes_the_curve(load_script, tmp_path, residual_run):
    out = tmp_path / "curve"
    curves = load_script("task_curve").main([str(residual_run), "--names", "tiny", "--seeds", "2",
                                            "--out", str(out)])
    assert set(curves) == {"tiny"}
    assert {p.name for p in out.iterdir()} == {"task_curve.json", "task_curve.md",
                                               "task_curve.png"}
    assert json.loads((out / "task_curve.json").read_text()) == json.loads(json.dumps(curves))
    with pytest.raises(SystemExit, match="one distinct label per run"):
        load_script("task_curve").main([str(residual_run), "--names", "a", "b", "--out",
                                        str(out)])


def test_stored_curve_is_its_returns_and_the_shipped_policys():
    """agents/ppo_training/task_curve.json: every median and each run's final interval
    recomputed from the stored returns (the bootstrap of all 55 intervals takes 20 s); its
    reference is modal_lqg_shaped and its final seed-0 point the shipped policy, both re-flown
    here on the first two seeds; the figures docs/learned.md quotes."""
    from aerostat_gym.agents.protocol_stats import paired_difference_ci
    from aerostat_gym.resources import shipped_path

    curves = json.loads(shipped_path("ppo_training", "task_curve.json").read_text())
    for c in curves.values():
        ref = np.array(c["reference_returns"])
        assert c["reference"] == "zero residual" and len(ref) == len(c["seeds"]) == 200
        # returns are stored to 1e-3: the statistics move by at most that
        for p in c["points"]:
            mine = np.array(p["returns"])
            assert p["median_minus_reference"] == pytest.approx(np.median(mine - ref), abs=2e-3)
            assert p["minus_reference"][0] == pytest.approx(np.mean(mine - ref), abs=2e-3)
        iv = paired_difference_ci(np.array(c["points"][-1]["returns"]), ref)
        assert c["points"][-1]["minus_reference"] == pytest.approx([iv.estimate, iv.low, iv.high],
                                                                   abs=2e-3)
    shipped = curves["seed 0 (shipped)"]
    task, seeds = shipped["task"], shipped["seeds"][:2]
    assert shipped["reference_returns"][:2] == pytest.approx(
        task_returns("modal_lqg_shaped", task, seeds), abs=1e-3)
    assert shipped["points"][-1]["returns"][:2] == pytest.approx(
        task_returns("shipped", task, seeds), abs=1e-3)
    assert round(shipped["points"][-1]["minus_reference"][0], 1) == -333.6
    below = [sum(p["minus_reference"][2] < 0 for p in c["points"]) for c in curves.values()]
    above = [sum(p["minus_reference"][1] > 0 for p in c["points"]) for c in curves.values()]
    assert below == [8, 8, 3, 11, 0] and sum(above) == 0
