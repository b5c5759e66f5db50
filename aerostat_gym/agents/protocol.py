"""The frozen evaluation protocol's statistics and tables, from :func:`evaluate_policy` results of
several policies on the same suite (issue 17).

Per cell (scenario, wind speed), over the seeds:

- every protocol metric's mean with its 95 % bootstrap interval (:func:`seed_interval`:
  studentized from :data:`STUDENTIZED_MIN_SEEDS` seeds, percentile below);
- the paired difference policy - baseline on the same seeds against every baseline present
  (:data:`aerostat_gym.agents.policies.BASELINES`), with a verdict: "better" or "worse" only
  where the paired interval excludes zero, in the metric's direction
  (:data:`aerostat_gym.agents.protocol_table.LOWER_IS_BETTER`: RMS figures, tension, length
  wander, energy and terminations lower is better; damping ratios and the return higher),
  "indistinguishable" otherwise. The interval must also clear the metric's numerical
  resolution (:data:`RESOLUTION`, far below the printed digits): a policy that reads no noisy
  channel (passive, LQR, modal) runs the same episode at every seed of a calm recover cell, so
  its paired interval is a point, and a rounding-level difference (8e-18 m of RMS cross-wind
  displacement after an along-wind swing) must not count. Pairs where either value is not
  finite (a failed fit, a terminated episode's RMS) are dropped; fewer than two pairs give
  "n/a".

Aggregate, per policy, over every cell: the interquartile mean of a per-episode score with a
stratified-bootstrap interval, and the probability of improvement over every other policy (with
its interval), in the style of ``rliable``. The score is the episode return normalised by the
passive policy's mean return in the same cell, ``score = return / |mean passive return|``
(passive scores about -1; 0 is a perfect episode under the environment's default reward; higher
is better). Without passive among the results the first policy is the reference.

In the recover scenarios the damping ratios shown are those of the pendulums the scenario
swings (:attr:`aerostat_gym.agents.evaluate.Scenario.pendulums`): the longitudinal pendulum
fitted on the along-wind displacement, the lateral one on the cross-wind displacement.
"""

from __future__ import annotations

import math

import numpy as np

from .. import jsonout
from ..checks import is_number
from .evaluate import SCENARIOS
from .policies import BASELINES
from .protocol_stats import (
    Interval,
    bootstrap_mean_ci,
    iqm_ci,
    paired_difference_ci,
    probability_of_improvement_ci,
    verdict,
)
from .protocol_table import LOWER_IS_BETTER

#: Seeds from which a cell's interval is studentized (with two or three seeds the studentized
#: interval degenerates: most resamples have no spread).
STUDENTIZED_MIN_SEEDS = 10
#: Metrics of a free response (recover scenarios), before the pendulum fits of the scenario.
FREE_METRICS = ("pitch_zeta", "rms_x_m", "rms_y_m", "rms_pitch_rad", "rms_pitch_rate_rad_s",
                "peak_tension_N", "length_wander_m", "winch_energy_J", "terminated", "return")
#: Metrics of a forced response (gusty scenarios).
FORCED_METRICS = ("rms_x_m", "rms_y_m", "rms_pitch_rad", "rms_pitch_rate_rad_s",
                  "peak_tension_N", "length_wander_m", "winch_energy_J", "terminated", "return")
PENDULUM_METRIC = {"x": "pendulum_zeta", "y": "lateral_pendulum_zeta"}
#: Paired differences within +-resolution are no difference (units of the metric); the
#: default for a metric not listed is 1e-9.
RESOLUTION = {"pendulum_zeta": 1e-4, "lateral_pendulum_zeta": 1e-4, "pitch_zeta": 1e-4,
              "rms_x_m": 1e-4, "rms_y_m": 1e-4, "rms_pitch_rad": 1e-6,
              "rms_pitch_rate_rad_s": 1e-6, "peak_tension_N": 0.1, "length_wander_m": 1e-4,
              "winch_energy_J": 0.1, "terminated": 1e-9, "return": 1e-6}
#: Columns of the Markdown cell tables: (metric, header, scale, digits).
SHOW = {"pendulum_zeta": ("pend. zeta (long.)", 1.0, 3),
        "lateral_pendulum_zeta": ("pend. zeta (lat.)", 1.0, 3),
        "pitch_zeta": ("pitch zeta", 1.0, 3), "rms_x_m": ("RMS x [m]", 1.0, 2),
        "rms_y_m": ("RMS y [m]", 1.0, 2), "rms_pitch_rad": ("RMS pitch [deg]", 180 / math.pi, 2),
        "peak_tension_N": ("peak T [kN]", 1e-3, 2), "terminated": ("terminations", 1.0, 2)}
SHORT = {"pendulum_zeta": "pend. zeta long.", "lateral_pendulum_zeta": "pend. zeta lat.",
         "pitch_zeta": "pitch zeta", "rms_x_m": "RMS x", "rms_y_m": "RMS y",
         "rms_pitch_rad": "RMS pitch", "rms_pitch_rate_rad_s": "RMS q",
         "peak_tension_N": "peak T", "length_wander_m": "length wander",
         "winch_energy_J": "energy", "terminated": "terminations", "return": "return"}


def scenario_metrics(scenario: str) -> tuple:
    """The protocol metrics of a scenario (pendulum fits first for a free response)."""
    sc = SCENARIOS.get(scenario)
    if sc is None or not sc.free:
        return FORCED_METRICS
    return tuple(PENDULUM_METRIC[a] for a in sc.pendulums) + FREE_METRICS


def table_metrics(scenario: str) -> tuple:
    """The metrics shown in the Markdown cell table of a scenario."""
    sc = SCENARIOS.get(scenario)
    if sc is not None and sc.free:
        return tuple(PENDULUM_METRIC[a] for a in sc.pendulums) + ("pitch_zeta",)
    return ("rms_x_m", "rms_y_m", "rms_pitch_rad", "peak_tension_N", "terminated")


def seed_interval(x) -> Interval | None:
    """Mean of the finite values with its 95 % bootstrap interval; None without any. One value,
    or values without spread, give the value itself as the interval."""
    x = np.asarray([v for v in x if isinstance(v, (int, float)) and math.isfinite(v)], float)
    if x.size == 0:
        return None
    if x.size == 1 or np.ptp(x) == 0.0:
        return Interval(float(x[0]), float(x[0]), float(x[0]), 0.95, int(x.size))
    method = "studentized" if x.size >= STUDENTIZED_MIN_SEEDS else "percentile"
    return bootstrap_mean_ci(x, method=method)


def paired_interval(a, b) -> Interval | None:
    """Paired difference a - b over the pairs where both are finite; None below two pairs."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    keep = np.isfinite(a) & np.isfinite(b)
    if keep.sum() < 2:
        return None
    d = a[keep] - b[keep]
    if np.ptp(d) == 0.0:
        return Interval(float(d[0]), float(d[0]), float(d[0]), 0.95, int(d.size))
    method = "studentized" if d.size >= STUDENTIZED_MIN_SEEDS else "percentile"
    return paired_difference_ci(a[keep], b[keep], method=method)


def paired_verdict(diff: Interval, metric: str) -> str:
    """"better", "worse" or "indistinguishable": the paired interval of policy - baseline must
    exclude zero and clear the metric's :data:`RESOLUTION`, in the metric's direction."""
    tol = RESOLUTION.get(metric, 1e-9)
    if diff.low <= tol and diff.high >= -tol:
        return "indistinguishable"
    return verdict(diff, higher_is_better=metric not in LOWER_IS_BETTER)


def cell_values(result: dict, scenario: str, speed: float, metric: str) -> tuple[list, np.ndarray]:
    """(seeds, values) of ``metric`` over a cell's episodes, ordered by training seed (pooled
    results) then evaluation seed; a missing or non-numeric value reads NaN."""
    eps = sorted((e for e in result["scenarios"][scenario]["episodes"]
                  if e["wind_speed"] == speed), key=lambda e: (e.get("group", 0), e["seed"]))
    vals = [e.get(metric) for e in eps]
    return [e["seed"] for e in eps], np.array(
        [v if is_number(v) else np.nan for v in vals],
        float)


def _cells(results: list[dict]) -> list[tuple[str, float]]:
    first = results[0]["scenarios"]
    return [(s, u) for s in first
            for u in sorted({e["wind_speed"] for e in first[s]["episodes"]})]


def _check_paired(results: list[dict]) -> None:
    labels = [r["label"] for r in results]
    if len(set(labels)) != len(labels):
        raise ValueError(f"policy labels must be distinct, got {labels}")
    for s, u in _cells(results):
        seeds = {tuple(cell_values(r, s, u, "return")[0]) for r in results}
        if len(seeds) != 1:
            raise ValueError(f"cell ({s}, {u:g} m/s): the policies ran different seeds; the "
                             "protocol pairs episodes by seed (evaluate them on one suite)")


def protocol(results: list[dict], baselines=BASELINES, seed: int = 0) -> dict:
    """Per-cell means and paired differences, and the aggregate, as JSON-ready data.

    Parameters
    ----------
    results : list of dict
        :func:`aerostat_gym.agents.evaluate.evaluate_policy` results with a ``label`` each, on
        the same suite (the cells and seeds must match).
    baselines : sequence of str
        Labels the paired differences are taken against (those present).
    seed : int
        Seed of the aggregate's bootstraps.

    Returns
    -------
    dict with ``cells`` (one entry per (scenario, wind speed): ``policies`` {label: {metric:
    {mean, ci}}} and ``paired`` {label: {baseline: {metric: {diff, ci, verdict}}}}), ``score``
    (how the aggregate's per-episode score is formed) and ``aggregate`` ({label: {iqm, iqm_ci,
    p_improvement: {other: {p, ci}}}}).
    """
    _check_paired(results)
    labels = [r["label"] for r in results]
    refs = [b for b in baselines if b in labels]
    cells = []
    for s, u in _cells(results):
        cell = {"scenario": s, "wind_speed": u, "policies": {}, "paired": {}}
        metrics = scenario_metrics(s)
        vals = {r["label"]: {m: cell_values(r, s, u, m)[1] for m in metrics} for r in results}
        cell["n_seeds"] = int(len(vals[labels[0]]["return"]))
        for lab in labels:
            cell["policies"][lab] = {}
            for m in metrics:
                iv = seed_interval(vals[lab][m])
                cell["policies"][lab][m] = (None if iv is None else
                                            {"mean": iv.estimate, "ci": [iv.low, iv.high]})
            cell["paired"][lab] = {}
            for ref in refs:
                if ref == lab:
                    continue
                per = {}
                for m in metrics:
                    iv = paired_interval(vals[lab][m], vals[ref][m])
                    per[m] = ({"diff": None, "ci": None, "verdict": "n/a"} if iv is None else
                              {"diff": iv.estimate, "ci": [iv.low, iv.high],
                               "verdict": paired_verdict(iv, m)})
                cell["paired"][lab][ref] = per
        cells.append(cell)
    out = {"cells": cells, "baselines": refs}
    out.update(aggregate(results, seed=seed))
    return out


def scores(results: list[dict]) -> tuple[str, dict]:
    """(reference label, {label: (seeds, cells) score matrix}): return / |reference cell mean
    return| per episode (the reference is passive, else the first policy)."""
    labels = [r["label"] for r in results]
    if len(set(labels)) != len(labels):
        raise ValueError(f"policy labels must be distinct, got {labels}")
    ref = "passive" if "passive" in labels else labels[0]
    by = {r["label"]: r for r in results}
    cols = {lab: [] for lab in labels}
    for s, u in aggregate_cells(results):
        norm = abs(float(np.mean(cell_values(by[ref], s, u, "return")[1])))
        norm = norm if norm > 0.0 else 1.0
        for lab in labels:
            cols[lab].append(cell_values(by[lab], s, u, "return")[1] / norm)
    return ref, {lab: np.column_stack(c) for lab, c in cols.items()}


def aggregate_cells(results: list[dict]) -> list[tuple[str, float]]:
    """The cells the aggregate pools: those with the most seeds (a score matrix needs the same
    runs in every column; in the report suites that is every cell)."""
    cells = _cells(results)
    n = {c: len(cell_values(results[0], *c, "return")[0]) for c in cells}
    top = max(n.values())
    return [c for c in cells if n[c] == top]


def pool_training_seeds(results: list[dict], label: str) -> dict:
    """One result of several trainings of the same configuration (one result per training
    seed, each on the same suite): every cell's episodes, seed-major, and ``groups``, the number
    of training seeds, which :func:`aggregate` resamples hierarchically (training seeds, then
    episodes), so its intervals carry the spread between training seeds."""
    if not results:
        raise ValueError("pool_training_seeds needs at least one result")
    _check_paired(results)
    pooled = {k: v for k, v in results[0].items() if k != "scenarios"}
    pooled["scenarios"] = {
        name: {"episodes": [{**e, "group": g} for g, r in enumerate(results)
                            for e in r["scenarios"][name]["episodes"]]}
        for name in results[0]["scenarios"]}
    pooled.update(label=label, groups=len(results),
                  members=[r["label"] for r in results])
    return pooled


def aggregate(results: list[dict], seed: int = 0) -> dict:
    """IQM of the normalised score with its stratified-bootstrap interval and the probability
    of improvement of each policy over each other one (see the module notes). A pooled result
    (:func:`pool_training_seeds`) is resampled over its training seeds and their episodes."""
    ref, mats = scores(results)
    groups = {r["label"]: int(r.get("groups", 1)) for r in results}
    agg = {}
    for lab, s in mats.items():
        if s.shape[0] < 2:  # one seed per cell: no interval over runs
            iv = Interval(float(np.mean(s)), math.nan, math.nan, 0.95, 1)
        else:
            iv = iqm_ci(s, seed=seed, groups=groups[lab])
        row = {"iqm": iv.estimate, "iqm_ci": [iv.low, iv.high], "p_improvement": {}}
        if groups[lab] > 1:
            row["training_seeds"] = groups[lab]
        for other, t in mats.items():
            if other == lab or s.shape[0] < 2:
                continue
            p = probability_of_improvement_ci(s, t, seed=seed, groups_x=groups[lab],
                                              groups_y=groups[other])
            row["p_improvement"][other] = {"p": p.estimate, "ci": [p.low, p.high]}
        agg[lab] = row
    cells = aggregate_cells(results)
    return {"score": f"episode return / |mean return of {ref} in the same cell|",
            "aggregate_cells": [f"{s} {u:g} m/s" for s, u in cells], "aggregate": agg}


def _num(v: float, scale: float, digits: int) -> str:
    return "n/a" if v is None or not math.isfinite(v) else f"{v * scale:.{digits}f}"


def interval_text(entry, scale: float, digits: int) -> str:
    """``mean [low, high]`` of a metric entry, scaled; the interval is left out where it rounds
    to one point at the printed digits (every seed gave the same episode)."""
    if entry is None:
        return "n/a"
    lo, hi = (_num(v, scale, digits) for v in entry["ci"])
    mean = _num(entry["mean"], scale, digits)
    return mean if lo == hi else f"{mean} [{lo}, {hi}]"


def _verdict_text(paired: dict) -> str:
    words = {"better": [], "worse": []}
    for m, d in paired.items():
        if d["verdict"] in words:
            words[d["verdict"]].append(SHORT.get(m, m))
    parts = [f"{k}: {', '.join(v)}" for k, v in words.items() if v]
    if parts:
        return "; ".join(parts)
    if paired and all(d["verdict"] == "n/a" for d in paired.values()):
        return "n/a (fewer than 2 paired seeds: no interval)"
    return "indistinguishable"


def cell_markdown(cell: dict, reference: str = "passive") -> str:
    """Markdown table of one cell: a row per policy, the key metrics' means [95 % CI] and the
    metrics on which the policy is better or worse than ``reference`` (paired CI excludes 0)."""
    shown = table_metrics(cell["scenario"])
    head = ["policy", *(SHOW[m][0] for m in shown), f"vs {reference} (paired 95 % CI)"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for lab, means in cell["policies"].items():
        row = [lab] + [interval_text(means.get(m), *SHOW[m][1:]) for m in shown]
        paired = cell["paired"].get(lab, {}).get(reference)
        row.append("(reference)" if lab == reference else
                   "n/a" if paired is None else _verdict_text(paired))
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def aggregate_markdown(proto: dict, label=str) -> str:
    """Markdown table: IQM [95 % CI] of the normalised score and P(improvement) [95 % CI] over
    each other policy; ``label(name)`` names the policies."""
    agg = proto["aggregate"]
    labels = list(agg)
    head = ["policy", "IQM score [95 % CI]", *(f"P(better than {label(o)})" for o in labels)]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for lab in labels:
        row = agg[lab]
        lo, hi = row["iqm_ci"]
        cells = [label(lab), f"{row['iqm']:.3f} [{_num(lo, 1, 3)}, {_num(hi, 1, 3)}]"]
        for o in labels:
            p = row["p_improvement"].get(o)
            cells.append("-" if p is None else
                         f"{p['p']:.2f} [{p['ci'][0]:.2f}, {p['ci'][1]:.2f}]")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def protocol_markdown(proto: dict, reference: str = "passive",
                      tether_length: float | None = None) -> str:
    """The protocol's report: one table per cell and the aggregate table (the scenarios
    described on a tether of ``tether_length`` [m], None: the reference)."""
    ref = reference if reference in proto["baselines"] else (
        proto["baselines"][0] if proto["baselines"] else None)
    parts = []
    for cell in proto["cells"]:
        sc = SCENARIOS.get(cell["scenario"])
        desc = f" ({sc.describe(tether_length)})" if sc is not None else ""
        seeds = f"{cell['n_seeds']} seed{'' if cell['n_seeds'] == 1 else 's'}"
        parts += [f"### {cell['scenario']}, {cell['wind_speed']:g} m/s, {seeds}{desc}", "",
                  cell_markdown(cell, ref), ""]
    n_all, cells = len(proto["cells"]), proto["aggregate_cells"]
    over = ("all cells" if len(cells) == n_all else
            f"the {len(cells)} of {n_all} cells with the most seeds ({', '.join(cells)})")
    parts += [f"### Aggregate over {over}", "",
              f"Score: {proto['score']} (higher is better); IQM with a stratified-bootstrap "
              "95 % interval, probability of improvement in the style of rliable.", "",
              aggregate_markdown(proto), ""]
    return "\n".join(parts)


#: Importable from here as before 0.7.17.
json_safe = jsonout.plain


def dumps(proto: dict) -> str:
    """JSON text of :func:`protocol`'s output (NaN written as null)."""
    return jsonout.dumps(proto, indent=1)
