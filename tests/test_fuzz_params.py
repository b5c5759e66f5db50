"""Issue 14: fuzz of the parameter loader over mutated parameter files.

Each mutation of the shipped baseline is written to a TOML file and loaded. It is either
refused by the loader with a :class:`ParameterError` whose message names the field, or accepted
and then runs (a trim at 5 m/s and ten environment steps with finite observations). Nothing
may reach a traceback from numpy, scipy or numba: any other exception fails the test.
"""

from __future__ import annotations

import copy
import json
import math
import warnings

import numpy as np
import pytest

from aerostat_gym.envs import TetheredAerostatEnv
from aerostat_gym.params import ParameterError, load_params, params_to_dict

BASE = params_to_dict(load_params())
DROP = object()


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(v)


def to_toml(data: dict) -> str:
    """A TOML document for a parameter dict, wrong types and non-finite values included."""
    lines = [f"{k} = {_toml_value(v)}" for k, v in data.items() if not isinstance(v, dict)]
    for sec, table in data.items():
        if not isinstance(table, dict):
            continue
        lines.append(f"[{sec}]")
        arrays = {k: v for k, v in table.items()
                  if isinstance(v, list) and v and all(isinstance(x, dict) for x in v)}
        lines += [f"{k} = {_toml_value(v)}" for k, v in table.items() if k not in arrays]
        for key, items in arrays.items():
            for item in items:
                lines.append(f"[[{sec}.{key}]]")
                lines += [f"{k} = {_toml_value(v)}" for k, v in item.items()]
    return "\n".join(lines) + "\n"


def _set(data: dict, path: str, value) -> None:
    """Set (or drop) ``a.b`` / ``a.b[i]`` / ``fins.panels[i].key`` in a nested dict."""
    keys = path.replace("]", "").replace("[", ".").split(".")
    node = data
    for k in keys[:-1]:
        node = node[int(k)] if isinstance(node, list) else node[k]
    last = keys[-1]
    if isinstance(node, list):
        node[int(last)] = value
    elif value is DROP:
        del node[last]
    else:
        node[last] = value


#: (mutation, value, text the loader's error must contain; None: accepted, and it must run)
MUTATIONS = [
    # unknown keys and sections
    ("aerostat.colour", "red", "colour"),
    ("weather", {"rain": 1.0}, "weather"),
    ("fins.panels[0].chord", 2.0, "chord"),
    # missing sections and keys
    ("winch", DROP, "winch"),
    ("wind", DROP, "wind"),
    ("tether.strength", DROP, "strength"),
    ("fins.panels[1].cp_position", DROP, "cp_position"),
    # wrong types
    ("aerostat.volume", "519", "aerostat.volume"),
    ("environment.rho_air", True, "environment.rho_air"),
    ("tether.n_elements", 10.5, "tether.n_elements"),
    ("tether.n_elements", True, "tether.n_elements"),
    ("wind.profile", 3, "wind.profile"),
    ("aerostat.cb_position", 1.0, "aerostat.cb_position"),
    ("aerostat.cb_position", [0.05, 0.7], "aerostat.cb_position"),
    ("fins.panels", 3, "fins.panels"),
    ("environment", 1.0, "environment"),
    ("tether.loading_fn", "abc", "tether.loading_fn"),
    ("tether.loading_ft", [0.1, "x", 0.1, 0.1, 0.1, 0.1], "tether.loading_ft"),
    # NaN / inf scalars
    ("environment.rho_air", math.nan, "environment.rho_air"),
    ("environment.g", math.inf, "environment.g"),
    ("aerostat.mass", math.nan, "aerostat.mass"),
    ("winch.max_speed", math.inf, "winch.max_speed"),
    ("hull.Cdc", -math.inf, "hull.Cdc"),
    ("tether.youngs_modulus", math.nan, "tether.youngs_modulus"),
    # NaN / inf list entries
    ("tether.loading_fn[0]", math.nan, "tether.loading_fn"),
    ("tether.loading_ft[3]", math.inf, "tether.loading_ft"),
    ("aerostat.cb_position[1]", math.nan, "aerostat.cb_position"),
    ("tether.anchor_position[2]", math.inf, "tether.anchor_position"),
    ("fins.panels[0].cp_position[0]", math.nan, "cp_position"),
    # wrong coefficient counts
    ("tether.loading_fn", [0.5, -0.1, 0.1, -0.4], "tether.loading_fn"),
    ("tether.loading_ft", [0.02] * 7, "tether.loading_ft"),
    # zero, negative, huge
    ("aerostat.volume", 0.0, "aerostat.volume"),
    ("tether.diameter", -0.006, "tether.diameter"),
    ("winch.max_speed", 0.0, "winch.max_speed"),
    ("tether.n_elements", 0, "tether.n_elements"),
    ("tether.n_elements", 100000, "tether.n_elements"),
    ("aerostat.volume", 1e30, "aerostat.volume"),
    ("aerostat.mass", 1e30, "aerostat.mass"),
    ("tether.length", 1e30, "tether.length"),
    ("fins.alpha_stall_deg", 95.0, "fins.alpha_stall_deg"),
    ("aerostat.trim_pitch_deg", 120.0, "aerostat.trim_pitch_deg"),
    # cross-section infeasibility
    ("tether.length", 100.0, "winch.min_length"),
    ("winch.total_line_length", 300.0, "winch.total_line_length"),
    ("tether.density", 40000.0, "tether.density"),
    ("tether.strength", 2000.0, "tether.strength"),
    ("winch.safe_working_load", 5e4, "winch.safe_working_load"),
    ("winch.min_length", 500.0, "winch.min_length"),
    ("winch.slack_tension", 2e4, "winch.slack_tension"),
    ("wind.turbulence", "hurricane", "wind.turbulence"),
    # accepted: these must run
    ("aerostat.Ixx", 6270.0, None),
    ("tether.n_elements", 3, None),
    ("tether.length", 200, None),
    ("tether.damping_ratio", 0.0, None),
    ("wind.speed", 5, None),
    ("aerostat.Ixz", 0.0, None),
    ("tether.Cd_normal", 0.0, None),
    ("hull.eta_k", 0.0, None),
    ("aerostat.Izz", 1e6, "aerostat.Iyy"),  # |Izz - Ixx| > Iyy: no body has it
    ("aerostat.Izz", 10000.0, None),
    ("winch.max_motor_force", 1e5, None),
]


def test_fuzz_has_enough_mutations():
    assert len(MUTATIONS) >= 40
    assert sum(m[2] is None for m in MUTATIONS) >= 8


@pytest.mark.parametrize("path, value, names", MUTATIONS,
                         ids=[f"{m[0]}={'DROP' if m[1] is DROP else m[1]!r}"[:60] for m in MUTATIONS])
def test_mutated_parameter_file(tmp_path, path, value, names):
    data = copy.deepcopy(BASE)
    _set(data, path, value)
    f = tmp_path / "mutated.toml"
    f.write_text(to_toml(data))
    if names is not None:
        with pytest.raises(ParameterError) as err:
            load_params(f)
        assert names in str(err.value)
        return
    p = load_params(f)
    env = _make(p)
    obs, _ = env.reset(seed=0)
    rng = np.random.default_rng(0)
    for _ in range(10):
        obs, reward, terminated, truncated, _ = env.step(rng.uniform(-1, 1, 1).astype(np.float32))
        assert np.all(np.isfinite(obs)) and math.isfinite(reward)
        if terminated:
            break


def _make(p):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return TetheredAerostatEnv(params=p, wind_speed=(5.0, 5.0), turbulence="none",
                                   perturbation="none")
