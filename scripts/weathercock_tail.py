"""The realistic task's heavy tail and the aerostats that do not weathervane
(:mod:`aerostat_gym.agents.weathercock`).

For each policy, its returns on ``TetheredAerostatRealistic-v0`` (independent draws) and
``TetheredAerostatRealisticWeathervaning-v0`` (aerostats that do not weathervane drawn again) over the same seeds: mean with its 95 %
interval, median, worst episode and the share of the summed return in the ten worst; on v0
the mean over the draws that weathervane and over those that do not, on the weathervaning task
the mean over the draws whose static yaw moment still pushes off somewhere at 15-60 deg of yaw
offset and over those that restore there too.

Usage: python scripts/weathercock_tail.py [--policy passive --policy shipped ...]
       [--seeds 200] [--json FILE] [--markdown FILE]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from aerostat_gym.agents.protocol import dumps
from aerostat_gym.agents.returns import task_returns
from aerostat_gym.agents.weathercock import (
    LARGE_OFFSETS_DEG,
    TAIL_EPISODES,
    WEATHERCOCK_SEEDS,
    drawn_weathercock,
    drawn_yaw_curves,
    tail_summary,
)
from aerostat_gym.cli.common import first_seeds, run_script, script_description

TASK_IDS = ("TetheredAerostatRealistic-v0", "TetheredAerostatRealisticWeathervaning-v0")


def study(policies, seeds) -> dict:
    """Returns and summaries per policy and task; which v0 draws weathervane, and which of the
    weathervaning task's draws push off at large yaw offsets."""
    split = {TASK_IDS[0]: drawn_weathercock(TASK_IDS[0], seeds),
             TASK_IDS[1]: np.all(drawn_yaw_curves(TASK_IDS[1], seeds, LARGE_OFFSETS_DEG) < 0.0,
                                 axis=1)}
    rows = []
    for name in policies:
        for task_id in TASK_IDS:
            r = task_returns(name, task_id, seeds)
            ok = split[task_id]
            rows.append({"policy": name, "task": task_id, "returns": r.tolist(),
                         **tail_summary(r), "mean_restoring": float(r[ok].mean()),
                         "mean_not_restoring": float(r[~ok].mean()) if (~ok).any() else None})
    return {"seeds": [int(s) for s in seeds], "v0_weathervanes": split[TASK_IDS[0]].tolist(),
            "weathervaning_restores_to_60_deg": split[TASK_IDS[1]].tolist(), "rows": rows}


def markdown(result: dict) -> str:
    v0 = np.array(result["v0_weathervanes"])
    wv = np.array(result["weathervaning_restores_to_60_deg"])
    lines = [f"Seeds {result['seeds'][0]}-{result['seeds'][-1]}: {int((~v0).sum())} of {v0.size} "
             f"draws of {TASK_IDS[0]} do not weathervane at their trim; {int((~wv).sum())} of "
             f"{wv.size} draws of {TASK_IDS[1]} push off somewhere at 15-60 deg of yaw offset.",
             "", f"| policy | task | mean return [95 % CI] | median | worst | share of the sum "
             f"in the {TAIL_EPISODES} worst | mean where the draw restores / where not (v0: to "
             "10 deg; weathervaning: to 60 deg) |", "|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        other = "-" if r["mean_not_restoring"] is None else f"{r['mean_not_restoring']:.1f}"
        lines.append(f"| {r['policy']} | {r['task']} | {r['return']:.1f} [{r['return_ci'][0]:.1f}, "
                     f"{r['return_ci'][1]:.1f}] | {r['median']:.1f} | {r['worst']:.0f} | "
                     f"{r['tail_share']:.2f} | {r['mean_restoring']:.1f} / {other} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--policy", action="append", default=None,
                    help="a baseline name, 'shipped' or a saved model (default: passive, "
                         "modal_lqg_shaped, shipped)")
    ap.add_argument("--seeds", type=int, default=len(WEATHERCOCK_SEEDS),
                    help="the first N seeds of the study (a smoke run)")
    ap.add_argument("--json", default=None, help="write every return here")
    ap.add_argument("--markdown", default=None, help="write the table here")
    args = ap.parse_args(argv)
    result = study(args.policy or ["passive", "modal_lqg_shaped", "shipped"],
                   first_seeds(args.seeds, WEATHERCOCK_SEEDS))
    table = markdown(result)
    print(table)
    for path, text in ((args.json, dumps(result)), (args.markdown, table)):
        if path:
            Path(path).parent.mkdir(parents=True, exist_ok=True)
            Path(path).write_text(text)
    return result


if __name__ == "__main__":
    raise SystemExit(run_script(main))
