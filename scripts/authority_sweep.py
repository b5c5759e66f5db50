"""Authority sweep: what privileged full-state winch feedback (the modal controller at several
pendulum damping ratios, the LQR at several displacement weights) reaches on the report suite's
light and moderate turbulence cells at 8, 12 and 16 m/s, and on the 10 m swing recovery, against
the braked winch on the same seeds (:mod:`aerostat_gym.agents.authority`).

Usage::

    PYTHONPATH=. python scripts/authority_sweep.py [--json docs/figures/authority.json]
        [--markdown docs/figures/authority.md] [--seeds 20]

It prints, per cell, the designs that meet every gust target of issue 18 (RMS x <= 0.8 x
passive, RMS pitch and peak tension not above passive, each on a paired 95 % interval) and the
best RMS x ratio reached; the Markdown file holds the full tables.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from aerostat_gym.agents.authority import (
    authority_sweep,
    gust_markdown,
    reachable,
    recover_markdown,
)
from aerostat_gym.agents.evaluate import REPORT_SEEDS
from aerostat_gym.agents.protocol import json_safe
from aerostat_gym.cli.common import run_script, script_description
from aerostat_gym.params import load_params


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--seeds", type=int, default=len(REPORT_SEEDS),
                    help="report seeds to run, from the first (default all 20)")
    ap.add_argument("--json", default=None, help="write the sweep to this JSON file")
    ap.add_argument("--markdown", default=None, help="write the tables to this Markdown file")
    args = ap.parse_args(argv)
    if not 2 <= args.seeds <= len(REPORT_SEEDS):
        ap.error(f"--seeds must lie in 2..{len(REPORT_SEEDS)}, got {args.seeds}")
    t0 = time.perf_counter()
    sweep = authority_sweep(load_params(), seeds=REPORT_SEEDS[:args.seeds],
                            progress=lambda label: print(f"  {label} ...", flush=True))
    sweep["wall_s"] = time.perf_counter() - t0
    for cell in reachable(sweep):
        ok = ", ".join(cell["all_targets"]) or "none"
        print(f"{cell['scenario']:12s} {cell['wind_speed']:4.0f} m/s: every gust target met by "
              f"{ok}; best RMS x / passive {cell['best_rms_x_ratio']:.3f} ({cell['best_design']})")
    md = "\n\n".join([f"### {u:g} m/s\n\n" + gust_markdown(sweep, u)
                      for u in sorted({r["wind_speed"] for r in sweep["gusty"]})]
                     + ["### recover (10 m swing)\n\n" + recover_markdown(sweep)])
    if args.markdown:
        Path(args.markdown).write_text(
            "# Authority sweep\n\n`PYTHONPATH=. python scripts/authority_sweep.py`, "
            f"{len(sweep['seeds'])} report seeds, {sweep['wall_s']:.0f} s.\n\n" + md + "\n")
    if args.json:
        Path(args.json).write_text(json.dumps(json_safe(sweep), indent=1))
    print(f"{sweep['wall_s']:.0f} s")
    return sweep


if __name__ == "__main__":
    raise SystemExit(run_script(main))
