"""Dwell-time brake logic (aerostat_gym.winch_dwell): step-by-step known answers, equivalence
to the shipped rule at zero dwell, and the LQR's small-swing damping it recovers. Every
assertion states its tolerance.
"""

import itertools

import numpy as np
import pytest

from aerostat_gym.agents.frontier import swing_response, swing_response_dwell
from aerostat_gym.agents.lqr import LQRPolicy, LQRSchedule
from aerostat_gym.params import load_params
from aerostat_gym.sim.winch import brake_rule
from aerostat_gym.sim.winch_dwell import DwellBrake, dwell_brake_rule

VMAX, BAND, HOLD, DT = 1.0, 0.02, 0.02, 0.2


def test_small_command_passes_until_dwell():
    """A steady 0.01 m/s command (inside the 0.02 m/s band), dwell 1 s at 0.2 s steps: steps
    1-4 send 0.01 m/s to the speed loop, step 5 (quiet = 1.0 s) applies the brake, which clamps
    the drum (v_w = 0.01 <= hold speed) and keeps it while the command stays small."""
    braked, v_w, quiet, out = False, 0.01, 0.0, []
    for _ in range(7):
        v_set, braked, v_w, quiet = dwell_brake_rule(0.01, False, braked, v_w, quiet, DT, VMAX,
                                                     BAND, HOLD, 1.0)
        out.append((v_set, braked))
        v_w = 0.01 if not braked else v_w
    assert out[:4] == [(0.01, False)] * 4
    assert out[4:] == [(0.0, True)] * 3


def test_zero_command_brakes_at_once_and_large_command_releases():
    """Action 0 keeps its meaning (the braked winch) on the first step; a command at or above
    the band releases the brake and restarts the stand-still clock (exact values)."""
    v_set, braked, v_w, quiet = dwell_brake_rule(0.0, False, False, 0.0, 0.0, DT, VMAX, BAND,
                                                 HOLD, 10.0)
    assert (v_set, braked, v_w) == (0.0, True, 0.0)
    v_set, braked, v_w, quiet = dwell_brake_rule(0.5, False, True, 0.0, 7.0, DT, VMAX, BAND,
                                                 HOLD, 10.0)
    assert (v_set, braked, quiet) == (0.5, False, 0.0)
    v_set, braked, _, _ = dwell_brake_rule(2.0, False, False, 0.3, 0.0, DT, VMAX, BAND, HOLD,
                                           10.0)
    assert (v_set, braked) == (1.0, False)  # clipped to max_speed


def test_zero_dwell_is_the_shipped_rule():
    """With dwell 0 the rule returns exactly what aerostat_gym.winch.brake_rule returns, over a
    grid of set-points, brake commands, brake states and reel speeds."""
    grid = itertools.product([-1.5, -0.3, -0.019, -0.005, 0.0, 0.01, 0.02, 0.4, 1.2],
                             [False, True], [False, True], [-0.5, -0.01, 0.0, 0.015, 0.3])
    for v, cmd, braked, v_w in grid:
        got = dwell_brake_rule(v, cmd, braked, v_w, 0.0, DT, VMAX, BAND, HOLD, 0.0)[:3]
        assert got == brake_rule(v, cmd, braked, v_w, VMAX, BAND, HOLD), (v, cmd, braked, v_w)


def test_python_filter_matches_compiled_rule():
    """DwellBrake (the set-point filter for simulate) asks for the brake on the same steps the
    compiled rule wants it, for a decaying oscillating command (exact)."""
    t = np.arange(300) * DT
    cmd = 0.05 * np.exp(-t / 20.0) * np.cos(2 * np.pi * t / 40.0)
    filt, quiet = DwellBrake(BAND, DT, 10.0), 0.0
    for v in cmd:
        want_py = filt(float(v))[1] == 1.0
        quiet = quiet + DT if abs(v) < BAND else 0.0
        assert want_py == (v == 0.0 or (abs(v) < BAND and quiet >= 10.0 - 1e-9))
    with pytest.raises(ValueError, match="dwell"):
        DwellBrake(BAND, DT, -1.0)


def test_lqr_small_swing_damping_recovered():
    """10 m/s, 0.5 m swing: with the shipped dead band the LQR's commands (below 0.02 m/s) are
    swallowed and its damping falls to the braked winch's (measured 0.281); with the proposed
    dwell brake (10 s inside 0.002 m/s) the sinusoid-plus-drift fit gives 0.343 against the
    linear prediction 0.344: asserted within 5 % of the prediction and 0.01 of 0.343."""
    params = load_params()
    sch = LQRSchedule(params, speeds=np.array([10.0]))
    pol = LQRPolicy(params, schedule=sch)
    pred = sch.designs[0].mode("pendulum").zeta
    dead = swing_response(pol, 10.0, 0.5)
    dwell = swing_response_dwell(pol, 10.0, 0.5)
    assert dead.zeta == pytest.approx(0.281, abs=0.01)
    assert dwell.zeta_drift == pytest.approx(0.343, abs=0.01)
    assert dwell.zeta_drift == pytest.approx(pred, rel=0.05)
    # 99.4 % of the commands lie inside the old dead band (peak 0.030 m/s on the first step)
    assert np.mean(np.abs(dwell.set_point) < 0.02) > 0.95


def test_standstill_band_must_be_small():
    """15 m/s, 0.5 m swing, LQR, dwell 10 s: with the old 0.02 m/s band as the stand-still band
    the brake sets in the tail and the drift-fit damping is 0.384 (37 % under the prediction
    0.611); with the proposed 0.002 m/s band 0.592 (3 % under). Asserted: the first more than
    20 % under, the second within 20 % (and each within 0.01 of its measured value)."""
    params = load_params()
    sch = LQRSchedule(params, speeds=np.array([15.0]))
    pol = LQRPolicy(params, schedule=sch)
    pred = sch.designs[0].mode("pendulum").zeta
    wide = swing_response_dwell(pol, 15.0, 0.5, band=0.02)
    narrow = swing_response_dwell(pol, 15.0, 0.5)
    assert wide.zeta_drift == pytest.approx(0.384, abs=0.01) and wide.zeta_drift < 0.8 * pred
    assert narrow.zeta_drift == pytest.approx(0.592, abs=0.01)
    assert narrow.zeta_drift == pytest.approx(pred, rel=0.20)
