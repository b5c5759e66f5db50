"""The agents' and the CLI's doors: what a policy's ``predict``, ``load_policy``, the SB3
adapter, ``train`` and ``evaluate`` refuse, and that they refuse it before touching state,
building a model or writing a directory."""

from __future__ import annotations

import re
import warnings

import gymnasium as gym
import numpy as np
import pytest

from aerostat_gym.agents.hyperparams import TrainingError, check_hyperparams, load_hyperparams
from aerostat_gym.agents.policies import load_policy
from aerostat_gym.agents.sb3io import PolicyError, SB3Policy, saved_algorithm
from aerostat_gym.agents.train import train
from aerostat_gym.cli import main
from aerostat_gym.envs.sb3 import sb3_vec_env
from aerostat_gym.envs.spaces import (
    N_OBS,
    OBS_DPITCH,
    OBS_DZ,
    OBS_FULL_STATE,
    OBS_FULL_WIND,
    OBS_VX,
    as_batch,
)
from aerostat_gym.envs.vector import TetheredAerostatVectorEnv
from aerostat_gym.resources import shipped_root

#: Policies that read the standard observation, and those that read the full one.
STANDARD = ("passive", "tension", "lqg", "modal_lqg", "modal_lqg_shaped", "shipped")
FULL = ("lqr", "modal")


@pytest.fixture(scope="module")
def observations():
    """A standard and a full observation of the registered task at its first step (seed 0)."""
    standard, _ = gym.make("TetheredAerostat-v0").reset(seed=0)
    full, _ = gym.make("TetheredAerostat-v0", observation="full").reset(seed=0)
    return standard, full


class _Box(gym.Env):
    """A bare space pair for building SB3 models that never step."""

    action_space = gym.spaces.Box(-1, 1, (1,), np.float32)

    def __init__(self, width: int):
        self.observation_space = gym.spaces.Box(-1, 1, (width,), np.float32)


# --- D6: observations and episode starts -------------------------------------------------------

@pytest.mark.parametrize("name", STANDARD + FULL)
def test_every_policy_refuses_a_non_finite_observation_naming_the_channel(name, observations):
    """NaN in the along-wind velocity is named as vx (a standard channel), NaN in the full
    layout's mean wind speed as wind_speed: a ValueError, not torch's or numpy's message."""
    standard, full = observations
    obs, index, channel = ((standard, OBS_VX, "vx") if name in STANDARD
                           else (full, OBS_FULL_WIND, "wind_speed"))
    bad = obs.copy()
    bad[index] = np.nan
    with pytest.raises(ValueError, match=f"^observations must be finite: got nan in {channel}$"):
        load_policy(name).predict(bad, episode_start=np.array([True]))


def test_non_finite_entries_are_named_by_channel_and_batch_row(observations):
    """Two channels of the second row: each named with its value, the row given; the full
    layout's state deviation by its index; a vector narrower than the standard one by
    position."""
    standard, full = observations
    batch = np.stack([standard, standard])
    batch[1, OBS_VX], batch[1, OBS_DPITCH] = np.inf, -np.inf
    with pytest.raises(ValueError, match=re.escape(
            "got inf in vx, -inf in dpitch (batch rows [1])")):
        load_policy("shipped").predict(batch, episode_start=np.ones(2, bool))
    wide = full.copy()
    wide[OBS_FULL_STATE + 5] = np.inf
    with pytest.raises(ValueError, match=re.escape("got inf in state[5]")):
        as_batch(wide)
    with pytest.raises(ValueError, match=re.escape("got nan in channel 2")):
        as_batch([0.0, 1.0, np.nan])


@pytest.mark.parametrize("name", ["shipped", "modal_lqg"])
def test_a_refused_observation_leaves_the_policy_state_as_it_was(name, observations):
    """The shipped policy (residual on modal_lqg: a Kalman filter, a command filter) and the
    LQG: after an infinite velocity is refused, the next finite observation gives the same
    action as on a run that never saw it (a poisoned state gave NaN for the next 3 steps)."""
    standard, _ = observations
    policy = load_policy(name)
    start = np.array([True])
    _, state = policy.predict(standard, None, start)
    clean, _ = policy.predict(standard, state, np.array([False]))
    poisoned = standard.copy()
    poisoned[OBS_VX] = np.inf
    with pytest.raises(ValueError, match="got inf in vx"):
        policy.predict(poisoned, state, np.array([False]))
    after, _ = policy.predict(standard, state, np.array([False]))
    assert np.isfinite(after).all() and np.array_equal(after, clean)


@pytest.mark.parametrize("name", ["passive", "tension", "lqr", "modal", "shipped", "lqg",
                                  "modal_lqg", "modal_lqg_shaped"])
def test_episode_start_of_another_length_is_refused(name, observations):
    """Four observations with three start flags: named, not numpy's broadcast error (the
    privileged controllers read the full observation)."""
    standard, full = observations
    obs = full if name in ("lqr", "modal") else standard
    with pytest.raises(ValueError, match=re.escape(
            "episode_start must hold one flag per observation of the batch (4), got 3")):
        load_policy(name).predict(np.tile(obs, (4, 1)), episode_start=np.ones(3, bool))


def test_frame_stack_policy_checks_at_the_door(observations):
    """An SB3Policy with a two-frame stack: NaN and a short episode_start refused, then a
    finite step acts (the stack untouched by the refusals)."""
    from stable_baselines3 import PPO

    standard, _ = observations
    policy = SB3Policy(PPO("MlpPolicy", _Box(2 * N_OBS), n_steps=8, batch_size=8),
                       frame_stack=2)
    bad = standard.copy()
    bad[OBS_DZ] = np.nan
    with pytest.raises(ValueError, match="got nan in dz$"):
        policy.predict(bad, episode_start=np.array([True]))
    with pytest.raises(ValueError, match=re.escape("of the batch (2), got 1")):
        policy.predict(np.stack([standard, standard]), episode_start=np.array([True]))
    action, state = policy.predict(standard, episode_start=np.array([True]))
    assert action.shape == (1,) and state["stack"].shape == (1, 2 * N_OBS)
    assert np.array_equal(state["stack"][0, :N_OBS], np.zeros(N_OBS))


@pytest.mark.parametrize("wind_range, needle", [
    ("x", "wind_range must be a number or a (low, high) pair, got 'x'"),
    ((0, 200), "wind_range must satisfy 0.0 <= low <= high <= 100 (finite), got (0, 200)"),
    ((3, float("nan")), "wind_range must satisfy 0.0 <= low <= high <= 100 (finite)"),
    ((1, 2, 3), "wind_range must be a number or a (low, high) pair, got (1, 2, 3)"),
])
def test_load_policy_refuses_a_bad_wind_range(wind_range, needle):
    with pytest.raises(PolicyError, match=re.escape(needle)):
        load_policy("lqr", wind_range=wind_range)


def test_load_policy_reads_a_single_wind_speed_as_the_task_does():
    """wind_range=5 is the fixed speed (5, 5), as the task's wind_speed=5: the LQR schedule
    covers it with one design step of margin each side."""
    assert load_policy("lqr", wind_range=5).schedule.speeds.tolist() == [4.0, 5.0, 6.0]


def test_covering_speeds_keep_the_default_table_and_reach_above_the_range():
    """The modal and LQG tables keep DEFAULT_SPEEDS (2-16 m/s) wherever they cover the range
    (None: the default table, so the default ranges build what they always built) and continue
    it in 1 m/s steps to one step above a higher top."""
    from aerostat_gym.agents.scheduling import DEFAULT_SPEEDS, covering_speeds

    for inside in ((3.0, 15.0), (3.0, 16.0), (0.0, 16.0), (5.0, 5.0)):
        assert covering_speeds(inside) is None, inside
    assert covering_speeds((20.0, 25.0)).tolist() == [float(u) for u in range(2, 27)]
    assert covering_speeds((3.0, 16.5)).tolist() == [float(u) for u in range(2, 19)]
    assert np.array_equal(covering_speeds((3.0, 18.0))[:DEFAULT_SPEEDS.size], DEFAULT_SPEEDS)


@pytest.mark.parametrize("name", ["passive", "lqr", "modal_lqg", "shipped"])
@pytest.mark.parametrize("noise", [-1.0, "x", float("nan")])
def test_load_policy_refuses_a_bad_obs_noise_for_every_policy(name, noise):
    """A baseline without a filter and a saved model (whose base filters at the noise it was
    trained with) check ``obs_noise`` as the LQG does: at the door, naming it."""
    with pytest.raises(PolicyError, match=re.escape(f"obs_noise must be a finite number >= 0, "
                                                    f"got {noise!r}")):
        load_policy(name, obs_noise=noise)


def test_evaluate_names_the_speeds_given_when_one_is_too_high(capsys):
    """``--speeds 200``: the message names --speeds and the 200 given, not the scheduling
    range (3, 200) built from it; the limit is MAX_WIND_SPEED = 100 m/s."""
    assert main(["evaluate", "--policy", "passive", "--speeds", "200", "--no-plots"]) == 2
    assert capsys.readouterr().err == ("aerostat-gym evaluate: error: --speeds: speeds must be "
                                       "finite wind speeds in [0, 100] m/s without repeats, "
                                       "got [200.0]\n")


# --- D8: the SB3 adapter -----------------------------------------------------------------------

def test_sb3_adapter_passes_set_options_to_the_next_reset_only():
    """As DummyVecEnv: set_options applies at the next reset (one dict for all, or one per
    environment), then is cleared; reset_infos holds each environment's reset info, also after
    a same-step automatic reset."""
    venv = sb3_vec_env(2, seed=0, max_episode_steps=2)
    venv.set_options({"wind_speed": 5.0})
    venv.reset()
    assert [ep.wind_speed for ep in venv.venv.batch.episodes] == [5.0, 5.0]
    assert [info["wind_speed"] for info in venv.reset_infos] == [5.0, 5.0]
    assert venv._options == [{}, {}]
    venv.set_options([{"wind_speed": 12.0}, {}])
    venv.reset()
    assert venv.venv.batch.episodes[0].wind_speed == 12.0
    assert venv.reset_infos[0]["wind_speed"] == 12.0
    for _ in range(2):
        *_, dones, _ = venv.step(np.zeros((2, 1), np.float32))
    assert dones.tolist() == [True, True]
    assert [info["wind_speed"] for info in venv.reset_infos] == [
        ep.wind_speed for ep in venv.venv.batch.episodes]


def test_sb3_adapter_seeds_as_the_native_batch():
    """Without options, a seeded reset is the native batch's reset(seed=[0, 1])."""
    venv = sb3_vec_env(2, seed=0)
    venv.reset()
    native = TetheredAerostatVectorEnv(2)
    _, info = native.reset(seed=[0, 1])
    assert [ep.wind_speed for ep in venv.venv.batch.episodes] == info["wind_speed"].tolist()
    assert [i["wind_speed"] for i in venv.reset_infos] == info["wind_speed"].tolist()


@pytest.mark.parametrize("seed", [-1, 1.5, True])
def test_sb3_adapter_refuses_a_bad_seed_when_made(seed):
    with pytest.raises(ValueError, match=re.escape(
            f"seed must be None or an integer >= 0, got {seed!r}")):
        sb3_vec_env(2, seed=seed)


def test_sb3_adapter_refuses_options_that_are_not_one_per_environment():
    venv = sb3_vec_env(2)
    with pytest.raises(ValueError, match=re.escape(
            "set_options takes a dict of reset options or a list of 2 (one per environment), "
            "got [{}]")):
        venv.set_options([{}])


# --- D9, D11: the checkpoint to resume ---------------------------------------------------------

@pytest.fixture(scope="module")
def checkpoints(tmp_path_factory):
    """Untrained models of each algorithm, saved: their policy class is what names them."""
    from sb3_contrib import RecurrentPPO
    from stable_baselines3 import PPO, SAC, TD3

    folder = tmp_path_factory.mktemp("checkpoints")
    out = {}
    for Algo, policy in ((PPO, "MlpPolicy"), (SAC, "MlpPolicy"), (TD3, "MlpPolicy"),
                         (RecurrentPPO, "MlpLstmPolicy")):
        path = folder / f"{Algo.__name__}.zip"
        Algo(policy, _Box(N_OBS)).save(path)
        out[Algo.__name__] = path
    return out


def test_saved_algorithm_is_read_from_the_policy_class(checkpoints):
    """RecurrentPPO's LSTM policy is an actor-critic too: the most derived match names it."""
    assert {name: saved_algorithm(path) for name, path in checkpoints.items()} == {
        "PPO": "PPO", "SAC": "SAC", "TD3": "TD3", "RecurrentPPO": "RecurrentPPO"}


def test_resuming_a_checkpoint_of_another_algorithm_is_refused(tmp_path, checkpoints, capsys):
    """A PPO checkpoint resumed as SAC: one line naming both, exit 2, no run directory."""
    run = tmp_path / "run"
    needle = (f"the checkpoint to resume {checkpoints['PPO']} is a PPO model, but the algorithm "
              "is sac (SAC): resume it with --algo ppo")
    with pytest.raises(TrainingError, match=re.escape(needle)):
        train("sac", resume=checkpoints["PPO"], timesteps=512, n_envs=2, run_dir=run,
              progress_bar=False)
    assert main(["train", "--algo", "sac", "--resume", str(checkpoints["PPO"]), "--timesteps",
                 "512", "--n-envs", "2", "--run-dir", str(run), "--no-progress"]) == 2
    assert capsys.readouterr().err == f"aerostat-gym train: error: {needle}\n"
    assert not run.exists()


@pytest.mark.parametrize("content, needle", [
    (None, "checkpoint to resume not found: {path}"),
    (b"not a zip", "checkpoint to resume {path} is not a Stable-Baselines3 model (.zip archive)"),
])
def test_a_bad_checkpoint_is_named_before_the_run_directory(tmp_path, content, needle, capsys):
    path = tmp_path / "bad.zip"
    if content is not None:
        path.write_bytes(content)
    run = tmp_path / "run"
    assert main(["train", "--resume", str(path), "--timesteps", "512", "--n-envs", "2",
                 "--run-dir", str(run), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("aerostat-gym train: error: " + needle.format(path=path))
    assert err.count("\n") == 1 and "hyperparameters" not in err
    assert not run.exists()


# --- D10: hyperparameter values ----------------------------------------------------------------

BLOCK = "TetheredAerostat-v0:\n  n_envs: 1\n  n_steps: 32\n  batch_size: 32\n"


@pytest.mark.parametrize("extra, needle", [
    ('  normalize: "dict(bogus=1)"\n', "normalize: unknown VecNormalize argument(s) ['bogus']; "
                                       "it takes ['clip_obs', "),
    ('  normalize: "dict(norm_obs=True, epsilon=-1.0)"\n',
     "normalize's epsilon must be a finite number > 0, got -1.0"),
    ("  ent_coef: .nan\n", "ent_coef must be a finite number >= 0, got nan"),
    ("  gamma: 1.5\n", "gamma must be a discount in (0, 1], got 1.5"),
    ("  gae_lambda: 0\n", "gae_lambda must be a number in (0, 1], got 0"),
    ("  vf_coef: -1\n", "vf_coef must be a finite number >= 0, got -1"),
    ("  learning_rate: lin_3e-4\n", "learning_rate must be a finite number > 0, got 'lin_3e-4'"),
    ("  n_epochs: 2.5\n", "n_epochs must be an integer >= 1, got 2.5"),
])
def test_a_hyperparameter_out_of_range_is_named(tmp_path, extra, needle, capsys):
    """One line naming the key and the value, exit 2, before a model or a run directory."""
    path = tmp_path / "hp.yml"
    path.write_text(BLOCK + extra)
    run = tmp_path / "run"
    assert main(["train", "--hyperparams", str(path), "--timesteps", "512", "--run-dir",
                 str(run), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("aerostat-gym train: error: PPO refuses the hyperparameters: " + needle)
    assert err.count("\n") == 1 and not run.exists()


@pytest.mark.parametrize("value, accepted", [
    ("auto", True), ("auto_0.1", True), (0.05, True), (0.0, True), ("auto_0", False),
    ("auto_x", False), (-0.1, False), (float("inf"), False)])
def test_sac_entropy_weight_is_learned_or_fixed(value, accepted):
    hp = {"ent_coef": value}
    if accepted:
        assert check_hyperparams("sac", hp) is None
    else:
        with pytest.raises(TrainingError, match=re.escape(
                f"SAC refuses the hyperparameters: ent_coef must be 'auto', 'auto_X' (X > 0) "
                f"or a finite number >= 0, got {value!r}")):
            check_hyperparams("sac", hp)


def test_a_key_the_algorithm_does_not_take_is_left_to_it():
    """tau is SAC's and TD3's: in a PPO block SB3 names it (unexpected keyword), so the
    range check does not; TD3's noise_std (not a constructor argument) is checked."""
    assert check_hyperparams("ppo", {"tau": 5.0}) is None
    with pytest.raises(TrainingError, match=re.escape("tau must be a soft-update rate in (0, 1]")):
        check_hyperparams("sac", {"tau": 5.0})
    with pytest.raises(TrainingError, match=re.escape("noise_std must be a finite number >= 0")):
        check_hyperparams("td3", {"noise_std": -0.1})


def test_every_shipped_hyperparameter_file_passes_the_checks():
    """The shipped training files (18; ppo_space.yml is tune's search space) are in range;
    their normalize blocks parse to VecNormalize's."""
    files = sorted(p for p in (shipped_root() / "hyperparams").glob("*.yml")
                   if not p.stem.endswith("_space"))
    assert len(files) == 18
    for path in files:
        algo = path.stem.split("_")[0]
        _, hp, _ = load_hyperparams(algo, path)
        norm = check_hyperparams(algo, hp)
        assert norm["norm_obs"] is True and 0 < norm["gamma"] <= 1


def test_a_shipped_hyperparameter_file_is_found_by_name(tmp_path, monkeypatch):
    """From any directory, ``--hyperparams ppo_damping_noisy.yml`` is the shipped file (as
    ``--config tcom_32m`` is a shipped configuration); a local file of that name wins; an
    unknown name lists the shipped ones."""
    monkeypatch.chdir(tmp_path)
    task, _, _ = load_hyperparams("ppo", "ppo_damping_noisy.yml")
    assert task == "TetheredAerostatDampingNoisy-v0"
    local = tmp_path / "ppo_damping_noisy.yml"
    local.write_text((shipped_root() / "hyperparams" / "ppo.yml").read_text())
    assert load_hyperparams("ppo", "ppo_damping_noisy.yml")[0] == load_hyperparams("ppo")[0]
    assert load_hyperparams("ppo")[0] != "TetheredAerostatDampingNoisy-v0"
    with pytest.raises(TrainingError, match=r"not found: nope\.yml \(neither a file nor a "
                       r"shipped one: ppo\.yml, .*sac\.yml"):
        load_hyperparams("ppo", "nope.yml")


# --- D12: the report directory -----------------------------------------------------------------

def test_evaluate_checks_its_output_directory_before_evaluating(tmp_path, monkeypatch, capsys):
    """--out under a file: one line, exit 2, and no episode run."""
    import aerostat_gym.cli.agents as cli_agents

    ran = []
    monkeypatch.setattr(cli_agents, "run_evaluations", lambda *a, **k: ran.append(a))
    blocker = tmp_path / "file"
    blocker.write_text("")
    out = blocker / "report"
    assert main(["evaluate", "--policy", "passive", "--speeds", "10", "--out", str(out)]) == 2
    assert capsys.readouterr().err == (f"aerostat-gym evaluate: error: --out {out}: cannot "
                                       "write there (Not a directory)\n")
    assert ran == []


# --- a stateful policy's state dropped between steps ---------------------------------------------

@pytest.mark.parametrize("name", ["modal_lqg", "shipped"])
def test_dropping_a_stateful_policys_state_warns_once(name):
    """``action, _ = policy.predict(obs)`` in a loop restarts the filter at every call: the
    second such call on the same stream warns once (DroppedStateWarning naming the policy and
    what its state holds), and its action is the first call's to the bit (both are episode
    starts). Passing the state back, or marking each call as a start, does not warn."""
    from aerostat_gym.agents.state_check import DroppedStateWarning

    env = gym.make("TetheredAerostat-v0", wind_speed=10.0)
    obs, _ = env.reset(seed=0)
    policy = load_policy(name)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DroppedStateWarning)
        a0, state = policy.predict(obs)
        a1, state = policy.predict(obs, state=state)  # passed back: no warning
        policy.predict(obs, episode_start=np.array([True]))
        policy.predict(obs, episode_start=np.array([True]))  # starts: no warning
        policy.predict(np.stack([obs, obs]))  # another stream (two observations): no warning
    with pytest.warns(DroppedStateWarning, match=r"predict got state=None on two calls in a "
                                                 r"row: its state \(.*\) restarts"):
        again, _ = policy.predict(obs)
        again, _ = policy.predict(obs)
    np.testing.assert_array_equal(again, a0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DroppedStateWarning)
        policy.predict(obs)  # once per policy


def test_demo_takes_a_baseline_it_already_runs_and_prints_every_scenario(tmp_path, capsys):
    """``demo --policy lqr``: the help offers the baselines' names, and lqr is already in the
    comparison; it runs once (was "a policy is listed twice" after the stability summary).
    The console shows every scenario of the suite (the tiny suite: recover and gusty), each
    with passive and lqr at every speed, as evaluate does."""
    assert main(["demo", "--policy", "lqr", "--out", str(tmp_path / "demo")]) == 0
    out = capsys.readouterr().out
    assert "\nrecover:\n" in out and "\ngusty:\n" in out
    rows = [line.split("|")[1:3] for line in out.splitlines() if line.startswith("| 10 |")]
    assert [policy.strip() for _, policy in rows] == ["passive", "lqr", "passive", "lqr"]


def test_a_hyperparameter_file_that_is_not_utf8_is_named(tmp_path):
    path = tmp_path / "latin1.yml"
    path.write_bytes("TetheredAerostat-v0:\n  # caf\xe9\n  n_envs: 4\n".encode("latin-1"))
    with pytest.raises(TrainingError, match=rf"{re.escape(str(path))}: not UTF-8 text: byte "
                       r"0xe9"):
        load_hyperparams("ppo", path)


def test_a_folder_given_as_the_parameter_file_is_named(tmp_path):
    from aerostat_gym.params import ParameterError, load_params
    with pytest.raises(ParameterError, match=rf"{re.escape(str(tmp_path))} is a folder: give a "
                       r"parameter file"):
        load_params(tmp_path)


@pytest.mark.parametrize("name", ["shipped", "lqg", "lqr"])
def test_a_policy_state_of_another_batch_size_is_refused_naming_both(name):
    """A state returned for one observation, passed back with a batch of three: a ValueError
    naming the shapes (for the LQG-based paths it was numpy's 'cannot reshape array of size
    47 into shape (3,newaxis)')."""
    policy = load_policy(name)
    kwargs = {"observation": "full"} if name == "lqr" else {}
    env = gym.make("TetheredAerostatRealistic-v0", **kwargs)
    obs, _ = env.reset(seed=0)
    _, state = policy.predict(obs, episode_start=np.array([True]))
    expected = (r"state must hold one integral per environment, shape \(3,\), got \(1,\)"
                if name == "lqr" else r"LQG state must have shape \(3, 47\) for 3 observation")
    with pytest.raises(ValueError, match=expected):
        policy.predict(np.stack([obs] * 3), state=state, episode_start=np.zeros(3, bool))
