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
    PYTHONPATH=. python scripts/task_gate.py --incumbent s0/ppo_final \\
        --policy runs/seeds/s0/ppo_final.zip ... --label s0/ppo_final ... --out runs/gate/cand.json
    PYTHONPATH=. python scripts/select_policy.py runs/val/base/report.json \\
        runs/val/cand/report.json --candidates s0/ppo_final ... s4/ppo_final \\
        [--names "seed 0" ... "seed 4"] --gate runs/gate/cand.json --out agents/ppo_training

``--gate`` reads the returns of ``scripts/task_gate.py`` runs (one or several, the incumbent,
the shipped policy, among the candidates and in one of them) and puts the task-return gate
before the targets; without it the ranking is the rule before 0.7.20.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from aerostat_gym.agents.policies import BASELINES
from aerostat_gym.agents.protocol import dumps
from aerostat_gym.agents.report import load_results
from aerostat_gym.agents.selection import GATE_SEEDS, select, selection_markdown, task_gate
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
    ap.add_argument("--gate", nargs="+", default=None,
                    help="returns JSON of scripts/task_gate.py runs: the task-return gate")
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
    gate = None
    if args.gate:
        try:
            verdicts = task_gate(*read_gate(args.gate))
            gate = {n: verdicts[c] for c, n in zip(args.candidates, names, strict=True)}
        except KeyError as err:
            raise SystemExit(f"the gate's returns have no candidate {err}") from None
        except ValueError as err:
            raise SystemExit(str(err)) from None
    sel = select([{**results[c], "label": n} for c, n in zip(args.candidates, names,
                                                              strict=True)], baselines,
                 gate=gate)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    md = selection_markdown(sel)
    (out / "selection.md").write_text(
        "# Choosing the shipped policy on the validation suite\n\n"
        "`PYTHONPATH=. python scripts/select_policy.py` (its docstring has the evaluate "
        "commands) on the `validation` suite: the report's scenarios at recover 7.5 / 12.5 m/s "
        "and gusty 6 / 10 / 14 m/s, seeds 7000-7009, sensor noise 0.01. The rule "
        "(`aerostat_gym.agents.selection`): most issue-18 targets met on these cells, ties to "
        "the higher IQM" + (GATE_TEXT if gate else "") + f".\n\nChosen: **{sel['chosen']}**."
        f"\n\n{md}")
    (out / "selection.json").write_text(dumps(sel))
    print(f"chosen: {sel['chosen']}\n\n{md}")


GATE_TEXT = (
    "; before them the task-return gate: a challenger whose return on the shipped policy's "
    "training task is worse than the shipped policy's (paired 95 % interval over the gate's "
    f"seeds {GATE_SEEDS[0]}-{GATE_SEEDS[-1]}, `scripts/task_gate.py`) ranks after every "
    "candidate that passes")


def read_gate(paths) -> tuple[dict, str]:
    """(label -> returns, the incumbent's label), merged from ``scripts/task_gate.py`` files
    of one task, seed set and incumbent."""
    returns, keys = {}, set()
    for path in paths:
        record = json.loads(Path(path).read_text())
        missing = sorted({"task", "seeds", "incumbent", "returns"} - set(record))
        if missing:
            raise ValueError(f"{path} is not a scripts/task_gate.py record: no {missing}")
        keys.add((record["task"], tuple(record["seeds"]), record["incumbent"]))
        if len(keys) > 1:
            raise ValueError(f"the gate files {list(map(str, paths))} ran different tasks, "
                             "seeds or incumbents")
        twice = sorted(set(returns) & set(record["returns"]))
        if twice:
            raise ValueError(f"the gate files give {twice} twice")
        returns.update(record["returns"])
    return returns, record["incumbent"]


if __name__ == "__main__":
    raise SystemExit(run_script(main))
