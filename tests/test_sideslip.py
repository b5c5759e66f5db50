"""The sideslip figures of the README ("Large-angle fins, sideslip and the air-inertia force"),
measured by aerostat_gym.agents.sideslip (scripts/sideslip_departures.py)."""

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
    """At 8 m/s with [LN02]'s flat post-stall lift and the 2-D stall angle (16 deg), the static
    yaw moment restores at yaw offsets of 5-15 deg and turns divergent at 20-60 deg; with the
    baseline fins (Viterna-Corrigan beyond a 45 deg stall) it restores at every offset to
    90 deg (exact signs)."""
    flat = dict(zip(script.OFFSETS_DEG,
                    script.yaw_curve(8.0, {"fins.post_stall": "flat", "fins.alpha_stall_deg": 16.0}),
                    strict=True))
    assert all(flat[d] < 0 for d in (5, 10, 15))
    assert all(flat[d] > 0 for d in (20, 30, 45, 60))
    assert all(v < 0 for v in script.yaw_curve(8.0))
