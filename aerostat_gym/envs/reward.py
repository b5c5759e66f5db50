"""The environment's reward: the winch-control score, and a swappable component.

Default: the **winch-control score**, a weighted sum of named, non-positive terms computed
inside the compiled control step (:func:`reward_terms`), each reported in
``info["reward_<name>"]`` so that ``reward == sum(info["reward_*"])``. The episode return is the
score the evaluator reports (``aerostat-gym evaluate``: the suite score is the mean return), so
the reward a policy is trained on and the headline it is judged by are one number. What it
asks of a winch controller, term by term:

- the swing damped: the horizontal CM displacement from trim and the horizontal CM velocity
  (the pendulum's potential and kinetic parts; the integral of both over a free decay falls as
  1 / (zeta omega), so a better-damped pendulum scores higher);
- the pitch oscillation damped: pitch deviation and pitch rate, weighted lightly because any
  reeling excites pitch (heavier weights rank the braked winch first whatever the swing does);
- tension peaks within the tether's margin: the peak element tension over the safe working
  load;
- bounded length wander: the paid-out length may wander within a band of
  :data:`LENGTH_BAND_FRACTION` of the tether length (15 m for the 300 m baseline) at no cost, as
  an operator holds the altitude within a band rather than at a point; beyond the band the cost
  grows quadratically (a quadratic cost from zero wander ranked a 30 s length loop's 8 m
  excursion above a swing it halves);
- small winch effort and effort rate; a terminating step (break, ground strike, length limit,
  numerical failure) costs a fixed penalty.

Measured across the five classical baselines (passive, tension, LQR, modal, LQG) in the
steady-wind swing recoveries (along-wind, cross-wind and combined swings, 1 and 10 m, 3-15 m/s),
the score's Spearman rank correlation with the fitted pendulum damping ratio averages 0.8
(README, "One objective"). The weights are an environment argument (``reward_weights``,
defaults :data:`DEFAULT_WEIGHTS`), stated for the 300 m reference tether; on another tether
the swing terms' weights follow its length (:func:`sized_weights`, since 0.7.10), so that a
geometrically similar aerostat's swing through the same angle scores as the baseline's.

Custom: pass ``reward_fn`` to the environment (``gym.make("TetheredAerostat-v0",
reward_fn=f)``, or the vector env). ``f(obs, action, info) -> float`` is called once per step
and environment, after the step, with the new observation (float32, the env's layout), the
applied action in [-1, 1] (after clipping), and the step's ``info`` (which still carries the
default terms and ``info["peak_tension"]``, the largest element tension over the step [N]).
Its value replaces the reward; the default terms stay in ``info`` for comparison. The compiled
default is a few hundred nanoseconds; a Python ``reward_fn`` costs a Python call per step.
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable, Mapping

import numpy as np
from numba import njit

from ..checks import is_finite_number, is_number
from ..physics.core import FASTMATH
from ..sim.events import FIELD_END, RUNNING
from .spaces import (
    OBS_DLENGTH,
    OBS_DPITCH,
    OBS_DX,
    OBS_DY,
    OBS_Q,
    OBS_VX,
    OBS_VY,
    displacement_scale,
)

#: A user reward: ``f(obs, action, info) -> float`` (see the module docstring).
RewardFn = Callable[[np.ndarray, float, dict], float]

#: Reward terms, in the order of the compiled step's output; info carries "reward_<name>".
REWARD_TERMS: tuple[str, ...] = ("displacement", "velocity", "pitch", "pitch_rate", "effort",
                                 "effort_rate", "over_tension", "termination", "length")
R_DISPLACEMENT, R_VELOCITY, R_PITCH, R_PITCH_RATE, R_EFFORT = 0, 1, 2, 3, 4
R_EFFORT_RATE, R_OVER_TENSION, R_TERMINATION, R_LENGTH = 5, 6, 7, 8
REWARD_DOC = {
    "displacement": "-w (dx^2 + dy^2), scaled horizontal position channels dx, dy (blow-by)",
    "velocity": "-w (vx^2 + vy^2), scaled horizontal velocity channels vx, vy",
    "pitch": "-w dpitch^2, scaled pitch channel",
    "pitch_rate": "-w q^2, scaled pitch-rate channel",
    "effort": "-w a^2, a the action in [-1, 1]",
    "effort_rate": "-w (a - a_previous)^2",
    "over_tension": "-w max(0, peak element tension / safe working load - 1) over the step",
    "termination": "-w once, on a terminating step (break, ground strike, length limit, "
                   "numerical failure)",
    "length": "-w max(0, |dlength| - band)^2, scaled length channel, band = "
              "LENGTH_BAND_FRACTION x tether length: bounded length wander",
}
#: The pendulum (blow-by) swing carries the weight, its displacement and velocity equally (in
#: the channels' scales, 10 m and 2 m/s: the potential and kinetic parts of a 40 s pendulum are
#: then of one size). Pitch and pitch rate are weighted lightly because any reeling excites
#: pitch, so heavy weights there would make the braked winch unbeatable (measured with the
#: baselines: pitch weights of 0.3 drop the rank correlation with the damping to 0.72).
DEFAULT_WEIGHTS = {"displacement": 1.0, "velocity": 1.0, "pitch": 0.1, "pitch_rate": 0.1,
                   "effort": 0.01, "effort_rate": 0.1, "over_tension": 10.0, "termination": 100.0,
                   "length": 1.0}
#: Free band of the length wander, as a fraction of the tether length (the ``length`` term).
LENGTH_BAND_FRACTION = 0.05
#: How the quantity of each swing term grows with the tether, as the power of k = L / 300 m
#: (:func:`aerostat_gym.envs.spaces.displacement_scale`): a pendulum swung through the same
#: angle on a geometrically similar aerostat (Froude similarity, period ~ sqrt(L)) has k times
#: the displacement and length excursion and sqrt(k) times the velocity, so the squared terms
#: grow as k^2, k and k^2. :func:`sized_weights` divides their weights by that, so every
#: aerostat's swing weighs against its pitch, effort and tension terms (angles, fractions of
#: the winch's speed and of its load: sized already) as the baseline's does.
SIZE_POWERS = {"displacement": 2.0, "velocity": 1.0, "length": 2.0}


def weights_vector(weights: dict | None) -> np.ndarray:
    """Reward weights in REWARD_TERMS order; unknown names or negative/non-finite values raise."""
    if weights is not None and not isinstance(weights, Mapping):
        raise ValueError(f"reward_weights must map reward terms {list(REWARD_TERMS)} to "
                         f"weights, got {weights!r}")
    w = dict(DEFAULT_WEIGHTS)
    for k, v in (weights or {}).items():
        if k not in w:
            raise ValueError(f"unknown reward weight {k!r}; known: {list(REWARD_TERMS)}")
        if not (is_finite_number(v) and v >= 0):
            raise ValueError(f"reward weight {k!r} must be a finite number >= 0, got {v!r}")
        w[k] = float(v)
    return np.array([w[k] for k in REWARD_TERMS])


def sized_weights(weights: np.ndarray, tether_length: float | None) -> np.ndarray:
    """The compiled reward's weights (REWARD_TERMS order) on a tether of ``tether_length`` [m]:
    each term of :data:`SIZE_POWERS` divided by k ** power, k = L / 300 m (exactly the given
    weights on the 300 m baseline, k = 1)."""
    k = displacement_scale(tether_length)
    return np.array([w / k ** SIZE_POWERS.get(name, 0.0)
                     for name, w in zip(REWARD_TERMS, weights, strict=True)])


def reward_table(weights: dict | None = None, tether_length: float | None = None) -> list[dict]:
    """Rows (term, weight, formula) of the default reward, in REWARD_TERMS order, with the
    given weight overrides (like :func:`aerostat_gym.envs.observation_table`), as applied on a
    tether of ``tether_length`` [m] (None: the 300 m reference; :func:`sized_weights`)."""
    w = sized_weights(weights_vector(weights), tether_length)
    return [{"term": k, "weight": float(w[i]), "formula": REWARD_DOC[k]}
            for i, k in enumerate(REWARD_TERMS)]


def check_reward_fn(fn) -> RewardFn | None:
    """``fn`` if it is None or callable, else a ValueError naming what was given."""
    if fn is not None and not callable(fn):
        raise ValueError(f"reward_fn must be a callable f(obs, action, info) -> float, got "
                         f"{type(fn).__name__}")
    if fn is not None:
        try:
            inspect.signature(fn).bind(None, None, None)
        except TypeError:
            raise ValueError(f"reward_fn must take three arguments f(obs, action, info), got "
                             f"{getattr(fn, '__name__', type(fn).__name__)}"
                             f"{inspect.signature(fn)}") from None
        except ValueError:  # no signature to read (some builtins): the first call will tell
            pass
    return fn


def custom_reward(fn: RewardFn, obs: np.ndarray, action: float, info: dict) -> float:
    """Call a user reward and check its value (a finite float, else a ValueError)."""
    r = fn(obs, action, info)
    if isinstance(r, np.ndarray) and r.ndim == 0:
        r = r.item()
    if not is_number(r):  # "1" and True are no rewards
        raise ValueError(f"reward_fn must return a number, got {r!r}")
    value = float(r)
    if not math.isfinite(value):
        raise ValueError(f"reward_fn returned a non-finite reward {value!r}")
    return value


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def reward_terms(obs, a, a_prev, peak, code, weights, swl, band, terms):
    """The default reward's terms (module docstring) into ``terms`` (REWARD_TERMS order).

    obs : the new observation (scaled channels). a, a_prev : this and the previous action.
    peak : largest element tension over the step [N]. code : the step's outcome code.
    weights : REWARD_TERMS-ordered weights. swl : the winch's safe working load [N].
    band : free band of the length wander, in the scaled length channel's units.
    """
    # blow-by: horizontal motion only (the winch's own reeling moves the aerostat vertically)
    terms[R_DISPLACEMENT] = -weights[R_DISPLACEMENT] * (obs[OBS_DX] ** 2 + obs[OBS_DY] ** 2)
    terms[R_VELOCITY] = -weights[R_VELOCITY] * (obs[OBS_VX] ** 2 + obs[OBS_VY] ** 2)
    terms[R_PITCH] = -weights[R_PITCH] * obs[OBS_DPITCH] ** 2
    terms[R_PITCH_RATE] = -weights[R_PITCH_RATE] * obs[OBS_Q] ** 2
    terms[R_EFFORT] = -weights[R_EFFORT] * a * a
    terms[R_EFFORT_RATE] = -weights[R_EFFORT_RATE] * (a - a_prev) ** 2
    terms[R_OVER_TENSION] = -weights[R_OVER_TENSION] * max(0.0, peak / swl - 1.0)
    ends = code != RUNNING and code != FIELD_END
    terms[R_TERMINATION] = -weights[R_TERMINATION] if ends else 0.0
    terms[R_LENGTH] = -weights[R_LENGTH] * max(0.0, abs(obs[OBS_DLENGTH]) - band) ** 2
