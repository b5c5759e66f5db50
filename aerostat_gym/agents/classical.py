"""The model-based baselines of issue 17 by name, for the evaluator's ``--policy NAME``:
``modal`` (:class:`aerostat_gym.agents.modal.ModalPolicy`, privileged full state) and ``lqg``
(:class:`aerostat_gym.agents.lqg.LQGPolicy`, standard observation). One line in
:func:`aerostat_gym.agents.baselines.load_policy` wires them in (not done here: that module is
being reorganised)."""

from __future__ import annotations

from ..params import Params, load_params
from .lqg import LQGPolicy
from .modal import ModalPolicy

CLASSICAL = ("modal", "lqg")


def load_classical(name: str, params: Params | None = None, dt: float = 0.2,
                   obs_noise: float = 0.0):
    """A modal or LQG baseline, its gain tables built for ``params`` (2-16 m/s).

    Parameters
    ----------
    name : str
        "modal" or "lqg".
    params : Params or None
        Parameters of the environment (default: the shipped baseline).
    dt : float
        Control step [s].
    obs_noise : float
        The environment's sensor noise (scaled units); designs the LQG's filter.

    Returns
    -------
    ModalPolicy or LQGPolicy
    """
    params = params or load_params()
    if name == "modal":
        return ModalPolicy(params, dt=dt)
    if name == "lqg":
        return LQGPolicy(params, dt=dt, obs_noise=obs_noise)
    raise ValueError(f"unknown classical baseline {name!r}; choose one of {CLASSICAL}")
