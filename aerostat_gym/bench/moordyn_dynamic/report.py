"""The study's settings and its tables, in words."""

from __future__ import annotations

from ...params import Params
from ..moordyn import (
    RHO_AIR,
    WIND,
    _version,
    axial_cdt,
)
from .cases import WINDOW
from .runs import MOORDYN_SUBSTEPS, OUTPUT_DT, RK4_SUBSTEPS, SETTLE


def settings_text(p: Params) -> str:
    return (f"MoorDyn {_version()} RK4 at dt = {OUTPUT_DT / MOORDYN_SUBSTEPS * 1e3:.3g} ms "
            f"(checked against {OUTPUT_DT / MOORDYN_SUBSTEPS / 2 * 1e3:.3g} ms), coupled top point "
            f"driven every step; ours RK4 at {OUTPUT_DT / RK4_SUBSTEPS * 1e3:.3g} ms and "
            f"semi-implicit at {p.simulation.semi_implicit_dt * 1e3:.3g} ms; n = "
            f"{p.tether.n_elements}, L = {p.tether.length} m, rho = {RHO_AIR}, uniform current "
            f"{WIND} m/s along +X, Cd = {p.tether.Cd_normal}, CdAx = {axial_cdt(p):.4g}, "
            f"BA = b = {p.derived.damping_b:.4g} N s; settle {SETTLE:.0f} s at the trim; samples "
            f"every {OUTPUT_DT} s; window {WINDOW:.0f} s after the first cycle (sines) or from "
            "the start (reel, drop)")


def format_table(rows: dict) -> str:
    """Markdown table of :func:`run_case` results, ``rows[variant][case]``."""
    head = ("| variant | case | slack | RK4 pos RMS / max (% L) | RK4 top / bottom T RMS (%) "
            "| RK4 top / bottom lag | SI pos RMS / max (% L) | SI top / bottom T RMS (%) "
            "| MoorDyn dt/2 check: pos max (% L) / top T (%) | speed ratio RK4 / SI |")
    lines = [head, "|" + "---|" * 10]
    for variant, by_case in rows.items():
        for name, r in by_case.items():
            a, b = r["rk4"], r["semi-implicit"]
            lag = (f"{a['top_lag_deg']:+.2f} / {a['bottom_lag_deg']:+.2f} deg (h{a['top_harmonic']})"
                   if "top_lag_deg" in a
                   else f"{a['top_lag_s'] * 1e3:+.1f} / {a['bottom_lag_s'] * 1e3:+.1f} ms")
            chk = r.get("moordyn_step_check")
            chk_s = f"{chk['pos_max_pct']:.4f} / {chk['top_rms_pct']:.3f}" if chk else "-"
            lines.append(
                f"| {variant} | {name} | {'yes' if r['is_slack'] else 'no'} "
                f"| {a['pos_rms_pct']:.4f} / {a['pos_max_pct']:.4f} "
                f"| {a['top_rms_pct']:.3f} / {a['bottom_rms_pct']:.3f} | {lag} "
                f"| {b['pos_rms_pct']:.4f} / {b['pos_max_pct']:.4f} "
                f"| {b['top_rms_pct']:.3f} / {b['bottom_rms_pct']:.3f} | {chk_s} "
                f"| {a['speed_ratio']:.1f} / {b['speed_ratio']:.1f} |")
    return "\n".join(lines)


def format_report(res: dict) -> str:
    """Text report of :func:`run_dynamic_comparison`: settings, table, switches, overhead."""
    o = res["moordyn_step_call_overhead"]
    out = [f"Dynamic comparison with MoorDyn {res['moordyn_version']}: {res['settings']}", "",
           format_table(res["rows"])]
    if res["explained"]:
        out += ["", "Cases outside the bounds with each named difference switched off "
                "(one repeat, no step check; semi-implicit columns are the unswitched scheme "
                "except for the MoorDyn-side switches):", "", format_table(res["explained"])]
    out += ["", f"MoorDyn, top end held {o['simulated_s']:g} s: one Step call per step "
            f"{o['per_step_s']:.3f} s, one per second {o['per_second_s']:.3f} s "
            f"(ratio {o['ratio']:.2f})"]
    return "\n".join(out)
