"""What decides the probability of improvement: the aggregate's P(X > Y) split into the calm
(free-response) and the turbulent cells, and the most any policy X could reach against Y.

The aggregate's P is the mean over cells of the Mann-Whitney statistic between the two policies'
episodes in the cell (unpaired, rliable's definition; :mod:`aerostat_gym.agents.protocol_stats`).
In a calm cell every seed flies the same swing and only the sensor noise differs, so a small but
systematic difference in return decides the cell outright (P near 0 or 1). In a turbulent cell
each seed is another gust field; the spread of the return between seeds is orders of magnitude
larger than what separates two good winch controllers, and P stays near 0.5 however consistent
the difference is seed by seed. :func:`poi_split` measures both parts, the paired win rate in
the turbulent cells (the same seed, so the same field, for both policies) and ``bound``: X's P
over Y had it won every calm cell outright and kept its measured turbulent cells.

:func:`lost_by_all` asks the converse: the calm cells that every one of several policies loses
outright to Y (P = 0: each of its episodes below each of Y's), and the cap they put on P over Y
for a policy that loses them too, with every other cell won outright.
"""

from __future__ import annotations

import numpy as np

from .evaluate import GUSTY_SCENARIOS
from .protocol import aggregate_cells, scores
from .protocol_stats import poi_per_task


def poi_split(results: list[dict], x: str, y: str) -> dict:
    """P(X > Y) of the aggregate over all cells, over the calm and the turbulent cells, the
    paired win rate of X over Y in the turbulent cells, and the bound with every calm cell won
    (``results`` as for :func:`aerostat_gym.agents.protocol.aggregate`, both labels among them)."""
    _, gusty, mats = _scored_cells(results, (x, y))
    p = poi_per_task(mats[x], mats[y])
    diff = mats[x] - mats[y]  # same seed, same episode start and wind field
    paired = (diff > 0).mean(axis=0) + 0.5 * (diff == 0).mean(axis=0)
    return {"x": x, "y": y, "p": float(p.mean()),
            "calm": float(p[~gusty].mean()) if (~gusty).any() else float("nan"),
            "turbulent": float(p[gusty].mean()) if gusty.any() else float("nan"),
            "turbulent_paired_win": float(paired[gusty].mean()) if gusty.any() else float("nan"),
            "bound": float(np.where(gusty, p, 1.0).mean()),
            "calm_lost": int(((p == 0.0) & ~gusty).sum()),
            "calm_cells": int((~gusty).sum()), "turbulent_cells": int(gusty.sum())}


def lost_by_all(results: list[dict], xs, y: str) -> dict:
    """The calm cells that every policy of ``xs`` loses outright to ``y`` (P(X > Y) = 0 in the
    cell), as (scenario, wind speed) pairs, and ``cap``: P over Y with those cells lost and every
    other cell won outright."""
    cells, gusty, mats = _scored_cells(results, [*xs, y])
    lost = ~gusty
    for x in xs:
        lost &= poi_per_task(mats[x], mats[y]) == 0.0
    return {"y": y, "xs": list(xs), "cells": [cells[i] for i in np.flatnonzero(lost)],
            "cap": float(1.0 - lost.mean()), "n_cells": len(cells)}


def _scored_cells(results: list[dict], wanted):
    """The aggregate's cells, which of them are turbulent, and every policy's score matrix
    (seeds x cells), once the ``wanted`` labels are found among the results."""
    labels = [r["label"] for r in results]
    missing = [lab for lab in wanted if lab not in labels]
    if missing:
        raise ValueError(f"poi_split: {missing} not among the results' labels {labels}")
    cells = aggregate_cells(results)
    _, mats = scores(results)
    return cells, np.array([s in GUSTY_SCENARIOS for s, _ in cells]), mats


def split_markdown(rows: list[dict]) -> str:
    """A Markdown table of :func:`poi_split` rows."""
    head = ("| X | Y | P(X > Y) | calm cells | turbulent cells | paired win rate, turbulent | "
            "bound: every calm cell won | calm cells lost outright |\n"
            "|---|---|---|---|---|---|---|---|\n")
    return head + "".join(
        f"| {r['x']} | {r['y']} | {r['p']:.2f} | {r['calm']:.2f} ({r['calm_cells']}) | "
        f"{r['turbulent']:.2f} ({r['turbulent_cells']}) | {r['turbulent_paired_win']:.2f} | "
        f"{r['bound']:.2f} | {r['calm_lost']} |\n" for r in rows)


def lost_markdown(rows: list[dict]) -> str:
    """A Markdown table of :func:`lost_by_all` rows."""
    head = ("| Y | calm cells every X loses outright | cap on P(X > Y) |\n|---|---|---|\n")
    return head + "".join(
        f"| {r['y']} | {len(r['cells'])}: "
        + (", ".join(f"{s} {u:g}" for s, u in r["cells"]) or "none")
        + f" | {r['cap']:.2f} |\n" for r in rows)
