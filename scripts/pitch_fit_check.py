"""What the protocol's pitch damping ratio measures (:mod:`aerostat_gym.agents.pitch_check`).

For each recover scenario and wind speed: the linear pitching and axial-spring modes, and the
protocol's pitch fit applied to the linear braked response and to the nonlinear braked run
from the scenario's start. Usage::

    PYTHONPATH=. python scripts/pitch_fit_check.py [--config TOML] [--speeds 5 10 15] \\
        [--markdown docs/figures/pitch_fit_check.md --json docs/figures/pitch_fit_check.json]
"""

from __future__ import annotations

import argparse

from aerostat_gym.agents.evaluate import SCENARIOS
from aerostat_gym.agents.pitch_check import check_markdown, linear_pitch_check
from aerostat_gym.agents.report import emit_table
from aerostat_gym.cli.common import run_script, script_description
from aerostat_gym.params import load_params


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--config", default=None, help="parameter TOML (default: the baseline)")
    ap.add_argument("--speeds", nargs="+", type=float, default=[5.0, 10.0, 15.0])
    ap.add_argument("--scenarios", nargs="+", default=["recover", "recover_small"],
                    choices=[name for name, s in SCENARIOS.items() if s.free])
    ap.add_argument("--markdown", default=None, help="write the table here")
    ap.add_argument("--json", default=None, help="write the rows here")
    args = ap.parse_args(argv)
    params = load_params(args.config)
    rows = [linear_pitch_check(params, u, s) for s in args.scenarios for u in args.speeds]
    emit_table(check_markdown(rows), rows, args.markdown, args.json)


if __name__ == "__main__":
    raise SystemExit(run_script(main))
