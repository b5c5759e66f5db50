"""The spread of a training configuration over its training seeds on the report suite.

Reads the ``report.json`` of ``aerostat-gym evaluate --suite report`` runs (one or several, on
the same suite) that evaluated the baselines and one model per training seed, and writes
per-seed and pooled aggregate tables to ``seeds.md`` and ``seeds.json``
(:mod:`aerostat_gym.agents.seed_spread`). Usage::

    aerostat-gym evaluate --suite report --out agents/baseline_report --policy passive ... \\
        --policy shipped
    aerostat-gym evaluate --suite report --out runs/seeds/eval --no-plots \\
        --policy runs/seeds/s1/ppo_final.zip ... --policy runs/seeds/s4/ppo_final.zip
    PYTHONPATH=. python scripts/seed_spread.py agents/baseline_report/report.json \\
        runs/seeds/eval/report.json --seeds ppo_tethered_aerostat s1/ppo_final ... s4/ppo_final \\
        --label "shipped configuration" [--names "seed 0" ... "seed 4"] --out agents/ppo_training
"""

from __future__ import annotations

import argparse
from pathlib import Path

from aerostat_gym.agents.policies import BASELINES
from aerostat_gym.agents.protocol import dumps
from aerostat_gym.agents.report import load_results
from aerostat_gym.agents.seed_spread import seed_spread, seed_spread_markdown
from aerostat_gym.cli.common import run_script, script_description


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("report_json", nargs="+",
                    help="report.json of evaluate runs on the report suite")
    ap.add_argument("--seeds", nargs="+", required=True,
                    help="labels (as in report.json) of the models, one per training seed")
    ap.add_argument("--names", nargs="+", default=None,
                    help="names to show for the models in the tables, one per --seeds label")
    ap.add_argument("--label", default="learned", help="name of the pooled configuration")
    ap.add_argument("--out", default="runs/seed_spread", help="directory for seeds.md/json")
    args = ap.parse_args(argv)
    try:
        results = load_results(args.report_json, args.seeds)
    except ValueError as err:
        raise SystemExit(str(err)) from None
    names = args.names or args.seeds
    if len(names) != len(args.seeds):
        raise SystemExit(f"--names gives {len(names)} names for {len(args.seeds)} --seeds")
    baselines = [results[b] for b in BASELINES if b in results]
    spread = seed_spread(baselines, [{**results[s], "label": n}
                                     for s, n in zip(args.seeds, names, strict=True)],
                         args.label)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    md = seed_spread_markdown(spread)
    (out / "seeds.md").write_text(f"# {args.label}: spread over training seeds\n\n{md}")
    (out / "seeds.json").write_text(dumps(spread))
    print(md)


if __name__ == "__main__":
    raise SystemExit(run_script(main))
