"""TetheredAerostat-v0: API conformance, determinism, episode ends, batching.

Physics checks assert numbers against references with the tolerance stated; API checks use
Gymnasium's and Stable-Baselines3's own checkers.
"""

from __future__ import annotations

import copy
import math
import pickle
import warnings
from dataclasses import replace

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.error import ResetNeeded

import aerostat_gym  # noqa: F401  (registers the environment)
from aerostat_gym.envs import (
    REWARD_TERMS,
    ActionError,
    TaskError,
    TetheredAerostatEnv,
    observation_table,
    sb3_vec_env,
    spaces,
)
from aerostat_gym.envs.spaces import N_OBS
from aerostat_gym.physics.state import StateLayout

ENV_ID = "TetheredAerostat-v0"


def _rollout(env, seed, actions):
    obs, _ = env.reset(seed=seed)
    out = [obs]
    for a in actions:
        obs, *_ = env.step(a)
        out.append(obs)
    return np.array(out)


@pytest.mark.parametrize("integrator", ["rk4", "semi-implicit"])
def test_gymnasium_check_env_no_warnings(integrator):
    from gymnasium.utils.env_checker import check_env

    env = gym.make(ENV_ID, integrator=integrator)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped, skip_render_check=True)


@pytest.mark.parametrize("integrator", ["rk4", "semi-implicit"])
def test_sb3_check_env_no_warnings(integrator):
    from stable_baselines3.common.env_checker import check_env

    env = TetheredAerostatEnv(integrator=integrator)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env, warn=True)


def test_make_without_prior_import_and_time_limit():
    env = gym.make("aerostat_gym:TetheredAerostat-v0")
    assert env.spec.max_episode_steps == 600
    assert env.observation_space.shape == (N_OBS,)
    assert env.observation_space.dtype == np.float32
    assert np.all(np.isfinite(env.observation_space.low))
    assert np.all(np.isfinite(env.observation_space.high))
    assert len(observation_table()) == N_OBS


def test_same_seed_bit_identical_with_turbulence():
    """Two environments, same seed, same actions, moderate turbulence: identical bits."""
    rng = np.random.default_rng(0)
    actions = rng.uniform(-1, 1, (60, 1)).astype(np.float32)
    a = _rollout(gym.make(ENV_ID, turbulence="moderate"), 123, actions)
    b = _rollout(gym.make(ENV_ID, turbulence="moderate"), 123, actions)
    c = _rollout(gym.make(ENV_ID, turbulence="moderate"), 124, actions)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_pickle_and_deepcopy_continue_identically():
    env = gym.make(ENV_ID)
    env.reset(seed=5)
    for _ in range(5):
        env.step(np.array([0.5], np.float32))
    clones = [pickle.loads(pickle.dumps(env)), copy.deepcopy(env)]
    ref = [env.step(np.array([-0.3], np.float32))[0] for _ in range(5)]
    for c in clones:
        got = [c.step(np.array([-0.3], np.float32))[0] for _ in range(5)]
        assert np.array_equal(np.array(ref), np.array(got))


def test_reward_is_sum_of_named_terms():
    """The reward is the sum of the info terms, and each term is its formula (reward.REWARD_DOC,
    default weights on the 300 m baseline, band 15 m = 1.5 scaled) applied to the observation,
    the action and the peak tension the step returned (float32 observation: rel 1e-5)."""
    env = gym.make(ENV_ID)
    env.reset(seed=3)
    swl, prev = env.unwrapped.task.params_resolved.winch.safe_working_load, 0.0
    ch = {name: spaces.OBS_INDEX[name] for name in spaces.OBS_INDEX}
    for k in range(20):
        a = math.sin(k / 3.0)
        o, r, _, _, info = env.step(np.array([a], np.float32))
        a = float(np.float32(a))
        terms = [info["reward_" + t] for t in REWARD_TERMS]
        assert all(t <= 0.0 for t in terms)
        assert abs(r - sum(terms)) <= 1e-12 * max(1.0, abs(r))  # float precision
        o = o.astype(float)
        expect = {"displacement": -(o[ch["dx"]] ** 2 + o[ch["dy"]] ** 2),
                  "velocity": -(o[ch["vx"]] ** 2 + o[ch["vy"]] ** 2),
                  "pitch": -0.1 * o[ch["dpitch"]] ** 2, "pitch_rate": -0.1 * o[ch["q"]] ** 2,
                  "effort": -0.01 * a * a, "effort_rate": -0.1 * (a - prev) ** 2,
                  "over_tension": -10.0 * max(0.0, info["peak_tension"] / swl - 1.0),
                  "termination": 0.0,
                  "length": -max(0.0, abs(o[ch["dlength"]]) - 1.5) ** 2}
        for name, value in expect.items():
            assert info["reward_" + name] == pytest.approx(value, rel=1e-5, abs=1e-9), name
        prev = a


def test_nan_action_is_a_clear_error_and_out_of_range_is_clipped():
    env = gym.make(ENV_ID)
    env.reset(seed=0)
    with pytest.raises(ActionError, match="finite"):
        env.step(np.array([np.nan], np.float32))
    with pytest.raises(ActionError, match="shape"):
        env.unwrapped.step(np.array([0.1, 0.2]))
    env2 = gym.make(ENV_ID)
    env2.reset(seed=0)
    env.reset(seed=0)
    o1, *_, info = env.unwrapped.step(np.array([7.0]))
    o2, *_ = env2.unwrapped.step(np.array([1.0]))
    assert info["action_clipped"] and np.array_equal(o1, o2)


def test_invalid_arguments_name_the_problem():
    with pytest.raises(TaskError, match="integrator"):
        TetheredAerostatEnv(integrator="euler")
    with pytest.raises(TaskError, match="turbulence"):
        TetheredAerostatEnv(turbulence="hurricane")
    with pytest.raises(TaskError, match="wind_speed"):
        TetheredAerostatEnv(wind_speed=(10.0, 5.0))
    with pytest.raises(TaskError, match="reward weight"):
        TetheredAerostatEnv(reward_weights={"comfort": 1.0})
    with pytest.raises(TaskError, match="unknown perturbation"):
        TetheredAerostatEnv(perturbation="earthquake")
    with pytest.raises(ValueError, match="render_mode"):
        TetheredAerostatEnv(render_mode="ascii")
    with pytest.raises(TaskError, match=r"'control_dt' \(did you mean 'control_step'\?\)"):
        TetheredAerostatEnv(control_dt=0.1)
    with pytest.raises(TaskError, match="unknown environment argument.*'foo'"):
        gym.make_vec("TetheredAerostat-v0", num_envs=2, vectorization_mode="vector_entry_point",
                     foo=1)
    for noise in (-0.01, float("nan"), True, "0.01"):  # one shared check (envs.spaces)
        with pytest.raises(TaskError, match="obs_noise"):
            TetheredAerostatEnv(obs_noise=noise)


def test_a_single_wind_speed_fixes_the_wind():
    """wind_speed=10.0 is the range (10, 10): every episode's mean wind is 10 m/s (exact), as
    with the pair; a negative number or a bool is refused by name, quoting the value given."""
    env = TetheredAerostatEnv(wind_speed=10.0)
    assert env.task.resolved["wind_speed"] == (10.0, 10.0)
    for seed in range(3):
        assert env.reset(seed=seed)[1]["wind_speed"] == 10.0
    with pytest.raises(TaskError, match=r"wind_speed must satisfy .* got -1.0$"):
        TetheredAerostatEnv(wind_speed=-1.0)
    with pytest.raises(TaskError, match="wind_speed must be a number or a"):
        TetheredAerostatEnv(wind_speed=True)


def test_bad_reset_options_name_the_problem():
    """reset(options=...): a misspelt key names the known ones; a wind speed that is not a
    number, NaN, or outside the task's range is a TaskError that quotes it."""
    env = TetheredAerostatEnv()
    with pytest.raises(TaskError, match=r"unknown reset option\(s\) \['windspeed'\]"):
        env.reset(seed=0, options={"windspeed": 5.0})
    with pytest.raises(TaskError, match="wind_speed must be a number .* got 'fast'"):
        env.reset(seed=0, options={"wind_speed": "fast"})
    for bad in (float("nan"), 50.0, 2.9):
        with pytest.raises(TaskError, match=r"outside the task's range \[3.0, 15.0\]"):
            env.reset(seed=0, options={"wind_speed": bad})
    assert env.reset(seed=0, options={"wind_speed": 14.96})[1]["wind_speed"] == 14.96  # exact


def test_reset_starts_at_exact_trim_without_perturbation():
    """perturbation='none', no turbulence: the start is an equilibrium, so after 10 s with the
    brake on the aerostat has moved < 1e-3 m (trim residual 1e-9 relative)."""
    env = gym.make(ENV_ID, turbulence="none", perturbation="none")
    obs, info = env.reset(seed=0, options={"wind_speed": 10.0})
    assert info["wind_speed"] == 10.0
    assert np.max(np.abs(obs[:12])) == 0.0
    for _ in range(50):
        obs, *_ = env.step(np.array([0.0], np.float32))
    assert np.max(np.abs(obs[:3])) * 10.0 < 1e-3


def test_perturbation_swings_without_stretching():
    """The rigid swing about the winch keeps every element's stretch: tensions equal the
    trim's within 1e-6 relative when the pitch kick is off."""
    from aerostat_gym.sim import Model

    env = TetheredAerostatEnv(turbulence="none", perturbation={"swing": 10.0, "lateral": 5.0})
    obs, info = env.reset(seed=2, options={"wind_speed": 8.0})
    ep = env.episode
    model = Model(ep.params, 8.0)
    t0, t1 = model.tensions(ep.x_trim), model.tensions(ep.x0)
    assert np.allclose(t0, t1, rtol=1e-6)
    assert abs(obs[0] * 10.0 - info["swing_m"]) < 0.05 * 10.0  # CM moves ~ the swing (5 %)


@pytest.mark.parametrize("anchor", [(100.0, 0.0, 0.0), (0.0, -40.0, 0.0), (0.0, 0.0, 50.0)])
def test_perturbation_swings_about_a_winch_off_the_origin(anchor):
    """Moving the winch translates the whole problem (the wind profile is measured from the
    anchor's height): the swung start keeps every element's trim tension to 1e-6 relative, and
    the first 50 braked steps observe what the winch at the origin observes to 1e-9 (the
    swing once pivoted on the origin, which broke the tether on the first step)."""
    from aerostat_gym.params import load_params
    from aerostat_gym.sim import Model

    pert = {"swing": 10.0, "lateral": 5.0}
    runs = []
    for where in ((0.0, 0.0, 0.0), anchor):
        params = load_params(overrides={"tether.anchor_position": list(where)})
        env = TetheredAerostatEnv(params=params, turbulence="none", perturbation=pert)
        obs, _ = env.reset(seed=2, options={"wind_speed": 8.0})
        ep = env.episode
        model = Model(ep.params, 8.0)
        assert np.allclose(model.tensions(ep.x0), model.tensions(ep.x_trim), rtol=1e-6)
        history = [obs]
        for _ in range(50):
            obs, _, terminated, _, _ = env.step(np.zeros(1, np.float32))
            assert not terminated
            history.append(obs)
        runs.append(np.array(history))
    assert np.allclose(runs[1], runs[0], rtol=0.0, atol=1e-9)


def test_full_observation_holds_state_deviation():
    env = gym.make(ENV_ID, observation="full")
    obs, info = env.reset(seed=1)
    lay = StateLayout(10)
    assert obs.shape == (N_OBS + 1 + lay.size,)
    assert obs[N_OBS] == pytest.approx(info["wind_speed"])
    ep = env.unwrapped.episode
    dev = (ep.x0 - ep.x_trim).astype(np.float32)
    assert np.allclose(obs[N_OBS + 1:], dev, atol=1e-6)


def test_nonfinite_state_terminates_with_failure_not_exception():
    env = gym.make(ENV_ID)
    env.reset(seed=0)
    b = env.unwrapped._batch
    b.state[0, 0] = np.nan  # a numerical failure, injected
    obs, r, term, trunc, info = env.step(np.array([0.0], np.float32))
    assert term and info["failure"] == "nonfinite_state"
    assert np.all(np.isfinite(obs)) and math.isfinite(r)


def test_ground_strike_terminates():
    env = gym.make(ENV_ID, turbulence="none", perturbation="none", tether_length=150.0,
                   wind_speed=(3.0, 3.0))
    env.reset(seed=0)
    b = env.unwrapped._batch
    lay = b.layout
    z = b.state[0, lay.cm_pos.start + 2]
    b.state[0, lay.node_pos.start + 2:lay.node_pos.stop:3] *= 1.0 / z  # squash the system to the
    b.state[0, lay.cm_pos.start + 2] = 1.0  # ground (elements go slack): CM below one diameter
    _, r, term, _, info = env.step(np.array([0.0], np.float32))
    assert term and info["termination"] == "ground_strike"
    assert info["reward_termination"] == -100.0
    # the episode is over: stepping on is refused (it went on integrating the struck system,
    # -100 a step) until a reset starts a new one
    with pytest.raises(ResetNeeded, match=r"step\(\) after the episode ended \(ground_strike\): "
                       r"call reset\(\)"):
        env.step(np.array([0.0], np.float32))
    env.reset(seed=1)
    assert not env.step(np.array([0.0], np.float32))[2]


def test_vector_env_matches_single_envs():
    n = 3
    venv = gym.make_vec(ENV_ID, num_envs=n, vectorization_mode="vector_entry_point")
    obs, _ = venv.reset(seed=40)
    singles = [gym.make(ENV_ID) for _ in range(n)]
    sobs = [s.reset(seed=40 + i)[0] for i, s in enumerate(singles)]
    assert np.array_equal(obs, np.array(sobs))
    rng = np.random.default_rng(1)
    for _ in range(30):
        a = rng.uniform(-1, 1, (n, 1)).astype(np.float32)
        obs, rew, *_ = venv.step(a)
        ref = [s.step(a[i]) for i, s in enumerate(singles)]
        assert np.array_equal(obs, np.array([r[0] for r in ref]))
        assert np.array_equal(rew, np.array([r[1] for r in ref]))


def test_sync_vector_env_of_the_single_env_works():
    """Gymnasium's SyncVectorEnv stacks the reset and step infos (same keys every episode)."""
    venv = gym.make_vec(ENV_ID, num_envs=3, vectorization_mode="sync")
    obs, info = venv.reset(seed=0)
    assert obs.shape == (3, N_OBS) and info["_wind_speed"].all()
    obs, rew, term, trunc, info = venv.step(np.zeros((3, 1), np.float32))
    assert np.allclose(rew, info["reward_displacement"] + info["reward_velocity"]
                       + sum(info["reward_" + k] for k in REWARD_TERMS[2:]))


def test_vector_env_next_step_autoreset():
    venv = gym.make_vec(ENV_ID, num_envs=2, vectorization_mode="vector_entry_point",
                        max_episode_steps=5)
    venv.reset(seed=0)
    a = np.zeros((2, 1), np.float32)
    for _ in range(4):
        _, _, term, trunc, _ = venv.step(a)
        assert not trunc.any()
    _, _, term, trunc, info = venv.step(a)
    assert trunc.all() and not term.any()
    _, rew, term, trunc, info = venv.step(a)  # the reset step
    assert np.all(rew == 0.0) and not (term | trunc).any() and info["_wind_speed"].all()


def test_vector_env_disabled_autoreset_waits_for_a_masked_reset():
    """DISABLED: an ended slot reports its end once, then holds its final observation with
    reward 0 until reset with a mask; the reset slot starts the episode a single env reset with
    the same seed starts, the other keeps holding."""
    from gymnasium.vector import AutoresetMode

    venv = gym.make_vec(ENV_ID, num_envs=2, vectorization_mode="vector_entry_point",
                        max_episode_steps=3, autoreset_mode=AutoresetMode.DISABLED)
    venv.reset(seed=5)
    a = np.full((2, 1), 0.2, np.float32)
    for _ in range(3):
        obs, rew, term, trunc, _ = venv.step(a)
    assert trunc.all() and not term.any()
    final = obs.copy()
    venv.reset(seed=[None, None], options={"reset_mask": np.array([False, False])})
    for _ in range(2):  # nothing reset: both slots hold, report nothing, score nothing
        obs, rew, term, trunc, info = venv.step(a)
        assert np.array_equal(obs, final) and np.all(rew == 0.0) and not (term | trunc).any()
        assert info == {}  # as SyncVectorEnv stacks them: no slot stepped, no key
    obs, _ = venv.reset(seed=[7, None], options={"reset_mask": np.array([True, False])})
    assert np.array_equal(obs[0], gym.make(ENV_ID).reset(seed=7)[0])
    assert np.array_equal(obs[1], final[1])
    with pytest.raises(ValueError, match=r"reset_mask must be a boolean array of shape \(2,\)"):
        venv.reset(options={"reset_mask": np.array([True, False, True])})


@pytest.mark.parametrize("steps", [0, -5, 2.5])
def test_vector_env_refuses_a_bad_episode_limit(steps):
    """max_episode_steps 0 used to mean the default 600 and a negative one truncated every step;
    both, and a non-integer, are refused naming the argument."""
    with pytest.raises(ValueError, match=rf"max_episode_steps must be an integer >= 1, got {steps}"):
        gym.make_vec(ENV_ID, num_envs=2, vectorization_mode="vector_entry_point",
                     max_episode_steps=steps)


def test_sb3_adapter_is_a_vecenv():
    from stable_baselines3.common.vec_env import VecEnv

    venv = sb3_vec_env(4, seed=0, max_episode_steps=3)
    assert isinstance(venv, VecEnv)
    obs = venv.reset()
    assert obs.shape == (4, N_OBS)
    for _ in range(3):
        obs, rew, dones, infos = venv.step(np.zeros((4, 1), np.float32))
    assert dones.all()
    assert infos[0]["TimeLimit.truncated"] and infos[0]["terminal_observation"].shape == (N_OBS,)


def test_rendering_single_and_vector():
    env = gym.make(ENV_ID, render_mode="rgb_array")
    env.reset(seed=0)
    assert env.render().shape == (480, 800, 3)
    venv = gym.make_vec(ENV_ID, num_envs=2, vectorization_mode="vector_entry_point",
                        render_mode="rgb_array")
    venv.reset(seed=0)
    frames = venv.render()  # one per environment, as SyncVectorEnv (env 0's alone before 0.7.17)
    assert isinstance(frames, tuple) and len(frames) == 2
    assert all(f.shape == (480, 800, 3) and f.dtype == np.uint8 for f in frames)
    assert not np.array_equal(frames[0], frames[1])  # two episodes, two pictures
    single = gym.make(ENV_ID, render_mode="rgb_array")
    single.reset(seed=1)  # environment 1 of the batch seeded 0
    assert np.array_equal(frames[1], single.render())
    sb3 = sb3_vec_env(2, seed=0, render_mode="rgb_array")
    sb3.reset()
    images = sb3.get_images()
    assert len(images) == 2 and np.array_equal(images[1], frames[1])
    tiled = sb3.render()  # SB3 tiles the frames into one picture
    assert tiled.shape[0] * tiled.shape[1] == 2 * 480 * 800 and tiled.shape[2] == 3


def test_trim_cache_is_bounded(monkeypatch):
    """The process-wide trim cache keeps at most MAX_CACHED_TRIMS tables, evicting the oldest;
    a table already cached is served without being rebuilt (the builder is stubbed: the bound,
    not the trims, is under test)."""
    from aerostat_gym.envs import episodes
    from aerostat_gym.params import load_params

    built = []

    def fake_build(params, speeds):
        built.append(params.tether.length)
        return np.zeros((speeds.size, 3)), np.zeros(speeds.size), np.zeros(speeds.size)

    monkeypatch.setattr(episodes, "_TRIMS", {})
    monkeypatch.setattr(episodes, "_build_trims", fake_build)
    monkeypatch.setattr(episodes, "MAX_CACHED_TRIMS", 3)
    base = load_params()
    lengths = [200.0, 250.0, 300.0, 350.0]
    for length in lengths:
        episodes.TrimTable(replace(base, tether=replace(base.tether, length=length)), 3.0, 15.0)
    assert len(episodes._TRIMS) == 3 and built == lengths
    # the newest three are served from the cache; the oldest (200 m) was evicted and is rebuilt
    for length in lengths[1:]:
        episodes.TrimTable(replace(base, tether=replace(base.tether, length=length)), 3.0, 15.0)
    assert built == lengths
    episodes.TrimTable(replace(base, tether=replace(base.tether, length=200.0)), 3.0, 15.0)
    assert built == [*lengths, 200.0] and len(episodes._TRIMS) == 3


def test_an_off_grid_reset_speed_is_trimmed_once_and_remembered(monkeypatch):
    """A reset option off the 0.1 m/s grid is trimmed exactly (the start is an equilibrium:
    < 1e-3 m drift in 10 s with the brake on) the first time; a second reset at that speed
    reads the remembered trim: no trim runs, and the start is bit-identical."""
    from aerostat_gym.envs import episodes

    env = gym.make(ENV_ID, turbulence="none", perturbation="none")
    obs1, _ = env.reset(seed=0, options={"wind_speed": 7.33})
    state1 = env.unwrapped._batch.state[0].copy()
    for _ in range(50):
        obs, *_ = env.step(np.array([0.0], np.float32))
    assert np.max(np.abs(obs[:3])) * 10.0 < 1e-3

    def no_trim(*args, **kwargs):
        raise AssertionError("the off-grid trim ran again")
    monkeypatch.setattr(episodes, "find_equilibrium", no_trim)
    obs2, info = env.reset(seed=1, options={"wind_speed": 7.33})
    assert info["wind_speed"] == 7.33
    np.testing.assert_array_equal(obs2, obs1)
    np.testing.assert_array_equal(env.unwrapped._batch.state[0], state1)
