"""Command-line interface: ``aerostat-gym <command> [options]``.

Commands: ``trim`` (equilibrium summary), ``params`` (every parameter with its unit and status),
``bench`` (speed and accuracy figures), ``wind`` (turbulence statistics), ``stability``,
``table2`` and ``sensitivity`` (linear stability analysis), ``train``, ``evaluate`` and ``demo``
(winch-control agents), ``tune`` and ``montecarlo`` (Ray, the optional extra). Errors in user
input print one clear line and exit with status 2.
"""

from __future__ import annotations

import argparse
import json
import sys

from .params import ParameterError, load_params


def _add_config(p: argparse.ArgumentParser) -> None:
    p.add_argument("--config", help="parameter TOML file (default: the shipped baseline)")
    p.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override one parameter, e.g. --set tether.length=150 (repeatable)")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")


def _overrides(items: list[str]) -> dict:
    import tomllib

    out = {}
    for item in items:
        if "=" not in item:
            raise ParameterError(f"--set expects SECTION.KEY=VALUE, got {item!r}")
        key, raw = item.split("=", 1)
        try:
            out[key.strip()] = tomllib.loads(f"v = {raw}")["v"]
        except tomllib.TOMLDecodeError:
            out[key.strip()] = raw  # a bare string
    return out


def _params(args):
    return load_params(args.config, _overrides(args.set) or None)


def cmd_trim(args) -> int:
    from .analysis.trim import find_equilibrium

    eq = find_equilibrium(_params(args), args.wind)
    s = dict(eq.summary, relative_residual=eq.residual)
    if args.json:
        print(json.dumps(s, indent=2))
        return 0
    print(f"Trim at U = {args.wind:g} m/s (relative residual {eq.residual:.1e})")
    x, y, z = s["aerostat_position_m"]
    print(f"  aerostat CM position      x = {x:8.2f} m, y = {y:6.2f} m, z = {z:8.2f} m")
    print(f"  blow-by angle             {s['blow_by_deg']:8.3f} deg")
    print(f"  pitch (negative nose up)  {s['pitch_deg']:8.3f} deg")
    print(f"  tether tension, top       {s['top_tension_N']:8.1f} N")
    print(f"  tether tension, bottom    {s['bottom_tension_N']:8.1f} N")
    print(f"  elevation at the winch    {s['elevation_at_winch_deg']:8.3f} deg")
    return 0


def cmd_params(args) -> int:
    from .params import parameter_table

    rows = parameter_table(_params(args))
    if args.json:
        print(json.dumps(rows, indent=2, default=str))
        return 0
    for r in rows:
        print(f"{r['name']:34s} {str(r['value']):>28s} {r['unit']:8s} {r['status']:8s} {r['description']}")
    return 0


def cmd_bench(args) -> int:
    from .bench import format_text, run_bench

    res = run_bench(quick=args.quick)
    print(json.dumps(res, indent=2) if args.json else format_text(res))
    return 0


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="aerostat-gym", description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("trim", help="steady equilibrium in a steady wind")
    p.add_argument("--wind", type=float, default=10.0, help="mean wind speed [m/s] (default 10)")
    _add_config(p)
    p.set_defaults(func=cmd_trim)
    p = sub.add_parser("params", help="every parameter with unit and status")
    _add_config(p)
    p.set_defaults(func=cmd_params)
    p = sub.add_parser("bench", help="speed and accuracy figures")
    p.add_argument("--json", action="store_true")
    p.add_argument("--quick", action="store_true", help="shorter runs (smoke test)")
    p.set_defaults(func=cmd_bench)
    from .analysis.stability_cli import add_stability_parsers
    from .wind.cli import add_wind_parser

    add_wind_parser(sub)
    add_stability_parsers(sub)
    from .agents.cli import add_agent_parsers

    add_agent_parsers(sub)
    from .scale.cli import add_montecarlo_parser, add_tune_parser

    add_tune_parser(sub)
    add_montecarlo_parser(sub)
    return ap


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except (ParameterError, ValueError, RuntimeError) as exc:
        print(f"aerostat-gym {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
