"""The environment's doors for a client: calls out of order (step or render before reset, any
call after close), the wind speed taken exactly as asked, bounded perturbations, a turbulence
grid refused before it is allocated, the vector env's seeds, and the native vector env's infos
laid out as Gymnasium's SyncVectorEnv lays out the single env's."""

import json
import pickle
import re
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.error import ClosedEnvironmentError, ResetNeeded
from gymnasium.vector import AutoresetMode

from aerostat_gym.envs import ENV_ID, TaskError, TetheredAerostatEnv
from aerostat_gym.envs.vector import SB3_REASONS, SB3_RESET_PREFIX, TetheredAerostatVectorEnv
from aerostat_gym.params import load_params
from aerostat_gym.sim.events import TETHER_BREAK
from aerostat_gym.wind.synthesis import MAX_FIELD_BYTES

SMALL = {"n_elements": 5}  # a short tether discretisation: quick trims and steps
CALM = {"turbulence": "none", "perturbation": "none", **SMALL}


def _vector(n=2, **kw):
    return TetheredAerostatVectorEnv(n, **{**SMALL, **kw})


# --- D1: step before reset ------------------------------------------------------------------


def test_single_env_step_before_reset_asks_for_reset():
    env = TetheredAerostatEnv(**SMALL)
    with pytest.raises(ResetNeeded, match=r"^step\(\) before reset\(\): call reset\(\)"):
        env.step([0.0])


def test_vector_env_step_before_reset_names_the_slots():
    venv = gym.make_vec(ENV_ID, num_envs=2, vectorization_mode="vector_entry_point", **SMALL)
    with pytest.raises(ResetNeeded, match=r"environment\(s\) \[0, 1\] never reset"):
        venv.step(np.zeros((2, 1)))


def test_vector_env_masked_first_reset_leaves_the_other_slot_unstarted():
    venv = _vector(2, autoreset_mode=AutoresetMode.DISABLED)
    venv.reset(seed=0, options={"reset_mask": np.array([True, False])})
    with pytest.raises(ResetNeeded, match=r"environment\(s\) \[1\] never reset"):
        venv.step(np.zeros((2, 1)))
    venv.reset(seed=[None, 4], options={"reset_mask": np.array([False, True])})
    _, rewards, *_ = venv.step(np.zeros((2, 1)))
    assert rewards.shape == (2,) and np.all(rewards <= 0.0)


def test_set_state_starts_an_unreset_env():
    """A snapshot restored into a fresh env is an episode: step() goes on from it."""
    src = TetheredAerostatEnv(**SMALL)
    src.reset(seed=3)
    saved = src.get_state()
    ref = src.step([0.2])[0]
    env = TetheredAerostatEnv(**SMALL)
    env.set_state(saved)
    assert np.array_equal(env.step([0.2])[0], ref)


# --- D2: render before reset, any call after close -------------------------------------------


def test_render_before_reset_asks_for_reset():
    env = TetheredAerostatEnv(render_mode="rgb_array", **SMALL)
    with pytest.raises(ResetNeeded, match=r"^render\(\) before reset\(\)"):
        env.render()
    venv = _vector(2, render_mode="rgb_array")
    with pytest.raises(ResetNeeded, match=r"^render\(\) before reset\(\)"):
        venv.render()


@pytest.mark.parametrize("call, name", [
    (lambda env: env.step([0.0]), "step()"),
    (lambda env: env.reset(seed=0), "reset()"),
    (lambda env: env.render(), "render()"),
    (lambda env: env.set_state({}), "set_state()"),
    (lambda env: env.get_state(), "get_state()"),
])
def test_single_env_refuses_every_call_after_close(call, name):
    """Without its turbulence bank a closed env would run in calm air while its infos report
    the turbulence (std of the measured air speed 1e-7 instead of 0.06 in severe turbulence)."""
    env = TetheredAerostatEnv(render_mode="rgb_array", turbulence="severe", wind_speed=12.0,
                              **SMALL)
    env.reset(seed=0)
    env.close()
    env.close()  # twice is fine
    with pytest.raises(ClosedEnvironmentError, match=re.escape(
            f"{name} on a closed environment: close() released its turbulence fields")):
        call(env)


def test_render_without_a_render_mode_is_refused_after_close_too():
    """render() of an env made without a render_mode warns and returns None while it is
    open; after close() it is refused as every other call (it returned None before 0.7.17)."""
    env = TetheredAerostatEnv(**SMALL)
    env.reset(seed=0)
    env.close()
    with pytest.raises(ClosedEnvironmentError, match=r"^render\(\) on a closed environment"):
        env.render()
    venv = _vector(2)
    venv.reset(seed=0)
    assert venv.render() is None
    venv.close()
    with pytest.raises(ClosedEnvironmentError, match=r"^render\(\) on a closed environment"):
        venv.render()


def test_vector_env_refuses_step_reset_and_render_after_close():
    venv = _vector(2, render_mode="rgb_array")
    venv.reset(seed=0)
    venv.close()
    venv.close()
    assert venv.closed is True
    for call, name in ((lambda: venv.step(np.zeros((2, 1))), r"step\(\)"),
                       (lambda: venv.reset(seed=0), r"reset\(\)"),
                       (venv.render, r"render\(\)")):
        with pytest.raises(ClosedEnvironmentError, match=rf"^{name} on a closed environment"):
            call()


def test_a_closed_env_stays_closed_through_pickle():
    env = TetheredAerostatEnv(**SMALL)
    env.reset(seed=0)
    env.close()
    copy = pickle.loads(pickle.dumps(env))
    with pytest.raises(ClosedEnvironmentError, match=r"^reset\(\) on a closed environment"):
        copy.reset(seed=0)


# --- D3: the wind speed asked for -----------------------------------------------------------


@pytest.mark.parametrize("speed", [10.05, 7.25, 0.05])
def test_a_fixed_wind_speed_off_the_grid_is_taken_exactly_at_its_trim(speed):
    """Off the 0.1 m/s grid the trim is computed at the speed itself: unperturbed in calm
    air, the aerostat starts at rest and stays there (< 1 mm after 10 s)."""
    env = TetheredAerostatEnv(wind_speed=speed, **CALM)
    obs, info = env.reset(seed=0)
    assert info["wind_speed"] == speed and env.episode.wind_speed == speed
    assert np.max(np.abs(obs[:12])) == 0.0
    for _ in range(50):
        obs, *_ = env.step([0.0])
    assert np.max(np.abs(obs[:3])) * 10.0 < 1e-3


def test_a_reset_option_off_the_grid_is_exact_and_deterministic():
    env = TetheredAerostatEnv(**SMALL)
    a = env.reset(seed=5, options={"wind_speed": 10.05})
    b = env.reset(seed=5, options={"wind_speed": 10.05})
    assert a[1]["wind_speed"] == b[1]["wind_speed"] == 10.05
    assert np.array_equal(a[0], b[0])
    assert env.reset(seed=5, options={"wind_speed": 10.0})[1]["wind_speed"] == 10.0


def test_the_registered_task_draws_the_speeds_it_always_drew():
    """Random speeds still land on the grid points they landed on (stored evaluations)."""
    env = gym.make(ENV_ID)
    assert [env.reset(seed=s)[1]["wind_speed"] for s in range(6)] == \
        [13.2, 8.7, 13.1, 12.8, 11.7, 11.1]


def test_a_range_draws_only_grid_points_inside_it():
    env = TetheredAerostatEnv(wind_speed=(3.05, 3.25), **CALM)
    drawn = {env.reset(seed=s)[1]["wind_speed"] for s in range(30)}
    assert drawn == {3.1, 3.2}
    assert env.reset(seed=0, options={"wind_speed": 3.05})[1]["wind_speed"] == 3.05  # its end


@pytest.mark.parametrize("speeds", [(3.01, 3.04), (3.06, 3.09)])
def test_a_range_without_a_grid_point_is_refused_at_make(speeds):
    with pytest.raises(TaskError, match=r"holds no point of the 0.1 m/s grid .*nearest: 3 and "
                                        r"3.1 m/s"):
        TetheredAerostatEnv(wind_speed=speeds, **CALM)


@pytest.mark.parametrize("option, message", [
    (3.3, r"reset option wind_speed=3.3 is outside the task's range \[3.05, 3.25\] m/s"),
    (True, r"reset option wind_speed must be a number \[m/s\], got True"),
    ("3.1", r"reset option wind_speed must be a number \[m/s\], got '3.1'"),
])
def test_bad_wind_speed_options_are_named(option, message):
    env = TetheredAerostatEnv(wind_speed=(3.05, 3.25), **CALM)
    with pytest.raises(TaskError, match=message):
        env.reset(seed=0, options={"wind_speed": option})


def test_a_wind_speed_string_is_not_a_range():
    with pytest.raises(TaskError, match=r"wind_speed must be a number or a \(low, high\) pair, "
                                        r"got '12'"):
        TetheredAerostatEnv(wind_speed="12")


# --- D4: bounded perturbations --------------------------------------------------------------

BAD_PERTURBATIONS = [
    ({"gust_duration": (0, 0), "gust_probability": 1.0},
     r"perturbation gust_duration must be > 0 s .* got \(0.0, 0.0\)"),
    ({"swing": 1e6}, r"perturbation swing = 1000000.0 m exceeds the tether length: \|swing\| "
                     r"<= 300 m"),
    ({"lateral": -400.0, "fixed": True}, r"perturbation lateral = -400.0 m exceeds the tether "
                                         r"length"),
    ({"pitch": 1e300}, r"perturbation pitch = 1e\+300 rad exceeds pi/2"),
    ({"gust_amplitude": 1e4}, r"perturbation gust_amplitude \[m/s\] must satisfy 0.0 <= low "
                              r"<= high <= 100 \(finite\), got 10000.0"),
    ({"gust_duration": (5.0, 1e300)}, r"perturbation gust_duration \[s\] must satisfy .* <= "
                                      r"3600"),
    ({"gust_onset": 1e300}, r"perturbation gust_onset \[s\] must satisfy .* <= 86400"),
    ({"gust_probability": "often"}, r"perturbation gust_probability must be a number in "
                                    r"\[0, 1\], got 'often'"),
    ({"swing": True}, r"perturbation swing must be a finite number \(>= 0 unless fixed\), "
                      r"got True"),
]


@pytest.mark.parametrize("spec, message", BAD_PERTURBATIONS)
def test_bad_perturbations_are_refused_at_make(spec, message):
    with pytest.raises(TaskError, match=message):
        TetheredAerostatEnv(perturbation=spec, **SMALL)


@pytest.mark.parametrize("spec, message", BAD_PERTURBATIONS[:3])
def test_bad_perturbations_are_refused_as_reset_options(spec, message):
    env = TetheredAerostatEnv(**SMALL)
    with pytest.raises(TaskError, match=message):
        env.reset(seed=0, options={"perturbation": spec})


def test_a_gust_on_the_top_mean_wind_stays_below_the_wind_cap():
    """The gust adds to the mean wind: a 60 m/s gust on winds up to 45 m/s (105 m/s) is refused
    at make and as a reset option on a 3-15 m/s task with 90 m/s gusts; 85 m/s gusts on 15 m/s
    (100 m/s) and any gust that never blows (probability 0) pass."""
    gust = {"gust_probability": 1.0, "gust_amplitude": (1.0, 60.0)}
    with pytest.raises(TaskError, match=r"up to 60 m/s on a mean wind_speed up to 45 m/s "
                                        r"reaches 105 m/s, above 100 m/s"):
        TetheredAerostatEnv(turbulence="none", wind_speed=(3.0, 45.0), perturbation=gust)
    env = TetheredAerostatEnv(turbulence="none", wind_speed=(3.0, 15.0),
                              perturbation={**gust, "gust_amplitude": (1.0, 85.0)})
    with pytest.raises(TaskError, match=r"reaches 105 m/s"):
        env.reset(seed=0, options={"perturbation": {**gust, "gust_amplitude": (1.0, 90.0)}})
    TetheredAerostatEnv(turbulence="none", wind_speed=(3.0, 45.0),
                        perturbation={**gust, "gust_probability": 0.0})


def test_the_swing_bound_follows_the_configured_tether():
    with pytest.raises(TaskError, match=r"\|swing\| <= 150 m"):
        TetheredAerostatEnv(perturbation={"swing": 151.0}, tether_length=150.0, **SMALL)
    env = TetheredAerostatEnv(perturbation={"swing": 150.0, "fixed": True}, tether_length=150.0,
                              turbulence="none", **SMALL)
    assert env.reset(seed=0)[1]["swing_m"] == 150.0


# --- D5: turbulence grids refused before allocation -----------------------------------------


@pytest.mark.parametrize("turbulence, message", [
    ({"preset": "moderate", "dz": 1e-3},
     r"wind_bank_size = 8\): 8 field\(s\) of 421779 heights \(dz = 0.001 m .* would take 350 "
     r"GiB, above the 4 GiB cap"),
    ({"preset": "moderate", "downwind_extent": 1e12},
     r"samples along the wind \(every 1 m over twice downwind_extent = 1e\+12 m .* above the 4 "
     r"GiB cap"),
])
def test_a_turbulence_grid_above_the_cap_is_refused_naming_its_setting(turbulence, message):
    with pytest.raises(TaskError, match=message):
        TetheredAerostatEnv(turbulence=turbulence)
    assert MAX_FIELD_BYTES == 4 * 2**30


def test_a_subnormal_dz_is_named_not_an_overflow():
    with pytest.raises(TaskError, match=r"turbulence dz = 1e-320 m is too small for the field's "
                                        r"42\d.\d+ m of heights"):
        TetheredAerostatEnv(turbulence={"preset": "moderate", "dz": 1e-320})


def test_a_large_bank_is_refused_naming_wind_bank_size():
    with pytest.raises(TaskError, match=r"turbulence bank \(wind_bank_size = 10000\): 10000 "
                                        r"field\(s\) .* lower the extents or wind_bank_size"):
        TetheredAerostatEnv(wind_bank_size=10_000, **SMALL)


def test_a_winch_below_the_ground_names_the_anchor():
    """The parameter loader's limit (a ParameterError) names it before the turbulence grid,
    whose z_min it is, would refuse it as "turbulence z_min"."""
    with pytest.raises(ValueError, match=r"tether.anchor_position = \[0.0, 0.0, -1000.0\] puts "
                                         r"the winch at z = -1000 m, below the ground"):
        TetheredAerostatEnv(overrides={"tether.anchor_position": [0, 0, -1000.0]}, **SMALL)


# --- D13: the vector env's seeds ------------------------------------------------------------


@pytest.mark.parametrize("seed, message", [
    ("a", r"seed must be None, an integer >= 0 or a list of 3 of them .* got 'a'"),
    (-1, r"seed must be None, an integer >= 0 or a list of 3 of them .* got -1"),
    ([1, "b", 3], r"seed must be None, an integer >= 0 or a list of 3 .* got \[1, 'b', 3\]"),
    ([1, 2], r"seed: expected a list of 3 seeds \(one per environment\), got 2"),
])
def test_bad_vector_seeds_are_named(seed, message):
    venv = _vector(3)
    with pytest.raises(TaskError, match=message):
        venv.reset(seed=seed)


def test_good_vector_seeds_match_single_envs():
    venv = _vector(3)
    obs, _ = venv.reset(seed=[7, None, np.int64(9)])
    assert np.array_equal(obs[0], TetheredAerostatEnv(**SMALL).reset(seed=7)[0])
    assert np.array_equal(obs[2], TetheredAerostatEnv(**SMALL).reset(seed=9)[0])


# --- D7: the native vector env's infos are SyncVectorEnv's -----------------------------------

#: a tether just 30 % stronger than its trim at 12 m/s in severe turbulence: some episodes
#: break it, others reach the 12-step limit, at different steps
BREAKING = 3302.0 * 1.3
EPISODES = {"n_elements": 5, "wind_speed": 12.0, "turbulence": "severe", "max_episode_steps": 12,
            "overrides": {"tether.strength": BREAKING, "winch.safe_working_load": BREAKING / 3,
                          "winch.max_motor_force": BREAKING / 3}}


def _pair(mode):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the winch-motor warning of the weak tether
        native = gym.make_vec(ENV_ID, num_envs=4, vectorization_mode="vector_entry_point",
                              autoreset_mode=mode, **EPISODES)
        sync = gym.make_vec(ENV_ID, num_envs=4, vectorization_mode="sync",
                            vector_kwargs={"autoreset_mode": mode}, **EPISODES)
    return native, sync


def _assert_same(a, b, where):
    """Same keys, dtypes and values, recursively (final_info is a dict; final_obs holds
    arrays or None)."""
    if isinstance(b, dict):
        assert isinstance(a, dict) and set(a) == set(b), (where, sorted(set(a) ^ set(b)))
        for k in b:
            _assert_same(a[k], b[k], f"{where}/{k}")
        return
    assert a.dtype == b.dtype, (where, a.dtype, b.dtype)
    if b.dtype == object:
        assert all((x is None and y is None) or np.array_equal(x, y)
                   for x, y in zip(a, b, strict=True)), where
    else:
        assert np.array_equal(a, b), where


@pytest.mark.parametrize("mode", [AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP])
def test_native_vector_infos_are_sync_vector_infos(mode):
    """Over 30 steps with breaks and time limits, autoreset on: the same keys, masks and values
    as SyncVectorEnv's, but for the SAME_STEP keys the SB3 adapter reads (the ended slots'
    reasons at the top level, their reset infos prefixed reset_)."""
    native, sync = _pair(mode)
    started, s_started = native.reset(seed=3)[1], sync.reset(seed=3)[1]
    _assert_same(started, s_started, "reset")
    reset_keys = [k for k in started if not k.startswith("_")]
    count, reasons = {"terminated": 0, "truncated": 0}, []
    for k in range(30):
        a = np.full((4, 1), 0.3 * (-1) ** k, np.float32)
        obs, rew, term, trunc, info = native.step(a)
        s_obs, s_rew, s_term, s_trunc, s_info = sync.step(a)
        assert np.array_equal(obs, s_obs) and np.array_equal(rew, s_rew)
        assert np.array_equal(term, s_term) and np.array_equal(trunc, s_trunc)
        legacy = set()
        if mode == AutoresetMode.SAME_STEP and (term | trunc).any():
            names = [SB3_RESET_PREFIX + k for k in reset_keys]
            names += [k for k in SB3_REASONS if k in s_info["final_info"]]
            legacy = {key for k in names for key in (k, "_" + k)}
        assert set(info) - set(s_info) == legacy
        _assert_same({k: v for k, v in info.items() if k not in legacy}, s_info, f"step {k}")
        count["terminated"] += int(term.sum())
        count["truncated"] += int(trunc.sum())
        ended = info["final_info"] if mode == AutoresetMode.SAME_STEP and term.any() else info
        reasons += list(ended["termination"][term]) if term.any() else []
    assert count == {"terminated": 1, "truncated": 8} and reasons == ["tether_break"]


def test_sb3_adapter_infos_are_dummy_vec_env_infos():
    """Over 30 steps with breaks and time limits: sb3_vec_env's per-environment infos have the
    keys and values of DummyVecEnv's over the single env (every step's reward terms, time, peak
    tension, action_clipped and TimeLimit.truncated; an ended episode's reason and terminal
    observation), and its reset_infos the new episodes'. Before 0.7.17 a running
    environment's info was empty."""
    from stable_baselines3.common.vec_env import DummyVecEnv

    from aerostat_gym.envs import sb3_vec_env

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the winch-motor warning of the weak tether
        native = sb3_vec_env(4, seed=3, **EPISODES)
        steps = EPISODES["max_episode_steps"]
        task = {k: v for k, v in EPISODES.items() if k != "max_episode_steps"}
        dummy = DummyVecEnv([lambda: gym.make(ENV_ID, max_episode_steps=steps, **task)] * 4)
    dummy.seed(3)
    assert np.array_equal(native.reset(), dummy.reset())
    ends = []
    for k in range(30):
        a = np.full((4, 1), 0.3 * (-1) ** k, np.float32)
        obs, rew, done, infos = native.step(a)
        d_obs, d_rew, d_done, d_infos = dummy.step(a)
        assert np.array_equal(obs, d_obs) and np.array_equal(rew, d_rew)
        assert np.array_equal(done, d_done)
        for i, (mine, theirs) in enumerate(zip(infos, d_infos, strict=True)):
            assert set(mine) == set(theirs), (k, i, sorted(set(mine) ^ set(theirs)))
            for key, value in theirs.items():
                assert np.array_equal(mine[key], value), (k, i, key)
            if done[i]:
                ends.append(mine.get("termination", "time limit"))
                assert native.reset_infos[i]["wind_speed"] == dummy.reset_infos[i]["wind_speed"]
    assert sorted(set(ends)) == ["tether_break", "time limit"]


def test_time_limit_sets_no_truncation_reason_but_time():
    """As the single env (its TimeLimit wrapper names no reason): no 'truncation' key."""
    venv = _vector(2, max_episode_steps=2, **{"turbulence": "none"})
    venv.reset(seed=0)
    venv.step(np.zeros((2, 1)))
    _, _, term, trunc, info = venv.step(np.zeros((2, 1)))
    assert trunc.all() and not term.any() and "truncation" not in info
    assert np.allclose(info["time"], 0.4) and info["_time"].all()
    _, rew, _, _, info = venv.step(np.zeros((2, 1)))  # NEXT_STEP: both slots reset
    assert np.all(rew == 0.0) and info["_wind_speed"].all() and "reward_effort" not in info


def test_an_unknown_turbulence_preset_lists_every_valid_one():
    """'config' (the parameter file's own turbulence) is valid too, so the refusal lists it."""
    with pytest.raises(TaskError, match=re.escape(
            "unknown turbulence preset 'lite'; choose one of ['none', 'light', 'moderate', "
            "'severe', 'config']")):
        gym.make(ENV_ID, turbulence="lite")


def test_a_params_rebuilt_with_dataclasses_replace_meets_the_loader_checks():
    """dataclasses.replace skips Params.replace's checks; the environment runs them at make:
    a zero element count and a string for g are named (were a ZeroDivisionError and a numpy
    TypeError deep in the model), an eta_k of 5 refused (was accepted)."""
    import dataclasses

    from aerostat_gym.params import ParameterError, load_params
    p = load_params()
    cases = [(dataclasses.replace(p, tether=dataclasses.replace(p.tether, n_elements=0)),
              "tether.n_elements must be an integer >= 1"),
             (dataclasses.replace(p, environment=dataclasses.replace(p.environment, g="9.81")),
              "environment.g must be a number, got '9.81'"),
             (dataclasses.replace(p, hull=dataclasses.replace(p.hull, eta_k=5.0)),
              "hull.eta_k must lie in [0, 1], got 5.0")]
    for bad, message in cases:
        with pytest.raises(ParameterError, match=re.escape(message)):
            gym.make(ENV_ID, params=bad)


def test_a_log_profile_needs_its_roughness_below_its_reference_height():
    """ln(z / z0) / ln(z_ref / z0) with z0 >= z_ref turns the wind around (a reset failed on a
    'turbulence speed -51.57'): refused where the file loads, naming both fields."""
    from aerostat_gym.params import ParameterError
    with pytest.raises(ParameterError, match=r"wind\.roughness_length = 20 m must be below "
                       r"wind\.reference_height = 10 m"):
        gym.make(ENV_ID, overrides={"wind.profile": "log", "wind.roughness_length": 20.0})


def test_num_envs_is_bounded_before_anything_is_allocated():
    """10**7 environments allocated 12.7 GB for minutes; the count is refused at once."""
    with pytest.raises(ValueError, match=re.escape("num_envs must be an integer in [1, 65536], "
                                                   "got 10000000")):
        TetheredAerostatVectorEnv(num_envs=10**7)


def test_a_randomisation_range_must_stay_plausible():
    """rk4_safety 0.9 +- 60 % reaches 1.44, past the RK4 stability edge the loader refuses
    (6 of 12 resets drew such values): refused at make."""
    with pytest.raises(TaskError, match=r"reaches simulation\.rk4_safety = 1\.44, which the "
                       r"loader refuses: simulation\.rk4_safety = 1\.44 exceeds 1\.02"):
        gym.make(ENV_ID, randomize={"simulation.rk4_safety": 0.6}, integrator="rk4")


def test_a_reward_fn_must_take_three_arguments_and_return_a_number():
    """A reward_fn without the (obs, action, info) signature is named at make (was a TypeError
    at the first step); "1" and True are not rewards (were read as 1.0); a NumPy scalar and a
    0-d array are the numbers they hold."""
    with pytest.raises(TaskError, match=re.escape("reward_fn must take three arguments f(obs, "
                                                  "action, info), got <lambda>()")):
        gym.make(ENV_ID, reward_fn=lambda: 0.0)
    for bad in ("1", True):
        env = gym.make(ENV_ID, reward_fn=lambda o, a, i, bad=bad: bad)
        env.reset(seed=0)
        with pytest.raises(ValueError, match=re.escape(f"reward_fn must return a number, got "
                                                       f"{bad!r}")):
            env.step(np.zeros(1, np.float32))
    for good, value in ((np.float32(2.0), 2.0), (np.array(3.0), 3.0)):
        env = gym.make(ENV_ID, reward_fn=lambda o, a, i, good=good: good)
        env.reset(seed=0)
        assert env.step(np.zeros(1, np.float32))[1] == value


def test_the_sb3_adapter_names_a_bad_seed_and_an_unknown_attribute():
    """seed('x') and seed(-1) are refused at the call (were an SB3 TypeError, and a refusal at
    the next reset); get_attr of an unknown name is an AttributeError, as DummyVecEnv's (was
    a list of None)."""
    from aerostat_gym.envs import sb3_vec_env
    venv = sb3_vec_env(2)
    for bad in ("x", -1):
        with pytest.raises(ValueError, match=re.escape(f"seed must be None or an integer >= 0, "
                                                       f"got {bad!r}")):
            venv.seed(bad)
    with pytest.raises(AttributeError, match="bogus"):
        venv.get_attr("bogus")
    assert venv.get_attr("num_envs") == [2, 2]
    venv.close()


def test_the_sb3_adapter_refuses_per_environment_calls_it_cannot_make():
    """Its environments are slots of one batch: env_method is refused naming why (it called
    the batch's method once per index, so env_method('reset', indices=[0]) reset both), and
    set_attr for some environments only is refused; set_attr for all sets the batch's."""
    from aerostat_gym.envs import sb3_vec_env
    venv = sb3_vec_env(2, seed=0, **SMALL)
    obs = venv.reset()
    with pytest.raises(AttributeError, match=r"env_method\('reset'\): sb3_vec_env steps one "
                                             "compiled batch and has no per-environment"):
        venv.env_method("reset", indices=[0])
    assert np.array_equal(venv.venv.batch.obs, obs)  # nothing was reset
    with pytest.raises(ValueError, match=r"set_attr\('spec', indices=\[1\]\): the "
                                         "environments of sb3_vec_env share one batch"):
        venv.set_attr("spec", None, indices=[1])
    venv.set_attr("spec", "mine")
    assert venv.get_attr("spec") == ["mine", "mine"]


def test_a_snapshot_restores_into_a_fresh_gym_make_env_through_reset():
    """A planner's pattern on environments made by gym.make: reset(options={"snapshot": s})
    restores s through the wrappers' reset (Gymnasium's order check refuses a step after
    env.unwrapped.set_state on an env never reset, and its env checker fails on it), and the
    steps that follow are bit-identical; the reset info is the episode's. With a seed or
    another option, or from an ended episode, it is refused."""
    env = gym.make(ENV_ID, **CALM)
    _, started = env.reset(seed=4)
    env.step(np.array([0.3], np.float32))
    saved = env.unwrapped.get_state()
    ref = env.step(np.array([-0.2], np.float32))
    fresh = gym.make(ENV_ID, **CALM)
    obs, info = fresh.reset(options={"snapshot": saved})
    assert np.array_equal(obs, saved["obs"]) and info == started
    out = fresh.step(np.array([-0.2], np.float32))
    assert np.array_equal(out[0], ref[0]) and out[1] == ref[1] and out[4] == ref[4]
    with pytest.raises(TaskError, match="it takes no seed and no other option"):
        fresh.reset(seed=1, options={"snapshot": saved})
    with pytest.raises(TaskError, match="it takes no seed and no other option"):
        fresh.reset(options={"snapshot": saved, "wind_speed": 8.0})
    ended = {**saved, "code": np.int64(TETHER_BREAK)}
    with pytest.raises(TaskError, match=r"the snapshot's episode has ended \(tether_break\)"):
        fresh.reset(options={"snapshot": ended})


def test_a_snapshot_of_an_ended_episode_stays_ended():
    """Restoring a snapshot taken after a tether break does not reopen step(): the restored
    env refuses it with ResetNeeded naming the reason, as the env it was taken from does
    (before 0.7.17 the restore integrated the broken system again). The snapshot of a running
    episode, restored into the same env after the break, steps on."""
    env = TetheredAerostatEnv(**{k: v for k, v in EPISODES.items() if k != "max_episode_steps"})
    env.reset(seed=0)
    running = env.get_state()
    for _ in range(2000):
        *_, terminated, truncated, info = env.step([0.3])
        if terminated or truncated:
            break
    assert info.get("termination") == "tether_break"
    ended = env.get_state()
    for snapshot in (ended, pickle.loads(pickle.dumps(ended))):
        env.set_state(snapshot)
        with pytest.raises(ResetNeeded, match=r"after the episode ended \(tether_break\)"):
            env.step([0.0])
    env.set_state(running)
    assert env.step([0.0])[2] is False  # the running snapshot's first step: no break


def test_a_snapshot_without_its_episode_object_is_refused():
    """A snapshot keeps its Episode (the trim, parameters and wind of its start) through
    pickle; one whose episode came back from JSON as text is refused at set_state (it was
    accepted and broke render() and .episode later), leaving the env as it was."""
    env = TetheredAerostatEnv(**CALM)
    env.reset(seed=0)
    saved = env.get_state()
    env.step([0.1])
    state = env.state
    with pytest.raises(ValueError, match="episode is a str, not the Episode from get_state"):
        env.set_state({**saved, "episode": repr(saved["episode"])})
    np.testing.assert_array_equal(env.state, state)
    env.set_state(pickle.loads(pickle.dumps(saved)))
    np.testing.assert_array_equal(env.state, saved["state"])


def test_a_refused_snapshot_leaves_the_env_as_it_was():
    """A snapshot whose np_random is not the env's generator state is refused before the
    simulator slot is touched (the slot used to be overwritten, then numpy raised)."""
    env = TetheredAerostatEnv()
    env.reset(seed=0)
    saved = env.get_state()
    env.step(np.array([0.5], np.float32))
    state = env.state
    with pytest.raises(ValueError, match="set_state: np_random is not a PCG64 state"):
        env.set_state({**saved, "np_random": {"bit_generator": "X"}})
    np.testing.assert_array_equal(env.state, state)
    env.set_state(saved)
    np.testing.assert_array_equal(env.state, saved["state"])


def test_a_snapshot_from_another_world_is_refused_naming_what_differs():
    """get_state's snapshot carries what the batch adds to its future (``world()``): restored
    into an env of another tether length (same element count, so the same state layout) it
    would run on with that env's reward band. It is refused, naming what differs,
    and the env is left as it was. Arguments that resolve to the same world (the baseline
    given as None or loaded, a wind range given as a pair or a number) take it and go on bit
    for bit, and so does an env on a finer integration step (a re-run)."""
    calm = {**CALM, "wind_speed": 8.0}
    src = TetheredAerostatEnv(**calm)
    src.reset(seed=3)
    saved = src.get_state()
    ref = src.step([0.2])[0]
    other = TetheredAerostatEnv(**{**calm, "tether_length": 250.0})
    other.reset(seed=3)
    state = other.state
    with pytest.raises(ValueError, match=r"another world \(reward weights and length band\)"):
        other.set_state(saved)
    np.testing.assert_array_equal(other.state, state)
    twin = TetheredAerostatEnv(**{**calm, "wind_speed": (8.0, 8.0), "params": load_params()})
    twin.set_state(saved)
    assert np.array_equal(twin.step([0.2])[0], ref)
    finer = TetheredAerostatEnv(**calm, overrides={"simulation.semi_implicit_dt": 0.01})
    finer.set_state(saved)
    assert np.abs(finer.step([0.2])[0] - ref).max() < 0.05
    # a world written to JSON and read back (tuples become lists) is the same world
    twin.set_state({**saved, "world": json.loads(json.dumps(saved["world"]))})
    assert np.array_equal(twin.step([0.2])[0], ref)
