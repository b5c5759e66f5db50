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
on every aerostat. :func:`screen_fits` then sets to NaN what the record cannot support: a pitch
fit that caught none of the fast modes, a pendulum slower than the record, the "period" of a
fit that found no oscillation. On the baseline the evaluator does neither (its fits find these
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
#: at 5-15 m/s (7 policies, the 6 recover scenarios, seeds 5000-5002: 378 fits,
#: ``scripts/pitch_fit_coverage.py``) every fitted damped pitch period lies within 1.42 x of
#: one of them. A fit further away caught something else (a winch-loop mode, the pendulum's
#: remainder).
FAST_MODE_FACTOR = 1.5
#: A fitted damping ratio at or above this is the fit's bound (damped frequency at its floor):
#: the record showed a decay and no oscillation.
RAILED_ZETA = 0.999


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
        aerostat's fast modes, the modes the pitch history carries (see
        :mod:`aerostat_gym.agents.pitch_check`): the pitching mode, and the axial-spring mode
        where it lies within :data:`FAST_MODE_FACTOR` of the pitching mode (the baseline's
        blend, 2.4 s against 3.3 s at 10 m/s; a near-neutral aerostat's axial spring of 20 s is
        not pitch). max(d / p, p / d) of the damped periods d (fit) and p (mode), >= 1; inf for
        a fit that railed to zeta = 1 (no oscillation found, no damped period) or without a
        pitching mode."""
        if not (math.isfinite(zeta) and math.isfinite(period) and 0.0 <= zeta < 1.0):
            return math.inf
        damped = _damped(zeta, period)
        return min((_ratio(damped, ref) for ref in self.pitch_modes()), default=math.inf)

    def pitch_modes(self) -> tuple:
        """Damped periods [s] a pitch fit may catch (see :meth:`fast_mode_ratio`)."""
        if self.pitch_period is None:
            return ()
        axial = self.axial_period
        if axial is not None and _ratio(axial, self.pitch_period) <= FAST_MODE_FACTOR:
            return (self.pitch_period, axial)
        return (self.pitch_period,)

    def pitch_found(self, zeta: float, period: float) -> bool:
        """Whether a pitch fit caught one of the aerostat's fast modes: within
        :data:`FAST_MODE_FACTOR` of it (:meth:`fast_mode_ratio`)."""
        return self.fast_mode_ratio(zeta, period) <= FAST_MODE_FACTOR


def _ratio(a: float, b: float) -> float:
    return max(a / b, b / a)


def _damped(zeta: float, period: float) -> float:
    """2 pi / w_d [s] (the period a record shows) of a mode of natural period ``period`` and
    damping ratio 0 <= ``zeta`` < 1."""
    return period / math.sqrt(1.0 - zeta**2)


def _damped_period(mode) -> float | None:
    """:func:`_damped` of an oscillatory linear mode; None otherwise."""
    if mode is None or not mode.oscillatory or not 0.0 <= mode.zeta < 1.0:
        return None
    return _damped(mode.zeta, mode.period)


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


def screen_fits(metrics: dict, guides: FitGuides | None, record_s: float) -> dict:
    """``metrics`` (of :func:`~aerostat_gym.agents.metrics.response_metrics`, fitted over a
    record of ``record_s`` seconds) with the fits a record cannot support set to NaN (n/a in
    the tables; the protocol's paired comparisons leave the episode out). Unchanged without
    guides (the baseline). The rules:

    - pitch: a fit that caught none of the aerostat's fast modes (:meth:`FitGuides.pitch_found`)
      reads NaN, rather than a slow winch-loop mode or a fit without oscillation;
    - pendulums (longitudinal and lateral): where the fitted or the linear (braked) damped
      period is longer than the record, less than one swing was seen and period and damping
      are not separable: both NaN (a 345 s lateral pendulum fitted in 180 s read zeta 0.21
      against the linear 0.15); a fit that railed to zeta = 1 saw a decay and no oscillation:
      its zeta stays 1 ("at least critically damped, or too slow to swing in the record"), its
      period, 2 pi / sigma, is not a period: NaN.
    """
    if guides is None:
        return metrics
    if not guides.pitch_found(metrics["pitch_zeta"], metrics["pitch_period_s"]):
        metrics["pitch_zeta"] = metrics["pitch_period_s"] = math.nan
    for prefix, linear in (("pendulum", guides.pendulum_period),
                           ("lateral_pendulum", guides.lateral_period)):
        zkey, pkey = f"{prefix}_zeta", f"{prefix}_period_s"
        zeta, period = metrics.get(zkey, math.nan), metrics.get(pkey, math.nan)
        if not (math.isfinite(zeta) and math.isfinite(period)):
            continue
        if zeta >= RAILED_ZETA:
            metrics[pkey] = math.nan
        if (linear is not None and linear > record_s) or (
                zeta < RAILED_ZETA and _damped(zeta, period) > record_s):
            metrics[zkey] = metrics[pkey] = math.nan
    return metrics
