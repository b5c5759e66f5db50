"""Model commands: ``trim`` (equilibrium summary), ``params`` (every parameter with its unit and
status) and ``bench`` (speed and accuracy figures)."""

from __future__ import annotations

from .. import jsonout
from ..analysis.trim import find_equilibrium, limit_warnings
from ..bench import format_text, run_bench
from ..bench.moordyn_dynamic import format_report, run_dynamic_comparison
from ..params import parameter_table
from .common import add_config, nonneg_float, params_from_args, warn


def cmd_trim(args) -> int:
    params = params_from_args(args)
    eq = find_equilibrium(params, args.wind)
    for message in limit_warnings(params, eq.summary):  # TrimLimitError past the tether strength
        warn("trim", message)
    s = dict(eq.summary, relative_residual=eq.residual)
    if args.json:
        print(jsonout.dumps(s, indent=2))
        return 0
    print(f"Trim at U = {args.wind:g} m/s (relative residual {eq.residual:.1e})")
    x, y, z = s["aerostat_position_m"]
    print(f"  aerostat CM position      x = {x:8.2f} m, y = {y:6.2f} m, z = {z:8.2f} m")
    print(f"  blow-by angle             {s['blow_by_deg']:8.3f} deg")
    print(f"  pitch (negative nose up)  {s['pitch_deg']:8.3f} deg")
    print(f"  tether tension, top       {s['top_tension_N']:8.1f} N")
    print(f"  tether tension, bottom    {s['winch_tension_N']:8.1f} N")
    print(f"  elevation at the winch    {s['elevation_at_winch_deg']:8.3f} deg")
    return 0


def cmd_params(args) -> int:
    rows = parameter_table(params_from_args(args))
    if args.json:
        print(jsonout.dumps(rows, indent=2, default=str))
        return 0
    for r in rows:
        print(f"{r['name']:34s} {str(r['value']):>28s} {r['unit']:8s} {r['status']:8s} {r['description']}")
    return 0


def cmd_bench(args) -> int:
    if args.moordyn_dynamic:  # the tether in motion against MoorDyn (bench extra)
        res = run_dynamic_comparison(quick=args.quick)
        print(jsonout.dumps(res, indent=2, default=float) if args.json else format_report(res))
        return 0
    res = run_bench(quick=args.quick)
    print(jsonout.dumps(res, indent=2) if args.json else format_text(res))
    return 0


def add_model_parsers(sub) -> None:
    """Register ``trim``, ``params`` and ``bench``."""
    p = sub.add_parser("trim", help="steady equilibrium in a steady wind")
    p.add_argument("--wind", type=nonneg_float, default=10.0,
                   help="mean wind speed [m/s] (default 10)")
    add_config(p)
    p.set_defaults(func=cmd_trim)
    p = sub.add_parser("params", help="every parameter with unit and status")
    add_config(p)
    p.set_defaults(func=cmd_params)
    p = sub.add_parser("bench", help="speed and accuracy figures")
    p.add_argument("--json", action="store_true", help="print the figures as JSON")
    p.add_argument("--quick", action="store_true", help="shorter runs (smoke test)")
    p.add_argument("--moordyn-dynamic", action="store_true",
                   help="only the dynamic comparison with MoorDyn (driven top end)")
    p.set_defaults(func=cmd_bench)
