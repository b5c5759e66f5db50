"""Where the evaluator's damped-sinusoid fits should look, from the configured aerostat's own
linear model.

The fits of :func:`aerostat_gym.agents.metrics.response_metrics` find their start periods in
the record (spectral peak, zero crossings) and separate the pitch mode from the pendulum with
a high-pass at 0.1 Hz. Both were sized on the baseline (pendulum 36-45 s, pitching 2.0-2.8 s
at 5-15 m/s, a 0.1 Hz cutoff near their geometric mean). On another aerostat the modes sit
elsewhere (the baseline scaled to a 5 m hull on 100 m at 10 m/s: pendulum 18 s, pitching
0.95 s), and the record's own peaks lead the fit astray: a slow winch-loop mode of 6 s read as
the pitch mode, a 20 s component as the pitch on a 60 m tether.

:func:`fit_guides` reads the linearization at the trim (:mod:`aerostat_gym.analysis.modes`)
of the aerostat the episodes ran on. Its periods only *start* the fits (every fit still
refines period and damping freely), so they steer the fit to the right mode without setting
its answer. The high-pass cutoff scales with the geometric mean of the pendulum and pitching
frequencies, anchored to the baseline's 0.1 Hz: the same separation, in the same proportion,
on every aerostat. On the baseline the evaluator does not use the guides (its fits find these
modes unaided and its stored reports were measured so); see :func:`guides_for`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

from ..analysis.modes import analyse
from ..analysis.trim import find_equilibrium
from ..params import Params, load_params

#: The pitch high-pass cutoff the fits were sized with on the baseline [Hz].
BASELINE_HIGHPASS_HZ = 0.1
#: The baseline's pendulum and pitching frequencies the cutoff is anchored at: the geometric
#: mean of both modes' natural frequencies at 10 m/s (42.0 s and 2.43 s: 0.0991 Hz), the middle
#: of the suites' 5-15 m/s.
ANCHOR_WIND = 10.0
#: How far a pitch fit's damped period may lie from the linear pitching or axial-spring mode's
#: and still count as that mode. The winch controllers move these modes little: on the baseline
#: at 5-15 m/s (7 policies, the 6 recover scenarios, seeds 5000-5002: 378 fits) every fitted
#: damped pitch period lies within 1.33 x of one of them. A fit further away caught something
#: else (a winch-loop mode, the pendulum's remainder).
FAST_MODE_FACTOR = 1.5


@dataclass(frozen=True)
class FitGuides:
    """Start periods of the fits [s] (the linear modes' damped periods; None: no such
    oscillatory mode) and the pitch high-pass cutoff [Hz]."""

    pendulum_period: float | None
    pitch_period: float | None
    axial_period: float | None
    lateral_period: float | None
    pitch_highpass_hz: float

    def fast_mode_ratio(self, zeta: float, period: float) -> float:
        """How far a pitch fit (damping ratio, natural period [s]) lies from the nearer of the
        aerostat's fast modes, the pitching and axial-spring modes the pitch history carries
        (see :mod:`aerostat_gym.agents.pitch_check`): max(d / p, p / d) of the damped periods
        d (fit) and p (mode), >= 1; inf for a fit that railed to zeta = 1 (no oscillation
        found, no damped period) or without either mode."""
        if not (math.isfinite(zeta) and math.isfinite(period) and 0.0 <= zeta < 1.0):
            return math.inf
        damped = period / math.sqrt(1.0 - zeta**2)
        return min((max(damped / ref, ref / damped) for ref in (self.pitch_period,
                                                                 self.axial_period)
                    if ref is not None), default=math.inf)

    def pitch_found(self, zeta: float, period: float) -> bool:
        """Whether a pitch fit caught one of the aerostat's fast modes: within
        :data:`FAST_MODE_FACTOR` of it (:meth:`fast_mode_ratio`)."""
        return self.fast_mode_ratio(zeta, period) <= FAST_MODE_FACTOR


def _damped_period(mode) -> float | None:
    """2 pi / w_d of an oscillatory linear mode (the period a record shows); None otherwise."""
    if mode is None or not mode.oscillatory or not 0.0 <= mode.zeta < 1.0:
        return None
    return mode.period / math.sqrt(1.0 - mode.zeta**2)


def _separation_hz(analysis) -> float | None:
    """Geometric mean of the longitudinal pendulum's and the pitching mode's natural
    frequencies [Hz]; None without both."""
    pend, pitch = analysis.find("long", "pendulum"), analysis.find("long", "pitching")
    if pend is None or pitch is None or not (pend.period > 0 and pitch.period > 0):
        return None
    return 1.0 / math.sqrt(pend.period * pitch.period)


@lru_cache(maxsize=1)
def _baseline() -> Params:
    return load_params()


@lru_cache(maxsize=1)
def _baseline_separation_hz() -> float:
    return _separation_hz(analyse(_baseline(), find_equilibrium(_baseline(), ANCHOR_WIND)))


@lru_cache(maxsize=256)
def fit_guides(params: Params, wind_speed: float) -> FitGuides | None:
    """The fits' guides for ``params`` trimmed at ``wind_speed`` [m/s]; None where the aerostat
    has no trim there or its linearization fails (the fits then go unguided)."""
    try:
        analysis = analyse(params, find_equilibrium(params, float(wind_speed)))
    except (ValueError, RuntimeError, ArithmeticError):
        return None
    sep = _separation_hz(analysis)
    cutoff = (BASELINE_HIGHPASS_HZ if sep is None
              else BASELINE_HIGHPASS_HZ * sep / _baseline_separation_hz())
    return FitGuides(pendulum_period=_damped_period(analysis.find("long", "pendulum")),
                     pitch_period=_damped_period(analysis.find("long", "pitching")),
                     lateral_period=_damped_period(analysis.find("lat", "pendulum")),
                     pitch_highpass_hz=cutoff,
                     axial_period=_damped_period(analysis.find("long", "axial spring")))


def is_baseline(params: Params | None) -> bool:
    """Whether ``params`` (None: the baseline) are the baseline's, however they were given."""
    return params is None or params == _baseline()


def guides_for(params: Params | None, wind_speed: float) -> FitGuides | None:
    """:func:`fit_guides` for an evaluation on ``params`` (None: the baseline), or None on the
    baseline itself: there the unguided fits are the protocol's definition, which every stored
    report and the README's tables were measured with."""
    return None if is_baseline(params) else fit_guides(params, wind_speed)


def guide_kwargs(guides: FitGuides | None) -> dict:
    """The keyword arguments of :func:`~aerostat_gym.agents.metrics.response_metrics` that
    ``guides`` set (none for None)."""
    if guides is None:
        return {}
    return {"pendulum_period_guess": guides.pendulum_period,
            "pitch_period_guess": guides.pitch_period,
            "lateral_period_guess": guides.lateral_period,
            "pitch_highpass_hz": guides.pitch_highpass_hz}


def drop_stray_pitch(metrics: dict, guides: FitGuides | None) -> dict:
    """``metrics`` (of :func:`~aerostat_gym.agents.metrics.response_metrics`) with the pitch
    damping ratio and period NaN where the pitch fit caught none of the aerostat's fast modes
    (:meth:`FitGuides.pitch_found`): the tables then read n/a, and the protocol's paired
    comparisons leave the episode out, rather than report a slow winch-loop mode or a fit
    without oscillation as the pitch damping. Unchanged without guides."""
    if guides is not None and not guides.pitch_found(metrics["pitch_zeta"],
                                                     metrics["pitch_period_s"]):
        metrics["pitch_zeta"] = metrics["pitch_period_s"] = math.nan
    return metrics
