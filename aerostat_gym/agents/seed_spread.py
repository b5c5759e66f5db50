"""The spread of a training configuration over its training seeds, on the report suite.

From one evaluation result per training seed (same configuration, same suite) and the
baselines' results on that suite:

- per training seed: its aggregate IQM and probability of improvement over every baseline
  (:func:`aerostat_gym.agents.protocol.aggregate`, the baselines' episodes as the other runs),
  and its pendulum damping in the ``recover`` cells;
- pooled: the configuration as one policy whose runs are every seed's episodes
  (:func:`aerostat_gym.agents.protocol.pool_training_seeds`), its intervals from a
  hierarchical bootstrap over training seeds and then episodes, so they carry the spread
  between seeds (the issue's "the CIs come from the seeds too").
"""

from __future__ import annotations

import numpy as np

from .protocol import aggregate, aggregate_markdown, cell_values, pool_training_seeds

#: The recover cells whose pendulum damping the per-seed table shows.
DAMPING_CELLS = (("recover", 5.0), ("recover", 10.0), ("recover", 15.0))


def _mean(result: dict, scenario: str, speed: float, metric: str) -> float:
    """Mean of the finite values over the cell's episodes (NaN: no such cell or value)."""
    if scenario not in result["scenarios"]:
        return float("nan")
    v = cell_values(result, scenario, speed, metric)[1]
    v = v[np.isfinite(v)]
    return float(np.mean(v)) if v.size else float("nan")


def seed_spread(baselines: list[dict], seeds: list[dict], label: str, seed: int = 0) -> dict:
    """Per-seed and pooled aggregate statistics (see the module notes) as JSON-ready data."""
    names = [r["label"] for r in baselines]
    per_seed = []
    for r in seeds:
        agg = aggregate([*baselines, r], seed=seed)["aggregate"][r["label"]]
        per_seed.append({
            "label": r["label"], "iqm": agg["iqm"], "iqm_ci": agg["iqm_ci"],
            "p_improvement": {b: agg["p_improvement"][b] for b in names},
            "pendulum_zeta": {f"{s} {u:g}": _mean(r, s, u, "pendulum_zeta")
                              for s, u in DAMPING_CELLS}})
    pooled = aggregate([*baselines, pool_training_seeds(seeds, label)], seed=seed)
    reference = {b: {f"{s} {u:g}": _mean(r, s, u, "pendulum_zeta") for s, u in DAMPING_CELLS}
                 for b, r in zip(names, baselines, strict=True)}
    iqms = np.array([p["iqm"] for p in per_seed])
    return {"label": label, "training_seeds": len(seeds), "per_seed": per_seed,
            "iqm_over_seeds": {"min": float(iqms.min()), "median": float(np.median(iqms)),
                               "max": float(iqms.max())},
            "pooled": pooled["aggregate"], "score": pooled["score"],
            "baseline_pendulum_zeta": reference}


def _p(entry: dict) -> str:
    return f"{entry['p']:.2f} [{entry['ci'][0]:.2f}, {entry['ci'][1]:.2f}]"


def seed_spread_markdown(spread: dict) -> str:
    """Two Markdown tables: one row per training seed, then the pooled aggregate of every
    policy."""
    names = list(spread["per_seed"][0]["p_improvement"])
    cells = [f"{s} {u:g}" for s, u in DAMPING_CELLS]
    head = ["training run", "IQM [95 % CI]", *(f"P(> {b})" for b in names),
            *(f"ζ {c} m/s" for c in cells)]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in spread["per_seed"]:
        lo, hi = row["iqm_ci"]
        lines.append("| " + " | ".join([
            row["label"], f"{row['iqm']:.3f} [{lo:.3f}, {hi:.3f}]",
            *(_p(row["p_improvement"][b]) for b in names),
            *(f"{row['pendulum_zeta'][c]:.3f}" for c in cells)]) + " |")
    for b, z in spread["baseline_pendulum_zeta"].items():
        lines.append("| " + " | ".join([f"({b})", "", *([""] * len(names)),
                                         *(f"{z[c]:.3f}" for c in cells)]) + " |")
    s = spread["iqm_over_seeds"]
    out = ["\n".join(lines), "",
           f"IQM over the {spread['training_seeds']} training seeds: min {s['min']:.3f}, median "
           f"{s['median']:.3f}, max {s['max']:.3f}.", "",
           f"Pooled ({spread['label']}: every seed's episodes; intervals from a hierarchical "
           "bootstrap over training seeds, then episodes). Score: " + spread["score"] + ".", ""]
    out.append(aggregate_markdown({"aggregate": spread["pooled"]}))
    return "\n".join(out) + "\n"
