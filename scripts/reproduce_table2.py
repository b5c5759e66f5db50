"""Reproduce [LN02] Table 2 (theory at U = 0 vs the linear model at U = 1 m/s; for any
aerostat, its linear model in still air vs its still-air closed form) and the sensitivity of
its periods to the estimated parameters.

Usage: python scripts/reproduce_table2.py --out DIR [--config FILE] [--no-sensitivity]
Writes DIR/table2.json, table2.csv, table2.txt and (unless --no-sensitivity)
sensitivity.json, sensitivity.txt, lateral_pendulum_fixes.json.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from aerostat_gym.analysis.figures import write_table
from aerostat_gym.analysis.reference import format_table2, table2
from aerostat_gym.analysis.sensitivity import (
    format_sensitivity,
    lateral_pendulum_fixes,
    sensitivity_table,
)
from aerostat_gym.cli.common import add_config, params_from_args, run_script, script_description


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--out", required=True, help="output folder")
    add_config(ap, json=False)
    ap.add_argument("--no-sensitivity", action="store_true", help="Table 2 only")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    params = params_from_args(args)
    rows = table2(params)
    (out / "table2.json").write_text(json.dumps(rows, indent=1))
    write_table(rows, out / "table2.csv")
    text = format_table2(rows)
    (out / "table2.txt").write_text(text + "\n")
    print(text)
    if not args.no_sensitivity:
        sens = sensitivity_table(params)
        (out / "sensitivity.json").write_text(json.dumps(sens, indent=1, default=str))
        text = format_sensitivity(sens)
        (out / "sensitivity.txt").write_text(text + "\n")
        print(text)
        fixes = lateral_pendulum_fixes(params)
        (out / "lateral_pendulum_fixes.json").write_text(json.dumps(fixes, indent=1, default=str))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_script(main))
