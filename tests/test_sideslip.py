"""The yaw-departure figures of the README ("Known limitation: yaw departures at large
sideslip"), measured by aerostat_gym.agents.sideslip (scripts/sideslip_departures.py)."""

import numpy as np
import pytest

from aerostat_gym.agents import sideslip as script


def test_sideslip_closed_form():
    """Sideslip of the body velocity relative to the air, exact to 1e-12 deg: 45 deg for equal
    forward and lateral components (level body), 0 deg flying nose-first at psi = 180 deg, 180 deg
    tail-first, and the sign of the lateral component ignored."""
    e0, e180 = np.zeros(3), np.array([0.0, 0.0, np.pi])
    v = np.array([[1.0, 1.0, 0.0], [1.0, -1.0, 0.0], [-3.0, 0.0, 0.0], [3.0, 0.0, 0.0]])
    got = script.sideslip(np.array([e0, e0, e180, e180]), v)
    assert got == pytest.approx([45.0, 45.0, 0.0, 180.0], abs=1e-12)


def test_static_yaw_moment_sign_structure():
    """At 8 m/s with the baseline stall angle (16 deg), the static yaw moment restores at yaw
    offsets of 5-15 deg and turns divergent at 20-60 deg (the flat post-stall fin lift); with a
    45 deg stall angle it restores at every offset (exact signs, as the README states)."""
    curve16 = dict(zip(script.OFFSETS_DEG, script.yaw_curve(16.0), strict=True))
    curve45 = script.yaw_curve(45.0)
    assert all(curve16[d] < 0 for d in (5, 10, 15))
    assert all(curve16[d] > 0 for d in (20, 30, 45, 60))
    assert curve16[80] < 0  # the second, side-on equilibrium lies between 60 and 80 deg
    assert all(v < 0 for v in curve45)
