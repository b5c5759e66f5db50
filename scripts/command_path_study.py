"""Command-path study: a policy through the residual's command low-pass at several time
constants, judged on issue 18's targets at the report's wind speeds with the validation seeds
(:mod:`aerostat_gym.agents.command_path`).

Usage::

    PYTHONPATH=. python scripts/command_path_study.py [--base modal_lqg] [--lowpass 0 1 2 3]
        [--deadband 0] [--policy shipped] [--markdown docs/figures/command_path.md]
        [--json docs/figures/command_path.json]

``--policy`` adds policies as they are (a baseline's name, ``shipped`` or a saved model).
About a minute per design on one core.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from aerostat_gym.agents.command_path import (
    ShapedDesign,
    command_path_study,
    lowpass_designs,
    study_markdown,
)
from aerostat_gym.agents.protocol import json_safe
from aerostat_gym.cli.common import run_script, script_description
from aerostat_gym.params import load_params


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--base", default="modal_lqg", help="the policy to shape (default modal_lqg)")
    ap.add_argument("--lowpass", type=float, nargs="+", default=[0.0, 1.0, 2.0, 3.0],
                    help="low-pass time constants [s] (0: none; default 0 1 2 3)")
    ap.add_argument("--deadband", type=float, default=0.0,
                    help="deadband, a fraction of the winch's top speed (default 0)")
    ap.add_argument("--policy", action="append", default=[], metavar="NAME_OR_PATH",
                    help="a policy run as it is (repeatable)")
    ap.add_argument("--markdown", default=None, help="write the tables to this Markdown file")
    ap.add_argument("--json", default=None, help="write the study to this JSON file")
    args = ap.parse_args(argv)
    designs = lowpass_designs(args.lowpass, args.base, args.deadband)
    designs += [ShapedDesign(p, p) for p in args.policy]
    t0 = time.perf_counter()
    study = command_path_study(load_params(), designs,
                               progress=lambda label: print(f"  {label} ...", flush=True))
    study["wall_s"] = time.perf_counter() - t0
    md = study_markdown(study)
    print(md)
    if args.markdown:
        given = sys.argv[1:] if argv is None else argv
        cmd = "PYTHONPATH=. python scripts/command_path_study.py " + " ".join(given)
        Path(args.markdown).write_text(
            "# Command-path study\n\n`" + cmd.strip() + f"`, {study['wall_s']:.0f} s. Cells: "
            "the report's wind speeds with the validation seeds 7000-7009, sensor noise 0.01; "
            "targets: those of the seed selection (aerostat_gym.agents.selection).\n\n"
            + md + "\n")
    if args.json:
        Path(args.json).write_text(json.dumps(json_safe(study), indent=1))
    print(f"{study['wall_s']:.0f} s")
    return study


if __name__ == "__main__":
    raise SystemExit(run_script(main))
