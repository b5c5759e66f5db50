"""Table 2's still-air check on generated aerostats: how far the linear model's periods lie from
the closed form, row by row, and which rows miss their band.

    python scripts/table2_generated.py --seeds 0 1 2 --count 200

Each aerostat is the baseline scaled by ``scale_aerostat`` to a random volume (10^-2.5 to 10x,
log-uniform), tether length (30-3000 m, log-uniform), element count (2-29) and zero-wind trim
pitch (-12 to +12 deg). Printed: per Table 2 row, the range of the still-air difference from
the closed form, the share within 0.7 %, the rows that miss their band (with the aerostat),
and the rows whose mode the linear model does not name (a missing label reads nan).
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from aerostat_gym.analysis.reference import TABLE2, table2
from aerostat_gym.analysis.trim import TrimError
from aerostat_gym.cli.common import positive_int, run_script, script_description, seed_int
from aerostat_gym.params import ParameterError, load_params
from aerostat_gym.scaling import scale_aerostat


def draw(rng: np.random.Generator) -> tuple[float, float, int, float]:
    """(volume factor, tether length [m], elements, trim pitch [deg]) of one aerostat."""
    return (float(10.0 ** rng.uniform(-2.5, 1.0)), float(10.0 ** rng.uniform(math.log10(30.0),
                                                                            math.log10(3000.0))),
            int(rng.integers(2, 30)), float(rng.uniform(-12.0, 12.0)))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=script_description(__doc__))
    ap.add_argument("--seeds", type=seed_int, nargs="+", default=[0])
    ap.add_argument("--count", type=positive_int, default=200, help="aerostats per seed")
    args = ap.parse_args(argv)
    base = load_params()
    diffs = {key: [] for key in TABLE2}
    misses, unnamed, skipped = [], [], 0
    drawn = [draw(rng) for seed in args.seeds
             for rng in [np.random.default_rng(seed)] for _ in range(args.count)]
    for factor, length, n, pitch in drawn:
        name = f"{factor:.3g}x on {length:.0f} m, {n} el., {pitch:+.1f} deg"
        try:
            rows = table2(scale_aerostat(base, factor, length, n, pitch))
        except (TrimError, ParameterError) as exc:
            skipped += 1
            print(f"skipped {name}: {str(exc).splitlines()[0]}")
            continue
        for row in rows:
            diff = row["calm_diff_pct"]
            if math.isnan(diff):
                unnamed.append(f"{row['key']} ({name})")
            else:
                diffs[row["key"]].append(diff)
            if not row["within_tolerance"]:
                misses.append(f"{row['key']} {diff:+.2f} % (band {row['tolerance_pct']:g} %; {name})")
    print(f"{len(drawn)} aerostats (seeds {args.seeds}), {skipped} skipped")
    for key, d in diffs.items():
        a = np.array(d)
        print(f"{key:15s} {a.min():+7.2f} to {a.max():+7.2f} %, "
              f"{np.mean(np.abs(a) <= 0.7):.1%} within 0.7 % ({len(a)} rows)")
    print(f"{len(misses)} rows miss their band:")
    for m in misses:
        print("  " + m)
    print(f"{len(unnamed)} rows have no mode of that name:")
    for m in unnamed:
        print("  " + m)
    return 0


if __name__ == "__main__":
    raise SystemExit(run_script(main))
