"""The comparison of the two codes' runs (node positions, end tensions, phase lags, slack) per
case, and the whole study."""

from __future__ import annotations

import math
import tempfile

import numpy as np

from ...params import Params, load_params
from ..moordyn import (
    RHO_AIR,
    _import_moordyn,
    _version,
)
from .cases import SINE, DrivenCase, DynamicBenchError, standard_cases
from .report import settings_text
from .runs import (
    MOORDYN_SUBSTEPS,
    OUTPUT_DT,
    SETTLE,
    Setup,
    prepare,
    run_moordyn,
    run_ours,
    step_call_overhead,
)

POSITION_TARGET_PCT = 0.5  # issue 20: node positions within 0.5 % of L (max over the window)
TENSION_TARGET_PCT = 2.0  # issue 20: tensions within 2 % RMS of the mean tension


# --- comparison ------------------------------------------------------------------------------


def harmonic_fit(signal: np.ndarray, t: np.ndarray, omega: float) -> np.ndarray:
    """Amplitudes and phases [rad] of the first two harmonics: least-squares fit of
    a + sum_k R_k sin(k omega t + phase_k), k = 1, 2, to ``signal``; rows (R_k, phase_k).

    Both are fitted because a symmetric motion (across the wind) changes the tension at twice
    the drive frequency."""
    cols = [np.ones_like(t)]
    for k in (1, 2):
        cols += [np.sin(k * omega * t), np.cos(k * omega * t)]
    c = np.linalg.lstsq(np.column_stack(cols), signal, rcond=None)[0]
    return np.array([[math.hypot(c[2 * k - 1], c[2 * k]), math.atan2(c[2 * k], c[2 * k - 1])]
                     for k in (1, 2)])


def harmonic_lag(ours: np.ndarray, ref: np.ndarray, t: np.ndarray, period: float) -> dict:
    """Phase lag of ``ours`` behind ``ref`` in the harmonic (1 or 2, at the drive period) that
    dominates ``ref``: degrees of that harmonic's cycle and seconds (positive: ours lags)."""
    w = 2.0 * math.pi / period
    fa, fb = harmonic_fit(ours, t, w), harmonic_fit(ref, t, w)
    k = int(np.argmax(fb[:, 0]))
    lag = math.degrees((fb[k, 1] - fa[k, 1] + math.pi) % (2.0 * math.pi) - math.pi)
    return {"harmonic": k + 1, "lag_deg": lag, "lag_s": lag / 360.0 * period / (k + 1),
            "amplitude_ratio": float(fa[k, 0] / fb[k, 0]) if fb[k, 0] > 0 else float("nan")}


def correlation_lag(ours: np.ndarray, ref: np.ndarray, dt: float, max_lag: float = 2.0) -> float:
    """Delay [s] of ``ours`` behind ``ref`` at the peak of their cross-correlation (demeaned),
    refined by a parabola through the peak and its neighbours."""
    a, b = ours - ours.mean(), ref - ref.mean()
    kmax = int(round(max_lag / dt))
    lags = np.arange(-kmax, kmax + 1)
    cc = np.array([np.dot(a[max(k, 0):len(a) + min(k, 0)], b[max(-k, 0):len(b) - max(k, 0)])
                   for k in lags])
    i = int(np.argmax(cc))
    frac = 0.0
    if 0 < i < len(cc) - 1:
        den = cc[i - 1] - 2.0 * cc[i] + cc[i + 1]
        frac = 0.5 * (cc[i - 1] - cc[i + 1]) / den if den != 0 else 0.0
    return float((lags[i] + frac) * dt)


def compare_runs(ours: dict, ref: dict, case: DrivenCase, length: float) -> dict:
    """Figures of ``ours`` against ``ref`` over the case's window
    (:mod:`aerostat_gym.bench.moordyn_dynamic`, Figures)."""
    t = np.arange(len(ref["top"])) * OUTPUT_DT
    win = t >= case.window_start - 1e-9
    d = np.linalg.norm(ours["nodes"][win, 1:-1] - ref["nodes"][win, 1:-1], axis=2)
    out = {"pos_rms_pct": float(100.0 * np.sqrt(np.mean(d**2)) / length),
           "pos_max_pct": float(100.0 * d.max() / length)}
    for end in ("top", "bottom"):
        a, b = ours[end][win], ref[end][win]
        out[f"{end}_rms_pct"] = float(100.0 * np.sqrt(np.mean((a - b) ** 2)) / b.mean())
        if case.kind == SINE:
            h = harmonic_lag(a, b, t[win], case.period)
            out.update({f"{end}_{k}": v for k, v in h.items()})
        else:
            out[f"{end}_lag_s"] = correlation_lag(a, b, OUTPUT_DT)
    return out


def _slack_summary(run: dict, case: DrivenCase) -> dict:
    """When segments were slack (drive start to window end) and the tension extremes."""
    t = np.arange(len(run["top"])) * OUTPUT_DT
    s = run["slack"]
    on = np.nonzero(s > 0)[0]
    return {"max_slack_segments": int(s.max()),
            "slack_time_s": float(np.count_nonzero(s) * OUTPUT_DT),
            "first_slack_s": float(t[on[0]]) if on.size else None,
            "last_slack_s": float(t[on[-1]]) if on.size else None,
            "top_max_N": float(run["top"].max()), "top_min_N": float(run["top"].min()),
            "bottom_max_N": float(run["bottom"].max()),
            "bottom_min_N": float(run["bottom"].min())}


def run_case(case: DrivenCase, setup: Setup | None = None, repeats: int = 3,
             step_check: bool = True, md=None) -> dict:
    """Run one case in both codes and compare.

    Parameters
    ----------
    case : DrivenCase
        The prescribed motion.
    setup : Setup, optional
        From :func:`prepare` (default: the baseline variant).
    repeats : int
        Timed repeats of each code (the best is kept).
    step_check : bool
        Also run MoorDyn at half its step and report its difference from the reference.
    md : module, optional
        The ``moordyn`` module (imported when None).

    Returns
    -------
    dict with ``rk4`` and ``semi-implicit`` (:func:`compare_runs` figures plus ``wall_s``,
    ``dt_s`` and ``speed_ratio`` = MoorDyn wall / ours; the semi-implicit entry also has
    ``vs_our_rk4``, its figures against our RK4), ``moordyn`` (``wall_s``, ``dt_s``),
    ``moordyn_step_check`` (MoorDyn at half its step against the reference), ``slack`` (per code,
    :func:`_slack_summary`), ``is_slack`` (any segment slack in the window, either code),
    ``mean_top_tension_N``, ``within_targets`` (RK4 against the issue's bounds) and ``case``.
    """
    if repeats < 1:
        raise DynamicBenchError(f"repeats must be >= 1, got {repeats!r}")
    md = md or _import_moordyn()
    setup = setup or prepare()
    p = setup.params
    path = case.pack(setup.top, setup.lever, p.tether.length)
    L = p.tether.length
    with tempfile.TemporaryDirectory(prefix="aerostat_moordyn_dyn_") as tmp:
        ref = run_moordyn(md, setup, path, case, MOORDYN_SUBSTEPS, tmp, record=True)
        walls = [run_moordyn(md, setup, path, case, MOORDYN_SUBSTEPS, tmp, record=False)["wall_s"]
                 for _ in range(repeats)]
        fine = (run_moordyn(md, setup, path, case, 2 * MOORDYN_SUBSTEPS, tmp, record=True)
                if step_check else None)
    md_wall = float(min(walls))
    res = {"case": case.name, "duration_s": case.duration, "window_start_s": case.window_start,
           "moordyn": {"dt_s": ref["dt_s"], "wall_s": md_wall,
                       "real_time_factor": case.duration / md_wall}}
    if fine is not None:
        res["moordyn_step_check"] = compare_runs(fine, ref, case, L)
    win = np.arange(len(ref["top"])) * OUTPUT_DT >= case.window_start - 1e-9
    res["mean_top_tension_N"] = float(ref["top"][win].mean())
    slack = {"moordyn": _slack_summary(ref, case)}
    runs = {}
    for integ in ("rk4", "semi-implicit"):
        ours = runs[integ] = run_ours(setup, path, case, integ, repeats)
        fig = compare_runs(ours, ref, case, L)
        fig.update(dt_s=ours["dt_s"], wall_s=ours["wall_s"],
                   real_time_factor=case.duration / ours["wall_s"],
                   speed_ratio=md_wall / ours["wall_s"])
        res[integ] = fig
        slack[integ] = _slack_summary(ours, case)
    # the semi-implicit scheme against our RK4: its own time-step error, for comparison
    res["semi-implicit"]["vs_our_rk4"] = compare_runs(runs["semi-implicit"], runs["rk4"], case, L)
    res["slack"] = slack
    res["is_slack"] = bool(any(v["max_slack_segments"] > 0 for v in slack.values()))
    r = res["rk4"]
    res["within_targets"] = bool(r["pos_max_pct"] < POSITION_TARGET_PCT
                                 and r["top_rms_pct"] < TENSION_TARGET_PCT
                                 and r["bottom_rms_pct"] < TENSION_TARGET_PCT)
    return res


EXPLAIN_VARIANTS = ("crossflow_drag", "moordyn_drag", "no_buoyancy", "moordyn_slack_rule",
                    "moordyn_drag_and_slack_rule")


def _select_cases(base: Params, quick: bool, cases: list[str] | None) -> list[DrivenCase]:
    """The cases to run: the smoke case, the named ones, or the whole table."""
    table = standard_cases(base)
    if quick:
        harm = next(c for c in table if c.name == "across-harmonic-1m")
        return [DrivenCase(harm.name, SINE, harm.direction, harm.amplitude, harm.period,
                           window=10.0)]
    if cases is None:
        return table
    known = {c.name: c for c in table}
    missing = [c for c in cases if c not in known]
    if missing:
        raise DynamicBenchError(f"unknown case(s) {missing}; choose from {sorted(known)}")
    return [known[c] for c in cases]


def _outside_targets(row: dict) -> bool:
    """A case whose RK4 figures exceed the issue's bounds (slack or not)."""
    r = row["rk4"]
    return (r["pos_max_pct"] >= POSITION_TARGET_PCT
            or max(r["top_rms_pct"], r["bottom_rms_pct"]) >= TENSION_TARGET_PCT)


def run_dynamic_comparison(quick: bool = False, cases: list[str] | None = None,
                           variants: tuple = ("baseline",), repeats: int = 3,
                           explain: bool = True) -> dict:
    """The dynamic comparison table, and the switches applied to the cases outside the bounds.

    Parameters
    ----------
    quick : bool
        One short case (across the wind at the tether harmonic, 1 m, 10 s window, 15 s settle,
        no step check, one timed repeat): the smoke run.
    cases : list of str, optional
        Names from :func:`standard_cases` (default all).
    variants : tuple of str
        Which ``VARIANTS`` to run every selected case under.
    repeats : int
        Timed repeats per code and case (the best is kept).
    explain : bool
        Also run each case whose RK4 figures exceed the bounds (in the first variant) under
        ``EXPLAIN_VARIANTS`` (one repeat, no step check): the named differences switched off.

    Returns
    -------
    dict with ``rows`` (per variant, per case: :func:`run_case`), ``explained`` (per switch,
    per case outside the bounds: :func:`run_case`), ``settings`` (text), ``moordyn_version``,
    ``moordyn_step_call_overhead`` (:func:`step_call_overhead`) and the targets.
    """
    if repeats < 1:
        raise DynamicBenchError(f"repeats must be >= 1, got {repeats!r}")
    md = _import_moordyn()
    base = load_params(overrides={"environment.rho_air": RHO_AIR})
    table = _select_cases(base, quick, cases)
    settle = 15.0 if quick else SETTLE
    rows, overhead = {}, None
    for variant in variants:
        setup = prepare(variant, settle=settle)
        if overhead is None:
            overhead = step_call_overhead(md, setup, seconds=5.0 if quick else 20.0,
                                          repeats=1 if quick else repeats)
        rows[variant] = {c.name: run_case(c, setup, repeats=1 if quick else repeats,
                                          step_check=not quick, md=md) for c in table}
    explained = {}
    first = rows[variants[0]]
    over = [c for c in table if _outside_targets(first[c.name])] if explain else []
    for variant in EXPLAIN_VARIANTS if over else ():
        setup = prepare(variant, settle=settle)
        explained[variant] = {c.name: run_case(c, setup, repeats=1, step_check=False, md=md)
                              for c in over}
    return {"rows": rows, "explained": explained, "moordyn_version": _version(),
            "moordyn_step_call_overhead": overhead,
            "targets": {"position_max_pct_L": POSITION_TARGET_PCT,
                        "tension_rms_pct": TENSION_TARGET_PCT},
            "settings": settings_text(base)}
