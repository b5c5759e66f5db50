"""Dynamic comparison of the tether with MoorDyn v2 (issue 20): a thin shim over
:func:`aerostat_gym.bench.moordyn_dynamic.run_dynamic_comparison`.

Usage::

    PYTHONPATH=. python scripts/moordyn_dynamic.py            # the full table, ~2 min
    PYTHONPATH=. python scripts/moordyn_dynamic.py --quick    # one short case
    PYTHONPATH=. python scripts/moordyn_dynamic.py --cases vertical-harmonic-1m \\
        --variants baseline,moordyn_drag_and_slack_rule --no-explain
"""

from __future__ import annotations

import argparse
import json

from aerostat_gym.bench.moordyn_dynamic import format_report, run_dynamic_comparison
from aerostat_gym.cli.common import run_script, script_description


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--quick", action="store_true", help="one short case (smoke run)")
    ap.add_argument("--cases", help="comma-separated case names (default: the whole table)")
    ap.add_argument("--variants", default="baseline",
                    help="comma-separated variants to run every case under (default baseline)")
    ap.add_argument("--repeats", type=int, default=3, help="timed repeats per code and case")
    ap.add_argument("--no-explain", action="store_true",
                    help="skip the switched runs of the cases outside the bounds")
    ap.add_argument("--json", metavar="PATH", help="also write the full results as JSON")
    args = ap.parse_args(argv)
    res = run_dynamic_comparison(quick=args.quick,
                                 cases=args.cases.split(",") if args.cases else None,
                                 variants=tuple(args.variants.split(",")), repeats=args.repeats,
                                 explain=not args.no_explain)
    print(format_report(res))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(res, f, indent=2, default=float)
    return 0


if __name__ == "__main__":
    raise SystemExit(run_script(main))
