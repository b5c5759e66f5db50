"""Protocol tables: per cell, every policy's mean with its bootstrap interval and its paired
difference against a baseline; across cells, the interquartile mean and the probability of
improvement (:mod:`aerostat_gym.agents.protocol_stats`).

Input layout: ``values[policy][metric]`` is an array over the cell's seeds, the same seeds in
the same order for every policy (episode i of every policy starts from the same seed, so the
differences are paired).
"""

from __future__ import annotations

import numpy as np

from .protocol_stats import (
    bootstrap_mean_ci,
    iqm_ci,
    paired_difference_ci,
    probability_of_improvement_ci,
    verdict,
)

#: Metrics where smaller is better (the rest, e.g. damping ratios and returns, larger).
LOWER_IS_BETTER = ("rms_x_m", "rms_pitch_rad", "peak_tension_N", "rms_tension_N",
                   "tension_std_N", "winch_energy_J", "peak_winch_power_W",
                   "peak_reel_speed_m_s", "settling_time_s", "rms_y_m",
                   "rms_pitch_rate_rad_s", "length_wander_m", "rms_length_m", "terminated")


def cell_table(values: dict, metrics, baseline: str, seed: int = 0) -> list[dict]:
    """One row per (policy, metric): mean, ``mean_ci``, paired difference against ``baseline``
    with ``diff_ci`` and the verdict ("better", "worse", "indistinguishable").

    Parameters
    ----------
    values : dict
        values[policy][metric] -> per-seed array (paired across policies).
    metrics : sequence of str
        Metrics to tabulate.
    baseline : str
        The policy the paired differences are taken against.
    seed : int
        Seed of every bootstrap.

    Returns
    -------
    list of dict
    """
    if baseline not in values:
        raise ValueError(f"baseline {baseline!r} is not among the policies {list(values)}")
    rows = []
    for policy, by_metric in values.items():
        for m in metrics:
            x = np.asarray(by_metric[m], float)
            row = {"policy": policy, "metric": m, **bootstrap_mean_ci(x, seed=seed).as_dict(
                "mean")}
            if policy != baseline:
                d = paired_difference_ci(x, np.asarray(values[baseline][m], float), seed=seed)
                row.update(d.as_dict("diff"))
                row["verdict"] = verdict(d, higher_is_better=m not in LOWER_IS_BETTER)
            rows.append(row)
    return rows


def aggregate_table(scores: dict, baseline: str, seed: int = 0) -> list[dict]:
    """IQM (stratified-bootstrap interval) of each policy's (runs, cells) score matrix and its
    probability of improvement over ``baseline`` (interval likewise)."""
    rows = []
    for policy, s in scores.items():
        row = {"policy": policy, **iqm_ci(s, seed=seed).as_dict("iqm")}
        if policy != baseline:
            row.update(probability_of_improvement_ci(s, scores[baseline], seed=seed)
                       .as_dict("p_improvement"))
        rows.append(row)
    return rows


def markdown(rows: list[dict], fmt: str = "{:.4g}") -> str:
    """Markdown table of :func:`cell_table` or :func:`aggregate_table` rows."""
    if not rows:
        return ""
    keys = list(dict.fromkeys(k for r in rows for k in r))

    def cell(v):
        if isinstance(v, list):
            return "[" + ", ".join(fmt.format(x) for x in v) + "]"
        if isinstance(v, float):
            return fmt.format(v)
        return "" if v is None else str(v)

    out = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    out += ["| " + " | ".join(cell(r.get(k)) for k in keys) + " |" for r in rows]
    return "\n".join(out)
