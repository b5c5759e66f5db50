"""Dynamic comparison with MoorDyn v2 (issue 20): the tether with its top end driven.

Tolerances
----------
- Prescribed paths: closed forms of the sine and cosine ramps and the linear reel, to 1e-12.
- The top end placed on the path: the confluence point (CM + R r_l) lands on the path to 1e-9 m.
- Drag and segment rules used by the switches: closed forms on a straight vertical line in a
  uniform 10 m/s crossflow (0.5 rho Cd d l U^2 = 13.23 N per inner node, both laws, since our
  f_n(90 deg) = 1) and on single elements (EA strain, c* ldot), to 1e-9 relative.
- Smoke run (across the wind, tether harmonic 1.68 s, 1 m, 10 s window): RK4 node positions
  within 0.05 % of L (measured 0.015 %) and tensions within 0.2 % RMS (measured 0.03 %), ten and
  sixty times inside the issue's bounds (0.5 %, 2 %); the semi-implicit scheme within 1 %
  (measured 0.49 %: its first-order error at 50 ms on a 0.84 s tension harmonic). With
  MoorDyn's nodal drag switched in on our side the two codes solve the same equations, and agree
  to 0.01 % (measured 0.002 %): what is left is time discretization.
- Full table (slow): the issue's bounds for RK4 in every non-slack case, every horizontal case
  non-slack, and every case outside the bounds brought to within 5 % by switching MoorDyn's drag
  and slack rule in on our side (measured: 0.04 % to 4.1 %; the largest residuals are in the two
  snap-load cases where MoorDyn's own dt/2 check differs by 1.5 % and 2.9 %).
"""

from __future__ import annotations

import contextlib
import io
import json
import math

import numpy as np
import pytest

from aerostat_gym.bench import moordyn_dynamic as B
from aerostat_gym.bench.moordyn import RHO_AIR
from aerostat_gym.bench.moordyn_dynamic.driven import _place_top
from aerostat_gym.cli import main
from aerostat_gym.physics.integrators import OK
from aerostat_gym.sim import BRAKED

L = 300.0


def _path(case, top=(20.0, 0.0, 300.0)):
    return case.pack(np.array(top), np.zeros(3), L)


def test_sine_path_closed_form():
    case = B.DrivenCase("s", B.SINE, (2.0, 0.0, 0.0), amplitude=5.0, period=2.0)
    p = _path(case)
    t = 0.3
    s, sd = B.path_displacement(p, t)
    assert s == pytest.approx(5.0 * math.sin(math.pi * t), rel=1e-12)
    assert sd == pytest.approx(5.0 * math.pi * math.cos(math.pi * t), rel=1e-12)
    assert B.path_displacement(p, -1.0) == (0.0, 0.0)  # held before the drive
    np.testing.assert_allclose(p[B.K_DIR:B.K_DIR + 3], [1.0, 0.0, 0.0])  # normalized
    assert case.window_start == 2.0 and case.duration == 62.0


def test_drop_path_closed_form():
    p = _path(B.drop_case())  # 20 m in 2 s, hold 3 s, back up in 4 s
    s, sd = B.path_displacement(p, 1.0)  # mid-fall: half depth, peak speed pi D / (2 T)
    assert s == pytest.approx(-10.0, rel=1e-12)
    assert sd == pytest.approx(-20.0 * math.pi / 4.0, rel=1e-12)
    assert B.path_displacement(p, 3.0) == (-20.0, 0.0)
    s, sd = B.path_displacement(p, 7.0)  # mid-rise
    assert s == pytest.approx(-10.0, rel=1e-12)
    assert sd == pytest.approx(20.0 * math.pi / 8.0, rel=1e-12)
    assert B.path_displacement(p, 9.5) == (0.0, 0.0)


def test_reel_length_closed_form():
    p = _path(B.DrivenCase("r", B.REEL, reel_speed=1.0, reel_time=10.0))
    assert B.path_length(p, 4.0) == (pytest.approx(304.0, rel=1e-12), 1.0)
    assert B.path_length(p, 25.0) == (pytest.approx(310.0, rel=1e-12), 0.0)
    assert B.path_displacement(p, 4.0) == (0.0, 0.0)  # the top end is held


@pytest.fixture(scope="module")
def setup():
    return B.prepare(settle=10.0)


def test_top_end_on_the_path(setup):
    case = B.DrivenCase("s", B.SINE, (0.0, 0.0, 1.0), amplitude=5.0, period=3.0)
    path = case.pack(setup.top, setup.lever, L)
    x = setup.x_settled.copy()
    m = setup.model
    h = B.OUTPUT_DT / B.RK4_SUBSTEPS
    assert B.driven_rk4(x, 0.0, h, 90, path, BRAKED, m.p, m.wp, m.wf, m.work, B.NO_SWAP) == OK
    t = 90 * h
    expected = setup.top + np.array([0.0, 0.0, 5.0 * math.sin(2.0 * math.pi * t / 3.0)])
    np.testing.assert_allclose(m.node_positions(x)[0], expected, atol=1e-9)
    vel = x[m.layout.cm_vel]
    np.testing.assert_allclose(vel, [0.0, 0.0, 5.0 * 2.0 * math.pi / 3.0
                                     * math.cos(2.0 * math.pi * t / 3.0)], atol=1e-9)


def test_held_top_stays_settled(setup):
    # zero amplitude: the settled tether stays where it is (the 10 s settle leaves < 2 cm of
    # drift; a wrong lever or velocity would move the top end and the nodes by metres)
    path = B.DrivenCase("hold", B.SINE, period=1.0).pack(setup.top, setup.lever, L)
    m = setup.model
    x = setup.x_settled.copy()
    B.driven_rk4(x, 0.0, 0.005, 1000, path, BRAKED, m.p, m.wp, m.wf, m.work, B.NO_SWAP)
    moved = np.abs(m.node_positions(x) - m.node_positions(setup.x_settled)).max()
    assert moved < 0.02


def _vertical_line(setup):
    """The model's state with the top end 300.3 m straight above the anchor, at rest."""
    m = setup.model
    top = np.array([0.0, 0.0, 300.3])
    x = setup.x_settled.copy()
    _place_top(x, m.layout.cm_pos.start, B.DrivenCase("v", B.SINE, period=1.0)
                 .pack(top, setup.lever, L), 0.0, 0.0)
    n = m.n
    for k in range(1, n):
        x[3 * (k - 1):3 * k] = top * (1.0 - k / n)
    x[3 * (n - 1):6 * (n - 1)] = 0.0
    return x, m._forces(x).copy()


def test_node_drag_laws_closed_form(setup):
    x, w = _vertical_line(setup)
    m, swap = setup.model, setup.swap
    q = 0.5 * RHO_AIR * 1.2 * 0.006 * 30.0 * 10.0**2  # 13.23 N on each inner node
    for j in (1, 5, 9):
        np.testing.assert_allclose(B.moordyn_node_drag(x, m.p, w, j, swap), [q, 0.0, 0.0],
                                   rtol=1e-9, atol=1e-9)
        # ours: f_n(90 deg) = 1 exactly; the fitted f_t is 7e-5 (not 0) at 90 deg, along -z
        np.testing.assert_allclose(B.our_node_drag(x, m.p, w, j), [q, 0.0, 0.0],
                                   rtol=1e-9, atol=1e-4 * q)
    # the end nodes carry half a segment
    np.testing.assert_allclose(B.moordyn_node_drag(x, m.p, w, 0, swap)[0], 0.5 * q, rtol=1e-9)


def test_segment_rule_closed_form(setup):
    x, w = _vertical_line(setup)
    m = setup.model
    d = setup.params.derived
    l_u = L / m.n
    # stretched and at rest: both rules give EA (l / l_u - 1)
    T, *_ = B.moordyn_segment_tension(x, m.p, w, 4)
    assert T == pytest.approx(d.EA * (300.3 / 300.0 - 1.0), rel=1e-9)
    assert T == pytest.approx(m.tensions(x)[4], rel=1e-9)
    # node 5 pushed up 0.2 m (element 4 slack) and moving up at 1 m/s: MoorDyn's dashpot
    # pushes with c* ldot = -c* (element 4 shortens), ours carries nothing
    n = m.n
    x[3 * 4 + 2] += 0.2
    x[3 * (n - 1) + 3 * 4 + 2] = 1.0
    w = m._forces(x).copy()
    T, *_ = B.moordyn_segment_tension(x, m.p, w, 4)
    assert T == pytest.approx(-d.dashpot * 1.0, rel=1e-9)
    assert d.dashpot * l_u == pytest.approx(d.damping_b, rel=1e-12)  # BA = b = c* l_u
    assert m.tensions(x)[4] == 0.0


def test_harmonic_and_correlation_lags():
    t = np.arange(0.0, 60.0, 0.05)
    w = 2.0 * math.pi / 2.0
    ref = 3.0 + 2.0 * np.sin(w * t)
    lag = B.harmonic_lag(3.0 + 2.0 * np.sin(w * (t - 0.1)), ref, t, 2.0)
    assert lag["harmonic"] == 1
    assert lag["lag_s"] == pytest.approx(0.1, abs=1e-9)
    assert lag["lag_deg"] == pytest.approx(18.0, abs=1e-6)
    # a response at twice the drive frequency (motion across the wind)
    lag2 = B.harmonic_lag(np.sin(2.0 * w * (t + 0.05)), np.sin(2.0 * w * t), t, 2.0)
    assert lag2["harmonic"] == 2 and lag2["lag_s"] == pytest.approx(-0.05, abs=1e-9)
    pulse = np.exp(-((t - 20.0) / 0.8) ** 2)
    later = np.exp(-((t - 20.13) / 0.8) ** 2)
    assert B.correlation_lag(later, pulse, 0.05) == pytest.approx(0.13, abs=0.005)


def test_bad_input_is_named():
    with pytest.raises(B.DynamicBenchError, match="unknown variant 'nope'"):
        B.prepare("nope")
    with pytest.raises(B.DynamicBenchError, match="settle"):
        B.prepare(settle=-1.0)
    with pytest.raises(B.DynamicBenchError, match="repeats"):
        B.run_dynamic_comparison(repeats=0)


# --- against MoorDyn ------------------------------------------------------------------------

POSITION_TOL = 0.05  # % of L, smoke case (measured 0.015)
TENSION_TOL = 0.2  # % RMS, smoke case (measured 0.03)


@pytest.fixture(scope="module")
def quick_cli():
    pytest.importorskip("moordyn")
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(["bench", "--moordyn-dynamic", "--quick", "--json"]) == 0
    return json.loads(buf.getvalue())


def test_smoke_agreement(quick_cli):
    row = quick_cli["rows"]["baseline"]["across-harmonic-1m"]
    assert not row["is_slack"]
    r, si = row["rk4"], row["semi-implicit"]
    assert r["pos_max_pct"] < POSITION_TOL, r
    assert r["top_rms_pct"] < TENSION_TOL and r["bottom_rms_pct"] < TENSION_TOL, r
    assert row["within_targets"]
    assert r["top_harmonic"] == 2  # across the wind the tension swings at twice the drive
    assert abs(r["top_lag_deg"]) < 5.0  # measured ~1 deg of the 0.84 s harmonic
    assert si["top_rms_pct"] < 1.0 and si["pos_max_pct"] < 0.5, si


def test_same_equations_agree_to_time_discretization():
    pytest.importorskip("moordyn")
    res = B.run_dynamic_comparison(quick=True, variants=("moordyn_drag",), explain=False)
    r = res["rows"]["moordyn_drag"]["across-harmonic-1m"]["rk4"]
    assert r["pos_max_pct"] < 1e-3 and r["top_rms_pct"] < 0.01, r


@pytest.mark.slow
def test_full_table_targets():
    pytest.importorskip("moordyn")
    res = B.run_dynamic_comparison()
    rows = res["rows"]["baseline"]
    assert len(rows) == 20
    for name, row in rows.items():
        if name.startswith(("along", "across")):
            assert not row["is_slack"], name  # horizontal motion keeps the line taut
        if not row["is_slack"]:
            assert row["within_targets"], (name, row["rk4"])
    for name, row in res["explained"]["moordyn_drag_and_slack_rule"].items():
        r = row["rk4"]
        assert r["pos_max_pct"] < 0.5 and max(r["top_rms_pct"], r["bottom_rms_pct"]) < 5.0, (name, r)
