"""Small statistics used by the study reports: percentile bootstrap confidence intervals,
correlation of a parameter with an outcome, and the Wilson interval of a probability."""

from __future__ import annotations

import math

import numpy as np
from scipy import stats

#: Two-sided 95 % normal quantile.
Z95 = 1.959963984540054


def bootstrap_ci(data, level: float = 0.95, n_boot: int = 10_000,
                 seed: int = 0) -> tuple[float, float]:
    """Percentile bootstrap confidence interval of the mean.

    Parameters
    ----------
    data : 1-D sample (e.g. one score per training seed).
    level : coverage of the interval.
    n_boot : bootstrap resamples.
    seed : seed of the resampling generator (the interval is reproducible).

    Returns
    -------
    (low, high); (x, x) for a single value.

    Notes
    -----
    Resamples of size n are drawn with replacement, their means sorted, and the
    (1 - level) / 2 and (1 + level) / 2 quantiles returned. With few seeds (5-10) the
    percentile interval is somewhat narrower than nominal coverage; it is what rliable-style
    reports use and is stated as such.
    """
    x = np.asarray(data, float).ravel()
    if x.size == 0 or not np.all(np.isfinite(x)):
        raise ValueError(f"bootstrap_ci needs a non-empty finite sample, got {x.tolist()}")
    if not 0 < level < 1:
        raise ValueError(f"level must be in (0, 1), got {level!r}")
    if x.size == 1:
        return float(x[0]), float(x[0])
    rng = np.random.default_rng(seed)
    means = x[rng.integers(0, x.size, size=(n_boot, x.size))].mean(axis=1)
    lo, hi = np.quantile(means, [(1 - level) / 2, (1 + level) / 2])
    return float(lo), float(hi)


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
