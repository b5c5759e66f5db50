"""The simulator behind the environments: N episodes held in flat arrays and stepped by one
compiled call. It owns time, the episode starts and the turbulence bank; the Gymnasium classes
(:mod:`aerostat_gym.envs.env`, :mod:`aerostat_gym.envs.vector`) only adapt it to their API.
"""

from __future__ import annotations

import math

import numpy as np

from ..physics.core import work_size
from ..physics.layout import P_SIZE, StateLayout
from ..physics.wind import W_SIZE
from . import kernel as K
from . import spaces
from .task import (
    DEFAULT_HORIZON,
    TaskConfig,
    TrimTable,
    field_length_needed,
    sample_episode,
    turbulence_bank,
)

NO_BANK = np.zeros((1, 1, 0, 3))


class ActionError(ValueError):
    """A non-finite or wrongly shaped action (the message names the value)."""


class EnvBatch:
    """N environments of one task in flat arrays (see the module docstring).

    Parameters
    ----------
    task : TaskConfig. num_envs : number of environments.
    horizon : longest episode [s] the turbulence must cover (None: 120 s).
    """

    def __init__(self, task: TaskConfig, num_envs: int, horizon: float | None = None):
        self.task = task
        self.num_envs = N = int(num_envs)
        params = task.params_resolved
        self.params = params
        self.layout = StateLayout(params.tether.n_elements)
        S = self.layout.size
        self.full_size = S if task.observation == "full" else 0
        self.obs_dim = spaces.N_OBS + (1 + S if self.full_size else 0)
        self.obs_low, self.obs_high = spaces.bounds(self.full_size)
        self.trims = TrimTable(params, *task.resolved["wind_speed"])
        self.horizon = float(horizon) if horizon else DEFAULT_HORIZON
        self.bank = self._bank()
        self.cfg = self._config(params)
        self.X = np.zeros((N, S))
        self.Xp = np.zeros((N, S))
        self.XT = np.zeros((N, S))
        self.TT = np.zeros(N)
        self.T = np.zeros(N)
        self.A = np.zeros(N)
        self.AP = np.zeros(N)
        self.BR = np.zeros(N, dtype=np.bool_)
        self._clipped = np.zeros(N, dtype=np.bool_)
        self.P = np.zeros((N, P_SIZE))
        self.WP = np.zeros((N, W_SIZE))
        self.KF = np.zeros(N, dtype=np.int64)
        self.W = np.zeros((N, work_size(params.tether.n_elements)))
        self.OBS = np.zeros((N, self.obs_dim), dtype=np.float32)
        self.TERMS = np.zeros((N, len(spaces.REWARD_TERMS)))
        self.CODE = np.zeros(N, dtype=np.int64)
        self.episodes: list = [None] * N
        self.scale = spaces.scales()
        self.low64 = self.obs_low[:spaces.N_OBS].astype(float)
        self.high64 = self.obs_high[:spaces.N_OBS].astype(float)

    def _bank(self) -> np.ndarray:
        turb = self.task.resolved["turbulence"]
        if turb.is_off:
            return NO_BANK
        u_max = self.trims.speeds[-1] * _advection_factor(self.params, turb)
        need = field_length_needed(turb, u_max, self.horizon)
        return turbulence_bank(turb, self.task.wind_bank_size, self.task.wind_bank_seed, need)

    def __getstate__(self):  # the trims and the bank are rebuilt (or found in the cache)
        d = dict(self.__dict__)
        d["trims"] = d["bank"] = None
        return d

    def __setstate__(self, d):
        self.__dict__.update(d)
        self.trims = TrimTable(self.params, *self.task.resolved["wind_speed"])
        self.bank = self._bank()

    def _config(self, params) -> np.ndarray:
        t, w = self.task, params.winch
        cfg = np.zeros(K.C_SIZE)
        cfg[K.C_DT] = t.control_step
        cfg[K.C_SEMI_IMPLICIT] = 1.0 if t.integrator == "semi-implicit" else 0.0
        cfg[K.C_SI_DT] = params.simulation.semi_implicit_dt
        cfg[K.C_RK4_SAFETY] = params.simulation.rk4_safety
        cfg[K.C_GROUND] = params.aerostat.diameter
        cfg[K.C_BRAKE_SPEED] = w.brake_speed
        cfg[K.C_HOLD_SPEED] = w.brake_hold_speed
        cfg[K.C_SWL] = w.safe_working_load
        cfg[K.C_FULL] = 1.0 if self.full_size else 0.0
        cfg[K.C_HORIZON] = math.inf if t.resolved["turbulence"].is_off else self.horizon
        cfg[K.C_WEIGHTS:] = t.resolved["weights"]
        return cfg

    # --- episodes --------------------------------------------------------------------------

    def reset_one(self, i: int, rng: np.random.Generator, options: dict | None = None) -> dict:
        """Start a new episode in slot i; fills OBS[i] and returns the episode info."""
        ep = sample_episode(self.task, self.trims, self.bank.shape, self.horizon, rng, options)
        self.X[i] = ep.x0
        self.XT[i] = ep.x_trim
        self.TT[i] = ep.tension_trim
        self.P[i] = ep.p
        self.WP[i] = ep.wp
        self.KF[i] = ep.field_index
        self.T[i] = 0.0
        self.A[i] = self.AP[i] = 0.0
        self.BR[i] = False
        self.CODE[i] = spaces.RUNNING
        self.episodes[i] = ep
        K.observe(self.X[i], 0.0, self.P[i], self.WP[i], self.bank[self.KF[i]], self.W[i],
                  self.cfg, self.XT[i], self.TT[i], self.scale, self.low64, self.high64,
                  self.OBS[i])
        return dict(ep.info)

    def set_actions(self, actions) -> np.ndarray:
        """Validate and store actions, shape (N,) or (N, 1): NaN/inf is an ActionError,
        out-of-range values are clipped to [-1, 1]. Returns the per-env clipped flags (a buffer
        reused by the next call)."""
        a = np.asarray(actions, dtype=float)
        if a.size != self.num_envs:
            raise ActionError(f"expected {self.num_envs} action(s) of shape (1,), got shape "
                              f"{np.shape(actions)}")
        a = a.reshape(self.num_envs)
        scalar = self.num_envs == 1  # scalar arithmetic: each numpy call costs ~1 us per step
        if not (math.isfinite(a[0]) if scalar else np.all(np.isfinite(a))):
            idx = np.flatnonzero(~np.isfinite(a))
            raise ActionError(f"action must be finite, got {a[idx][:4].tolist()} "
                              f"(environment(s) {idx[:4].tolist()})")
        if scalar:
            v = float(a[0])
            self._clipped[0] = abs(v) > 1.0
            self.A[0] = min(max(v, -1.0), 1.0)
        else:
            np.greater(np.abs(a), 1.0, out=self._clipped)
            np.clip(a, -1.0, 1.0, out=self.A)
        return self._clipped

    def step(self, active: np.ndarray | None = None) -> None:
        """Advance every active environment one control step with the stored actions."""
        if active is None and self.num_envs == 1:
            K.step_serial(self.X, self.Xp, self.T, self.A, self.AP, self.BR, self.P, self.WP,
                          self.bank, self.KF, self.W, self.cfg, self.XT, self.TT, self.scale,
                          self.low64, self.high64, self.OBS, self.TERMS, self.CODE)
            return
        if active is None:
            active = np.ones(self.num_envs, dtype=np.bool_)
        K.step_parallel(active, self.X, self.Xp, self.T, self.A, self.AP, self.BR, self.P,
                        self.WP, self.bank, self.KF, self.W, self.cfg, self.XT, self.TT,
                        self.scale, self.low64, self.high64, self.OBS, self.TERMS, self.CODE)

    def add_noise(self, i: int, rng: np.random.Generator) -> None:
        """Gaussian sensor noise of std ``obs_noise`` (in scaled units) on the standard channels."""
        sigma = self.task.obs_noise
        if sigma > 0.0:
            o = self.OBS[i, :spaces.N_OBS]
            o += rng.normal(0.0, sigma, o.shape).astype(np.float32)
            np.clip(o, self.obs_low[:spaces.N_OBS], self.obs_high[:spaces.N_OBS], out=o)

    def snapshot(self, i: int) -> dict:
        """Physical quantities of environment i for rendering and diagnostics."""
        from ..simulation import Model

        ep = self.episodes[i]
        x = self.X[i].copy()
        model = Model(ep.params, (self.WP[i], self.bank[self.KF[i]]))
        lay = self.layout
        return {"time": float(self.T[i]), "state": x, "nodes": model.node_positions(x),
                "cm_pos": x[lay.cm_pos], "euler": x[lay.euler], "trim_cm": self.XT[i][lay.cm_pos],
                "tension": model.end_tensions(x, float(self.T[i]))[1],
                "length": float(x[lay.winch_length]), "reel_speed": float(x[lay.winch_speed]),
                "wind_speed": ep.wind_speed, "params": ep.params}


def _advection_factor(params, turb) -> float:
    """U_a / U_ref for the configured mean profile (1 for the paper's uniform wind)."""
    from ..physics.wind import pack_wind, set_advection

    w = params.wind
    wp = pack_wind(w.profile, 1.0, w.direction_deg, w.reference_height, w.shear_exponent,
                   w.roughness_length)
    return set_advection(wp, turb.reference_height, 0.0)
