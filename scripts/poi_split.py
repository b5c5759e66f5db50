"""The aggregate's probability of improvement split into calm and turbulent cells, with the most
a policy could reach by winning every calm cell (:mod:`aerostat_gym.agents.poi_split`).

Reads the ``report.json`` of ``aerostat-gym evaluate`` runs on one suite (the normalising
passive policy among them) and prints, for every X of ``--x`` against every Y of ``--y``, P(X > Y)
over all cells, over the calm and the turbulent cells, the paired win rate in the turbulent
cells, the bound and the calm cells X loses outright; with ``--lost``, for every Y, the calm cells
that every X loses outright and the cap they put on P(X > Y). Usage::

    aerostat-gym evaluate --suite report --out runs/split --no-plots --policy passive \\
        --policy modal --policy modal_lqg_shaped --policy shipped
    PYTHONPATH=. python scripts/poi_split.py runs/split/report.json \\
        --x ppo_tethered_aerostat modal_lqg_shaped --y modal modal_lqg_shaped \\
        [--markdown docs/figures/poi_split.md --json docs/figures/poi_split.json] [--lost]
"""

from __future__ import annotations

import argparse

from aerostat_gym.agents.poi_split import lost_by_all, lost_markdown, poi_split, split_markdown
from aerostat_gym.agents.report import emit_table, load_results
from aerostat_gym.cli.common import run_script, script_description


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("report_json", nargs="+", help="report.json of evaluate runs on one suite")
    ap.add_argument("--x", nargs="+", required=True, help="labels of the improving policies")
    ap.add_argument("--y", nargs="+", required=True, help="labels of the policies compared to")
    ap.add_argument("--markdown", default=None, help="write the table here")
    ap.add_argument("--json", default=None, help="write the rows here")
    ap.add_argument("--lost", action="store_true",
                    help="instead: per Y, the calm cells every X loses outright, and the cap")
    args = ap.parse_args(argv)
    try:
        results = list(load_results(args.report_json, args.x + args.y).values())
        if args.lost:
            rows = [lost_by_all(results, [x for x in args.x if x != y], y) for y in args.y]
            table = lost_markdown(rows)
        else:
            rows = [poi_split(results, x, y) for x in args.x for y in args.y if x != y]
            table = split_markdown(rows)
    except ValueError as err:
        raise SystemExit(str(err)) from None
    emit_table(table, rows, args.markdown, args.json)


if __name__ == "__main__":
    raise SystemExit(run_script(main))
