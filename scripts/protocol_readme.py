"""Condensed Markdown tables of a report-suite evaluation (the README's view of
``protocol.json``): pendulum and pitch damping, RMS displacement and peak tension per cell with
intervals and paired verdicts against passive, and the aggregate.

Usage::

    PYTHONPATH=. python scripts/protocol_readme.py agents/baseline_report/protocol.json
"""

from __future__ import annotations

import argparse
import json

from aerostat_gym.agents.protocol_summary import condensed
from aerostat_gym.cli.common import run_script, script_description


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("protocol_json", help="protocol.json written by aerostat-gym evaluate")
    args = ap.parse_args(argv)
    with open(args.protocol_json) as fh:
        data = json.load(fh)
    if not (isinstance(data, dict) and "cells" in data):
        raise ValueError(f"{args.protocol_json}: not a protocol.json written by aerostat-gym "
                         "evaluate (no 'cells')")
    print(condensed(data))


if __name__ == "__main__":
    raise SystemExit(run_script(main))
