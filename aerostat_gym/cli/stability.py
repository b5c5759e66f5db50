"""Command-line front end of the linear stability analysis.

``add_stability_parsers(subparsers)`` registers:

* ``stability --wind 0:20:0.5 [--length 300] [--elements 10] [--config FILE] [--set K=V]
  [--json] [--plot DIR]``: trim, linearize and analyse at every wind speed; print the Figure 9
  modes (period and damping ratio), stability and the coupling ratios; ``--plot`` writes the
  Figure 9 PNG, CSV and JSON into DIR. Past the first speed whose trim breaks the tether or
  cannot be found the sweep stops: it reports the speeds below and says where and why it
  stopped (a warning, a last line, ``"stop"`` in the JSON).
* ``table2 [--config FILE] [--json]``: Table 2 for the configured aerostat, its linear model
  against its own closed forms (the paper's columns only for the paper's case).
* ``sensitivity [--config FILE] [--wind A:B:S] [--knob KEY] [--json]``: how the estimated
  parameters, each moved across a range relative to its configured value, move the Table 2
  periods and the smallest damping ratio.

Each handler returns an exit status; invalid input raises ValueError (the main CLI prints it
and exits with status 2).
"""

from __future__ import annotations

import math

import numpy as np

from .. import jsonout
from ..analysis.figures import figure9_data, write_figure9
from ..analysis.modes import FIGURE9_MODES, SET_NAMES, SETS, wind_sweep
from ..analysis.reference import format_table2, table2
from ..analysis.sensitivity import (
    DAMPING_SPEEDS,
    default_knobs,
    format_sensitivity,
    select_knobs,
    sensitivity_table,
)
from ..analysis.trim import TrimError, TrimLimitError, find_equilibrium, limit_warnings
from ..extras import require_plotting
from ..params import MAX_WIND_SPEED
from .common import (
    add_config,
    output_dir,
    params_from_args,
    positive_float,
    positive_int,
    warn,
)

#: the most wind speeds one sweep takes: 0.05 m/s steps over the model's whole 0-100 m/s
MAX_SPEEDS = 2001


def parse_speeds(text: str) -> np.ndarray:
    """"a:b:step" (inclusive), "a:b" (step 0.5) or a single speed, in m/s."""
    try:
        parts = [float(v) for v in text.split(":")]
    except ValueError as exc:
        raise ValueError(f"--wind expects START:STOP[:STEP] or a speed, got {text!r}") from exc
    if len(parts) > 3:
        raise ValueError(f"--wind expects START:STOP[:STEP], got {text!r}")
    if not all(math.isfinite(v) for v in parts) or min(parts[:2]) < 0:
        raise ValueError(f"--wind: wind speeds must be finite and >= 0, got {text!r}")
    if max(parts[:2]) > MAX_WIND_SPEED:
        raise ValueError(f"--wind: wind speeds must be <= {MAX_WIND_SPEED:g} m/s (the model's "
                         f"incompressible aerodynamics end near Mach 0.3), got {text!r}")
    if len(parts) == 1:
        return np.array(parts)
    a, b = parts[:2]
    step = parts[2] if len(parts) == 3 else 0.5
    if step <= 0 or b < a:
        raise ValueError(f"--wind needs START <= STOP and STEP > 0, got {text!r}")
    if (b - a) / step + 1 > MAX_SPEEDS:
        raise ValueError(f"--wind {text!r} asks for {(b - a) / step + 1:.3g} speeds; a sweep takes "
                         f"at most {MAX_SPEEDS} (a longer STEP)")
    return np.arange(a, b + 1e-9 * max(1.0, b), step)


def stability_params(args):
    return params_from_args(args, **{"tether.length": getattr(args, "length", None),
                                     "tether.n_elements": getattr(args, "elements", None)})


def _fmt(m) -> str:
    """A table cell: period (damping ratio); a neutral root's ratio (+-1 by the sign of its
    rounding) says nothing, so it reads "neutral"."""
    if m is None:
        return f"{'-':>15s}"
    if m.neutral:
        return f"{'neutral':>15s}"
    per = f"{m.period:7.2f}" if m.oscillatory else "   real"
    return f"{per} ({m.zeta:5.3f})"


def _stability_text(sweep, dec_ratios: list[dict]) -> str:
    lines = []
    for subset, name in zip(SETS, ("Longitudinal", "Lateral"), strict=True):
        labels = FIGURE9_MODES[subset]
        lines.append(f"{name} modes: period [s] (damping ratio)")
        lines.append(f"{'U m/s':>6s} " + " ".join(f"{lab[:15]:>15s}" for lab in labels))
        tracks = dict(sweep.tracks[subset])
        for k, u in enumerate(sweep.values):
            cells = [_fmt(tracks[lab][k]) if lab in tracks else _fmt(None) for lab in labels]
            lines.append(f"{u:6.2f} " + " ".join(cells))
        lines.append("")
    worst_ul = max(r["ul_max"] for r in dec_ratios)
    worst_ll = max(r["ll_max"] for r in dec_ratios)
    a0 = sweep.analyses[0]
    n_states = a0.linear.A.shape[0]
    lines.append(f"states {n_states} = long {a0.decoupled.A_long.shape[0]} + lat "
                 f"{a0.decoupled.A_lat.shape[0]}; coupling blocks / max|A|: upper right <= "
                 f"{worst_ul:.1e}, lower left <= {worst_ll:.1e}")
    lines.append(f"all modes stable at every speed: {sweep.all_stable()}   "
                 f"({len(sweep.values)} speeds, trims included, in {sweep.seconds:.2f} s)")
    lines += [_unstable_line(u) for u in sweep.unstable()]
    return "\n".join(lines)


#: Up to this many speeds an unstable mode's speeds are listed one by one, beyond it as a range.
LISTED_SPEEDS = 6


def _speeds_text(speeds: list[float]) -> str:
    if len(speeds) <= LISTED_SPEEDS:
        return ", ".join(f"{u:g}" for u in speeds) + " m/s"
    return f"{speeds[0]:g}-{speeds[-1]:g} m/s ({len(speeds)} speeds)"


def eigenvalue_text(lam: complex) -> str:
    """lambda [1/s] of a mode: one real number, or the pair Re +/- Im j."""
    return f"{lam.real:+.4g}" if lam.imag == 0 else f"{lam.real:+.4g} +/- {lam.imag:.4g}j"


def _unstable_line(entry: dict) -> str:
    """An unstable mode of :meth:`Sweep.unstable` named under the table, whether or not the
    table has its column (a divergent real eigenvalue beside the lateral pendulum has none):
    where it is unstable and its eigenvalue where it grows fastest."""
    worst = entry["worst"]
    subset = SET_NAMES[entry["set"]]
    return (f"  UNSTABLE {subset} {entry['label']} at U = {_speeds_text(entry['values'])}; "
            f"fastest at {entry['worst_value']:g} m/s: lambda = "
            f"{eigenvalue_text(worst.eigenvalue)} 1/s, {worst.describe().strip()}")


def _unstable_json(sweep) -> list[dict]:
    """:meth:`Sweep.unstable` as JSON: the fastest-growing point's modal row under the track's
    label (e.g. "pendulum (2)", the one the full modal table uses)."""
    return [{**u["worst"].row(), "set": u["set"], "label": u["label"],
             "wind_speeds_m_s": u["values"], "worst_wind_speed_m_s": u["worst_value"]}
            for u in sweep.unstable()]


def _trim_outcome(params, speed: float) -> tuple[Exception | None, list[str]]:
    """(why ``speed`` has no usable trim or None, the winch's limit warnings there): no
    equilibrium (:class:`TrimError`) or one whose tension breaks the tether
    (:class:`TrimLimitError`)."""
    try:
        return None, limit_warnings(params, find_equilibrium(params, speed).summary)
    except (TrimError, TrimLimitError) as exc:
        return exc, []


def _stop_reason(exc: Exception, speed: float) -> str:
    """Why the sweep ends before ``speed``: a broken tether names its speed and tension; a
    failed trim is told where it failed."""
    return str(exc) if isinstance(exc, TrimLimitError) else f"no trim at {speed:g} m/s: {exc}"


def trimmed_speeds(params, speeds: np.ndarray) -> tuple[np.ndarray, dict | None]:
    """(the sweep's speeds that trim within the tether's strength, why the sweep stops short or
    None), with a warning for what the winch and tether cannot do at the top one and one for
    the speeds left out. The tension grows with the wind and a trim is continued up from still
    air, so past the first speed that breaks the tether or has no trim none is usable: that
    speed is found by bisection. None usable re-raises the lowest speed's error."""
    speeds = np.sort(np.asarray(speeds, float))
    top = len(speeds) - 1
    failure, messages = _trim_outcome(params, float(speeds[top]))
    stop = None
    if failure is not None:
        held, past = -1, top  # speeds[past] has no usable trim
        while past - held > 1:
            mid = (held + past) // 2
            exc_mid, _ = _trim_outcome(params, float(speeds[mid]))
            if exc_mid is None:
                held = mid
            else:
                failure, past = exc_mid, mid
        if held < 0:
            raise failure
        top = held
        messages = _trim_outcome(params, float(speeds[top]))[1]
        stop = {"last_wind_speed_m_s": float(speeds[top]),
                "failed_wind_speed_m_s": float(speeds[past]),
                "reason": _stop_reason(failure, float(speeds[past]))}
    for message in messages:
        warn("stability", message)
    if stop is not None:
        warn("stability", _stop_text(stop))
    return speeds[: top + 1], stop


def _stop_text(stop: dict) -> str:
    return f"the sweep stops at {stop['last_wind_speed_m_s']:g} m/s: {stop['reason']}"


def _sweep_stop(sweep, speeds: np.ndarray, stop: dict | None) -> dict | None:
    """The stop of :func:`trimmed_speeds`, or (with a warning) the one of a sweep whose trims,
    continued from speed to speed, end below the speeds that trim from still air."""
    if len(sweep.values) == len(speeds):
        return stop
    failed = float(speeds[len(sweep.values)])
    stop = {"last_wind_speed_m_s": float(sweep.values[-1]), "failed_wind_speed_m_s": failed,
            "reason": _stop_reason(sweep.stop_error, failed)}
    warn("stability", _stop_text(stop))
    return stop


def cmd_stability(args) -> int:
    params = stability_params(args)
    if args.plot:  # before the sweep: a long run never ends on a path it cannot write
        require_plotting("--plot")
        output_dir(args.plot, "--plot")
    speeds, stop = trimmed_speeds(params, parse_speeds(args.wind))
    sweep = wind_sweep(params, speeds, stop_without_trim=True)
    stop = _sweep_stop(sweep, speeds, stop)
    ratios = [a.decoupled.ratios for a in sweep.analyses]
    if args.plot:
        write_figure9(args.plot, params, sweep=sweep)
    if args.json:
        out = {"tether_length_m": params.tether.length, "n_elements": params.tether.n_elements,
               "all_stable": sweep.all_stable(), "seconds": sweep.seconds, "stop": stop,
               "unstable_modes": _unstable_json(sweep),
               "coupling_ratios": ratios, "figure9": figure9_data(sweep),
               "modes": sweep.rows()}
        print(jsonout.dumps(out, indent=1))
    else:
        print(f"Linear stability, L = {params.tether.length:g} m, n = {params.tether.n_elements}, "
              f"trim pitch {params.aerostat.trim_pitch_deg:g} deg")
        print(_stability_text(sweep, ratios))
        if stop is not None:
            print(_stop_text(stop))
    return 0


def cmd_table2(args) -> int:
    rows = table2(stability_params(args))
    print(jsonout.dumps(rows, indent=1) if args.json else format_table2(rows))
    return 0


def cmd_sensitivity(args) -> int:
    params = stability_params(args)
    speeds = parse_speeds(args.wind) if args.wind else DAMPING_SPEEDS
    if np.any(np.asarray(speeds) <= 0):
        raise ValueError("sensitivity --wind speeds must be > 0 (at 0 m/s every mode is undamped)")
    knobs = select_knobs(default_knobs(params), args.knob)
    table = sensitivity_table(params, knobs, tuple(float(u) for u in speeds))
    print(jsonout.dumps(table, indent=1) if args.json else format_sensitivity(table))
    return 0


def add_stability_parsers(subparsers) -> None:
    """Register ``stability``, ``table2`` and ``sensitivity`` on an argparse subparsers object."""
    p = subparsers.add_parser("stability", help="linear stability against wind speed ([LN02] Fig. 9)")
    p.add_argument("--wind", default="0:20:0.5", help="START:STOP[:STEP] m/s (default 0:20:0.5)")
    p.add_argument("--length", type=positive_float, default=None,
                   help="tether length [m] (default: config)")
    p.add_argument("--elements", type=positive_int, default=None,
                   help="tether elements n (default: config)")
    p.add_argument("--plot", metavar="DIR", help="write figure9.png/.csv/.json into DIR")
    add_config(p)
    p.set_defaults(func=cmd_stability)
    p = subparsers.add_parser("table2", help="[LN02] Table 2: reference vs linear-model periods")
    add_config(p)
    p.set_defaults(func=cmd_table2)
    p = subparsers.add_parser("sensitivity", help="Table 2 periods and damping vs uncertain parameters "
                              "(ranges relative to the configured values)")
    p.add_argument("--wind", default=None, help="START:STOP[:STEP] speeds of the damping search "
                   "[m/s] (default 1, 2, 4, ..., 20)")
    p.add_argument("--knob", action="append", default=[],
                   help="only this knob, e.g. fins.planform_area (repeatable; default all)")
    add_config(p)
    p.set_defaults(func=cmd_sensitivity)
