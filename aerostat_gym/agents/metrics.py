"""Response metrics of closed-loop (or open-loop) runs: damped-sinusoid fits, settling time, RMS,
tension and winch energy.

:func:`fit_damped_sinusoid` fits y = offset + A e^{-zeta w_n t} cos(w_d t + phi),
w_d = w_n sqrt(1 - zeta^2), by nonlinear least squares. It is written as
y = c + e^{-sigma t} (a cos w_d t + b sin w_d t), which is linear in (c, a, b): a coarse grid over
(sigma, w_d) around the period guess (FFT peak, zero crossings or the caller's) with the linear
part solved exactly at each node picks the start, and :func:`scipy.optimize.least_squares`
refines all five. zeta = sigma / sqrt(sigma^2 + w_d^2) and the reported ``period`` is the
natural period 2 pi / w_n, the quantity the modal tables report (``damped_period`` is 2 pi / w_d).
It never raises: a flat, too short or non-finite signal, a failed fit, or a fitted natural
period shorter than the record resolves (2 samples, :func:`mode_fit`), gives NaNs with the
reason in ``DampedFit.reason``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares
from scipy.signal import butter, sosfiltfilt

from ..analysis.signals import dominant_period, zero_crossing_period

NAN = float("nan")


@dataclass(frozen=True)
class DampedFit:
    """Result of :func:`fit_damped_sinusoid`.

    zeta : damping ratio. period : natural period 2 pi / w_n [s]. amplitude : A at the first
    sample [units of y]. offset : constant c. r2 : coefficient of determination of the fit.
    damped_period : 2 pi / w_d [s]. phase : phi [rad]. reason : "" or why the fit is NaN.
    """

    zeta: float
    period: float
    amplitude: float
    offset: float
    r2: float
    damped_period: float = NAN
    phase: float = NAN
    reason: str = ""

    @property
    def ok(self) -> bool:
        return not self.reason and math.isfinite(self.zeta)


def _failed(reason: str, r2: float = NAN) -> DampedFit:
    return DampedFit(NAN, NAN, NAN, NAN, r2, reason=reason)


def nyquist_period(dt: float) -> float:
    """The shortest period [s] samples ``dt`` [s] apart resolve: 2 dt (Nyquist)."""
    return 2.0 * dt


def mode_fit(a: float, b: float, sigma: float, wd: float, offset: float, r2: float,
             dt: float) -> DampedFit:
    """The :class:`DampedFit` of one fitted term e^{-sigma t} (a cos w_d t + b sin w_d t) of a
    record sampled every ``dt`` [s]: zeta = sigma / w_n, natural period 2 pi / w_n with
    w_n = hypot(sigma, w_d).

    A natural period below :func:`nyquist_period` (w_n dt > pi) is NaN with the reason: the
    fits keep w_d <= pi / dt, but a large sigma lifts w_n past it, and a term that decays by
    more than e^{-pi zeta} from one sample to the next was not resolved by the record (the fit
    put its residual into a transient about one sample long; measured: 0.07-0.16 s at zeta
    0.92-0.99 on a 0.2 s record whose linear pitching mode is 0.40 s, zeta 0.35).
    """
    wn = math.hypot(sigma, wd)
    period = 2 * math.pi / wn
    if period < nyquist_period(dt):
        return _failed(f"fitted natural period {period:.3g} s is below the sampling's shortest, "
                       f"2 dt = {nyquist_period(dt):.3g} s (unresolved)", r2)
    return DampedFit(zeta=float(sigma / wn), period=float(period),
                     amplitude=float(math.hypot(a, b)), offset=float(offset), r2=float(r2),
                     damped_period=float(2 * math.pi / wd), phase=float(math.atan2(-b, a)))


def _linear_part(t, y, sigma, wd):
    """Least-squares (c, a, b) and the residual norm for fixed (sigma, w_d)."""
    e = np.exp(-sigma * t)
    M = np.column_stack([np.ones_like(t), e * np.cos(wd * t), e * np.sin(wd * t)])
    coef, *_ = np.linalg.lstsq(M, y, rcond=None)
    return coef, float(np.sum((M @ coef - y) ** 2))


def fit_damped_sinusoid(t, y, period_guess: float | None = None) -> DampedFit:
    """Fit y = offset + A exp(-zeta w_n t) cos(w_d t + phi) to samples (t, y).

    Parameters
    ----------
    t, y : 1-D arrays of equal length (t increasing; non-finite samples are dropped).
    period_guess : rough damped period [s]; default from the FFT peak (zero crossings as a
        cross-check when the spectrum is poorly resolved).

    Returns
    -------
    DampedFit; NaNs and a ``reason`` if the signal is flat, too short or the fit fails.
    """
    try:
        t = np.asarray(t, dtype=float).ravel()
        y = np.asarray(y, dtype=float).ravel()
        if t.shape != y.shape:
            return _failed(f"t and y differ in shape: {t.shape} vs {y.shape}")
        keep = np.isfinite(t) & np.isfinite(y)
        t, y = t[keep], y[keep]
        if t.size < 8:
            return _failed(f"too few finite samples ({t.size} < 8)")
        if np.any(np.diff(t) <= 0):
            return _failed("t must be strictly increasing")
        span = float(np.ptp(y))
        if not span > 1e-12 * max(1.0, float(np.max(np.abs(y)))):
            return _failed("flat signal")
        t0 = t[0]
        tt = t - t0
        T = tt[-1]
        dt = float(np.median(np.diff(tt)))
        guesses = []
        if period_guess is not None and math.isfinite(period_guess) and period_guess > 0:
            guesses.append(float(period_guess))
        else:
            p_fft = dominant_period(tt, y - np.mean(y), fmin=1.0 / (4.0 * T), fmax=0.5 / dt)
            p_zc = zero_crossing_period(tt, y)
            guesses += [p for p in (p_fft, p_zc) if math.isfinite(p) and 2 * dt < p < 4 * T]
            if not guesses:
                guesses.append(T / 2.0)
        # coarse grid: damped frequency within a factor 2 of each guess, zeta 0 .. 0.9
        best = None
        for pg in guesses:
            for wd in 2 * np.pi / pg * np.geomspace(0.5, 2.0, 25):
                for z in (0.0, 0.01, 0.03, 0.06, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.75, 0.9):
                    sigma = z / math.sqrt(1.0 - z * z) * wd
                    coef, sse = _linear_part(tt, y, sigma, wd)
                    if best is None or sse < best[0]:
                        best = (sse, coef, sigma, wd)
        _, (c, a, b), sigma, wd = best
        scale = span

        def resid(q):
            c_, a_, b_, s_, w_ = q
            e = np.exp(np.clip(-s_ * tt, -700.0, 700.0))
            return (c_ + e * (a_ * np.cos(w_ * tt) + b_ * np.sin(w_ * tt)) - y) / scale

        wmax = math.pi / dt
        lo = [-np.inf, -np.inf, -np.inf, -10.0 / T - 10.0 * wmax, 1e-9]
        hi = [np.inf, np.inf, np.inf, 10.0 * wmax, wmax]
        x0 = np.clip([c, a, b, sigma, wd], np.array(lo) + 1e-12, np.array(hi) - 1e-12)
        sol = least_squares(resid, x0, bounds=(lo, hi), x_scale="jac", max_nfev=2000)
        c, a, b, sigma, wd = sol.x
        res = resid(sol.x) * scale
        sst = float(np.sum((y - np.mean(y)) ** 2))
        r2 = 1.0 - float(np.sum(res**2)) / sst
        if not (np.all(np.isfinite(sol.x)) and math.isfinite(r2)):
            return _failed("least-squares fit did not converge to finite values")
        return mode_fit(a, b, sigma, wd, c, r2, dt)
    except Exception as exc:  # noqa: BLE001 - a metric must never abort an evaluation
        return _failed(f"fit failed: {type(exc).__name__}: {exc}")


def fit_two_modes(t, y, slow: tuple[float, float], fast_period_guess: float
                  ) -> tuple[DampedFit, DampedFit]:
    """Fit y = c + slow mode + fast mode, each e^{-sigma t}(a cos w_d t + b sin w_d t).

    Parameters
    ----------
    t, y : samples. slow : (zeta, natural period [s]) start of the slow mode (e.g. the pendulum
    fitted to another signal). fast_period_guess : damped period guess of the fast mode [s].

    Returns
    -------
    (slow_fit, fast_fit), each a :class:`DampedFit` (``offset`` is the common c, ``r2`` that of
    the whole fit). NaNs with a reason on failure; never raises.

    Notes
    -----
    The fast mode's start is chosen on a grid of (zeta, w_d) with the slow mode held at its
    guess and the five linear coefficients solved exactly; then all nine parameters are refined
    by :func:`scipy.optimize.least_squares`. Fitting both modes together, rather than filtering
    the slow one out first, has no filter start-up transient, which matters because a
    well-damped pitch mode lives only in the first few seconds of a record.
    """
    try:
        t = np.asarray(t, dtype=float).ravel()
        y = np.asarray(y, dtype=float).ravel()
        keep = np.isfinite(t) & np.isfinite(y)
        t, y = t[keep], y[keep]
        if t.size < 16:
            return _failed("too few finite samples"), _failed("too few finite samples")
        span = float(np.ptp(y))
        if not span > 1e-12 * max(1.0, float(np.max(np.abs(y)))):
            return _failed("flat signal"), _failed("flat signal")
        zs, ps = slow
        if not (math.isfinite(zs) and math.isfinite(ps) and ps > 0 and abs(zs) < 1):
            return _failed("no slow-mode guess"), _failed("no slow-mode guess")
        if not (math.isfinite(fast_period_guess) and fast_period_guess > 0):
            return _failed("no fast-period guess"), _failed("no fast-period guess")
        tt = t - t[0]
        dt = float(np.median(np.diff(tt)))
        wn_s = 2 * np.pi / ps
        s1, w1 = zs * wn_s, wn_s * math.sqrt(1 - zs * zs)

        def basis(q):
            s_1, w_1, s_2, w_2 = q
            e1 = np.exp(np.clip(-s_1 * tt, -700.0, 700.0))
            e2 = np.exp(np.clip(-s_2 * tt, -700.0, 700.0))
            return np.column_stack([np.ones_like(tt), e1 * np.cos(w_1 * tt), e1 * np.sin(w_1 * tt),
                                    e2 * np.cos(w_2 * tt), e2 * np.sin(w_2 * tt)])

        best = None
        for wd in 2 * np.pi / fast_period_guess * np.geomspace(0.7, 1.4, 15):
            for z in (0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.75):
                q = (s1, w1, z / math.sqrt(1 - z * z) * wd, wd)
                M = basis(q)
                coef, *_ = np.linalg.lstsq(M, y, rcond=None)
                sse = float(np.sum((M @ coef - y) ** 2))
                if best is None or sse < best[0]:
                    best = (sse, coef, q)
        _, coef, q = best

        def resid(p):
            return (basis(p[5:]) @ p[:5] - y) / span

        wmax = math.pi / dt
        x0 = np.concatenate([coef, q])
        lo = [-np.inf] * 5 + [-1.0, 1e-9, -1.0, 1e-9]
        hi = [np.inf] * 5 + [10 * wmax, wmax, 10 * wmax, wmax]
        x0 = np.clip(x0, np.array(lo) + 1e-12, np.array(hi) - 1e-12)
        sol = least_squares(resid, x0, bounds=(lo, hi), x_scale="jac", max_nfev=4000)
        c, a1, b1, a2, b2, s_1, w_1, s_2, w_2 = sol.x
        sst = float(np.sum((y - np.mean(y)) ** 2))
        r2 = 1.0 - float(np.sum((resid(sol.x) * span) ** 2)) / sst
        if not (np.all(np.isfinite(sol.x)) and math.isfinite(r2)):
            return (_failed("least-squares fit did not converge"),) * 2

        f1, f2 = mode_fit(a1, b1, s_1, w_1, c, r2, dt), mode_fit(a2, b2, s_2, w_2, c, r2, dt)
        # slow mode first: an unresolved (NaN) term is the fast one, faster than 2 dt
        return (f1, f2) if not f2.ok or (f1.ok and f1.period >= f2.period) else (f2, f1)
    except Exception as exc:  # noqa: BLE001 - a metric must never abort an evaluation
        return (_failed(f"fit failed: {type(exc).__name__}: {exc}"),) * 2


def settling_time(t, y, fraction: float = 0.05, reference: float = 0.0) -> float:
    """Time, measured from t[0], after which |y - reference| stays within
    ``fraction * max |y - reference|``.

    The crossing is interpolated linearly between the last sample outside the band and the next.
    Returns 0 for a signal already at the reference, NaN if it is still outside the band at the
    last sample (or the input is empty/non-finite).
    """
    t = np.asarray(t, dtype=float).ravel()
    e = np.abs(np.asarray(y, dtype=float).ravel() - reference)
    if t.size == 0 or t.size != e.size or not np.all(np.isfinite(e)) or not np.all(np.isfinite(t)):
        return NAN
    emax = float(np.max(e))
    if emax == 0.0:
        return 0.0
    thr = fraction * emax
    out = np.nonzero(e > thr)[0]
    if out.size == 0:
        return 0.0
    i = int(out[-1])
    if i == t.size - 1:
        return NAN
    # e[i] > thr >= e[i+1]: linear crossing
    frac = (e[i] - thr) / (e[i] - e[i + 1])
    return float(t[i] + frac * (t[i + 1] - t[i]) - t[0])


def highpass(t, y, cutoff_hz: float, order: int = 4) -> np.ndarray:
    """Zero-phase Butterworth high-pass of uniformly sampled y (sosfiltfilt, odd padding)."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    fs = 1.0 / float(np.median(np.diff(t)))
    sos = butter(order, cutoff_hz, btype="highpass", fs=fs, output="sos")
    return sosfiltfilt(sos, y, padlen=min(3 * (2 * len(sos) + 1), y.size - 1))


def _rms(a) -> float:
    a = np.asarray(a, dtype=float)
    return float(np.sqrt(np.mean(a**2))) if a.size else NAN


def _pitch_fit(t, th, pend: DampedFit, period_guess, cutoff_hz) -> DampedFit:
    """Pitch mode of a pitch history that also carries the slow pendulum (see
    :func:`response_metrics`)."""
    try:
        if period_guess is None:
            hp = highpass(t, th - np.mean(th), cutoff_hz)
            if not np.ptp(hp) > 0:
                return _failed("flat signal")
            dt = float(np.median(np.diff(t)))
            period_guess = dominant_period(t, hp, fmin=cutoff_hz, fmax=0.5 / dt)
        if pend.ok:
            return fit_two_modes(t, th, (pend.zeta, pend.period), period_guess)[1]
        return fit_damped_sinusoid(t, highpass(t, th - np.mean(th), cutoff_hz), period_guess)
    except Exception as exc:  # noqa: BLE001 - a metric must never abort an evaluation
        return _failed(f"pitch fit failed: {type(exc).__name__}: {exc}")


def response_metrics(time, x_disp, pitch, tension, reel_speed, *,
                     pendulum_period_guess: float | None = None,
                     pitch_period_guess: float | None = None,
                     pitch_highpass_hz: float = 0.1, settle_fraction: float = 0.05,
                     fit_start: float | None = None, y_disp=None, pitch_rate=None,
                     length_dev=None, fit_lateral: bool = False,
                     lateral_period_guess: float | None = None) -> dict:
    """Metrics of one response from its time histories (all arrays over the same samples).

    Parameters
    ----------
    time : [s]. x_disp : along-wind CM displacement from trim [m]. pitch : pitch deviation from
    trim [rad]. tension : tether tension at the winch [N]. reel_speed : v_w [m/s].
    pendulum_period_guess, pitch_period_guess : optional start periods for the fits [s].
    pitch_highpass_hz : cutoff separating the pitch mode from the slow pendulum part.
    settle_fraction : band of the settling time (fraction of the peak displacement).
    fit_start : fit the modes only to samples with time >= fit_start [s] (e.g. after a forcing
        pulse ends: the fits model a free response). Default: all samples. The other metrics
        always use the whole record.
    y_disp : cross-wind CM displacement from trim [m] (optional: ``rms_y_m``; with
        ``fit_lateral`` also the lateral pendulum fitted on it).
    pitch_rate : body pitch rate q [rad/s] (optional: ``rms_pitch_rate_rad_s``).
    length_dev : paid-out tether length minus trim [m] (optional: ``length_wander_m`` =
        max |L - L_trim| and ``rms_length_m``).
    fit_lateral : fit a damped sinusoid to ``y_disp`` (``lateral_pendulum_*``).
    lateral_period_guess : start period of that fit [s].

    Returns
    -------
    dict of floats: pendulum_zeta, pendulum_period_s, pendulum_fit_r2, pitch_zeta,
    pitch_period_s, pitch_fit_r2, settling_time_s, rms_x_m, rms_pitch_rad, peak_tension_N,
    rms_tension_N, tension_std_N, winch_energy_J, peak_winch_power_W, peak_reel_speed_m_s;
    with the optional histories also rms_y_m, lateral_pendulum_zeta, lateral_pendulum_period_s,
    lateral_pendulum_fit_r2 (NaN unless ``fit_lateral``), rms_pitch_rate_rad_s,
    length_wander_m, rms_length_m. A history with NaNs (an episode that terminated) gives NaN
    for its RMS and peak figures.

    Notes
    -----
    Pendulum: fit to x_disp (the pendulum dominates the along-wind CM motion). Pitch: the pitch
    history carries the pendulum (35-45 s) as well as the pitch mode (2-3 s). A zero-phase
    4th-order Butterworth high-pass at ``pitch_highpass_hz`` (forward-backward gain
    r^8 / (1 + r^8), r = f / f_c: 1.5e-5 at a 40 s pendulum, > 0.999 above 0.3 Hz for
    f_c = 0.1 Hz) gives the pitch period guess from its spectral peak; the damping comes from a
    two-mode fit (:func:`fit_two_modes`) of the raw pitch history with the slow mode started at
    the pendulum fit. Fitting the filtered signal directly is biased: the filter's start-up
    transient overlaps the first seconds, where a well-damped pitch mode lives (measured on a
    synthetic zeta = 0.35 pitch mode: 0.70 from the filtered signal, 0.35 from the two-mode fit).
    Without a pendulum fit the filtered signal is fitted. The fast mode found is the one that
    dominates the pitch history: after a winch pulse that is the axial-spring mode (measured at
    10 m/s, speed loop holding: 3.5 s, zeta 0.12, against the linear axial spring 3.3 s, 0.14),
    after a pitch disturbance the pitching mode. Multi-mode responses (e.g. the LQR's slow
    length/integral mode under the pendulum) lower r2 and bias the single-mode fits. The fits report r2; a response in which a mode is barely excited gives a poor r2 and
    its zeta should not be trusted. Winch energy = integral of |T v_w| dt (trapezoid): work
    the drum does or absorbs, counted either way.
    """
    t = np.asarray(time, dtype=float).ravel()
    xd = np.asarray(x_disp, dtype=float).ravel()
    th = np.asarray(pitch, dtype=float).ravel()
    T = np.asarray(tension, dtype=float).ravel()
    v = np.asarray(reel_speed, dtype=float).ravel()
    w = slice(None) if fit_start is None else t >= fit_start
    pend = fit_damped_sinusoid(t[w], xd[w], pendulum_period_guess)
    pit = _pitch_fit(t[w], th[w], pend, pitch_period_guess, pitch_highpass_hz)
    power = np.abs(T * v)
    energy = float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(t))) if t.size > 1 else 0.0
    out = {
        "pendulum_zeta": pend.zeta,
        "pendulum_period_s": pend.period,
        "pendulum_fit_r2": pend.r2,
        "pitch_zeta": pit.zeta,
        "pitch_period_s": pit.period,
        "pitch_fit_r2": pit.r2,
        "settling_time_s": settling_time(t, xd, settle_fraction),
        "rms_x_m": _rms(xd),
        "rms_pitch_rad": _rms(th),
        "peak_tension_N": float(np.max(T)) if T.size else NAN,
        "rms_tension_N": _rms(T),
        "tension_std_N": float(np.std(T)) if T.size else NAN,
        "winch_energy_J": energy,
        "peak_winch_power_W": float(np.max(power)) if power.size else NAN,
        "peak_reel_speed_m_s": float(np.max(np.abs(v))) if v.size else NAN,
    }
    if y_disp is not None:
        yd = np.asarray(y_disp, dtype=float).ravel()
        out["rms_y_m"] = _rms(yd)
        lat = (fit_damped_sinusoid(t[w], yd[w], lateral_period_guess) if fit_lateral
               else _failed("not fitted"))
        out.update({"lateral_pendulum_zeta": lat.zeta, "lateral_pendulum_period_s": lat.period,
                    "lateral_pendulum_fit_r2": lat.r2})
    if pitch_rate is not None:
        out["rms_pitch_rate_rad_s"] = _rms(pitch_rate)
    if length_dev is not None:
        dl = np.asarray(length_dev, dtype=float).ravel()
        out["length_wander_m"] = float(np.max(np.abs(dl))) if dl.size else NAN
        out["rms_length_m"] = _rms(dl)
    return out

