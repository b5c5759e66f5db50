"""First contact: the installed package finds its data from any directory, the hyperparameter
files are rl-zoo3's own format, the registered tasks reproduce their conditions, and the CLI
says what is wrong in one line."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import tomllib
import yaml

import aerostat_gym
from aerostat_gym.agents.hyperparams import TrainingError, load_hyperparams, normalize_kwargs
from aerostat_gym.agents.train import train
from aerostat_gym.registration import TASKS
from aerostat_gym.resources import SHIPPED_POLICY, shipped_path

ROOT = Path(__file__).resolve().parents[1]


def _cli(args, cwd, timeout=900):
    """Run the installed command line in another directory (a fresh Python process)."""
    env = {**os.environ, "PYTHONPATH": ""}
    return subprocess.run([sys.executable, "-m", "aerostat_gym.cli", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=timeout)


def test_every_package_folder_is_installed():
    """pyproject's explicit package list names every package folder under aerostat_gym/ and
    every data folder (aerostat_gym/data, agents/'s subfolders: setuptools drops a data folder
    it is not given), and the agents/ folder installs as aerostat_gym.shipped with its policy
    and hyperparameters."""
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(cfg["packages"])
    found = {".".join(p.parent.relative_to(ROOT).parts)
             for p in (ROOT / "aerostat_gym").rglob("__init__.py")}
    found.add("aerostat_gym.data")
    found |= {f"aerostat_gym.shipped.{d.name}" for d in (ROOT / "agents").iterdir()
              if d.is_dir() and not d.name.startswith((".", "_"))}
    assert found <= listed, f"not installed: {sorted(found - listed)}"
    assert cfg["package-dir"]["aerostat_gym.shipped"] == "agents"
    for rel in (SHIPPED_POLICY, "ppo_tethered_aerostat_vecnormalize.pkl", "hyperparams/ppo.yml"):
        assert shipped_path(*rel.split("/")).is_file(), rel


def test_missing_shipped_file_is_one_clear_line():
    with pytest.raises(FileNotFoundError, match="shipped file hyperparams/nope.yml not found"):
        shipped_path("hyperparams", "nope.yml")


@pytest.mark.parametrize("task_id", sorted(TASKS))
def test_registered_tasks_reproduce_their_conditions(task_id):
    """gym.make(ID) with no kwargs builds the task's registered conditions."""
    env = gym.make(task_id)
    kwargs, description = TASKS[task_id]
    task = env.unwrapped.task
    for key, value in kwargs.items():
        assert getattr(task, key) == value, key
    assert description
    assert env.spec.max_episode_steps == 600


def test_shipped_policy_trained_on_its_registered_task():
    """The shipped PPO was trained by a compatible package version on the task its
    hyperparameter block is keyed by: the recorded run's block equals the shipped YAML's, its
    summary names the same task, and its version record lies between
    aerostat_gym.TASKS_COMPATIBLE_SINCE and this package's version (so gym.make(task_id) is the
    training environment, reward and winch logic included)."""
    task_id, hp, project = load_hyperparams("ppo")
    assert task_id == "TetheredAerostatRealistic-v0"
    run = ROOT / "agents" / "ppo_training"
    recorded = yaml.safe_load((run / "hyperparams.yml").read_text())
    assert set(recorded) == {task_id, "aerostat_gym"}
    assert recorded[task_id] == hp and recorded["aerostat_gym"] == project
    assert json.loads((run / "training_summary.json").read_text())["task"] == task_id
    def version(text):
        return tuple(int(p) for p in text.split("."))

    trained = version(json.loads((run / "version.json").read_text())["aerostat_gym"])
    assert version(aerostat_gym.TASKS_COMPATIBLE_SINCE) <= trained <= version(
        aerostat_gym.__version__)
    assert project == {"eval_freq": 200000, "eval_suite": "damping",
                       "residual": {"base": "modal_lqg", "scale": 0.1, "deadband": 0.03,
                                    "lowpass": 1.0}}


@pytest.mark.parametrize("value, expect", [
    ("dict(norm_obs=True, norm_reward=False)", {"norm_obs": True, "norm_reward": False}),
    (True, {}), (False, None)])
def test_normalize_in_the_zoo_format(value, expect):
    assert normalize_kwargs({"normalize": value}) == expect


def test_normalize_is_parsed_not_evaluated():
    with pytest.raises(ValueError, match="normalize must be"):
        normalize_kwargs({"normalize": "__import__('os').system('true')"})


BLOCK = "TetheredAerostat-v0:\n  n_envs: 1\n  n_steps: 32\n  batch_size: 32\n"


@pytest.mark.parametrize("text, needle", [
    ("TetheredAerostat-v0: [1, 2\n", "not valid YAML (line 2)"),
    ("- TetheredAerostat-v0\n", "must hold a mapping of blocks, got list"),
    ("TetheredAerostat-v0: 5\n", "the 'TetheredAerostat-v0' block must be a mapping"),
    (BLOCK + "aerostat_gym: 5\n", "the 'aerostat_gym' block must be a mapping"),
    (BLOCK + "aerostat_gym:\n  env_kwargs: 3\n", "the 'aerostat_gym.env_kwargs' block must"),
])
def test_a_malformed_hyperparameter_file_is_named(tmp_path, text, needle):
    path = tmp_path / "hp.yml"
    path.write_text(text)
    with pytest.raises(TrainingError, match=re.escape(needle)):
        load_hyperparams("ppo", path)


@pytest.mark.parametrize("extra, needle", [
    ("  bogus_arg: 3\n", "PPO refuses the hyperparameters: TypeError: PPO.__init__() got an "
                          "unexpected keyword argument 'bogus_arg'"),
    ("  policy: NoSuchPolicy\n", "PPO refuses the hyperparameters: ValueError: Policy "
                                  "NoSuchPolicy unknown"),
])
def test_a_hyperparameter_the_algorithm_refuses_is_named(tmp_path, extra, needle):
    """SB3's own complaint, passed on as one TrainingError (not a traceback from its __init__)."""
    path = tmp_path / "hp.yml"
    path.write_text(BLOCK + extra)
    with pytest.raises(TrainingError, match=re.escape(needle)):
        train("ppo", path, timesteps=32, run_dir=tmp_path / "run", progress_bar=False)


def test_rl_zoo3_trains_on_the_shipped_yaml(tmp_path):
    """rl-zoo3 reads the shipped PPO file unchanged and trains a few thousand steps on the
    registered task (hyperparameters shrunk on the zoo's own command line only)."""
    pytest.importorskip("rl_zoo3")
    conf = shipped_path("hyperparams", "ppo.yml")
    cmd = [sys.executable, "-m", "rl_zoo3.train", "--algo", "ppo",
           "--env", "TetheredAerostatRealistic-v0", "--gym-packages", "aerostat_gym",
           "--conf-file", str(conf), "-n", "2048", "--eval-freq", "-1", "--seed", "0",
           "--log-folder", str(tmp_path), "--vec-env", "dummy", "--device", "cpu",
           "--hyperparams", "n_envs:2", "n_steps:512", "batch_size:256", "n_epochs:1"]
    out = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True, timeout=900)
    assert out.returncode == 0, out.stderr[-2000:]
    saved = list(tmp_path.rglob("TetheredAerostatRealistic-v0.zip"))
    assert saved, out.stdout[-2000:]
    from stable_baselines3 import PPO

    assert PPO.load(saved[0], device="cpu").num_timesteps == 2048


def test_commands_work_from_any_directory(tmp_path):
    """demo, train and evaluate run from a directory outside the repository with the installed
    package only, and write what they say they write."""
    demo = _cli(["demo", "--out", "demo"], tmp_path)
    assert demo.returncode == 0, demo.stderr[-2000:]
    assert "linear stability: all modes stable = True" in demo.stdout
    report = (tmp_path / "demo" / "report.md").read_text()
    assert "## Trim and linear stability" in report and "ppo_tethered_aerostat" in report
    train = _cli(["train", "--timesteps", "2000", "--n-envs", "4", "--run-dir", "run",
                  "--eval-freq", "1000000000", "--no-progress", "--threads", "1"], tmp_path)
    assert train.returncode == 0, train.stderr[-2000:]
    summary = json.loads((tmp_path / "run" / "training_summary.json").read_text())
    assert summary["task"] == "TetheredAerostatRealistic-v0" and summary["timesteps"] == 2000
    command = (tmp_path / "run" / "command.txt").read_text()
    assert command.startswith("aerostat-gym train") and str(tmp_path) not in command
    ev = _cli(["evaluate", "--policy", "passive", "--policy", "run/ppo_final.zip",
               "--suite", "damping", "--out", "ev", "--no-plots"], tmp_path)
    assert ev.returncode == 0, ev.stderr[-2000:]
    assert "](" not in ev.stdout  # no Markdown image links on the terminal
    rows = json.loads((tmp_path / "ev" / "report.json").read_text())
    assert [r["label"] for r in rows] == ["passive", "ppo_final"]
    assert all(np.isfinite(e["pendulum_zeta"]) for e in rows[0]["scenarios"]["recover"]["episodes"])


@pytest.mark.parametrize("args, needle", [
    (["demo", "--policy", "missing.zip"], "policy file not found: missing.zip"),
    (["evaluate", "--policy", "passive", "--policy", "missing.zip"],
     "--policy missing.zip: policy file not found: missing.zip"),
    (["evaluate", "--policy", "pasive"], "unknown policy 'pasive' (did you mean 'passive'?)"),
    (["evaluate", "--policy", "passive", "--policy", "lqr", "--label", "a"],
     "--label: 1 label(s) for 2 --policy; give one per --policy, in the same order"),
    (["evaluate", "--policy", "passive", "--policy", "lqr", "--label", "a", "--label", "a"],
     "--label: 'a' is given twice; labels must be distinct"),
    (["evaluate", "--policy", "passive", "--speeds", "60"],
     "--speeds: wind_speed up to 60.0 m/s: the trim at 60.0 m/s loads the tether with"),
    (["train", "--timesteps", "0"], "argument --timesteps: expected an integer >= 1, got '0'"),
    (["train", "--hyperparams", "nope.yml"], "hyperparameter file not found: nope.yml"),
])
def test_bad_input_is_one_line_on_stderr(tmp_path, args, needle):
    out = _cli(args, tmp_path, timeout=300)
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], out.stderr[-1000:]


def test_package_runs_as_a_module(tmp_path):
    """``python -m aerostat_gym`` is the ``aerostat-gym`` command; ``--version`` prints the
    package's version."""
    env = {**os.environ, "PYTHONPATH": ""}
    out = subprocess.run([sys.executable, "-m", "aerostat_gym", "--version"], cwd=tmp_path,
                         env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-1000:]
    assert out.stdout.strip() == f"aerostat-gym {aerostat_gym.__version__}"


def test_help_has_defaults_and_no_markup():
    """No RST markup in --help; every option documented, its default shown once."""
    from aerostat_gym.cli import build_parser

    text = build_parser().format_help()
    assert "``" not in text and ":func:" not in text
    sub = build_parser()._subparsers._group_actions[0].choices
    def flat(parser):  # the help as one line: argparse wraps it to the terminal's width
        return " ".join(parser.format_help().split())
    assert "(default: shipped)" in flat(sub["demo"])
    assert "(default: tiny)" in flat(sub["evaluate"])
    assert aerostat_gym.__version__
    # every option of every command has a help text, and none shows two defaults
    for name, parser in sub.items():
        formatter = parser._get_formatter()
        for action in parser._actions:
            if action.option_strings and action.dest != "help":
                assert action.help, (name, action.option_strings)
                shown = formatter._get_help_string(action).lower()
                assert shown.count("default:") + shown.count("(default ") <= 1, (name, shown)
