"""Training on the evaluator's score (issue 18): the braked-winch reference return of an episode
start is the return the passive policy gets on that episode, to the last bit; the score-reward
wrapper turns every episode's return into its score (passive: -1); and the per-episode
turbulence-class draw (``turbulence_mix``) gives each episode its class's sigma, calm air
exactly, without changing the rest of the episode."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from aerostat_gym.agents.hyperparams import TrainingError
from aerostat_gym.agents.sb3io import PolicyError
from aerostat_gym.agents.score_reward import (
    DEFAULT_FLOOR,
    check_score_reward,
    score_reward_vec_env,
)
from aerostat_gym.agents.train import train
from aerostat_gym.envs import TetheredAerostatEnv
from aerostat_gym.envs.config import TaskError
from aerostat_gym.envs.reference import BrakedReference
from aerostat_gym.envs.sb3 import sb3_vec_env
from aerostat_gym.envs.vector import TetheredAerostatVectorEnv
from aerostat_gym.wind.presets import CLASS_FACTOR

REALISTIC = {"turbulence": "light", "perturbation": "displacement", "randomize": True,
             "obs_noise": 0.01}
MIX = {"none": 0.5, "light": 0.25, "moderate": 0.25}


def _passive_returns(venv, steps):
    """Float64 returns of the braked winch over ``steps`` steps of a native vector env."""
    total = np.zeros(venv.num_envs)
    for _ in range(steps):
        _, r, term, trunc, _ = venv.step(np.zeros((venv.num_envs, 1)))
        total += r
    return total


@pytest.mark.parametrize("steps", [600, 40])
def test_braked_reference_is_the_passive_return(steps):
    """The reference of each slot equals, bit for bit, the return the braked winch then gets in
    the environment itself (randomised parameters, light turbulence, a mix with calm draws),
    over the whole 600-step episode and over a shorter limit; the slots are left as they were."""
    venv = TetheredAerostatVectorEnv(4, autoreset_mode="SameStep", max_episode_steps=steps,
                                     threads=1, **REALISTIC, turbulence_mix=MIX)
    obs, _ = venv.reset(seed=[21, 22, 23, 24])
    state = venv.batch.state.copy()
    ref = BrakedReference(venv.batch, steps).returns([0, 1, 2, 3])
    assert np.array_equal(venv.batch.state, state) and np.array_equal(venv.batch.obs, obs)
    assert np.array_equal(ref, _passive_returns(venv, steps))
    assert np.all(ref < 0)


def test_braked_reference_refuses_a_custom_reward():
    venv = TetheredAerostatVectorEnv(1, threads=1, reward_fn=lambda o, a, i: 0.0)
    with pytest.raises(ValueError, match="reward_fn"):
        BrakedReference(venv.batch, 600)


def test_score_reward_turns_returns_into_scores():
    """Through the wrapper the braked winch scores -1 on every episode (float32 sums, 1e-5),
    and a policy that reels scores its raw return over max(|braked return|, floor), episode by
    episode, with the episodes themselves unchanged by the wrapper."""
    n, steps = 4, 600
    kwargs = {**REALISTIC, "turbulence_mix": MIX, "threads": 1}
    plain = sb3_vec_env(n, seed=5, **kwargs)
    wrapped = score_reward_vec_env(sb3_vec_env(n, seed=5, **kwargs), {"floor": DEFAULT_FLOOR})
    assert np.array_equal(plain.reset(), wrapped.reset())
    braked = wrapped.braked.copy()
    rng = np.random.default_rng(0)
    raw, score, passive = np.zeros(n), np.zeros(n), np.zeros(n)
    for _ in range(steps):
        a = rng.uniform(-0.3, 0.3, (n, 1)).astype(np.float32)
        for venv in (plain, wrapped):
            venv.step_async(a)
        o1, r1, d1, _ = plain.step_wait()
        o2, r2, d2, info = wrapped.step_wait()
        assert np.array_equal(o1, o2) and np.array_equal(d1, d2)
        raw += r1
        score += r2
    assert all(i["braked_return"] == b for i, b in zip(info, braked, strict=True))
    assert score == pytest.approx(raw / np.maximum(np.abs(braked), DEFAULT_FLOOR), rel=1e-5)
    wrapped.reset()
    for _ in range(steps):
        wrapped.step_async(np.zeros((n, 1), np.float32))
        passive += wrapped.step_wait()[1]
    assert passive == pytest.approx(-np.ones(n), abs=1e-5)


@pytest.mark.parametrize("spec, expected", [(None, None), (False, None),
                                            (True, {"floor": DEFAULT_FLOOR}),
                                            ({"floor": 2}, {"floor": 2.0}),
                                            ({}, {"floor": DEFAULT_FLOOR})])
def test_score_reward_option(spec, expected):
    assert check_score_reward(spec) == expected


@pytest.mark.parametrize("spec, words", [("yes", "true, false"), ({"flor": 1}, "true, false"),
                                         ({"floor": 0}, "floor"), ({"floor": True}, "floor"),
                                         ({"floor": float("inf")}, "floor")])
def test_score_reward_refuses_bad_options(spec, words):
    with pytest.raises(PolicyError, match=words):
        check_score_reward(spec)


def test_training_refuses_a_bad_score_reward(tmp_path):
    path = tmp_path / "bad.yml"
    path.write_text(yaml.safe_dump({"TetheredAerostat-v0": {"n_envs": 2},
                                    "aerostat_gym": {"score_reward": {"floor": -1}}}))
    with pytest.raises(TrainingError, match="score_reward floor"):
        train("ppo", path, timesteps=64, run_dir=tmp_path / "r", progress_bar=False, threads=1)


# --- per-episode turbulence class ----------------------------------------------------------------


def test_mix_draws_each_class_at_its_sigma():
    """Over 200 resets each class comes up near its weight (binomial 4.5 sigma) and reads the
    field at its class's sigma: sigma_u / U(h) in the ratio of the MIL class factors
    (light : moderate = 0.5 : 1), zero for calm air."""
    env = TetheredAerostatEnv(**REALISTIC, turbulence_mix=MIX)
    ratio = {k: [] for k in MIX}
    for seed in range(200):
        _, info = env.reset(seed=seed)
        su = info["turbulence_sigma_m_s"][0]
        ratio[info["turbulence_class"]].append(su / info["wind_speed"])
    for k, w in MIX.items():
        assert abs(len(ratio[k]) - 200 * w) <= 4.5 * np.sqrt(200 * w * (1 - w))
    assert np.all(np.array(ratio["none"]) == 0.0)
    light, moderate = np.array(ratio["light"]), np.array(ratio["moderate"])
    assert np.ptp(light) < 1e-12 and np.ptp(moderate) < 1e-12  # uniform wind: sigma_u / U fixed
    assert light[0] / moderate[0] == pytest.approx(CLASS_FACTOR["light"] / CLASS_FACTOR["moderate"],
                                                   rel=1e-12)


def test_mix_draw_leaves_the_rest_of_the_episode():
    """The class is drawn last: with a one-class mix the episode (wind speed, parameters, field,
    offset, swing, sigma) is the single-class task's, and the physics steps to the same state
    (without sensor noise, whose stream the one extra draw shifts)."""
    quiet = {**REALISTIC, "obs_noise": 0.0}
    a = TetheredAerostatEnv(**quiet)
    b = TetheredAerostatEnv(**quiet, turbulence_mix={"light": 1.0})
    ia, ib = a.reset(seed=4)[1], b.reset(seed=4)[1]
    assert "turbulence_class" not in ia and ib.pop("turbulence_class") == "light"
    assert ia == ib
    for _ in range(50):
        oa = a.step(0.2)[0]
        ob = b.step(0.2)[0]
    assert np.array_equal(oa, ob)


def test_calm_draw_is_calm_air():
    """A calm draw reads the field at zero scale: its passive trajectory is that of the same
    episode in the calm task to round-off (1e-12 m on the aerostat's position)."""
    opts = {"wind_speed": 10.0,
            "perturbation": {"swing": 5.0, "lateral": 2.0, "pitch": 0.02, "fixed": True}}
    calm = TetheredAerostatEnv(turbulence="none")
    drawn = TetheredAerostatEnv(turbulence="light", turbulence_mix={"none": 1.0})
    calm.reset(seed=0, options=opts)
    drawn.reset(seed=0, options=opts)
    for _ in range(300):
        oc, od = calm.step(0.0)[0], drawn.step(0.0)[0]
    assert np.max(np.abs(oc[:3] - od[:3])) * 10.0 < 1e-12


@pytest.mark.parametrize("mix, words", [({"calm": 1.0}, "unknown intensity class"),
                                        ({"none": 0.0}, "not all be zero"),
                                        ({"light": -1.0}, "weight >= 0"),
                                        ({"light": True}, "weight >= 0"),
                                        ("light", "non-empty dict"), ({}, "non-empty dict")])
def test_mix_refuses_bad_weights(mix, words):
    with pytest.raises(TaskError, match=words):
        TetheredAerostatEnv(turbulence="light", turbulence_mix=mix)


def test_mix_needs_a_turbulence_class():
    with pytest.raises(TaskError, match="turbulence='none'"):
        TetheredAerostatEnv(turbulence="none", turbulence_mix={"light": 1.0})
