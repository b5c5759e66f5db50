"""The tools around the physics on aerostats other than the baseline: the stability table's
unstable modes, Figure 9's axes, and the fits' sampling limit."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from aerostat_gym.agents.metrics import fit_damped_sinusoid, fit_two_modes, mode_fit, nyquist_period
from aerostat_gym.analysis.figures import (
    FIGURE9_PERIOD_TOP,
    damping_limits,
    figure9_axes,
    figure9_data,
    isolated_points,
    period_limits,
)
from aerostat_gym.analysis.modes import wind_sweep
from aerostat_gym.cli import main
from aerostat_gym.params import load_params
from aerostat_gym.scaling import scale_aerostat

#: A hull efficiency past the 0.5 at which the baseline geometry turns yaw-divergent
#: (params.toml): the lateral pendulum splits into real eigenvalues, one of them positive.
DIVERGENT = {"hull.eta_k": 0.6}
#: Its growth rate at 10 m/s [1/s], the largest real part of the lateral A's eigenvalues there.
DIVERGENT_RATE_10 = 0.037979


def large_hull():
    """The baseline scaled to a 35 m hull (3600 m^3) on 1000 m of tether in 20 elements, as
    the audit's large35.toml: pendulums of 59-83 s (longitudinal) and 111-147 s (lateral)."""
    return scale_aerostat(load_params(), 3600.0 / 519.0, 1000.0, n_elements=20)


@pytest.fixture(scope="module")
def divergent_sweep():
    # 0 m/s first: there the lateral pendulum swings; at 10 m/s it splits into real
    # eigenvalues and the slowest, the growing one, is on the plain "pendulum" track (the
    # label's lowest-frequency mode at each speed, Table 2's; it was "pendulum (2)" before 0.7.14)
    return wind_sweep(load_params().replace(**DIVERGENT), [0.0, 10.0])


def damped(t, zeta: float, period: float, phase: float = 0.0) -> np.ndarray:
    """Free response e^{-zeta w_n t} cos(w_d t + phase) of a mode of natural period [s]."""
    wn = 2.0 * math.pi / period
    return np.exp(-zeta * wn * t) * np.cos(wn * math.sqrt(1.0 - zeta**2) * t + phase)


# --- defect 1: the unstable mode is always named --------------------------------------------------


def test_unstable_real_mode_is_named_with_its_eigenvalue(divergent_sweep):
    """The growing real eigenvalue is the largest real part of A_lat's eigenvalues at 10 m/s,
    named with its track, speed and eigenvalue; a real mode reports no period."""
    (entry,) = divergent_sweep.unstable()
    lam_lat = np.linalg.eigvals(divergent_sweep.analyses[1].decoupled.A_lat)
    assert (entry["set"], entry["label"], entry["values"]) == ("lat", "pendulum", [10.0])
    assert entry["worst"].eigenvalue.real == pytest.approx(float(lam_lat.real.max()), rel=1e-9)
    assert entry["worst"].eigenvalue.real == pytest.approx(DIVERGENT_RATE_10, rel=1e-4)
    row = entry["worst"].row()
    assert (row["zeta"], row["period_s"], row["oscillatory"]) == (-1.0, None, False)
    # time constant 1 / lambda of a real eigenvalue: 1 / 0.037979 = 26.3 s
    assert entry["worst"].describe() == "real (non-oscillatory), GROWS with time constant 26.3 s"


def test_stability_table_names_the_unstable_mode(capsys):
    """The UNSTABLE line names the track, the speed and the eigenvalue, and the table's
    lateral pendulum column shows the growing root at 10 m/s as real with zeta -1."""
    assert main(["stability", "--set", "hull.eta_k=0.6", "--wind", "0:10:10"]) == 0
    text = capsys.readouterr().out
    assert "all modes stable at every speed: False" in text
    assert ("UNSTABLE lateral pendulum at U = 10 m/s; fastest at 10 m/s: lambda = +0.03798 "
            "1/s, real (non-oscillatory), GROWS with time constant 26.3 s") in text
    assert main(["stability", "--set", "hull.eta_k=0.6", "--wind", "0:10:10", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    (unstable,) = out["unstable_modes"]
    assert (unstable["label"], unstable["wind_speeds_m_s"], unstable["period_s"]) == (
        "pendulum", [10.0], None)
    real_rows = [r for r in out["modes"] if not r["oscillatory"]]
    assert len(real_rows) == 6 and all(r["period_s"] is None for r in real_rows)


def test_stable_baseline_names_no_unstable_mode():
    sweep = wind_sweep(load_params(), [10.0])
    assert sweep.all_stable() and sweep.unstable() == []


# --- defect 2: Figure 9's axes follow the data ----------------------------------------------------


def _figure9(params):
    """Figure 9 data on the stability command's default sweep (0-20 m/s, 0.5 m/s steps) and
    its (figure, axes)."""
    data = figure9_data(wind_sweep(params, np.arange(0.0, 20.01, 0.5)))
    return data, figure9_axes(data)[1]


def _legend(ax) -> list[str]:
    return [text.get_text() for text in ax.get_legend().get_texts()]


def test_figure9_axes_hold_every_point_of_a_35m_hull():
    """A 35 m hull's pendulums (up to 83 s longitudinal, 147 s lateral at 0-20 m/s) lie above
    [LN02]'s 50 s and 100 s axes: both widen to the next round value that holds them, and
    every period and damping ratio plotted lies inside its axis, but for the yaw mode's
    low-wind end (350 s at 0.5 m/s, a weathervane losing its U^2 stiffness), which its legend
    names."""
    data, axes = _figure9(large_hull())
    expected = {"long": (0.0, 100.0), "lat": (0.0, 200.0)}
    for col, subset in enumerate(("long", "lat")):
        for row, quantity in enumerate(("period_s", "zeta")):
            lo, hi = axes[row, col].get_ylim()
            for label, curves in data[subset].items():
                values = [v for v in curves[quantity] if v is not None]
                if label == "yaw" and quantity == "period_s":
                    values = [v for v in values if v <= 200.0]
                assert lo <= min(values) and max(values) <= hi, (subset, label, quantity)
        assert axes[0, col].get_ylim() == expected[subset]
        assert axes[1, col].get_ylim() == (0.0, 1.0)
    assert _legend(axes[0, 1])[-1] == "yaw (to 350 s, off scale)"
    assert max(v for v in data["lat"]["yaw"]["period_s"] if v is not None) == pytest.approx(
        350.3, abs=0.1)
    assert max(v for v in data["lat"]["pendulum"]["period_s"] if v is not None) == pytest.approx(
        147.2, abs=0.1)


def test_baseline_figure9_keeps_the_papers_axes():
    """The baseline's curves fit [LN02]'s axes (pendulums 45 s and 80 s): 0-50 s, 0-100 s,
    damping 0-1, as the stored docs/img/figure9.png; its yaw's 183 s at 0.5 m/s is named."""
    _, axes = _figure9(load_params())
    assert [axes[0, col].get_ylim() for col in (0, 1)] == [(0.0, 50.0), (0.0, 100.0)]
    assert [axes[1, col].get_ylim() for col in (0, 1)] == [(0.0, 1.0), (0.0, 1.0)]
    assert _legend(axes[0, 1]) == ["pendulum", "rolling", "tether 1st harmonic",
                                   "tether 2nd harmonic", "yaw (to 183 s, off scale)"]


def test_figure9_axes_keep_the_papers_range_when_the_data_fit():
    assert period_limits([[44.9, 2.9, None, 1.2]], FIGURE9_PERIOD_TOP["long"]) == (0.0, 50.0)
    assert period_limits([[60.3, float("nan")]], FIGURE9_PERIOD_TOP["lat"]) == (0.0, 100.0)
    assert damping_limits([[0.0, 0.61], [None]]) == (0.0, 1.0)
    # a negative damping ratio (unstable) widens the bottom to a round value: -0.05 -> -0.1
    assert damping_limits([[-0.05, 0.3]]) == (-0.1, 1.0)


# --- defect 4: no fitted period below the sampling's Nyquist limit --------------------------------


def test_fit_of_a_period_below_two_samples_is_nan():
    t = np.arange(0.0, 30.0, 0.2)
    fit = fit_damped_sinusoid(t, damped(t, 0.0, 0.1))
    assert math.isnan(fit.period) and math.isnan(fit.zeta) and not fit.ok


def test_fit_of_a_resolved_period_is_exact():
    t = np.arange(0.0, 30.0, 0.2)
    fit = fit_damped_sinusoid(t, damped(t, 0.1, 3.0))
    assert fit.period == pytest.approx(3.0, abs=1e-6)
    assert fit.zeta == pytest.approx(0.1, abs=1e-6)


def test_mode_fit_refuses_a_natural_period_the_samples_cannot_hold():
    """small7 at 15 m/s, passive: the pitch fit read T = 0.16 s, zeta 0.917 from a 0.2 s
    record; its damped period (0.40 s) passes the fits' bound w_d <= pi / dt, its natural
    period does not."""
    wn = 2.0 * math.pi / 0.16
    fit = mode_fit(1.0, 0.0, 0.917 * wn, wn * math.sqrt(1.0 - 0.917**2), 0.0, 0.9, 0.2)
    assert nyquist_period(0.2) == 0.4
    assert math.isnan(fit.period) and math.isnan(fit.zeta) and fit.r2 == 0.9
    assert fit.reason == ("fitted natural period 0.16 s is below the sampling's shortest, "
                          "2 dt = 0.4 s (unresolved)")


@pytest.mark.parametrize("dt, pitch_ok", [(0.2, False), (0.05, True)])
def test_two_mode_pitch_fit_at_and_above_nyquist(dt, pitch_ok):
    """small7's linear modes at 15 m/s, pendulum 6.8 s (zeta 0.36) under pitching 0.40 s
    (zeta 0.35): at 0.2 s the pitching mode sits on the Nyquist period and is n/a; at 0.05 s
    both modes come back."""
    t = np.arange(0.0, 30.0, dt)
    y = damped(t, 0.36, 6.8) + 0.3 * damped(t, 0.35, 0.40, phase=1.0)
    slow, fast = fit_two_modes(t, y, (0.36, 6.8), 0.427)
    assert slow.period == pytest.approx(6.8, abs=0.01) and slow.zeta == pytest.approx(0.36, abs=0.01)
    if pitch_ok:
        assert fast.period == pytest.approx(0.40, abs=0.01)
        assert fast.zeta == pytest.approx(0.35, abs=0.01)
    else:
        assert math.isnan(fast.period) and "below the sampling's shortest" in fast.reason


def test_isolated_points_are_the_values_with_no_finite_neighbour():
    v = np.array([1.0, np.nan, 2.0, 3.0, np.nan, 4.0, np.nan, np.nan])
    np.testing.assert_array_equal(isolated_points(v),
                                  [True, False, False, False, False, True, False, False])


def test_figure9_marks_a_mode_found_at_one_speed():
    """A mode present at one speed of the sweep (a line through NaN neighbours draws nothing)
    is drawn as a marker at its value, in its curve's colour, and adds no legend entry."""
    data = {"wind_speed_m_s": [0.0, 5.0, 10.0],
            "long": {"pendulum": {"period_s": [None, 41.5, None], "zeta": [None, 0.12, None]}},
            "lat": {"pendulum": {"period_s": [80.0, 81.0, 82.0], "zeta": [0.1, 0.2, 0.3]}}}
    _, axes = figure9_axes(data)
    for row, value in ((0, 41.5), (1, 0.12)):
        marked = [line for line in axes[row, 0].get_lines() if line.get_marker() == "o"]
        assert len(marked) == 1
        assert list(marked[0].get_xdata()) == [5.0] and list(marked[0].get_ydata()) == [value]
        assert marked[0].get_color() == axes[row, 0].get_lines()[0].get_color()
    assert not [line for line in axes[0, 1].get_lines()
                if line.get_marker() == "o" and len(line.get_xdata())]
    assert _legend(axes[0, 0]) == ["pendulum"]


def test_figure9_axes_shrink_to_a_7m_hull():
    """A 7 m hull on 60 m (pendulums of at most 20.2 s longitudinal and 36.3 s lateral, under
    half the paper's 50 s and 100 s): the axes come down to the round value 5 % above them,
    25 s and 50 s, and every plotted period lies inside (on the paper's axes its pitching and
    tether modes lay on the floor)."""
    data, axes = _figure9(scale_aerostat(load_params(), (7.0 / 18.3) ** 3, 60.0, 5))
    assert [axes[0, col].get_ylim() for col in (0, 1)] == [(0.0, 25.0), (0.0, 50.0)]
    for col, subset in enumerate(("long", "lat")):
        top = axes[0, col].get_ylim()[1]
        for label, curves in data[subset].items():
            if label != "yaw":
                assert max(v for v in curves["period_s"] if v is not None) <= top, label
