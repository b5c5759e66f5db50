"""Choose the policy to ship among trained candidates, on the validation suite.

Reads the ``report.json`` of ``aerostat-gym evaluate --suite validation`` runs (the baselines
and the candidates, in one or several runs) and writes the ranking of
:func:`aerostat_gym.agents.selection.select` to ``selection.md`` and ``selection.json``.
Usage::

    aerostat-gym evaluate --suite validation --out runs/val/base --no-plots \\
        --policy passive --policy tension --policy lqr --policy modal --policy lqg \\
        --policy modal_lqg --policy modal_lqg_shaped
    aerostat-gym evaluate --suite validation --out runs/val/cand --no-plots \\
        --policy runs/seeds/s0/ppo_final.zip ... --policy runs/seeds/s4/ppo_final.zip
    (a candidate evaluated in a run of its own: ``--label s4/ppo_final``, or its label is the
    bare stem ``ppo_final`` and a second such run clashes with it)
    PYTHONPATH=. python scripts/select_policy.py runs/val/base/report.json \\
        runs/val/cand/report.json --candidates s0/ppo_final ... s4/ppo_final \\
        [--names "seed 0" ... "seed 4"] --out agents/ppo_training
"""

from __future__ import annotations

import argparse
from pathlib import Path

from aerostat_gym.agents.policies import BASELINES
from aerostat_gym.agents.protocol import dumps
from aerostat_gym.agents.report import load_results
from aerostat_gym.agents.selection import select, selection_markdown
from aerostat_gym.cli.common import run_script, script_description


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("report_json", nargs="+", help="report.json of evaluate runs on the "
                    "validation suite")
    ap.add_argument("--candidates", nargs="+", required=True,
                    help="labels (as in report.json) of the trained candidates")
    ap.add_argument("--out", default="runs/selection", help="directory for selection.md/json")
    ap.add_argument("--names", nargs="+", default=None,
                    help="names to show for the candidates in the tables, one per --candidates")
    args = ap.parse_args(argv)
    names = args.names or args.candidates
    if len(names) != len(args.candidates):
        raise SystemExit(f"--names gives {len(names)} names for {len(args.candidates)} "
                         "--candidates")
    try:
        results = load_results(args.report_json, args.candidates)
    except ValueError as err:
        raise SystemExit(str(err)) from None
    baselines = [results[b] for b in BASELINES if b in results]
    sel = select([{**results[c], "label": n} for c, n in zip(args.candidates, names,
                                                              strict=True)], baselines)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    md = selection_markdown(sel)
    (out / "selection.md").write_text(
        "# Choosing the shipped policy on the validation suite\n\n"
        "`PYTHONPATH=. python scripts/select_policy.py` (its docstring has the evaluate "
        "commands) on the `validation` suite: the report's scenarios at recover 7.5 / 12.5 m/s "
        "and gusty 6 / 10 / 14 m/s, seeds 7000-7009, sensor noise 0.01. The rule "
        "(`aerostat_gym.agents.selection`): most issue-18 targets met on these cells, ties to "
        f"the higher IQM.\n\nChosen: **{sel['chosen']}**.\n\n{md}")
    (out / "selection.json").write_text(dumps(sel))
    print(f"chosen: {sel['chosen']}\n\n{md}")


if __name__ == "__main__":
    raise SystemExit(run_script(main))
