"""What the aggregate score reaches with the privileged full state: every design of the
authority sweep (:data:`aerostat_gym.agents.authority.DESIGNS`) on every cell of the report
suite, pooled with the baselines' report results (:func:`aerostat_gym.agents.protocol.aggregate`).

It answers whether issue 18's aggregate bar (IQM above every baseline's, probability of
improvement above 0.75 over each) is within reach of any winch feedback in the family, before
asking it of a learned policy that reads noisy sensors. Usage::

    aerostat-gym evaluate --suite report --out runs/rep --no-plots --policy passive \\
        --policy tension --policy lqr --policy modal --policy lqg --policy modal_lqg
    PYTHONPATH=. python scripts/authority_aggregate.py runs/rep/report.json \\
        --markdown docs/figures/authority_aggregate.md \\
        --json docs/figures/authority_aggregate.json --episodes runs/authority_designs.json
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from aerostat_gym.agents.authority import DESIGNS, design_result
from aerostat_gym.agents.policies import BASELINES
from aerostat_gym.agents.protocol import aggregate, json_safe
from aerostat_gym.agents.report import load_results
from aerostat_gym.cli.common import run_script, script_description
from aerostat_gym.params import load_params


def table(agg: dict, designs: list[str], baselines: list[str]) -> str:
    """Markdown: one row per design, its IQM and its P(improvement) over each baseline, and the
    smallest of those P (the bar asks all of them above 0.75)."""
    lines = ["| design | IQM [95% CI] | " + " | ".join(f"P(> {b})" for b in baselines)
             + " | smallest P |", "|---|---|" + "---|" * (len(baselines) + 1)]
    for d in designs:
        row = agg[d]
        ps = [row["p_improvement"][b]["p"] for b in baselines if b != d]
        lines.append(f"| {d} | {row['iqm']:.3f} [{row['iqm_ci'][0]:.3f}, {row['iqm_ci'][1]:.3f}]"
                     " | " + " | ".join("-" if b == d else
                                        f"{row['p_improvement'][b]['p']:.2f}"
                                        for b in baselines) + f" | {min(ps):.2f} |")
    return "\n".join(lines)


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("report_json", nargs="+", help="report.json of the baselines' evaluate runs "
                    "on the report suite")
    ap.add_argument("--json", default=None, help="write the aggregate rows to this JSON file")
    ap.add_argument("--markdown", default=None, help="write the table to this Markdown file")
    ap.add_argument("--episodes", default=None, help="JSON file caching the designs' episodes: "
                    "read if present, written after each design")
    args = ap.parse_args(argv)
    try:
        found = load_results(args.report_json)
    except ValueError as err:
        raise SystemExit(str(err)) from None
    baselines = [found[b] for b in BASELINES if b in found]
    if not baselines or {r["suite"] for r in baselines} != {"report"}:
        raise SystemExit(f"need the baselines' report-suite results; found {list(found)}")
    t0 = time.perf_counter()
    params = load_params()
    names = [b["label"] for b in baselines]
    designs = []
    cache = Path(args.episodes) if args.episodes else None
    if cache is not None and cache.is_file():
        designs = json.loads(cache.read_text())
    cached = len(designs)
    # the default modal and LQR designs are the baselines of those names (the same episodes,
    # tests/test_authority.py), so only the other designs run
    for d in DESIGNS:
        if d.label in names or d.label in {r["label"] for r in designs}:
            continue
        print(f"  {d.label} ...", flush=True)
        designs.append(design_result(d, params))
        if cache is not None:
            cache.write_text(json.dumps(json_safe(designs)))
    agg = aggregate([*baselines, *designs])["aggregate"]
    wall = time.perf_counter() - t0
    md = table(agg, [b["label"] for b in baselines if b["label"] in ("modal", "lqr")]
               + [d["label"] for d in designs], names)
    print(md + f"\n\n{wall:.0f} s")
    if args.markdown:
        Path(args.markdown).write_text(
            "# The aggregate with the privileged full state\n\n`PYTHONPATH=. python "
            "scripts/authority_aggregate.py <baselines' report.json>`: every authority-sweep "
            "design on every report cell (20 seeds, the report's turbulence and noise; the "
            "designs read the noise-free state, a tension relief the noisy load cell), "
            f"{wall:.0f} s"
            + (f" ({cached} designs' episodes read from the --episodes cache)" if cached else "")
            + ". The default `modal` and `lqr` "
            "designs are the baselines of those names. P(> X): probability that the design "
            "beats baseline X on a random cell and seed.\n\n" + md + "\n")
    if args.json:
        Path(args.json).write_text(json.dumps(json_safe(
            {"aggregate": {k: agg[k] for k in [*names, *(d["label"] for d in designs)]},
             "wall_s": wall}), indent=1))
    return agg


if __name__ == "__main__":
    raise SystemExit(run_script(main))
