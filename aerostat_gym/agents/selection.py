"""Choosing a trained policy on the validation suite: issue 18's targets first, then the score.

Training seeds of one configuration differ in what they meet (docs/learned.md: of five seeds
trained with a deadband, one met the pitch and wander targets on the report suite). Choosing
the seed to ship on the report suite would be choosing on the test cases, and its report would
then overstate what the configuration does on cases it never saw. This module chooses on the
``validation`` suite (:mod:`aerostat_gym.agents.evaluate`: the report's scenarios and sensor
noise at other wind speeds and seeds) and leaves the report suite to judge the choice.

The rule, fixed before any candidate is evaluated:

1. count the targets a candidate meets on the validation cells (:data:`RECOVER_TARGETS` at each
   ``recover`` wind speed, :data:`GUST_TARGETS` at each wind speed of ``gusty_light`` and
   ``gusty``), each judged as issue 18 states it: ratios on the cell means, "above" and "not
   worse" on the paired 95 % interval over the seeds (:func:`protocol.paired_verdict`), "at most
   0.8 x" on the paired interval of candidate - 0.8 x passive
   (:func:`authority.target_verdict`); the pendulum target's "at equal or lower peak reel
   speed" needs the modal curve of the frontier runs and is left to them;
2. the candidate meeting the most targets is chosen; a tie goes to the higher IQM of the
   aggregate score on the validation suite (the baselines are the other runs, as in
   :func:`protocol.aggregate`).
"""

from __future__ import annotations

import numpy as np

from .authority import GUST_SCENARIOS, target_verdict
from .protocol import aggregate, cell_values, paired_interval, paired_verdict

#: The baselines the targets name; each must be in the validation results.
REQUIRED_BASELINES = ("passive", "modal", "lqg")
#: ``recover``: (name, metric, kind, reference, factor). kind "ratio": the candidate's cell
#: mean at least factor x the reference's; "at_most": its mean at most the reference's;
#: "better" / "not_worse": the paired verdict against the reference.
RECOVER_TARGETS = (
    ("pendulum zeta >= 0.9 x modal", "pendulum_zeta", "ratio", "modal", 0.9),
    ("pendulum zeta above passive", "pendulum_zeta", "better", "passive", None),
    ("pitch zeta not worse than passive", "pitch_zeta", "not_worse", "passive", None),
    ("length wander <= modal", "length_wander_m", "at_most", "modal", None),
)
#: ``gusty_light`` and ``gusty``: kind "fraction": the paired interval of candidate -
#: factor x reference at or below zero; "no_more": summed over the seeds, at most the
#: reference's.
GUST_TARGETS = (
    ("RMS x <= 0.8 x passive", "rms_x_m", "fraction", "passive", 0.8),
    ("RMS x not worse than LQG", "rms_x_m", "not_worse", "lqg", None),
    ("RMS pitch not worse than passive", "rms_pitch_rad", "not_worse", "passive", None),
    ("peak tension not above passive", "peak_tension_N", "not_worse", "passive", None),
    ("terminations <= passive", "terminated", "no_more", "passive", None),
)


def _met(kind: str, metric: str, mine: np.ndarray, ref: np.ndarray, factor) -> bool:
    """Whether one target holds on one cell (see the module notes for each kind)."""
    if kind == "ratio":
        return bool(np.nanmean(mine) >= factor * np.nanmean(ref))
    if kind == "at_most":
        return bool(np.nanmean(mine) <= np.nanmean(ref))
    if kind == "no_more":
        return bool(np.nansum(mine) <= np.nansum(ref))
    if kind == "fraction":
        return target_verdict(mine, ref, factor)[0] == "met"
    iv = paired_interval(mine, ref)
    v = "indistinguishable" if iv is None else paired_verdict(iv, metric)
    return v == "better" if kind == "better" else v != "worse"


def _speeds(result: dict, scenario: str) -> list[float]:
    return sorted({e["wind_speed"] for e in result["scenarios"][scenario]["episodes"]})


def target_checks(candidate: dict, baselines: dict) -> list[dict]:
    """One row per (target, scenario, wind speed) of the validation cells: {"target",
    "scenario", "wind_speed", "met"}. ``baselines``: label -> result, holding
    :data:`REQUIRED_BASELINES`."""
    missing = [b for b in REQUIRED_BASELINES if b not in baselines]
    if missing:
        raise ValueError(f"the selection needs the baselines {list(REQUIRED_BASELINES)}; "
                         f"missing {missing}")
    groups = [("recover", RECOVER_TARGETS)] + [(s, GUST_TARGETS) for s in GUST_SCENARIOS]
    rows = []
    for scenario, targets in groups:
        if scenario not in candidate["scenarios"]:
            raise ValueError(f"candidate {candidate['label']!r} has no {scenario!r} episodes: "
                             "evaluate it on the validation suite")
        for u in _speeds(candidate, scenario):
            for name, metric, kind, ref, factor in targets:
                mine = cell_values(candidate, scenario, u, metric)[1]
                other = cell_values(baselines[ref], scenario, u, metric)[1]
                rows.append({"target": name, "scenario": scenario, "wind_speed": u,
                             "met": _met(kind, metric, mine, other, factor)})
    return rows


def select(candidates: list[dict], baselines: list[dict], seed: int = 0) -> dict:
    """Rank ``candidates`` (evaluation results on the validation suite) by the module's rule.

    Returns {"chosen": label, "ranking": [{"label", "targets_met", "targets", "iqm",
    "iqm_ci", "p_improvement", "checks"}, ...] best first}.
    """
    if not candidates:
        raise ValueError("select needs at least one candidate")
    suites = {r.get("suite") for r in [*candidates, *baselines]}
    if suites != {"validation"}:
        raise ValueError(f"the selection runs on the validation suite only, got {suites}")
    by = {r["label"]: r for r in baselines}
    rows = []
    for c in candidates:
        checks = target_checks(c, by)
        agg = aggregate([*baselines, c], seed=seed)["aggregate"][c["label"]]
        rows.append({"label": c["label"], "targets_met": sum(k["met"] for k in checks),
                     "targets": len(checks), "iqm": agg["iqm"], "iqm_ci": agg["iqm_ci"],
                     "p_improvement": {b: agg["p_improvement"][b]["p"] for b in by},
                     "checks": checks})
    rows.sort(key=lambda r: (-r["targets_met"], -r["iqm"]))
    return {"chosen": rows[0]["label"], "ranking": rows}


def selection_markdown(sel: dict) -> str:
    """The ranking as a Markdown table, and per target the candidates' cells met."""
    base = list(sel["ranking"][0]["p_improvement"])
    lines = ["| rank | candidate | targets met | IQM [95% CI] | "
             + " | ".join(f"P(> {b})" for b in base) + " |",
             "|---|---|---|---|" + "---|" * len(base)]
    for i, r in enumerate(sel["ranking"], 1):
        lo, hi = r["iqm_ci"]
        lines.append(f"| {i} | {r['label']} | {r['targets_met']} / {r['targets']} | "
                     f"{r['iqm']:.3f} [{lo:.3f}, {hi:.3f}] | "
                     + " | ".join(f"{r['p_improvement'][b]:.2f}" for b in base) + " |")
    names = list(dict.fromkeys(f"{k['scenario']}: {k['target']}"
                               for k in sel["ranking"][0]["checks"]))
    lines += ["", "| target | " + " | ".join(r["label"] for r in sel["ranking"]) + " |",
              "|---|" + "---|" * len(sel["ranking"])]
    for n in names:
        cells = []
        for r in sel["ranking"]:
            ks = [k for k in r["checks"] if f"{k['scenario']}: {k['target']}" == n]
            cells.append(f"{sum(k['met'] for k in ks)} / {len(ks)}")
        lines.append(f"| {n} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
