"""Statistics of the evaluation protocol (aerostat_gym.agents.protocol_stats) on synthetic cases
with known answers: interval coverage over 1,000 synthetic experiments, IQM and probability of
improvement against values computed by hand, paired differences, seeding. Every assertion
states its tolerance.
"""

import numpy as np
import pytest
from scipy import stats

from aerostat_gym.agents.protocol_stats import (
    StatsInputError,
    bootstrap_mean_ci,
    coverage,
    interquartile_mean,
    iqm_ci,
    paired_difference_ci,
    probability_of_improvement,
    probability_of_improvement_ci,
    verdict,
)


def normal_sampler(rng, n):
    return rng.normal(1.0, 2.0, n)


def exponential_sampler(rng, n):
    return rng.exponential(1.0, n)


def test_coverage_normal_within_two_points():
    """Studentized bootstrap, 20 seeds per cell, 1,000 synthetic experiments of N(1, 2^2): the
    95 % interval contains the true mean 1 in 95 % +- 2 points of them (measured 94.5 %; the
    Monte Carlo standard error of the estimate is 0.7 points)."""
    c = coverage(normal_sampler, 1.0, experiments=1000, n=20, seed=0)
    assert abs(c - 0.95) <= 0.02, c


def test_coverage_skewed_within_two_points():
    """The same on a skewed distribution, Exp(1) with mean 1 (measured 94.0 %)."""
    c = coverage(exponential_sampler, 1.0, experiments=1000, n=20, seed=1)
    assert abs(c - 0.95) <= 0.02, c


def test_percentile_interval_undercovers_at_20_seeds():
    """Why the default is studentized: the plain percentile interval covers only ~92 % at n = 20
    (its width is a z-interval with the divisor-n standard deviation, expected coverage
    P(|t_19| < 1.96 sqrt(19/20)) = 0.928); measured 0.919, asserted within 2 points of 0.928."""
    c = coverage(normal_sampler, 1.0, experiments=1000, n=20, seed=0, method="percentile")
    assert abs(c - 0.928) <= 0.02, c
    assert c < 0.935


def test_studentized_interval_width_matches_t_interval():
    """For normal data the bootstrap-t interval approaches the Student-t interval
    mean +- t_(0.975, n-1) s / sqrt(n): the two half-widths agree within 10 % at n = 40
    (the bootstrap t-quantiles carry resampling error)."""
    x = np.random.default_rng(5).normal(0.0, 1.0, 40)
    ci = bootstrap_mean_ci(x, resamples=20000, seed=3)
    half = stats.t.ppf(0.975, 39) * np.std(x, ddof=1) / np.sqrt(40)
    assert (ci.high - ci.low) / 2 == pytest.approx(half, rel=0.10)
    assert ci.estimate == pytest.approx(np.mean(x), abs=1e-15)


def test_seeded_interval_is_bit_identical():
    """Same data and seed give the identical interval (exact); another seed a different one."""
    x = np.random.default_rng(2).normal(size=20)
    a, b = bootstrap_mean_ci(x, seed=7), bootstrap_mean_ci(x, seed=7)
    assert (a.low, a.high) == (b.low, b.high)
    c = bootstrap_mean_ci(x, seed=8)
    assert (c.low, c.high) != (a.low, a.high)


def test_paired_difference_cancels_shared_seed_effect():
    """a = s + 0.1, b = s with a large seed effect s (std 10): every paired difference is 0.1,
    so the interval is [0.1, 0.1] (to 1e-12) and the verdict is "better"; the unpaired
    intervals of a and b overlap and could not separate them."""
    s = np.random.default_rng(4).normal(0.0, 10.0, 20)
    d = paired_difference_ci(s + 0.1, s)
    assert d.estimate == pytest.approx(0.1, abs=1e-12)
    assert d.low == pytest.approx(0.1, abs=1e-12) and d.high == pytest.approx(0.1, abs=1e-12)
    assert verdict(d) == "better" and verdict(d, higher_is_better=False) == "worse"
    ia, ib = bootstrap_mean_ci(s + 0.1), bootstrap_mean_ci(s)
    assert ia.low < ib.high


def test_paired_difference_of_equal_policies_is_indistinguishable():
    """Two policies drawn from the same distribution, independent noise: the interval includes
    zero (verdict "indistinguishable") for this seed; its centre is the mean difference
    (1e-12)."""
    rng = np.random.default_rng(11)
    a, b = rng.normal(0.3, 0.05, 20), rng.normal(0.3, 0.05, 20)
    d = paired_difference_ci(a, b)
    assert d.estimate == pytest.approx(np.mean(a - b), abs=1e-12)
    assert verdict(d) == "indistinguishable"
    assert d.as_dict("zeta_diff")["zeta_diff_ci"] == [d.low, d.high]


def test_interquartile_mean_hand_computed():
    """Pooled scores 1, 2, 3, 4, 5, 6, 7, 100: the middle half is 3, 4, 5, 6, IQM 4.5 (exact)
    where the mean is 16. 10 values: floor(2.5) = 2 cut from each end, IQM of 1..10 = 5.5."""
    scores = np.array([[1.0, 2.0], [3.0, 4.0], [5.0, 6.0], [7.0, 100.0]])
    assert interquartile_mean(scores) == 4.5
    assert interquartile_mean(np.arange(1.0, 11.0)) == 5.5


def test_iqm_ci_stratified_keeps_tasks():
    """Task 0 scores all 0 and task 1 all 1: a stratified replicate keeps n of each, so every
    replicate's IQM is 0.5 and the interval is [0.5, 0.5] (exact). (Pooled resampling would
    mix the tasks and spread it.) A spread case: the interval contains the estimate."""
    scores = np.column_stack([np.zeros(8), np.ones(8)])
    ci = iqm_ci(scores, resamples=500)
    assert (ci.estimate, ci.low, ci.high) == (0.5, 0.5, 0.5)
    rng = np.random.default_rng(0)
    ci = iqm_ci(rng.normal(size=(20, 3)), resamples=500)
    assert ci.low < ci.estimate < ci.high


def test_probability_of_improvement_hand_computed():
    """Task 1: X = (1, 2, 3), Y = (2, 2, 0): of the 9 pairs X wins 1 + 1 + 3 = 5 and ties 2,
    P = (5 + 0.5 * 2) / 9 = 2/3. Task 2 all ties: 1/2. Average over tasks: 7/12 (1e-15)."""
    x = np.array([[1.0, 5.0], [2.0, 5.0], [3.0, 5.0]])
    y = np.array([[2.0, 5.0], [2.0, 5.0], [0.0, 5.0]])
    assert probability_of_improvement(x[:, :1], y[:, :1]) == pytest.approx(2.0 / 3.0, abs=1e-15)
    assert probability_of_improvement(x, y) == pytest.approx(7.0 / 12.0, abs=1e-15)
    # symmetry: P(X > Y) + P(Y > X) = 1 with ties split
    assert probability_of_improvement(y, x) == pytest.approx(5.0 / 12.0, abs=1e-15)


def test_probability_of_improvement_ci_separated():
    """X always above Y: P = 1 and every stratified replicate gives 1, interval [1, 1]."""
    x = np.full((10, 2), 2.0) + np.arange(10)[:, None] * 0.01
    y = np.zeros((10, 2))
    ci = probability_of_improvement_ci(x, y, resamples=300)
    assert (ci.estimate, ci.low, ci.high) == (1.0, 1.0, 1.0)


def test_hierarchical_bootstrap_carries_the_spread_between_training_seeds():
    """8 training seeds whose means scatter N(0, 1), 10 episodes each scattering 0.1 about
    their seed's mean: the population IQM is 0 (a symmetric mixture). Over 300 synthetic
    experiments (1000 resamples each) the 95 % interval that resamples training seeds, then
    episodes (groups=8), covers 0 in 90.0 % of them (asserted at least 85 %: 8 seeds give a
    percentile interval a little under nominal); the one that treats the 80 episodes as
    independent runs covers it in 47.7 % (asserted at most 60 %)."""
    rng = np.random.default_rng(1)
    covered = {1: 0, 8: 0}
    for k in range(300):
        means = rng.normal(size=8)
        s = (means[:, None] + 0.1 * rng.normal(size=(8, 10))).reshape(80, 1)
        for g in covered:
            ci = iqm_ci(s, resamples=1000, seed=k, groups=g)
            covered[g] += ci.low <= 0.0 <= ci.high
    assert covered[8] / 300 >= 0.85
    assert covered[1] / 300 <= 0.60
    x = np.full((10, 2), 2.0) + np.arange(10)[:, None] * 0.01
    ci = probability_of_improvement_ci(x, np.zeros((10, 2)), resamples=300, groups_x=5)
    assert (ci.estimate, ci.low, ci.high) == (1.0, 1.0, 1.0)
    with pytest.raises(StatsInputError, match="equal groups"):
        iqm_ci(np.zeros((10, 2)), groups=3)
    with pytest.raises(StatsInputError, match="equal groups"):
        iqm_ci(np.zeros((10, 2)), groups=10)


def test_bad_input_named():
    """A NaN entry, a length mismatch, a bad level or method: errors that name the problem."""
    with pytest.raises(StatsInputError, match="entry 2"):
        bootstrap_mean_ci([1.0, 2.0, np.nan])
    with pytest.raises(StatsInputError, match="equal length"):
        paired_difference_ci([1.0, 2.0], [1.0, 2.0, 3.0])
    with pytest.raises(StatsInputError, match="confidence"):
        bootstrap_mean_ci([1.0, 2.0], confidence=95)
    with pytest.raises(StatsInputError, match="method"):
        bootstrap_mean_ci([1.0, 2.0], method="normal")
    with pytest.raises(StatsInputError, match="same tasks"):
        probability_of_improvement(np.zeros((3, 2)), np.zeros((3, 1)))
