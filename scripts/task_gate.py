"""Returns on the incumbent's training task for the selection's task-return gate.

Runs each policy (a baseline name, "shipped" or a saved model) on the gate's seeds of a
registered task (:data:`aerostat_gym.agents.selection.GATE_SEEDS`, disjoint from every other
seed set) and writes the returns to a JSON file that ``scripts/select_policy.py --gate`` reads;
prints each challenger's paired difference from the incumbent where the incumbent ran in the
same run. Usage::

    PYTHONPATH=. python scripts/task_gate.py --incumbent s0/ppo_final \\
        --policy runs/seeds/s0/ppo_final.zip --label s0/ppo_final ... --out runs/gate/a.json
    PYTHONPATH=. python scripts/task_gate.py --incumbent s0/ppo_final --policy ... \\
        --out runs/gate/b.json
    (several runs side by side; the incumbent in one of them)

Labels default to those of ``aerostat-gym evaluate`` (so they match the validation reports);
``--label`` gives one per ``--policy``. ``--baselines`` adds baselines for the record (they
are not candidates).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from aerostat_gym.agents.report import given_labels, policy_labels
from aerostat_gym.agents.returns import task_returns
from aerostat_gym.agents.selection import GATE_SEEDS, task_gate
from aerostat_gym.cli.common import first_seeds, run_script, script_description
from aerostat_gym.registration import TASKS
from aerostat_gym.resources import shipped_path


def shipped_task() -> str:
    """The task the shipped policy was trained on (its training summary's)."""
    return json.loads(shipped_path("ppo_training", "training_summary.json").read_text())["task"]


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--policy", action="append", default=[],
                    help="a candidate: a saved model's .zip, 'shipped' or a baseline name")
    ap.add_argument("--label", action="append", default=None,
                    help="the candidate's label, one per --policy (default: evaluate's)")
    ap.add_argument("--incumbent", required=True,
                    help="label of the shipped policy the challengers are compared with")
    ap.add_argument("--baselines", nargs="*", default=[],
                    help="baselines to run too, for the record")
    ap.add_argument("--task", default=None, choices=sorted(TASKS),
                    help="the incumbent's training task (default: the shipped policy's)")
    ap.add_argument("--seeds", type=int, default=len(GATE_SEEDS),
                    help="the first N gate seeds (a smoke run)")
    ap.add_argument("--out", required=True, help="JSON file of the returns")
    args = ap.parse_args(argv)
    try:
        labels = (policy_labels(args.policy) if args.label is None
                  else given_labels(args.label, args.policy))
    except ValueError as err:
        raise SystemExit(str(err)) from None
    seeds = first_seeds(args.seeds, GATE_SEEDS)
    names = [*args.baselines, *labels]
    if len(set(names)) != len(names):
        raise SystemExit(f"a label is given twice: {names}")
    task = args.task or shipped_task()
    runs = [*((b, b) for b in args.baselines), *zip(labels, args.policy, strict=True)]
    returns = {label: task_returns(policy, task, seeds).tolist() for label, policy in runs}
    record = {"task": task, "seeds": list(seeds), "incumbent": args.incumbent,
              "returns": returns}
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(record, indent=1))
    if args.incumbent in returns:
        for label, v in task_gate(returns, args.incumbent).items():
            minus = v["minus_incumbent"]
            verdict = ("the incumbent" if minus is None else
                       f"minus the incumbent {minus[0]:+.1f} [{minus[1]:+.1f}, {minus[2]:+.1f}]"
                       + ("" if v["passed"] else ", worse"))
            print(f"{label}: mean return {v['mean']:.1f}, {verdict}")
    return record


if __name__ == "__main__":
    raise SystemExit(run_script(main))
