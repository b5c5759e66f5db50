"""The environment's documented contract: the sign of every attitude and position channel, one
simulator behind both front ends, the swappable reward, and get/set of the simulator state."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import aerostat_gym  # noqa: F401  (registers the environment)
from aerostat_gym.envs import spaces
from aerostat_gym.envs.reward import REWARD_TERMS
from aerostat_gym.envs.vector import TetheredAerostatVectorEnv
from aerostat_gym.physics import state as st
from aerostat_gym.physics.core import rotation_matrix
from aerostat_gym.sim import Model
from aerostat_gym.sim.winch import WinchController

CALM = {"turbulence": "none", "perturbation": "none"}

#: (state offset in the aerostat block, displacement in SI units, observation channel, the
#: channel's documented scale on the 300 m baseline: README's observation table, 10 m, 2 m/s,
#: 0.05 rad, 0.02 rad/s, 10 m of length, 1 m/s of reel speed)
DISPLACEMENTS = [
    (st.S_X, 1.0, spaces.OBS_DX, 10.0), (st.S_Y, -2.0, spaces.OBS_DY, 10.0),
    (st.S_Z, 0.5, spaces.OBS_DZ, 10.0), (st.S_VX, 0.3, spaces.OBS_VX, 2.0),
    (st.S_VY, -0.2, spaces.OBS_VY, 2.0), (st.S_VZ, 0.1, spaces.OBS_VZ, 2.0),
    (st.S_PHI, 0.02, spaces.OBS_DROLL, 0.05), (st.S_THETA, -0.01, spaces.OBS_DPITCH, 0.05),
    (st.S_PSI, 0.03, spaces.OBS_DYAW, 0.05), (st.S_P, 0.004, spaces.OBS_P, 0.02),
    (st.S_Q, -0.006, spaces.OBS_Q, 0.02), (st.S_R, 0.008, spaces.OBS_R, 0.02),
    (st.S_LENGTH, 2.0, spaces.OBS_DLENGTH, 10.0), (st.S_REEL, 0.4, spaces.OBS_REEL_SPEED, 1.0),
]


def test_named_channels_match_the_table():
    """Every OBS_* constant is the position of its channel in CHANNELS."""
    named = {k: v for k, v in vars(spaces).items() if k.startswith("OBS_") and isinstance(v, int)}
    named.pop("OBS_FULL_WIND")
    named.pop("OBS_FULL_STATE")
    assert sorted(named.values()) == list(range(spaces.N_OBS))
    for key, idx in named.items():
        assert spaces.OBS_INDEX[spaces.CHANNELS[idx].name] == idx, key
    assert spaces.OBS_FULL_WIND == spaces.N_OBS and spaces.OBS_FULL_STATE == spaces.N_OBS + 1


@pytest.fixture(scope="module")
def calm_env():
    env = gym.make("TetheredAerostat-v0", **CALM)
    env.reset(seed=0, options={"wind_speed": 10.0})
    return env.unwrapped


@pytest.mark.parametrize("offset, delta, channel, scale", DISPLACEMENTS)
def test_channel_sign_against_a_known_displacement(calm_env, offset, delta, channel, scale):
    """Displacing one state entry from the trim moves its channel by delta / the documented
    scale, exactly in sign and to float32 precision (1e-6 relative), and leaves the other
    kinematic channels at zero (the trim)."""
    b = calm_env._batch
    b.state[0] = b.trim_state[0]
    b.state[0, b.layout.aerostat + offset] += delta
    b.observe(0)
    obs = b.obs[0]
    assert obs[channel] == pytest.approx(delta / scale, rel=1e-6)
    kinematic = [row[2] for row in DISPLACEMENTS if row[2] != channel]
    np.testing.assert_array_equal(obs[kinematic], 0.0)


def test_nose_up_is_a_negative_pitch_observation(calm_env):
    """The documented sign: a nose-up rotation (the body x axis, the nose, tilts up) gives a
    negative pitch channel, as the observation table says (theta < 0 is nose up)."""
    b = calm_env._batch
    b.state[0] = b.trim_state[0]
    euler = b.state[0, b.layout.euler].copy()
    b.state[0, b.layout.aerostat + st.S_THETA] -= 0.01
    b.observe(0)
    nose_before = rotation_matrix(*euler)[:, 0]
    nose_after = rotation_matrix(*b.state[0, b.layout.euler])[:, 0]
    assert nose_after[2] > nose_before[2] + 0.009  # the nose rose by ~0.01 rad
    assert b.obs[0, spaces.OBS_DPITCH] == pytest.approx(-0.2, rel=1e-6)
    assert "positive is nose down" in spaces.CHANNELS[spaces.OBS_DPITCH].meaning


@pytest.mark.parametrize("integrator", ["rk4", "semi-implicit"])
def test_simulator_and_env_advance_bit_identically(integrator):
    """Model.advance with the winch controller and the environment's compiled step take the
    same steps: 60 control steps of varying winch commands (brake engaging and releasing) in
    moderate turbulence give bit-identical states."""
    env = gym.make("TetheredAerostat-v0", turbulence="moderate", perturbation="mixed",
                   integrator=integrator).unwrapped
    env.reset(seed=3)
    b = env._batch
    ep = b.episodes[0]
    model = Model(ep.params, (b.wind[0].copy(), b.bank[b.field_index[0]]))
    winch = WinchController(ep.params)
    x = b.state[0].copy()
    vmax = ep.params.winch.max_speed
    actions = 0.8 * np.sin(np.arange(60) / 5.0)
    actions[20:30] = 0.0  # brake
    t = 0.0
    for k, a in enumerate(actions):
        cmd = winch.command(float(np.float32(a)) * vmax, x)
        model.advance(x, t, env.task.control_step, cmd.as_input(), integrator)
        t += env.task.control_step  # the episode clock accumulates, as the env's does
        env.step(np.array([a], np.float32))
        np.testing.assert_array_equal(x, b.state[0], err_msg=f"step {k}")


def _dx_reward(obs, action, info):
    return -abs(float(obs[spaces.OBS_DX])) - 0.1 * action ** 2


def test_user_reward_replaces_the_default():
    """reward_fn's value is the reward; the dynamics, observations and the default terms in
    info are unchanged (bit-identical to the default env with the same seed)."""
    base = gym.make("TetheredAerostat-v0", turbulence="light")
    mine = gym.make("TetheredAerostat-v0", turbulence="light", reward_fn=_dx_reward)
    o1, _ = base.reset(seed=5)
    o2, _ = mine.reset(seed=5)
    for k in range(40):
        a = np.array([0.5 * np.sin(k / 4.0)], np.float32)
        o1, r1, *_, i1 = base.step(a)
        o2, r2, *_, i2 = mine.step(a)
        np.testing.assert_array_equal(o1, o2)
        assert r2 == pytest.approx(_dx_reward(o2, float(a[0]), i2), abs=1e-12)
        assert r1 == pytest.approx(sum(i2["reward_" + t] for t in REWARD_TERMS), abs=1e-9)
        assert i2["peak_tension"] == i1["peak_tension"] > 0


def test_user_reward_in_the_vector_env():
    venv = TetheredAerostatVectorEnv(num_envs=3, turbulence="light", reward_fn=_dx_reward)
    venv.reset(seed=1)
    a = np.array([[0.3], [-0.2], [0.0]], np.float32)
    obs, rew, *_ = venv.step(a)
    expect = [_dx_reward(obs[i], float(a[i, 0]), {}) for i in range(3)]
    np.testing.assert_allclose(rew, expect, rtol=0, atol=1e-12)


def test_bad_reward_fn_is_refused_at_the_door():
    with pytest.raises(ValueError, match="reward_fn must be a callable"):
        gym.make("TetheredAerostat-v0", reward_fn="velocity")
    env = gym.make("TetheredAerostat-v0", reward_fn=lambda o, a, i: float("nan"))
    env.reset(seed=0)
    with pytest.raises(ValueError, match="non-finite reward"):
        env.step(np.zeros(1, np.float32))


def test_get_set_state_replays_bit_identically():
    """Restore a snapshot taken mid-episode (turbulence, observation noise) and step on: the
    observations and rewards equal the original continuation bit for bit."""
    env = gym.make("TetheredAerostat-v0", turbulence="moderate", obs_noise=0.05).unwrapped
    env.reset(seed=11)
    rng = np.random.default_rng(0)
    actions = rng.uniform(-1, 1, (50, 1)).astype(np.float32)
    for a in actions[:20]:
        env.step(a)
    saved = env.get_state()
    first = [env.step(a)[:2] for a in actions[20:]]
    obs = env.set_state(saved)
    assert np.array_equal(obs, saved["obs"])
    second = [env.step(a)[:2] for a in actions[20:]]
    for (o1, r1), (o2, r2) in zip(first, second, strict=True):
        np.testing.assert_array_equal(o1, o2)
        assert r1 == r2


def test_set_state_refuses_a_foreign_state():
    env = gym.make("TetheredAerostat-v0", **CALM).unwrapped
    env.reset(seed=0)
    other = gym.make("TetheredAerostat-v0", n_elements=5, **CALM).unwrapped
    other.reset(seed=0)
    with pytest.raises(ValueError, match="shape"):
        env.set_state(other.get_state())
    with pytest.raises(ValueError, match="get_state"):
        env.set_state({"state": 1})


def test_threads_do_not_change_results():
    """The batched step gives bit-identical episodes on 1 thread and on every thread."""
    import numba

    runs = []
    for threads in (1, numba.config.NUMBA_NUM_THREADS):
        venv = TetheredAerostatVectorEnv(num_envs=6, turbulence="moderate", threads=threads)
        obs, _ = venv.reset(seed=2)
        for k in range(20):
            obs, *_ = venv.step(np.full((6, 1), 0.4 * np.sin(k / 3.0), np.float32))
        runs.append(obs)
    np.testing.assert_array_equal(runs[0], runs[1])


@pytest.mark.parametrize("threads", [0, -1, 1.5, True, 10**6])
def test_bad_thread_count_is_refused(threads):
    with pytest.raises(ValueError, match="threads must be an integer from 1 to"):
        TetheredAerostatVectorEnv(num_envs=2, threads=threads)


def test_reward_table_documents_every_term():
    """reward_table lists every compiled term once, with its default or overridden weight."""
    from aerostat_gym.envs import DEFAULT_WEIGHTS, reward_table

    rows = reward_table({"pitch": 0.5})
    assert [r["term"] for r in rows] == list(REWARD_TERMS)
    assert {r["term"]: r["weight"] for r in rows} == {**DEFAULT_WEIGHTS, "pitch": 0.5}
    assert all(r["formula"].startswith("-w") for r in rows)
