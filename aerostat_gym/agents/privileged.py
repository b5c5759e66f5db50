"""A full-observation (privileged) policy run outside the environment, e.g. in
:func:`aerostat_gym.sim.simulate`: the observation it would see, and its set-point law.
"""

from __future__ import annotations

import numpy as np

from ..envs.spaces import OBS_FULL_STATE, OBS_FULL_WIND
from ..params import Params
from ..physics.state import S_PSI, StateLayout


def full_observation(x: np.ndarray, x_trim: np.ndarray, wind_speed: float,
                     layout: StateLayout) -> np.ndarray:
    """The environment's ``observation="full"`` privileged part for a state outside it (e.g.
    in :func:`aerostat_gym.sim.simulate`): zeros for the standard channels, the mean wind speed
    at ``OBS_FULL_WIND`` and x - x_trim with the yaw wrapped to [-pi, pi) from
    ``OBS_FULL_STATE``."""
    dx = x - x_trim
    i_psi = layout.at(S_PSI)
    dx[i_psi] = (dx[i_psi] + np.pi) % (2.0 * np.pi) - np.pi
    obs = np.zeros(OBS_FULL_STATE + layout.size)
    obs[OBS_FULL_WIND], obs[OBS_FULL_STATE:] = wind_speed, dx
    return obs


def set_point_law(policy, x_trim: np.ndarray, wind_speed: float, params: Params,
                  to_input=None, record: list | None = None, state=None):
    """u(t, x) for :func:`aerostat_gym.sim.simulate` from a full-observation policy: the
    policy's action times ``winch.max_speed``, through ``to_input(v)`` (default: the released
    winch, [v, 0]). The policy's recurrent state travels between calls, starting from
    ``state`` (None: a fresh episode; e.g. the LQR's length integral to start on a mode), and
    each set-point is appended to ``record`` if given."""
    layout = StateLayout(params.tether.n_elements)
    vmax = float(params.winch.max_speed)
    memo = {"state": state, "start": np.full(1, state is None)}

    def u(t, x):
        obs = full_observation(x, x_trim, wind_speed, layout)
        a, memo["state"] = policy.predict(obs, memo["state"], memo["start"])
        memo["start"][:] = False
        v = float(np.clip(np.asarray(a).reshape(-1)[0], -1.0, 1.0)) * vmax
        if record is not None:
            record.append(v)
        return [v, 0.0] if to_input is None else to_input(v)

    return u
