"""The pitching mode's damping ratio in the recover scenarios, policy by policy, from a fit
whose fast modes start at the linear pitching and axial-spring modes
(:func:`aerostat_gym.agents.pitch_check.pitching_mode_study`), with the paired difference from
the braked winch on the report suite's seeds and sensor noise. Usage::

    PYTHONPATH=. python scripts/pitch_mode_study.py --speeds 5 10 15 \\
        --policies passive shipped modal_lqg_shaped modal \\
        [--markdown docs/figures/pitch_mode_study.md --json docs/figures/pitch_mode_study.json]
"""

from __future__ import annotations

import argparse

from aerostat_gym.agents.evaluate import REPORT_SEEDS, SCENARIOS, SENSOR_NOISE
from aerostat_gym.agents.pitch_check import pitching_mode_study, study_markdown
from aerostat_gym.agents.report import emit_table
from aerostat_gym.cli.common import run_script, script_description
from aerostat_gym.params import load_params


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--config", default=None, help="parameter TOML (default: the baseline)")
    ap.add_argument("--scenario", default="recover", choices=list(SCENARIOS))
    ap.add_argument("--speeds", nargs="+", type=float, default=[5.0, 10.0, 15.0])
    ap.add_argument("--policies", nargs="+", default=["passive", "shipped"],
                    help="policy names or saved models; the first is the reference")
    ap.add_argument("--markdown", default=None, help="write the table here")
    ap.add_argument("--json", default=None, help="write the results here")
    args = ap.parse_args(argv)
    params = load_params(args.config)
    studies = [pitching_mode_study(params, args.scenario, u, REPORT_SEEDS, args.policies,
                                   SENSOR_NOISE, reference=args.policies[0])
               for u in args.speeds]
    emit_table(study_markdown(studies), studies, args.markdown, args.json)


if __name__ == "__main__":
    raise SystemExit(run_script(main))
