"""Peer comparison with MoorDyn v2 (issue 2, item 5): static agreement of the tether alone.

Tolerances
----------
- Node positions: within 0.5 % of the tether length (the issue's target). Measured: ~1 cm,
  0.004 % of 300 m.
- End tensions: within 0.2 % (~7 N of ~3.45 kN). Both ends are fixed, so the tension follows
  from the settled shape; what differs between the codes is the air load: our normal loading
  function f_n is ~0.8 % below MoorDyn's sin^2 at the trim flow angle (~1 N of ~131 N of
  normal drag), the axial drag differs by ~0.5 N (loading function f_t vs CdAx cos^2), and
  MoorDyn adds the air buoyancy of the line (0.1 N). Together ~2 N, 0.06 % of the tension;
  0.2 % leaves a factor of three for the nodal vs element-midpoint drag lumping. Measured:
  0.03 % (top) and 0.02 % (bottom). A wrong EA, length or geometry would be far outside it
  (1 mm of stretch on the 300 m line is 3.5 N).
"""

from __future__ import annotations

import pytest

pytest.importorskip("moordyn")

from aerostat_gym.bench.moordyn import compare_with_moordyn  # noqa: E402

POSITION_TOL = 0.5  # % of the tether length (issue target)
TENSION_TOL = 2e-3  # relative, see the module docstring
INTEGRATORS = ("rk4", "semi-implicit")


@pytest.fixture(scope="module")
def quick():
    return compare_with_moordyn(quick=True)


def _check_static(res):
    for integ in INTEGRATORS:
        s = res["static"][integ]
        assert s["max_node_diff_pct_length"] < POSITION_TOL, (integ, s)
        assert s["position_target_met"]
        assert abs(s["top_tension_rel_diff"]) < TENSION_TOL, (integ, s["top_tension_N"])
        assert abs(s["bottom_tension_rel_diff"]) < TENSION_TOL, (integ, s["bottom_tension_N"])
        assert s["settle_drift_m"] < 0.01  # settled: the middle node moved < 1 cm in the last 5 s
    assert res["settle_drift_m"]["moordyn"] < 0.01


def test_static_agreement_quick(quick):
    _check_static(quick)


def test_moordyn_setup_quick(quick):
    """The comparison is set up as documented: the current acts (MoorDyn's x drag within 5 % of
    the crossflow estimate), MoorDyn's RK4 runs at our RK4 step, its RK2 at our safety factor
    times its linear bound (below the RK4 step), the default CFL step diverges within 1 s, and
    each speed ratio is the quotient of the two real-time factors it compares (1e-12)."""
    assert 0.95 < quick["current_check"]["ratio"] < 1.05
    md = quick["moordyn"]
    assert md["rk4"]["dt_s"] == quick["ours_tether"]["rk4"]["dt_s"]
    assert md["rk2"]["dt_s"] < md["rk4"]["dt_s"] < quick["moordyn_default"]["dt_s"]
    assert quick["moordyn_default"]["diverged_within_s"] <= 1.0
    ref = quick["moordyn_reference"]
    assert quick["moordyn_real_time_factor"] == md[ref]["real_time_factor"]
    for integ in INTEGRATORS:
        ratio = quick["ours_full_rtf"][integ] / quick["moordyn_real_time_factor"]
        assert quick["speed_ratio"][integ] == pytest.approx(ratio, rel=1e-12)
    assert "buoyancy" in quick["differences"]


@pytest.mark.slow
def test_full_comparison_60s():
    res = compare_with_moordyn(quick=False)
    _check_static(res)  # the speed ratio is a wall-clock figure: `aerostat-gym bench` reports it
