"""Swing-recovery runs of winch policies in the environment, and the damping-versus-reel-speed
frontier (pendulum damping ratio against the peak reel set-point a swing asks for).

One run (:func:`swing_response`): ``TetheredAerostat-v0`` in steady wind (no turbulence), the
aerostat and tether swung rigidly about the winch by ``swing`` metres along the wind (fixed, not
drawn, no pitch kick), the policy in the loop at the 0.2 s control step for ``duration``
seconds. The pendulum damping ratio is fitted to the along-wind CM displacement
(:func:`aerostat_gym.agents.metrics.fit_damped_sinusoid`); the peak reel speed and the peak
set-point come from the winch state and the action.

Brake logic. The shipped winch engages its brake whenever |v_set| < winch.brake_speed
(0.02 m/s), which swallows the small commands of a linear controller near the end of a swing
(and all of them at a 0.5-1 m swing). ``brake_speed=0`` turns this dead band off, which is what
a dwell-time brake (:func:`aerostat_gym.agents.brake_dwell.dwell_brake_rule`: engage only after
the command has stayed near zero for a dwell time) does for a controller whose command keeps
moving; the runs report which brake they used.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..envs.vector import TetheredAerostatVectorEnv
from .evaluate import policy_obs
from .metrics import fit_damped_sinusoid


@dataclass
class SwingRun:
    """Histories and figures of one swing-recovery run.

    Attributes
    ----------
    wind_speed : float
        Mean wind speed [m/s].
    swing : float
        Initial along-wind swing [m].
    time : numpy.ndarray
        Sample times [s] (control steps).
    x : numpy.ndarray
        Along-wind CM displacement from trim [m].
    length : numpy.ndarray
        Paid-out length minus trim [m].
    reel_speed : numpy.ndarray
        Winch reel speed v_w [m/s].
    set_point : numpy.ndarray
        Commanded set-point, action times max_speed [m/s] (one per step).
    zeta : float
        Pendulum damping ratio fitted to ``x``.
    period : float
        Natural period of that fit [s].
    r2 : float
        Coefficient of determination of that fit.
    ended : str or None
        Termination reason, None for a full run.
    """

    wind_speed: float
    swing: float
    time: np.ndarray
    x: np.ndarray
    length: np.ndarray
    reel_speed: np.ndarray
    set_point: np.ndarray
    zeta: float
    period: float
    r2: float
    ended: str | None

    @property
    def peak_reel_speed(self) -> float:
        return float(np.max(np.abs(self.reel_speed)))

    @property
    def peak_set_point(self) -> float:
        return float(np.max(np.abs(self.set_point)))

    @property
    def length_wander(self) -> float:
        """Largest |L - L_trim| over the run [m]."""
        return float(np.max(np.abs(self.length)))

    def row(self) -> dict:
        return {"wind_speed": self.wind_speed, "swing_m": self.swing, "zeta": self.zeta,
                "period_s": self.period, "fit_r2": self.r2,
                "peak_reel_speed_m_s": self.peak_reel_speed,
                "peak_set_point_m_s": self.peak_set_point,
                "length_wander_m": self.length_wander, "ended": self.ended}


def swing_env(wind_speed: float, swing: float, brake_speed: float | None = None,
              obs_noise: float = 0.0, params=None, control_step: float = 0.2,
              duration: float = 180.0, num_envs: int = 1) -> TetheredAerostatVectorEnv:
    """The vector environment of a swing-recovery run (full observation, steady wind)."""
    overrides = None if brake_speed is None else {"winch.brake_speed": float(brake_speed)}
    return TetheredAerostatVectorEnv(
        num_envs=num_envs, max_episode_steps=int(round(duration / control_step)),
        observation="full", control_step=control_step, turbulence="none",
        wind_speed=(wind_speed, wind_speed), params=params, overrides=overrides,
        obs_noise=obs_noise,
        perturbation={"swing": float(swing), "lateral": 0.0, "pitch": 0.0, "fixed": True})


def swing_response(policy, wind_speed: float, swing: float, *, brake_speed: float | None = None,
                   obs_noise: float = 0.0, seed: int = 0, params=None, duration: float = 180.0,
                   control_step: float = 0.2) -> SwingRun:
    """Run ``policy`` through one swing recovery and fit its pendulum damping.

    Parameters
    ----------
    policy : object
        Anything with SB3's ``predict(observation, state, episode_start, deterministic)``.
    wind_speed : float
        Mean wind speed [m/s].
    swing : float
        Initial along-wind swing of aerostat and tether [m].
    brake_speed : float or None
        Override of winch.brake_speed (None: the shipped 0.02 m/s dead band; 0: off).
    obs_noise : float
        Sensor noise std in the environment's scaled units.
    seed : int
        Reset seed (draws the sensor noise).
    params : Params or None
        Environment parameters (default: the shipped baseline).
    duration : float
        Length of the run [s].
    control_step : float
        Control step [s].

    Returns
    -------
    SwingRun
    """
    if not (math.isfinite(swing) and swing > 0):
        raise ValueError(f"swing must be finite and > 0 [m], got {swing!r}")
    env = swing_env(wind_speed, swing, brake_speed, obs_noise, params, control_step, duration)
    obs, _ = env.reset(seed=[seed], options={"wind_speed": [wind_speed]})
    b, lay = env.batch, env.batch.layout
    vmax = float(b.params.winch.max_speed)
    ix, iL, iv = lay.cm_pos.start, lay.winch_length, lay.winch_speed
    steps = env.max_episode_steps
    x, L, v, sp = (np.zeros(steps + 1) for _ in range(4))
    x[0], L[0], v[0] = (b.X[0, ix] - b.XT[0, ix], b.X[0, iL] - b.XT[0, iL], b.X[0, iv])
    state, start, ended, k_end = None, np.ones(1, bool), None, steps
    for k in range(1, steps + 1):
        action, state = policy.predict(policy_obs(policy, obs), state=state, episode_start=start,
                                       deterministic=True)
        start[:] = False
        a = np.asarray(action, np.float32).reshape(-1, 1)
        sp[k - 1] = float(np.clip(a[0, 0], -1.0, 1.0)) * vmax
        obs, _, term, trunc, info = env.step(a)
        x[k], L[k], v[k] = (b.X[0, ix] - b.XT[0, ix], b.X[0, iL] - b.XT[0, iL], b.X[0, iv])
        if term[0]:
            ended, k_end = str(info["termination"][0]), k
            break
    env.close()
    t = np.arange(k_end + 1) * control_step
    fit = fit_damped_sinusoid(t, x[:k_end + 1])
    return SwingRun(float(wind_speed), float(swing), t, x[:k_end + 1], L[:k_end + 1],
                    v[:k_end + 1], sp[:k_end], fit.zeta, fit.period, fit.r2, ended)


def initial_deviation(wind_speed: float, swing: float, params=None) -> np.ndarray:
    """The environment's start of a swing-recovery run as a deviation from trim (6n+8)."""
    env = swing_env(wind_speed, swing, params=params)
    env.reset(seed=[0], options={"wind_speed": [wind_speed]})
    dx = env.batch.X[0] - env.batch.XT[0]
    env.close()
    return dx


def linear_response(Acl: np.ndarray, K: np.ndarray, dx0: np.ndarray, steps: int
                    ) -> tuple[np.ndarray, np.ndarray]:
    """(states, set-points) of the discrete closed loop x_{k+1} = Acl x_k, v_k = -K x_k."""
    X = np.empty((steps + 1, dx0.size))
    X[0] = dx0
    for k in range(steps):
        X[k + 1] = Acl @ X[k]
    return X, -(X[:-1] @ K)


def modal_linear_peak(design, dx0_full: np.ndarray, duration: float = 180.0) -> float:
    """Peak |v_set| [m/s] the linear closed loop of a :class:`~aerostat_gym.agents.modal.
    ModalDesign` asks for from the start ``dx0_full`` (full layout; the subset is used)."""
    steps = int(round(duration / design.dt))
    _, v = linear_response(design.closed_loop_matrix, design.K_subset,
                           dx0_full[design.index], steps)
    return float(np.max(np.abs(v)))
