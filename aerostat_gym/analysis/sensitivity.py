"""Sensitivity of the linear results to the estimated and calibrated parameters.

Most aerostat parameters of the baseline are ESTIMATE or CALIB (``parameter_table()``); this
module moves each across a plausible range relative to the configured value (the baseline's
documented range in docs/parameters.md as factors of its value, positions in hull lengths;
:func:`default_knobs`) and reports how the four [LN02] Table 2 periods at U = 1 m/s and
the smallest damping ratio of the Figure 9 modes over 1..20 m/s respond. It tells a user which
of their own aerostat's numbers matter, and :func:`solve_for_period` says how far one knob must
move to put a period on a target (for a documented calibration, never applied silently).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ..params import ParameterError, Params, load_params, params_to_dict
from .modes import FIGURE9_MODES, SETS, analyse
from .reference import TABLE2, linear_table2_periods
from .trim import TrimError, find_equilibrium

#: Wind speeds of the damping search [m/s] (U = 0 is left out: without wind only the tether's
#: material damping acts and every aerostat mode is undamped whatever the parameters).
DAMPING_SPEEDS = (1.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 18.0, 20.0)
PERIOD_KEYS = tuple(TABLE2)


@dataclass(frozen=True)
class Knob:
    """One uncertain parameter with its plausible range.

    Attributes
    ----------
    key : identifier (a dotted parameter name, or a derived knob such as ``cm_x_shift``).
    label : text for tables. status : ESTIMATE or CALIB. unit : unit of the knob's value.
    low, high : ends of the plausible range. source : where the range comes from.
    get : value of the knob in a parameter set. put : parameter set with the knob at a value.
    override : the dotted parameter name when ``put`` sets that one field and nothing else
        (None for a derived knob), so that several draws can be applied as one override and
        checked together (e.g. the inertia triangle inequalities, which no single moment
        decides).
    """

    key: str
    label: str
    status: str
    unit: str
    low: float
    high: float
    source: str
    get: Callable[[Params], float]
    put: Callable[[Params, float], Params]
    override: str | None = None


def _dotted(key: str) -> tuple[Callable, Callable, str]:
    sec, name = key.split(".")
    return (lambda p: float(getattr(getattr(p, sec), name)),
            lambda p, v: p.replace(**{key: float(v)}), key)


def _vector_component(key: str, k: int) -> tuple[Callable, Callable]:
    sec, name = key.split(".")

    def put(p: Params, v: float) -> Params:
        vec = list(getattr(getattr(p, sec), name))
        vec[k] = float(v)
        return p.replace(**{key: vec})

    return (lambda p: float(getattr(getattr(p, sec), name)[k]), put)


def _shift_cm(p: Params, dx: float) -> Params:
    """Move the CM forward by dx [m] (toward the nose): every body position measured from the
    CM (CB, nose, fin points) moves aft by dx. Inertias are left unchanged (the parallel-axis
    change, m dx^2, is below 1 % for |dx| <= 0.3 m)."""
    d = params_to_dict(p)
    a = d["aerostat"]
    a["cb_position"][0] -= dx
    a["nose_position"][0] -= dx
    panels = [{**pan, "cp_position": [pan["cp_position"][0] - dx, *pan["cp_position"][1:]]}
              for pan in d["fins"]["panels"]]
    return p.replace(**{"aerostat.cb_position": a["cb_position"],
                        "aerostat.nose_position": a["nose_position"], "fins.panels": panels})


def _cm_knob() -> tuple[Callable, Callable]:
    # value = forward shift relative to the shipped CM; the shipped file has shift 0
    return (lambda p: 0.0, _shift_cm)


def _rho_keep_lift() -> tuple[Callable, Callable]:
    """Air density with the mass adjusted so that the net lift B - m g stays the same
    (density and mass are not separately identifiable from Table 2, parameters.md section 2)."""

    def put(p: Params, rho: float) -> Params:
        lift = p.derived.net_lift
        mass = (rho * p.environment.g * p.aerostat.volume - lift) / p.environment.g
        return p.replace(**{"environment.rho_air": float(rho), "aerostat.mass": float(mass)})

    return (lambda p: p.environment.rho_air, put)


def _pm(base: float, frac: float) -> tuple[float, float]:
    return base * (1 - frac), base * (1 + frac)


def _rel(base: float, low: float, high: float) -> tuple[float, float]:
    """(low base, high base): a range as factors of the configured value."""
    return base * low, base * high


def _fraction(lo_hi: tuple[float, float], source: str) -> tuple[tuple[float, float], str]:
    """A range of a coefficient that lies in [0, 1] (Lamb's k1 and k3, eta_k), kept there, and
    its source text saying so where it was cut: a slender hull's k3 of 0.96 times the
    baseline's factor 1.07 would end at an invalid 1.03."""
    kept = min(max(lo_hi[0], 0.0), 1.0), min(max(lo_hi[1], 0.0), 1.0)
    if kept != tuple(lo_hi):
        source += f"; capped to {kept[0]:.3g}-{kept[1]:.3g}, the coefficient's bounds [0, 1]"
    return kept, source


#: Half-width of the CM and CB position ranges in hull lengths: the baseline's +-0.3 m on its
#: 18.3 m hull (component mass model, docs/parameters.md section 1e).
POSITION_SPREAD_HULL_LENGTHS = 0.3 / 18.3


def default_knobs(params: Params | None = None) -> list[Knob]:
    """The uncertain parameters and their ranges, relative to the configured values.

    Every range is a factor of the configured value (or, for positions, a multiple of the
    configured hull length), so it follows the user's aerostat. The factors are the baseline's
    plausible ranges (docs/parameters.md sections 1-5) divided by the baseline's value; for the
    shipped baseline the ranges are therefore the documented absolute ones (e.g. fin area
    12-25 m^2, CM shift +-0.3 m).
    """
    p = params or load_params()
    a, h, f, t = p.aerostat, p.hull, p.fins, p.tether
    spread = POSITION_SPREAD_HULL_LENGTHS * a.length
    ks = []

    def add(key, label, status, unit, lo_hi, source, getput):
        ks.append(Knob(key, label, status, unit, float(lo_hi[0]), float(lo_hi[1]), source, *getput))

    add("hull.eta_k", "hull efficiency eta_k", "CALIB", "-", *_fraction(
        _rel(h.eta_k, 0.25, 1.25), "x0.25-1.25 (baseline 0.1-0.5: >= 0.5 yaw-divergent, sec. 5)"),
        _dotted("hull.eta_k"))
    add("fins.CL_alpha", "fin lift slope C_L_alpha", "CALIB", "1/rad",
        _rel(f.CL_alpha, 1.2 / 1.43, 2.5 / 1.43),
        "x0.84-1.75 (baseline 1.2-2.5 about 1.43, sec. 1d)", _dotted("fins.CL_alpha"))
    add("fins.planform_area", "fin planform area A_f", "ESTIMATE", "m^2",
        _rel(f.planform_area, 12.0 / 18.0, 25.0 / 18.0),
        "x0.67-1.39 (baseline 12-25 m^2 about 18, sec. 1d)", _dotted("fins.planform_area"))
    add("cm_x_shift", "CM moved forward", "CALIB", "m", (-spread, spread),
        "+-0.0164 hull lengths (baseline +-0.3 m, sec. 1e)", _cm_knob())
    xb, _, zb = a.cb_position
    add("aerostat.cb_position[x]", "CB x relative to CM", "CALIB", "m", (xb - spread, xb + spread),
        "+-0.0164 hull lengths, as the CM (sec. 1e); x_l moves 2.2x as much",
        _vector_component("aerostat.cb_position", 0))
    add("aerostat.cb_position[z]", "CB z relative to CM", "CALIB", "m", (zb - spread, zb + spread),
        "+-0.0164 hull lengths (sec. 1e)", _vector_component("aerostat.cb_position", 2))
    for name in ("Ixx", "Iyy", "Izz"):
        add(f"aerostat.{name}", f"inertia {name}", "ESTIMATE", "kg m^2", _pm(getattr(a, name), 0.3),
            "+-30 % (sec. 1a)", _dotted(f"aerostat.{name}"))
    add("aerostat.Ixz", "product of inertia Ixz", "ESTIMATE", "kg m^2", (-abs(a.Ixz), abs(a.Ixz)),
        "sign uncertain (sec. 1a)", _dotted("aerostat.Ixz"))
    add("hull.Cdc", "hull cross-flow drag (C_dc)_h", "ESTIMATE", "-", _rel(h.Cdc, 0.25, 1.0),
        "x0.25-1 (baseline 0.3-1.2: supercritical to subcritical cylinder, sec. 1c)",
        _dotted("hull.Cdc"))
    add("aerostat.k1", "axial added-mass coeff. k1", "ESTIMATE", "-",
        *_fraction(_rel(a.k1, 0.086 / 0.1672, 0.188 / 0.1672),
                   "x0.51-1.12 (baseline Table 2 fits 0.086-0.188, sec. 2)"), _dotted("aerostat.k1"))
    add("aerostat.k3", "lateral added-mass coeff. k3", "ESTIMATE", "-",
        *_fraction(_rel(a.k3, 0.584 / 0.7494, 0.803 / 0.7494),
                   "x0.78-1.07 (baseline Table 2 fits 0.584-0.803, sec. 2)"), _dotted("aerostat.k3"))
    add("environment.rho_air", "air density (net lift kept)", "DERIVED", "kg/m^3",
        _rel(p.environment.rho_air, 1.120 / 1.147, 1.225 / 1.147),
        "x0.976-1.068 (baseline 1.120-1.225, sec. 2); mass adjusted", _rho_keep_lift())
    add("hull.CD0", "hull axial drag (C_D,h)0", "ESTIMATE", "-",
        _rel(h.CD0, 0.025 / 0.029, 0.04 / 0.029), "x0.86-1.38 (baseline 0.025-0.04, sec. 1c)",
        _dotted("hull.CD0"))
    add("tether.Cd_normal", "tether normal drag C_dn", "ESTIMATE", "-",
        _rel(t.Cd_normal, 1.0 / 1.2, 1.5 / 1.2), "x0.83-1.25 (baseline 1.0-1.5, sec. 1f)",
        _dotted("tether.Cd_normal"))
    return ks


def select_knobs(knobs: list[Knob], keys) -> list[Knob]:
    """The knobs named in ``keys`` (all if ``keys`` is empty); an unknown key is an error naming
    the known ones."""
    if not keys:
        return knobs
    known = {k.key: k for k in knobs}
    unknown = [k for k in keys if k not in known]
    if unknown:
        raise ValueError(f"unknown sensitivity knob(s) {unknown}; known: {list(known)}")
    return [known[k] for k in keys]


# --- evaluation ----------------------------------------------------------------------------------


def stability_figures(params: Params, speeds=DAMPING_SPEEDS, period_speed: float = 1.0) -> dict:
    """Table 2 periods at ``period_speed`` and the damping/stability summary over ``speeds``.

    Returns
    -------
    dict with the four Table 2 periods [s] (keys of :data:`~.reference.TABLE2`),
    ``min_zeta`` (smallest damping ratio of the Figure 9 modes), ``min_zeta_at`` (speed, set,
    mode), ``all_stable`` (every mode, every speed) and ``max_real`` (largest Re lambda of a
    non-neutral mode [1/s]); or ``error`` if a trim fails.
    """
    out: dict = {}
    eq, zmin, where, stable, max_re = None, math.inf, None, True, -math.inf
    try:
        for u in sorted(set(speeds) | {period_speed}):
            eq = find_equilibrium(params, u, guess=eq)
            an = analyse(params, eq)
            if u == period_speed:
                out.update(linear_table2_periods(an))
            stable &= an.all_stable()
            max_re = max(max_re, max(m.eigenvalue.real for m in an.long + an.lat if not m.neutral))
            for subset in SETS:
                for label in FIGURE9_MODES[subset]:
                    m = an.find(subset, label)
                    if m is not None and not m.neutral and m.zeta < zmin and u in speeds:
                        zmin, where = m.zeta, {"wind_speed_m_s": u, "set": subset, "mode": label}
    except TrimError as exc:
        return {"error": str(exc)}
    out.update(min_zeta=zmin, min_zeta_at=where, all_stable=bool(stable), max_real=max_re)
    return out


def sensitivity_table(params: Params | None = None, knobs: list[Knob] | None = None,
                      speeds=DAMPING_SPEEDS) -> dict:
    """Move every knob to both ends of its range (one at a time) and evaluate.

    Returns
    -------
    {"baseline": stability_figures(params), "rows": [...]}: per knob its range and source, and for each
    end the Table 2 periods with their % change from the baseline, the smallest damping ratio
    and where it occurs, stability. Rows are sorted by the largest |% change| of any period.
    """
    p = params or load_params()
    knobs = default_knobs(p) if knobs is None else knobs
    base = stability_figures(p, speeds)
    rows = []
    for k in knobs:
        row = {"knob": k.key, "label": k.label, "status": k.status, "unit": k.unit,
               "baseline": k.get(p), "low": k.low, "high": k.high, "source": k.source}
        for end in ("low", "high"):
            res = _end_figures(k, p, getattr(k, end), speeds)
            row[end + "_result"] = res
            if "error" not in res:
                row[end + "_pct"] = {key: 100 * (res[key] - base[key]) / base[key] for key in PERIOD_KEYS}
        # a period that stops existing (the mode overdamped or gone: NaN) is the largest change
        row["max_abs_pct"] = max((math.inf if math.isnan(v) else abs(v)
                                  for end in ("low_pct", "high_pct") for v in row.get(end, {}).values()),
                                 default=math.inf)
        rows.append(row)
    rows.sort(key=lambda r: -r["max_abs_pct"])
    return {"baseline": base, "rows": rows, "speeds": list(speeds)}


def format_sensitivity(table: dict) -> str:
    """Plain-text table: % change of each Table 2 period at the low / high end, min zeta."""
    short = {"long_pendulum": "long.pend", "lat_pendulum": "lat.pend", "axial_spring": "axial",
             "tether_1st": "tether1"}
    b = table["baseline"]
    # a range wider than its 17 columns (a large aerostat's inertias) widens the column
    ranges = [f"{r['low']:8.4g}-{r['high']:<8.4g}" for r in table["rows"]]
    width = max([17] + [len(x) for x in ranges])
    head = (f"{'parameter':32s} {'range':>{width}s} "
            + " ".join(f"{short[k]:>13s}" for k in PERIOD_KEYS) + f" {'min zeta':>13s}")
    lines = ["baseline: " + ", ".join(f"{short[k]} {b[k]:.3f} s" for k in PERIOD_KEYS)
             + f", min zeta {b['min_zeta']:.3f} ({b['min_zeta_at']['set']} {b['min_zeta_at']['mode']}"
             f" at {b['min_zeta_at']['wind_speed_m_s']:g} m/s)", "% change of each period at the low / high end of the range",
             head, "-" * len(head)]
    for r, span in zip(table["rows"], ranges, strict=True):
        cells = []
        for k in PERIOD_KEYS:
            lo, hi = r.get("low_pct", {}).get(k, math.nan), r.get("high_pct", {}).get(k, math.nan)
            cells.append(f"{_signed(lo)}/{_signed(hi)}")
        ends = (r["low_result"], r["high_result"])
        zl, zh = (_plain(e.get("min_zeta", math.nan)) for e in ends)
        lines.append(f"{r['label']:32s} {span:<{width}s} " + " ".join(f"{c:>13s}" for c in cells)
                     + f" {zl}/{zh}{_verdict(ends)}")
    if any("n/a" in line for line in lines):
        lines.append("n/a: no trim at that end (--json has the error), the mode overdamped there "
                     "(a real eigenvalue: no period), or no mode of that name")
    return "\n".join(lines)


def _signed(x: float) -> str:
    return "   n/a" if math.isnan(x) else f"{x:+6.1f}"


def _end_figures(knob: Knob, params: Params, value: float, speeds) -> dict:
    """:func:`stability_figures` with one knob moved to ``value``. An end the loader refuses is
    recorded ({"error": ..., "invalid": True}), not raised: on an aerostat whose moments sit
    near a triangle inequality, one moment of inertia moved alone can leave every body."""
    try:
        moved = knob.put(params, value)
    except ParameterError as exc:
        return {"error": str(exc), "invalid": True}
    return stability_figures(moved, speeds)


def _plain(x: float) -> str:
    return "   n/a" if math.isnan(x) else f"{x:6.3f}"


def _verdict(ends) -> str:
    """' UNSTABLE' where an end's sweep found an unstable mode, ' NO TRIM (low/high)' where an
    end has no trim to judge, ' INVALID (low/high)' where the loader refuses an end; nothing
    when both ends are stable everywhere."""
    named = tuple(zip(("low", "high"), ends, strict=True))
    invalid = [name for name, e in named if e.get("invalid")]
    failed = [name for name, e in named if "error" in e and not e.get("invalid")]
    if invalid or failed:
        return "".join(f" {what} ({'/'.join(names)})" for what, names in
                       (("INVALID", invalid), ("NO TRIM", failed)) if names)
    return "" if all(e.get("all_stable", False) for e in ends) else " UNSTABLE"


def solve_for_period(params: Params, knob: Knob, target: float, key: str = "lat_pendulum",
                     bracket: tuple[float, float] | None = None, wind_speed: float = 1.0,
                     grid: int = 9, xtol: float = 1e-4) -> float | None:
    """Value of ``knob`` that puts the Table 2 period ``key`` at ``target`` seconds at
    ``wind_speed``; None if no value in ``bracket`` (default the knob's range) reaches it.

    Notes
    -----
    The period need not be monotonic in the knob (at 1 m/s the lateral pendulum sits near its
    veering with the yaw mode), so the bracket is scanned on ``grid`` points and Brent's method
    refines the sign change nearest the knob's current value.
    """
    lo, hi = bracket or (knob.low, knob.high)

    def f(v: float) -> float:
        try:
            p = knob.put(params, v)
            return linear_table2_periods(analyse(p, find_equilibrium(p, wind_speed)))[key] - target
        except (ParameterError, TrimError):  # no aerostat at v, or no trim: no period
            return math.nan

    xs = np.linspace(lo, hi, grid)
    fs = np.array([f(v) for v in xs])
    ok = np.isfinite(fs[:-1]) & np.isfinite(fs[1:]) & (fs[:-1] * fs[1:] <= 0)
    if not ok.any():
        return None
    base = knob.get(params)
    k = min(np.flatnonzero(ok), key=lambda i: abs(0.5 * (xs[i] + xs[i + 1]) - base))
    if fs[k] == 0.0:
        return float(xs[k])
    return float(brentq(f, xs[k], xs[k + 1], xtol=xtol))


def lateral_pendulum_fixes(params: Params | None = None, targets=(TABLE2["lat_pendulum"]["linear_s"] * 1.1,
                                                                   TABLE2["lat_pendulum"]["linear_s"]),
                           knobs: list[Knob] | None = None, widen: float = 1.0) -> list[dict]:
    """For each knob, the value that brings the lateral pendulum at 1 m/s to each target
    (default: the edge of the 10 % band, 74.14 s, and [LN02]'s 67.4 s), with the other Table 2
    periods, the smallest damping ratio and stability over 1..20 m/s at that value. ``widen`` stretches the search bracket
    beyond the stated range about its centre (1 = the range itself)."""
    p = params or load_params()
    rows = []
    for k in knobs or default_knobs(p):
        mid, half = 0.5 * (k.low + k.high), 0.5 * (k.high - k.low) * widen
        for t in targets:
            v = solve_for_period(p, k, t, bracket=(mid - half, mid + half))
            row = {"knob": k.key, "label": k.label, "target_s": t, "value": v,
                   "baseline": k.get(p), "in_range": v is not None and k.low <= v <= k.high}
            if v is not None:
                row["result"] = stability_figures(k.put(p, v))
            rows.append(row)
    return rows
