"""The spread of a training configuration over its training seeds on the report suite.

Reads the ``report.json`` of one ``aerostat-gym evaluate --suite report`` run that evaluated
the baselines and one model per training seed, and writes per-seed and pooled aggregate tables
(:mod:`aerostat_gym.agents.seed_spread`). Usage::

    aerostat-gym evaluate --suite report --out runs/seeds --policy passive ... \\
        --policy runs/train/s0/ppo_final.zip ... --policy runs/train/s4/ppo_final.zip
    PYTHONPATH=. python scripts/seed_spread.py runs/seeds/report.json --label residual-PPO \\
        --seeds s0/ppo_final s1/ppo_final ... --out agents/ppo_training/seeds
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from aerostat_gym.agents.policies import BASELINES
from aerostat_gym.agents.protocol import dumps
from aerostat_gym.agents.seed_spread import seed_spread, seed_spread_markdown


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("report_json", nargs="+",
                    help="report.json of evaluate runs on the report suite")
    ap.add_argument("--seeds", nargs="+", required=True,
                    help="labels (as in report.json) of the models, one per training seed")
    ap.add_argument("--label", default="learned", help="name of the pooled configuration")
    ap.add_argument("--out", default="runs/seed_spread", help="directory for seeds.md/json")
    args = ap.parse_args(argv)
    results = {}
    for path in args.report_json:
        for r in json.loads(Path(path).read_text()):
            if r["label"] in results:
                raise SystemExit(f"label {r['label']!r} appears twice in {args.report_json}")
            results[r["label"]] = r
    missing = [s for s in args.seeds if s not in results]
    if missing:
        raise SystemExit(f"not in {args.report_json}: {missing}; labels there: {list(results)}")
    baselines = [results[b] for b in BASELINES if b in results]
    spread = seed_spread(baselines, [results[s] for s in args.seeds], args.label)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    md = seed_spread_markdown(spread)
    (out / "seeds.md").write_text(f"# {args.label}: spread over training seeds\n\n{md}")
    (out / "seeds.json").write_text(dumps(spread))
    print(md)


if __name__ == "__main__":
    main()
