"""Small statistics used by the Monte Carlo study reports: correlation of a parameter with an
outcome and the Wilson interval of a probability (bootstrap intervals of means come from
:mod:`aerostat_gym.agents.protocol_stats`)."""

from __future__ import annotations

import math

import numpy as np
from scipy import stats

#: Two-sided 95 % normal quantile.
Z95 = 1.959963984540054


def wilson_interval(successes: int, n: int) -> tuple[float, float]:
    """95 % Wilson score interval of a binomial probability (nan, nan for n = 0).

    Parameters
    ----------
    successes : count of successes.
    n : trials.
    """
    if n == 0:
        return math.nan, math.nan
    p = successes / n
    den = 1 + Z95**2 / n
    centre = (p + Z95**2 / (2 * n)) / den
    half = Z95 * math.sqrt(p * (1 - p) / n + Z95**2 / (4 * n * n)) / den
    return max(0.0, centre - half), min(1.0, centre + half)


def point_biserial(values, indicator) -> float:
    """Pearson correlation of a parameter with a 0/1 outcome (nan if either is constant).

    Parameters
    ----------
    values : parameter value per sample.
    indicator : 1 where the outcome occurred (e.g. an instability), else 0.
    """
    x, y = np.asarray(values, float), np.asarray(indicator, float)
    if np.ptp(x) == 0 or np.ptp(y) == 0:
        return math.nan
    return float(np.corrcoef(x, y)[0, 1])


def spearman(values, outcome) -> float:
    """Spearman rank correlation (nan if either is constant)."""
    x, y = np.asarray(values, float), np.asarray(outcome, float)
    if np.ptp(x) == 0 or np.ptp(y) == 0:
        return math.nan
    return float(stats.spearmanr(x, y).statistic)
