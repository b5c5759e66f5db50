"""One rule for numbers at every door: a bool is never a count or a quantity, a NumPy scalar is
read as the Python number it holds, a table is a mapping, and every door names the value it
refuses (with the package's own error, never a TypeError from inside numpy or the standard
library)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from aerostat_gym.agents.evaluate import evaluate_policy
from aerostat_gym.agents.policies import load_policy
from aerostat_gym.agents.protocol_stats import StatsInputError, iqm_ci
from aerostat_gym.agents.sb3io import PolicyError
from aerostat_gym.analysis.trim import find_equilibrium
from aerostat_gym.checks import is_finite_number, is_number, is_whole
from aerostat_gym.envs.config import TaskConfig, TaskError
from aerostat_gym.envs.env import TetheredAerostatEnv
from aerostat_gym.envs.vector import TetheredAerostatVectorEnv
from aerostat_gym.params import MAX_WIND_SPEED, ParameterError, apply_overrides, load_params
from aerostat_gym.resources import SHIPPED_POLICY, shipped_path


@pytest.mark.parametrize("value, number, finite, whole", [
    (3, True, True, True),
    (np.int64(3), True, True, True),
    (3.0, True, True, False),
    (np.float32(2.5), True, True, False),
    (float("nan"), True, False, False),
    (math.inf, True, False, False),
    (True, False, False, False),
    (np.bool_(True), False, False, False),
    ("3", False, False, False),
    (None, False, False, False),
    (1 + 0j, False, False, False),
])
def test_what_counts_as_a_number(value, number, finite, whole):
    assert (is_number(value), is_finite_number(value), is_whole(value)) == (number, finite, whole)


def test_whole_numbers_respect_both_ends():
    assert [is_whole(v, 1, 64) for v in (0, 1, 64, 65)] == [False, True, True, False]
    assert is_whole(10**9) and not is_whole(-1)


def test_a_numpy_count_is_accepted_where_a_python_one_is():
    env = TetheredAerostatVectorEnv(num_envs=np.int64(2), max_episode_steps=np.int32(5))
    try:
        obs, _ = env.reset(seed=0)
        assert obs.shape == (2, env.single_observation_space.shape[0])
        assert type(env.num_envs) is int and env.max_episode_steps == 5
    finally:
        env.close()
    p = apply_overrides(load_params(), {"tether.n_elements": np.int64(6),
                                        "tether.length": np.float32(250.0)})
    assert (p.tether.n_elements, p.tether.length) == (6, 250.0)


@pytest.mark.parametrize("make, error, message", [
    (lambda: TetheredAerostatVectorEnv(num_envs=True), ValueError,
     "num_envs must be an integer in [1, 65536], got True"),
    (lambda: TaskConfig.from_kwargs(wind_bank_size=True), TaskError,
     "wind_bank_size must be an integer >= 1, got True"),
    (lambda: TaskConfig.from_kwargs(wind_bank_seed=-1), TaskError,
     "wind_bank_seed must be an integer >= 0, got -1"),
    (lambda: TaskConfig.from_kwargs(wind_bank_seed=None), TaskError,
     "wind_bank_seed must be an integer >= 0, got None"),
    (lambda: apply_overrides(load_params(), {"tether.n_elements": True}), ParameterError,
     "tether.n_elements must be an integer >= 1"),
    (lambda: apply_overrides(load_params(), {"tether.length": True}), ParameterError,
     "tether.length must be a number, got True"),
    (lambda: iqm_ci(np.ones((4, 2)), resamples=True), StatsInputError,
     "resamples must be an integer >= 100, got True"),
])
def test_a_bool_is_not_a_number_at_any_door(make, error, message):
    with pytest.raises(error, match=re.escape(message)):
        make()


@pytest.mark.parametrize("make, error, message", [
    (lambda: TaskConfig.from_kwargs(overrides=5), TaskError,
     "overrides must map dotted parameter names to values"),
    (lambda: apply_overrides(load_params(), [("tether.length", 300.0)]), ParameterError,
     "overrides must map dotted parameter names to values"),
    (lambda: TaskConfig.from_kwargs(reward_weights=0.5), TaskError,
     "reward_weights must map reward terms"),
    (lambda: TaskConfig.from_kwargs(reward_weights={"effort": True}), TaskError,
     "reward weight 'effort' must be a finite number >= 0, got True"),
    (lambda: TetheredAerostatEnv().reset(seed=0, options=12.0), TaskError,
     "reset options must be a dict"),
    (lambda: TetheredAerostatVectorEnv(num_envs=2).reset(seed=0, options=[("wind_speed", 5)]),
     TaskError, "reset options must be a dict"),
])
def test_a_table_must_be_a_mapping(make, error, message):
    with pytest.raises(error, match=message):
        make()


def test_the_wind_speed_ends_where_the_incompressible_model_does():
    """Mach 0.3 at sea level (a = 340 m/s) is 102 m/s: the cap sits just inside it, and a wind
    beyond it is refused at once (before, a trim continuation in 1 m/s steps ran towards it)."""
    assert 0.25 * 340.0 < MAX_WIND_SPEED <= 0.3 * 340.0
    for U in (MAX_WIND_SPEED + 0.1, 1e300):
        with pytest.raises(ValueError, match=r"wind_speed must be a number in \[0, 100\] m/s"):
            find_equilibrium(load_params(), U)
    with pytest.raises(TaskError, match="wind_speed must satisfy 0.0 <= low <= high <= 100"):
        TaskConfig.from_kwargs(wind_speed=(5.0, 1e300))


@pytest.mark.parametrize("make, error, message", [
    (lambda: evaluate_policy("passive", control_step=0), TaskError,
     r"control_step must be a number in \[0.001, 1\] s .* got 0"),
    (lambda: TaskConfig.from_kwargs(control_step=5e-324), TaskError,  # overflowed the step count
     r"control_step must be a number in \[0.001, 1\] s .* got 5e-324"),
    (lambda: load_policy("lqr", dt="0.2"), TaskError, "control_step must be a number"),
    (lambda: load_policy(None), PolicyError, "a policy is a baseline's name, 'shipped' or a "
                                             "path to a .zip, got None"),
])
def test_a_policy_and_its_step_are_checked_at_the_door(make, error, message):
    with pytest.raises(error, match=message):
        make()


def test_a_policy_path_may_be_a_path_object():
    """The shipped policy by pathlib.Path acts as by its name (same action on the same input)."""
    obs = np.full((1, 19), 0.1, dtype=np.float32)
    by_path = load_policy(shipped_path(SHIPPED_POLICY))
    by_name = load_policy("shipped")
    assert np.array_equal(by_path.predict(obs)[0], by_name.predict(obs)[0])


def test_numpy_scalars_and_0_d_arrays_are_numbers_at_the_env_door():
    """np.array(10.0) is the number it holds (was a TypeError from len()); a float32
    randomisation half-range is a number (was refused)."""
    task = TaskConfig.from_kwargs(wind_speed=np.array(10.0))
    assert task.resolved["wind_speed"] == (10.0, 10.0)
    spec = TaskConfig.from_kwargs(randomize={"aerostat.mass": np.float32(0.01)}).resolved
    assert spec["randomize"]["aerostat.mass"] == pytest.approx(0.01)


def test_json_text_writes_non_finite_numbers_as_null():
    """aerostat_gym.jsonout: NaN and infinities (Python floats, numpy scalars, inside arrays,
    tuples and dicts) become null, numpy numbers plain numbers; the text parses as strict
    JSON and finite values come back exactly."""
    import json

    from aerostat_gym import jsonout

    value = {"a": float("nan"), "b": (1.5, np.float32(0.25), np.inf), "c": np.array([2.0, -np.inf]),
             "d": [np.int64(3), {"e": np.float64(-np.nan)}], "f": "text", "g": None, "h": True}
    text = jsonout.dumps(value)
    back = json.loads(text, parse_constant=lambda token: pytest.fail(f"{token} in {text}"))
    assert back == {"a": None, "b": [1.5, 0.25, None], "c": [2.0, None],
                    "d": [3, {"e": None}], "f": "text", "g": None, "h": True}
