"""Winch-control agents: baselines, evaluator, training smoke test, policy loading errors."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from aerostat_gym.agents.evaluate import evaluate_policy, run_scenario
from aerostat_gym.agents.lqg import LQGSchedule
from aerostat_gym.agents.lqr import LQRSchedule
from aerostat_gym.agents.modal import ModalSchedule
from aerostat_gym.agents.policies import (
    PassivePolicy,
    TensionFeedbackPolicy,
    TensionRelief,
    load_policy,
)
from aerostat_gym.agents.report import comparison_table, lqr_predictions
from aerostat_gym.agents.sb3io import PolicyError
from aerostat_gym.agents.train import train
from aerostat_gym.analysis.reference import closed_form_periods
from aerostat_gym.cli import main
from aerostat_gym.envs.spaces import N_OBS
from aerostat_gym.params import apply_overrides, load_params
from aerostat_gym.resources import shipped_path

ROOT = Path(__file__).resolve().parents[1]


def test_baselines_have_sb3_predict_signature():
    obs = np.zeros((3, N_OBS), np.float32)
    obs[:, 13] = 2.0  # tension 2 kN above trim
    for pol in (PassivePolicy(), TensionFeedbackPolicy()):
        a, state = pol.predict(obs, state=None, episode_start=np.ones(3, bool),
                               deterministic=True)
        assert a.shape == (3, 1) and a.dtype == np.float32 and state is None
        a1, _ = pol.predict(obs[0])
        assert a1.shape == (1,)
    a, _ = TensionFeedbackPolicy(gain=0.3).predict(obs)
    assert np.allclose(a, 0.6)  # 0.3 m/s per kN x 2 kN = 0.6 m/s of a 1 m/s winch


def test_tension_relief_pays_out_on_tension_above_trim_only():
    """TensionRelief adds relief x max(T - T_trim, 0) / (B - m g) to its base's action: 2.5 top
    speeds per net lift on the baseline (net lift 2644.7 N) pays out 0.5 kN / 2644.7 N x 2.5 =
    0.4726 of the top speed on a 0.5 kN excess, nothing below trim, and clips at the winch's
    limit; its base's recurrent state passes through, and a negative or non-finite gain is
    refused at the door."""
    params = load_params()
    net_lift = params.derived.net_lift
    assert net_lift == pytest.approx(2644.7, abs=0.1)
    obs = np.zeros((4, N_OBS), np.float32)
    obs[:, 13] = (0.5, -0.5, 2.0, 0.0)  # tension minus trim [kN]
    relieved = TensionRelief(TensionFeedbackPolicy(gain=0.3), params, 2.5)
    a, state = relieved.predict(obs, state="kept")
    expected = 0.3 * obs[:, 13] + 2.5 * np.maximum(obs[:, 13] * 1e3, 0.0) / net_lift
    assert a[:, 0] == pytest.approx(np.clip(expected, -1.0, 1.0), abs=1e-6)
    assert a[0, 0] == pytest.approx(0.15 + 0.4726, abs=1e-4) and a[2, 0] == 1.0
    assert state == "kept"
    a0, _ = TensionRelief(PassivePolicy(), params, 2.5).predict(obs[1])
    assert a0.shape == (1,) and a0[0] == 0.0
    for bad in (-0.1, math.nan, math.inf):
        with pytest.raises(ValueError, match="tension relief"):
            TensionRelief(PassivePolicy(), params, bad)


def test_passive_recovery_damping_matches_linear_model():
    """Braked winch at 10 m/s after a 10 m swing: the identified pendulum damping ratio and
    period agree with the braked linear model (zeta 0.275, T 41.7 s) within 10 % / 3 %."""
    from aerostat_gym.agents.metrics import fit_damped_sinusoid

    ep = run_scenario(PassivePolicy(), "recover", [10.0], [0])
    fit = fit_damped_sinusoid(ep.time, ep.x[0])
    assert abs(fit.zeta - 0.275) / 0.275 < 0.10, fit
    assert abs(fit.period - 41.7) / 41.7 < 0.03, fit


def test_training_smoke_is_deterministic(tmp_path):
    """A seeded 4,096-step PPO run twice gives identical weights and evaluation scores."""
    import torch
    from stable_baselines3 import PPO

    runs = []
    for k in range(2):
        run = train("ppo", timesteps=4096, n_envs=8, seed=7, run_dir=tmp_path / f"r{k}",
                    progress_bar=False, threads=1, eval_freq=10**9)
        runs.append(run)
    a = PPO.load(runs[0] / "ppo_final.zip").policy.state_dict()
    b = PPO.load(runs[1] / "ppo_final.zip").policy.state_dict()
    assert all(torch.equal(a[k], b[k]) for k in a)
    for name in ("params.toml", "hyperparams.yml", "command.txt", "version.json",
                 "evaluations.json", "best_model.zip", "ppo_final_vecnormalize.pkl"):
        assert (runs[0] / name).is_file(), name
    ev = [json.loads((r / "evaluations.json").read_text())[-1]["score"] for r in runs]
    assert ev[0] == ev[1]


def test_policy_errors_are_clear(tmp_path, capsys):
    with pytest.raises(PolicyError, match="not found"):
        load_policy(str(tmp_path / "missing.zip"))
    bad = tmp_path / "corrupt.zip"
    bad.write_bytes(b"not a zip at all")
    with pytest.raises(PolicyError, match="corrupt"):
        load_policy(str(bad))
    with pytest.raises(PolicyError, match="unknown policy"):
        load_policy("telepathy")
    with pytest.raises(PolicyError, match="is a directory, not a policy file"):
        load_policy(str(tmp_path))
    with pytest.raises(PolicyError, match="unknown policy ''"):
        load_policy("")
    assert main(["evaluate", "--policy", str(bad), "--suite", "tiny"]) == 2
    assert "corrupt" in capsys.readouterr().err


def test_policy_parameters_and_observations_are_checked_at_the_door():
    """params: a Params, a TOML path or a shipped name (the same design either way), nothing
    else; observations: real numbers, refused with what was given (was numpy's message)."""
    with pytest.raises(PolicyError, match="params must be a Params, a TOML path or None, got int"):
        load_policy("passive", params=5)
    obs = np.linspace(-0.5, 0.5, N_OBS, dtype=np.float32)
    by_name = load_policy("tension", params="tcom_32m").predict(obs)[0]
    by_params = load_policy("tension", params=load_params("tcom_32m")).predict(obs)[0]
    assert np.array_equal(by_name, by_params) and abs(float(by_name[0])) > 0
    for name in ("passive", "tension", "lqr", "lqg", "shipped"):
        with pytest.raises(ValueError, match="observations must be an array of real numbers, "
                                             "got 'x'"):
            load_policy(name).predict("x")


def test_policy_for_another_observation_layout_is_rejected(tmp_path):
    import gymnasium as gym
    from stable_baselines3 import PPO

    from aerostat_gym.agents.sb3io import SB3Policy, policy_obs

    class Other(gym.Env):
        observation_space = gym.spaces.Box(-1, 1, (7,), np.float32)
        action_space = gym.spaces.Box(-1, 1, (1,), np.float32)

    model = PPO("MlpPolicy", Other(), n_steps=8, batch_size=8)
    path = tmp_path / "other.zip"
    model.save(path)
    with pytest.raises(PolicyError, match=r"trained on observations of shape \(7,\)"):
        load_policy(str(path))

    class Wide:  # a policy for a layout that is neither the standard nor the full one
        obs_dim = N_OBS + 5

    with pytest.raises(PolicyError, match="another observation layout"):
        policy_obs(Wide(), np.zeros((1, N_OBS + 69), np.float32))
    assert policy_obs(SB3Policy.__new__(SB3Policy), np.zeros((2, N_OBS))).shape == (2, N_OBS)


def test_shipped_policy_reads_the_standard_channels_of_a_full_observation():
    """The full observation leads with the standard channels, so the shipped policy (model,
    normaliser and residual base) given it acts as on the standard observation, bit for bit,
    over 20 steps of a swing start at 10 m/s; a batch of neither width is refused by name."""
    from aerostat_gym.envs.vector import TetheredAerostatVectorEnv

    pol = load_policy("shipped")
    env = TetheredAerostatVectorEnv(2, observation="full", wind_speed=10.0,
                                    perturbation="displacement")
    obs, _ = env.reset(seed=11)
    s_full = s_std = None
    for k in range(20):
        a_full, s_full = pol.predict(obs, s_full, np.full(2, k == 0))
        a_std, s_std = pol.predict(obs[:, :N_OBS], s_std, np.full(2, k == 0))
        assert np.array_equal(a_full, a_std)
        obs, *_ = env.step(a_full)
    with pytest.raises(PolicyError, match="trained for another observation layout"):
        pol.predict(np.zeros((2, N_OBS - 3), np.float32))
    with pytest.raises(PolicyError, match="one vector or a batch"):
        pol.predict(np.zeros((2, 1, N_OBS), np.float32))


def test_shipped_policy_scores_its_training_evaluation():
    """The shipped policy loaded from disk (model, normaliser, residual base and command path,
    low-pass included) scores the damping suite as its training run's final evaluation did,
    within 2e-8 (absolute): evaluation runs the command path training ran (a float32 rounding of
    the summed command dropped before the filter moved this score by 5e-8 and the retrained
    weights). On the machine that trained it the score is equal to 1e-12; on another CPU the
    network's float32 arithmetic rounds differently and the score moved by 8e-9 (session 10),
    so the tolerance sits between the two. The in-process training-evaluation identity is
    exact (tests/test_learned.py)."""
    from aerostat_gym.agents.evaluate import suite_score

    last = json.loads(shipped_path("ppo_training", "evaluations.json").read_text())[-1]
    assert last["timesteps"] >= json.loads(shipped_path(
        "ppo_training", "training_summary.json").read_text())["timesteps"]
    assert suite_score(load_policy("shipped"), "damping") == pytest.approx(last["score"],
                                                                          rel=0, abs=2e-8)


@pytest.mark.slow
def test_full_training_reaches_shipped_score(tmp_path):
    """Training from scratch with the shipped configuration reaches the shipped policy's suite
    score within 10 % (the README states the time it took)."""
    from aerostat_gym.agents.evaluate import suite_score

    seed = json.loads(shipped_path("ppo_training", "training_summary.json").read_text())["seed"]
    run = train("ppo", seed=seed, run_dir=tmp_path / "full", progress_bar=False)
    shipped = suite_score(load_policy("shipped"), "damping")
    best = max(e["score"] for e in json.loads((run / "evaluations.json").read_text()))
    assert best >= shipped - 0.1 * abs(shipped)


def test_resume_from_checkpoint_continues(tmp_path):
    """A run resumed from a saved model (with its VecNormalize statistics) keeps the step count."""
    from stable_baselines3 import PPO

    first = train("ppo", timesteps=2048, n_envs=8, seed=3, run_dir=tmp_path / "a",
                  progress_bar=False, threads=1, eval_freq=10**9)
    second = train("ppo", timesteps=2048, n_envs=8, seed=3, run_dir=tmp_path / "b",
                   resume=first / "ppo_final.zip", progress_bar=False, threads=1,
                   eval_freq=10**9)
    assert PPO.load(second / "ppo_final.zip").num_timesteps == 4096


@pytest.mark.parametrize("algo", ["sac", "td3"])
def test_off_policy_configs_train(tmp_path, algo):
    """The shipped SAC and TD3 configurations build and learn: with learning_starts lowered to
    256 (the rest as shipped), 1200 steps on 4 environments run in rollouts of train_freq 8
    steps x 4 envs = 32 steps, so 38 rollouts (1216 steps); the 30 that end past 256 steps
    each take gradient_steps = 4 updates: 120."""
    import yaml
    from stable_baselines3 import SAC, TD3

    shipped = yaml.safe_load((ROOT / "agents" / "hyperparams" / f"{algo}.yml").read_text())
    shipped["TetheredAerostat-v0"].update(learning_starts=256, batch_size=64)
    config = tmp_path / f"{algo}.yml"
    config.write_text(yaml.safe_dump(shipped))
    run = train(algo, config, timesteps=1200, n_envs=4, seed=0, run_dir=tmp_path / algo,
                progress_bar=False, threads=1, eval_freq=10**9)
    model = {"sac": SAC, "td3": TD3}[algo].load(run / f"{algo}_final.zip")
    assert model.num_timesteps == 1216
    assert model._n_updates == 120
    a, _ = model.predict(np.zeros(N_OBS, np.float32), deterministic=True)
    assert a.shape == (1,) and abs(float(a[0])) <= 1.0


def test_suite_at_other_speeds_is_the_suite_cell_it_replaces():
    """``speeds`` runs a suite's scenarios at other wind speeds on its own seeds: at a speed the
    suite already has (10 m/s, inside the default schedule range), the modal controller's
    episode is the suite's own to the last bit; at 18 m/s, beyond the training range, the
    schedule is widened to cover it and the run records the speeds it used."""
    from aerostat_gym.agents.evaluate import (
        cells_wind_range,
        describe_suite,
        evaluate_policy,
        suite_cells,
    )
    from aerostat_gym.agents.scheduling import schedule_speeds

    assert suite_cells("tiny", [18, 10]) == {"recover": ([10.0, 18.0], [0]),
                                            "gusty": ([10.0, 18.0], [100, 101])}
    assert "U = 10, 18 m/s; seeds 100, 101" in describe_suite("tiny", [10, 18])
    for bad in ([], [5.0, 5.0], [float("nan")], [-1.0], ["x"], [200.0]):
        with pytest.raises(ValueError, match="speeds"):
            suite_cells("tiny", bad)
    own = evaluate_policy("modal", "damping")
    at = evaluate_policy("modal", "damping", speeds=[10.0, 18.0])
    assert own["speeds"] is None and at["speeds"] == [10.0, 18.0]
    row = next(e for e in own["scenarios"]["recover"]["episodes"] if e["wind_speed"] == 10.0)
    new = {e["wind_speed"]: e for e in at["scenarios"]["recover"]["episodes"]}
    assert new[10.0]["pendulum_zeta"] == row["pendulum_zeta"]
    assert new[10.0]["return"] == row["return"]
    # the baselines' schedule covers 18 m/s (designed there, not clamped to 16 m/s)
    assert cells_wind_range(suite_cells("damping", [10.0, 18.0])) == (3.0, 18.0)
    assert schedule_speeds((3.0, 18.0))[-1] >= 18.0
    # the modal table the run used (shared, so not rebuilt here) is designed up to 19 m/s
    assert load_policy("modal", wind_range=(3.0, 18.0)).schedule.speeds[-1] == 19.0
    passive = evaluate_policy("passive", "damping", speeds=[18.0])
    assert new[18.0]["pendulum_zeta"] > 1.5 * passive["scenarios"]["recover"]["episodes"][0][
        "pendulum_zeta"]  # 0.85 against 0.39 when written


def test_scheduled_controllers_are_the_braked_winch_in_still_air_and_say_so():
    """At U = 0 the gains fade to zero (agents.scheduling.low_wind_fade: no linear authority over a
    vertical tether's pendulum): the LQR's still-air recovery is the braked winch's, sample
    for sample, and the evaluator warns rather than let the identical rows pass unexplained."""
    with pytest.warns(UserWarning, match="U = 0 m/s.*no linear authority"):
        lqr = evaluate_policy("lqr", suite="damping", speeds=[0.0])
    passive = evaluate_policy("passive", suite="damping", speeds=[0.0])
    a, b = (r["scenarios"]["recover"]["episodes"][0] for r in (lqr, passive))
    assert a["peak_reel_speed_m_s"] == 0.0
    for key in ("pendulum_zeta", "pitch_zeta", "rms_x_m", "peak_tension_N"):
        assert a[key] == b[key], key
    # the still-air pendulum against its closed form (44.87 s)
    assert b["pendulum_period_s"] == pytest.approx(closed_form_periods()["long_pendulum"],
                                                   rel=0.005)


def _result(label, scenario, episodes):
    return {"label": label, "scenarios": {scenario: {"episodes": episodes}}}


def test_report_tables_show_each_scenarios_pendulum_and_its_terminations():
    """A cross-wind scenario shows the lateral fit (it showed the barely excited longitudinal
    one); a cell whose episodes ended says how, under the table."""
    ep = {"wind_speed": 10.0, "pendulum_zeta": 1.0, "pendulum_period_s": 92.5,
          "lateral_pendulum_zeta": 0.341, "lateral_pendulum_period_s": 60.2, "ended": None}
    cross = comparison_table([_result("passive", "recover_cross", [ep])], "recover_cross")
    head, row = cross.splitlines()[0], cross.splitlines()[2]
    assert "lat. pend. zeta" in head and "| pend. zeta" not in head
    assert "| 0.341 | 60.2 |" in row and "92.5" not in row
    along = comparison_table([_result("passive", "recover", [ep])], "recover")
    assert "| 1.000 | 92.5 |" in along and "lat. pend." not in along
    broken = [{"wind_speed": 15.0, "rms_x_m": float("nan"), "ended": "tether_break"},
              {"wind_speed": 15.0, "rms_x_m": 2.0, "ended": None}]
    gusty = comparison_table([_result("lqr", "gusty", broken)], "gusty")
    assert "| 15 | lqr | 2.00 |" in gusty
    assert gusty.splitlines()[-1] == "- lqr at 15 m/s: 1 of 2 episodes ended by tether_break"


def test_model_based_predictions_name_the_policy_and_its_design_speed():
    pred = {"design_wind_speed": 9.0, "pendulum": {"open": {"zeta": 0.287},
                                                   "closed": {"zeta": 0.829}},
            "pitching": {"closed": {"zeta": 0.427}}}
    ep = {"wind_speed": 15.0, "pendulum_zeta": float("nan"), "pitch_zeta": 0.4, "predicted": pred}
    table = lqr_predictions([_result("lqr", "recover", [ep])])
    assert table.splitlines()[-1] == "| 15 | lqr | 9 | 0.287 | 0.829 | n/a | 0.427 | 0.400 |"


def test_recover_displacements_scale_with_the_tether():
    """The recover scenarios swing every aerostat through the same angle: their displacements
    are the baseline's 300 m tether's, times L / 300 m on another tether (the pitch kick is an
    angle and is kept). On 0.05 x the volume on 60 m the 10 m swing is 2 m: the tether turns
    about the winch through 2 m / the CM's height (1e-6), the episode starts there, and the
    description says so; on the baseline the scenarios and their descriptions are unchanged."""
    from aerostat_gym.agents.evaluate import (
        REFERENCE_TETHER_LENGTH,
        SCENARIOS,
        describe_suite,
    )
    from aerostat_gym.agents.pitch_check import scenario_start
    from aerostat_gym.analysis.trim import find_equilibrium
    from aerostat_gym.params import load_params
    from aerostat_gym.physics.state import StateLayout
    from aerostat_gym.scaling import scale_aerostat

    assert REFERENCE_TETHER_LENGTH == load_params().tether.length
    rec, cross = SCENARIOS["recover"], SCENARIOS["recover_combined_small"]
    assert rec.env_kwargs_for(None) == rec.env_kwargs == rec.env_kwargs_for(300.0)
    assert rec.env_kwargs_for(60.0, scale=1.0) == rec.env_kwargs  # the stated metres, asked for
    assert rec.describe() == "calm, 10 m along-wind swing + 0.05 rad pitch"
    assert cross.describe() == "calm, 0.707 m along + 0.707 m across + 0.005 rad pitch"
    pert = cross.env_kwargs_for(600.0)["perturbation"]
    assert (pert["swing"], pert["lateral"], pert["pitch"]) == pytest.approx((1.4142, 1.4142, 0.005),
                                                                          abs=1e-4)
    assert SCENARIOS["gusty"].env_kwargs_for(60.0) == SCENARIOS["gusty"].env_kwargs
    assert "x 0.2 for the 60 m tether" in rec.describe(60.0)
    assert "2 m along-wind swing" in describe_suite("damping", tether_length=60.0)
    p = scale_aerostat(load_params(), 0.05, 60.0)
    dx = scenario_start(p, 10.0, "recover")
    lay = StateLayout(p.tether.n_elements)
    trim = find_equilibrium(p, 10.0).x
    top, top0 = (trim + dx)[lay.node_pos][:3], trim[lay.node_pos][:3]
    turned = math.atan2(top[0], top[2]) - math.atan2(top0[0], top0[2])  # about the winch
    assert turned * trim[lay.cm_pos][2] == pytest.approx(2.0, rel=1e-6)
    # the nose faces upwind, so turning the whole downwind pitches it down by the same angle
    assert dx[lay.euler.start + 1] == pytest.approx(0.05 - turned, rel=1e-6)
    ep = run_scenario(PassivePolicy(), "recover", [10.0], [0], env_kwargs={"params": p})
    assert ep.x[0, 0] == pytest.approx(dx[lay.cm_pos.start], rel=1e-9)


def test_baseline_design_tables_are_shared_and_equal_a_fresh_build():
    """load_policy builds a model-based baseline's table once per design inputs and shares it:
    the shared table equals one built anew to the last bit, and another sensor noise, control
    step or parameter set gets its own."""
    lqr = load_policy("lqr").schedule
    assert load_policy("lqr").schedule is lqr
    assert np.array_equal(lqr.gains, LQRSchedule(load_params()).gains)
    assert np.array_equal(load_policy("modal").schedule.gains,
                          ModalSchedule(load_params()).gains)
    noisy = load_policy("modal_lqg", obs_noise=0.01).schedule
    assert load_policy("modal_lqg_shaped", obs_noise=0.01).policy.schedule is noisy
    fresh = LQGSchedule(load_params(), obs_noise=0.01, gains="modal")
    assert all(np.array_equal(noisy.tables[k], fresh.tables[k]) for k in fresh.tables)
    # the filter follows the noise; the gains follow the design, not the noise
    quiet = load_policy("modal_lqg", obs_noise=0.05).schedule
    assert quiet is not noisy and not np.array_equal(quiet.tables["L"], noisy.tables["L"])
    assert np.array_equal(quiet.tables["K"], noisy.tables["K"])
    assert load_policy("lqg", obs_noise=0.01).schedule is not noisy
    heavier = apply_overrides(load_params(), {"aerostat.mass": 1.01 * load_params().aerostat.mass})
    assert load_policy("lqr", params=heavier).schedule is not lqr
    with pytest.raises(ValueError, match="obs_noise must be a finite number >= 0, got 'x'"):
        load_policy("lqg", obs_noise="x")
