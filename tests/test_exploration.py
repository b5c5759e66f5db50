"""What a residual's exploration puts through the command path (aerostat_gym.agents.exploration),
against closed forms: the AR(1) low-pass variance, a deadband wider than any command, the
residual's scale without a filter."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from aerostat_gym.agents.exploration import exploration_reach, lowpass_noise_gain
from aerostat_gym.agents.sb3io import CommandShaper, lowpass_gain


def test_lowpass_noise_gain_closed_form():
    assert lowpass_noise_gain(1.0) == 1.0  # no filter: the input itself
    alpha = lowpass_gain(1.0, 0.2)  # the shipped residual's 1 s filter at 0.2 s steps
    assert lowpass_noise_gain(alpha) == pytest.approx(math.sqrt(alpha / (2 - alpha)), rel=1e-15)
    assert lowpass_noise_gain(alpha) == pytest.approx(0.3157, abs=1e-4)
    for bad in (0.0, -0.1, 1.5, float("nan")):
        with pytest.raises(ValueError, match="alpha"):
            lowpass_noise_gain(bad)


def test_reach_through_the_lowpass_matches_the_ar1_variance():
    """No deadband, no clipping in play: the RMS set-point change is scale sigma
    sqrt(alpha / (2 - alpha)) (the filter's start transient is 20 steps of 40 000)."""
    shaper = CommandShaper(0.1, deadband=0.0, lowpass=1.0, dt=0.2)
    n, sigma = 40_000, 0.13
    out = exploration_reach(shaper, np.zeros(n), np.zeros(n), sigma, np.random.default_rng(1))
    expected = 0.1 * sigma * lowpass_noise_gain(shaper.alpha)
    assert out["rms"] == pytest.approx(expected, rel=0.02)
    assert out["changed"] == 1.0
    assert out["rms_mean_command"] == 0.0


def test_no_filter_passes_scale_times_sigma():
    shaper = CommandShaper(0.5, deadband=0.0, lowpass=0.0, dt=0.2)
    n, sigma = 40_000, 0.2  # 5 sigma from the clip at 1: clipping is negligible
    out = exploration_reach(shaper, np.full(n, 0.3), np.zeros(n), sigma, np.random.default_rng(2))
    assert out["rms"] == pytest.approx(0.5 * sigma, rel=0.02)
    assert out["rms_mean_command"] == pytest.approx(0.3, rel=1e-6)


def test_a_deadband_wider_than_every_command_hides_all_exploration():
    """scale 0.1 bounds the residual's part at 0.1 top speeds; a base of 0.05 and a deadband of
    0.2 keep every filtered command under it: the brake holds whatever is sampled."""
    shaper = CommandShaper(0.1, deadband=0.2, lowpass=1.0, dt=0.2)
    n = 5_000
    out = exploration_reach(shaper, np.full(n, 0.05), np.zeros(n), 1.0, np.random.default_rng(3))
    assert out == {"changed": 0.0, "rms": 0.0, "rms_mean_command": 0.0}


def test_bad_episodes_are_refused():
    shaper = CommandShaper(0.1, lowpass=1.0)
    rng = np.random.default_rng(0)
    with pytest.raises(ValueError, match="equal-length"):
        exploration_reach(shaper, np.zeros(3), np.zeros(4), 0.1, rng)
    with pytest.raises(ValueError, match="sigma"):
        exploration_reach(shaper, np.zeros(3), np.zeros(3), -1.0, rng)


def test_script_on_the_shipped_policy(load_script, capsys):
    """One episode of the training task: the shipped policy's own spread is listed first, and
    its measured RMS change lies within a factor 2 of the closed form (the deadband's
    crossings add to it, the clip takes nothing at sigma 0.13)."""
    assert load_script("exploration_reach").main(["--seeds", "1", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    own = info["rows"][0]
    assert own["own"] and 0.05 < own["sigma"] < 0.5
    assert 0.5 * own["closed_form_rms"] < own["rms"] < 2.0 * own["closed_form_rms"]
