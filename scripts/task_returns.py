"""Print the seeded baseline returns of every registered task (the README's table for RL
researchers): mean episode return with its 95 % bootstrap CI over 20 held-out seeds, and the
paired difference from the braked winch.

Usage: python scripts/task_returns.py [--policy passive --policy lqr --policy shipped]
       [--task TASK_ID ...] [--json]
"""

from __future__ import annotations

import argparse
import json

from aerostat_gym.agents.returns import format_returns, returns_table
from aerostat_gym.cli.common import run_script, script_description
from aerostat_gym.registration import TASKS


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=script_description(__doc__),
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--policy", action="append", help="policies (default: passive, lqr, shipped)")
    ap.add_argument("--task", action="append", choices=sorted(TASKS),
                    help="registered tasks (default: every one)")
    ap.add_argument("--json", action="store_true", help="print JSON rows instead of Markdown")
    args = ap.parse_args(argv)
    rows = returns_table(args.policy or ["passive", "lqr", "shipped"],
                         tasks=tuple(args.task or TASKS))
    print(json.dumps(rows, indent=1) if args.json else format_returns(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_script(main))
