"""Linear stability analysis ([LN02] section 3): linearization, decoupling, modes, Table 2,
Figures 8 and 9, sensitivity, CLI and timing. Every assertion states its tolerance.

Measured values quoted in the docstrings are for the shipped baseline parameters.
"""

import argparse
import json
import math

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from aerostat_gym.analysis.figures import (
    FIG8_HEADINGS,
    FIG8_VARIABLES,
    figure8_data,
    figure8_decomposition,
    figure8_readings,
    figure9_data,
    write_figure9,
)
from aerostat_gym.analysis.linear import ACTUATORS, decouple, linearize
from aerostat_gym.analysis.modes import (
    FIGURE9_MODES,
    NEUTRAL_RATE,
    SETS,
    Mode,
    count_modes,
    damp_quantities,
    energy_vector,
    mac,
    mode_context,
    wind_sweep,
)
from aerostat_gym.analysis.reference import (
    TABLE2,
    reference_periods,
    table2,
    tether_harmonic_frequency,
    tether_mass_periods,
)
from aerostat_gym.analysis.sensitivity import default_knobs, solve_for_period, stability_figures
from aerostat_gym.analysis.trim import TrimLimitError, find_equilibrium
from aerostat_gym.bench.linear import bench_sweep
from aerostat_gym.cli.stability import _fmt, add_stability_parsers, parse_speeds
from aerostat_gym.params import load_params

control = pytest.importorskip("control")


@pytest.fixture(scope="module")
def base():
    return load_params()


@pytest.fixture(scope="module")
def sweep(base):
    """[LN02] Figure 9 sweep: 41 speeds, 0..20 m/s, L = 300 m, theta_0 = -4 deg."""
    return wind_sweep(base)


def _at(sweep, u):
    return sweep.analyses[int(np.argmin(np.abs(sweep.values - u)))]


def _match(a, b):
    """Pair two eigenvalue sets (Hungarian method on |a_i - b_j|); returns |a - b| / |a|."""
    cost = np.abs(a[:, None] - b[None, :])
    r, c = linear_sum_assignment(cost)
    return cost[r, c] / np.abs(a[r])


# --- linearization and decoupling ---------------------------------------------------------------


def test_state_and_mode_counts(sweep):
    """n = 10: 66 mechanical states, A_long of order 42 = 4n+2, A_lat of order 24 = 2n+4, and
    33 modes (complex pairs, real eigenvalues counted in pairs) as in [LN02] (exact)."""
    for u in (0.0, 1.0, 20.0):
        a = _at(sweep, u)
        assert a.linear.A.shape == (66, 66)
        assert a.decoupled.A_long.shape == (42, 42)
        assert a.decoupled.A_lat.shape == (24, 24)
        assert count_modes(a.long) + count_modes(a.lat) == 33


def test_coupling_blocks_vanish(sweep):
    """Lower-left (long -> lat) and upper-right (lat -> long) blocks of the reordered A are
    below 1e-8 of max |A_ij| at every speed ([LN02]: zero and ~1e-8). Measured <= 3e-11."""
    for a in sweep.analyses:
        r = a.decoupled.ratios
        assert r["ll_max"] <= 1e-8 and r["ul_max"] <= 1e-8, (a.wind_speed, r)


def test_linearization_insensitive_to_step(base):
    """Eigenvalues of the modes below 1 Hz agree between eps = 1e-5 and 10 eps to 1e-4
    relative (measured: 7.9e-5 at U = 0, where the quadratic drag |v| v is not differentiable
    and central differences leave an O(eps) damping; <= 4e-6 in wind). The neutral zero-wind
    yaw pair (|lambda| < 1e-3) is excluded."""
    eq = None
    for u in (0.0, 1.0, 10.0):
        eq = find_equilibrium(base, u, guess=eq)
        a = np.linalg.eigvals(linearize(base, eq, 1e-5).A)
        b = np.linalg.eigvals(linearize(base, eq, 1e-4).A)
        sel = a[(np.abs(a) < 2 * np.pi) & (np.abs(a) > 1e-3)]
        assert sel.size >= 14
        assert np.max(_match(sel, b)) <= 1e-4, u


def test_eigenvalues_equal_python_control(sweep):
    """control.ss(A, ...).poles() and control.damp equal our eigenvalues, natural frequencies
    and damping ratios to 1e-10 relative (both subsets, U = 1 and 10 m/s)."""
    for u in (1.0, 10.0):
        a = _at(sweep, u)
        for A, modes in ((a.decoupled.A_long, a.long), (a.decoupled.A_lat, a.lat)):
            n = A.shape[0]
            sys = control.ss(A, np.zeros((n, 1)), np.eye(n), np.zeros((n, 1)))
            ours = np.linalg.eigvals(A)
            assert np.max(_match(ours, sys.poles())) <= 1e-10
            wn, zeta, poles = control.damp(sys, doprint=False)
            for m in modes:
                k = int(np.argmin(np.abs(poles - m.eigenvalue)))
                assert abs(wn[k] - m.wn) <= 1e-10 * m.wn
                assert abs(zeta[k] - m.zeta) <= 1e-10 * max(abs(m.zeta), 1e-3)


def test_input_matrix_and_state_space(sweep):
    """B (brake released) has one column per actuator; the winch speed set-point acts only on
    the reel speed, dv_w/dv_set = 1/tau (rel 1e-8). A_free has dL/dt = v_w. ss() gives 66
    states (braked), ss(winch=True) 68 states and 1 input."""
    lin = _at(sweep, 10.0).linear
    lay, tau = lin.layout, load_params().winch.speed_time_constant
    assert lin.B.shape == (lay.size, len(ACTUATORS))
    assert lin.B[lay.winch_speed, 0] == pytest.approx(1 / tau, rel=1e-8)
    others = np.delete(lin.B[:, 0], lay.winch_speed)
    assert np.max(np.abs(others)) <= 1e-8
    assert lin.A_free[lay.winch_length, lay.winch_speed] == pytest.approx(1.0, rel=1e-8)
    assert lin.ss().nstates == 66
    s = lin.ss(winch=True)
    assert (s.nstates, s.ninputs) == (68, 1)
    assert s.input_labels == ["v_set"]


def test_decouple_accepts_any_matrix(base):
    """decouple() splits an arbitrary matrix into exactly the layout's index sets (exact)."""
    from aerostat_gym.physics.state import StateLayout

    lay = StateLayout(4)
    A = np.arange(30 * 30, dtype=float).reshape(30, 30)
    d = decouple(A, lay)
    li, ti = lay.longitudinal_indices(), lay.lateral_indices()
    assert np.array_equal(d.A_long, A[np.ix_(li, li)]) and np.array_equal(d.A_lat, A[np.ix_(ti, ti)])
    assert sorted(np.r_[li, ti]) == list(range(30))


# --- stability, Table 2, classification ---------------------------------------------------------


def test_every_mode_stable_0_to_20(sweep):
    """Every eigenvalue of both subsets has Re < 0 (or is the neutral zero-wind yaw pair,
    |lambda| < 1e-4 rad/s) for U = 0, 0.5, ..., 20 m/s ([LN02]: all stable)."""
    assert len(sweep.values) == 41
    bad = [(a.wind_speed, m.label, m.eigenvalue) for a in sweep.analyses
           for m in a.long + a.lat if not m.stable]
    assert not bad, bad


def test_reference_periods_closed_form(base):
    """[LN02] formulas with the baseline (Option A) parameters reproduce Table 2's theory row
    within 1.5 % (43.64 / 58.79 / 2.940 / 1.798 s against 43.9 / 58.0 / 2.96 / 1.81 s); the
    n-th harmonic frequency is n times the first (exact)."""
    ref = reference_periods(base)
    for key in TABLE2:
        assert ref[key] == pytest.approx(TABLE2[key]["theory_s"], rel=0.015), key
    d = base.derived
    w1 = tether_harmonic_frequency(1, 300.0, d.net_lift, d.mass_per_length)
    assert tether_harmonic_frequency(3, 300.0, d.net_lift, d.mass_per_length) == pytest.approx(3 * w1)


def test_tether_mass_periods_closed_form(base):
    """With the tether's mass: the baseline's pendulum 44.05 s, lateral 59.27 s, axial spring
    2.945 s, 1st harmonic 1.810 s (rel 1e-3: a 7.1 kg tether under 2645 N lengthens each by
    0.2-1 %); a tether of a millionth of the density gives reference_periods (rel 1e-6); the
    harmonic's period grows as 1 / sqrt(mean tension) (exact)."""
    got = tether_mass_periods(base)
    for key, want in (("long_pendulum", 44.05), ("lat_pendulum", 59.27),
                      ("axial_spring", 2.945), ("tether_1st", 1.810)):
        assert got[key] == pytest.approx(want, rel=1e-3), key
    light = base.replace(**{"tether.density": base.tether.density * 1e-6})
    ref = reference_periods(light)
    for key, value in tether_mass_periods(light).items():
        assert value == pytest.approx(ref[key], rel=1e-6), key
    d = base.derived
    mean = d.net_lift - d.mass_per_length * base.environment.g * base.tether.length / 2
    assert got["tether_1st"] / reference_periods(base)["tether_1st"] == pytest.approx(
        math.sqrt(d.net_lift / mean), rel=1e-12)


@pytest.fixture(scope="module")
def t2(base):
    return {r["key"]: r for r in table2(base)}


@pytest.mark.parametrize("key", ["long_pendulum", "axial_spring", "tether_1st"])
def test_table2_linear_model_within_3pct(t2, key):
    """Linear model at U = 1 m/s within 3 % of [LN02]'s linear column: long. pendulum 44.90 s
    (44.4, +1.1 %), axial spring 2.942 s (2.96, -0.6 %), 1st tether harmonic 1.780 s (1.78)."""
    assert abs(t2[key]["vs_paper_linear_pct"]) <= 3.0, t2[key]


def test_table2_lateral_pendulum_within_10pct(t2):
    """Lateral pendulum at U = 1 m/s within 10 % of 67.4 s (issue 3 target). Met through the
    CALIB fin lift slope fins.CL_alpha = 1.43 /rad (67.58 s, +0.3 %); with the former 1.79 /rad
    ESTIMATE it was 75.6 s (+12.1 %)."""
    assert abs(t2["lat_pendulum"]["vs_paper_linear_pct"]) <= 10.0, t2["lat_pendulum"]


def test_modes_classified_at_1ms(sweep):
    """At U = 1 m/s the four lowest longitudinal modes are [LN02]'s pendulum, pitching, axial
    spring and 1st tether harmonic; the lateral set holds pendulum, rolling, yaw and the 1st and
    2nd tether harmonics; the k-th tether harmonic has k - 1 sign changes (k = 1..4)."""
    a = _at(sweep, 1.0)
    assert {m.label for m in a.long[:4]} == set(FIGURE9_MODES["long"])
    assert set(FIGURE9_MODES["lat"]) <= {m.label for m in a.lat[:6]}
    for modes in (a.long, a.lat):
        for k in range(1, 5):
            name = {1: "1st", 2: "2nd", 3: "3rd", 4: "4th"}[k]
            m = next(m for m in modes if m.label == f"tether {name} harmonic")
            assert m.sign_changes == k - 1


def test_pendulum_shape_linear_and_harmonic_shape(sweep):
    """Pendulum: tether nodes move along a straight line from the anchor (correlation with
    height > 0.999, [LN02] 'increase linearly'). 1st harmonic: maximum at an interior node."""
    a = _at(sweep, 1.0)
    for subset in SETS:
        shape = a.find(subset, "pendulum").shape[:-1]  # anchor .. node 2
        assert abs(np.corrcoef(shape, np.arange(shape.size))[0, 1]) > 0.999
        h1 = np.abs(a.find(subset, "tether 1st harmonic").shape)
        assert 2 <= int(np.argmax(h1)) <= h1.size - 3


def test_pendulum_damping_rises_with_wind(sweep):
    """Longitudinal pendulum damping never decreases from 0 to 20 m/s (0 -> 0.39). Lateral
    pendulum: never decreases from 4.5 to 20 m/s (0.068 -> 0.142); below it the damping peaks
    at 0.27 at 1 m/s, where the yaw mode's period crosses the pendulum's (mode veering), and
    relaxes to the 0.068 minimum at 4.5 m/s. The veering speed is set by the yaw stiffness:
    with the CALIB fin lift slope 1.43 /rad (67.4 s lateral pendulum) the relaxation ends at
    4.5 m/s; with the former 1.79 /rad estimate it ended at 3 m/s, at a lower minimum (0.039)."""
    z_long = sweep.curve("long", "pendulum", "zeta")
    assert np.all(np.diff(z_long) >= -1e-6) and z_long[-1] > 0.3
    z_lat = sweep.curve("lat", "pendulum", "zeta")
    assert z_lat[sweep.values >= 1.0].min() > 0.06
    high = sweep.values >= 4.5
    assert np.all(np.diff(z_lat[high]) >= -1e-6) and z_lat[-1] > 2 * z_lat[high][0]


def test_tracks_are_continuous(base, sweep):
    """Each Figure 9 mode is tracked at all 41 speeds, and consecutive tracked eigenvectors
    have MAC >= 0.5 (measured min 0.54, at the yaw mode's first step; >= 0.93 for the others
    except the nearly degenerate pitch / axial pair at 0 -> 0.5 m/s)."""
    for subset in SETS:
        tracks = dict(sweep.tracks[subset])
        for label in FIGURE9_MODES[subset]:
            t = tracks[label]
            assert all(m is not None for m in t), label
            for k in range(1, len(t)):
                c0 = mode_context(base, sweep.analyses[k - 1].linear.x_eq, subset)
                c1 = mode_context(base, sweep.analyses[k].linear.x_eq, subset)
                assert mac(energy_vector(t[k - 1].vector, c0), energy_vector(t[k].vector, c1)) >= 0.5


# --- Figures 8 and 9 ----------------------------------------------------------------------------


def test_figure8_small_perturbation_agrees(base):
    """At 1/10 of [LN02]'s amplitude (0.01 m, 0.001 rad) the linear and nonlinear responses
    agree within 1.5 % nRMS for all six aerostat variables (measured <= 0.8 %): the
    linearization is right, and the larger differences at full amplitude are nonlinearity."""
    d = figure8_data(base, scale=0.1)
    assert d["status"] == "ok"
    assert max(d["nrms"].values()) <= 0.015, d["nrms"]


#: Measured nRMS for each reading of the [LN02] kick (figure8_readings, 80 s), keyed by
#: (wind.direction_deg, tether nodes): x, y, z, phi, theta, psi, and the confluence-tension
#: swing max |T / T_trim - 1|.
FIG8_READINGS = {
    (0.0, "trim"): (0.225, 0.090, 0.058, 0.083, 0.082, 0.076, 1.265),
    (0.0, "relaxed"): (0.137, 0.089, 0.037, 0.083, 0.066, 0.075, 0.138),
    (180.0, "trim"): (0.123, 0.040, 0.044, 0.047, 0.073, 0.041, 1.143),
    (180.0, "relaxed"): (0.061, 0.051, 0.027, 0.054, 0.055, 0.051, 0.122),
}


def test_figure8_readings_regression(base):
    """[LN02] amplitude under each reading the paper leaves open (axes directions x tether
    nodes): nRMS within 1.2 x the measured values above, tension swing within 5 %. No reading
    brings all six to 5 %; the best, aerostat heading 0 with relaxed nodes, reaches 2.7-6.1 %."""
    rows = figure8_readings(base)
    assert len(rows) == len(FIG8_READINGS)
    for r in rows:
        key = (FIG8_HEADINGS[r["axes"]], r["tether_nodes"])
        *expected, swing = FIG8_READINGS[key]
        for (name, _unit), v in zip(FIG8_VARIABLES, expected, strict=True):
            assert r[name] <= 1.2 * v, (key, name, r[name])
        assert r["top_tension_swing"] == pytest.approx(swing, rel=0.05), key


@pytest.mark.parametrize("nodes", ["trim", "relaxed"])
def test_figure8_odd_part_is_linear(base, nodes):
    """At [LN02]'s full amplitude the part of the nonlinear response odd in the kick (first plus
    third order) matches the linear response within 2 % nRMS for all six variables (measured
    <= 1.17 % with the nodes at trim, <= 0.62 % relaxed), and the part even in the kick
    (second order) accounts for the Figure 8 miss: |nRMS - even fraction| <= 0.015 (measured
    <= 0.009). So the linearization is right at full amplitude; the miss is the quadratic terms
    of the model, which no linear model has."""
    for r in figure8_decomposition(base, tether_nodes=nodes):
        assert r["odd_nrms"] <= 0.02, r
        assert abs(r["nrms"] - r["even_fraction"]) <= 0.015, r


def test_figure8_linearization_judged_on_odd_part(base):
    """The Figure 8 decision (issue 13), on the literal reading (package frame, tether nodes at
    trim): at [LN02]'s full amplitude the part of the nonlinear response odd in the kick,
    (y(+kick) - y(-kick)) / 2, matches the linear response within 2 % nRMS for all six
    aerostat variables (measured <= 1.17 %); the rest is the model's own second-order terms
    (the axial spring), which no linear model has, so the full-amplitude miss (3.7-22.5 %) does
    not count against the linearization. At a quarter of the amplitude the full response is
    within 5 % (measured in the README)."""
    rows = figure8_decomposition(base, tether_nodes="trim")
    assert len(rows) == 6
    assert max(r["odd_nrms"] for r in rows) <= 0.02, rows
    quarter = figure8_data(base, scale=0.25)
    assert quarter["status"] == "ok"
    assert max(quarter["nrms"].values()) <= 0.05, quarter["nrms"]


def test_figure9_outputs(sweep, tmp_path):
    """write_figure9 writes the PNG, CSV and JSON; the JSON has every Figure 9 mode at 41 speeds."""
    write_figure9(tmp_path, sweep=sweep)
    for name in ("figure9.png", "figure9.csv", "figure9.json", "figure9_modes.csv"):
        assert (tmp_path / name).stat().st_size > 0
    data = json.loads((tmp_path / "figure9.json").read_text())
    assert data == json.loads(json.dumps(figure9_data(sweep)))
    assert all(len(data[s][lab]["period_s"]) == 41 for s in SETS for lab in FIGURE9_MODES[s])


# --- sensitivity --------------------------------------------------------------------------------


def test_sensitivity_eta_k_moves_lateral_pendulum_only(base):
    """eta_k 0.3 (baseline 0.4) lengthens the lateral pendulum at 1 m/s by > 5 % (67.6 -> 74.7 s)
    and moves the longitudinal Table 2 periods by < 0.5 %."""
    knob = next(k for k in default_knobs(base) if k.key == "hull.eta_k")
    b = stability_figures(base, speeds=(1.0,))
    lo = stability_figures(knob.put(base, 0.3), speeds=(1.0,))
    assert lo["lat_pendulum"] > 1.05 * b["lat_pendulum"]
    for key in ("long_pendulum", "axial_spring", "tether_1st"):
        assert lo[key] == pytest.approx(b[key], rel=0.005)


def test_solve_for_period_hits_target(base):
    """The eta_k that puts the lateral pendulum at the edge of the 10 % band (74.14 s) lies in
    the stated range, and the period there is within 0.01 s of the target."""
    knob = next(k for k in default_knobs(base) if k.key == "hull.eta_k")
    v = solve_for_period(base, knob, 74.14)
    assert v is not None and knob.low <= v <= knob.high
    p = knob.put(base, v)
    assert stability_figures(p, speeds=(1.0,))["lat_pendulum"] == pytest.approx(74.14, abs=0.01)


# --- CLI and timing -----------------------------------------------------------------------------


def _cli(argv):
    ap = argparse.ArgumentParser()
    add_stability_parsers(ap.add_subparsers(dest="command", required=True))
    args = ap.parse_args(argv)
    return args.func(args)


def test_parse_speeds():
    """START:STOP:STEP is inclusive (41 speeds for 0:20:0.5); bad input raises ValueError."""
    assert len(parse_speeds("0:20:0.5")) == 41
    assert parse_speeds("10").tolist() == [10.0]
    for bad in ("a:b", "5:1:1", "0:1:0", "-1"):
        with pytest.raises(ValueError):
            parse_speeds(bad)


def test_cli_stability_and_table2(capsys, tmp_path):
    """``stability --json --plot`` prints valid JSON with stability and coupling and writes the
    figure; ``table2 --json`` prints the four rows; text output names every mode."""
    assert _cli(["stability", "--wind", "0:4:2", "--json", "--plot", str(tmp_path)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["all_stable"] and len(out["coupling_ratios"]) == 3
    assert (tmp_path / "figure9.png").exists()
    assert _cli(["stability", "--wind", "1", "--length", "200"]) == 0
    text = capsys.readouterr().out
    assert "L = 200 m" in text and "rolling" in text and "axial spring" in text
    assert _cli(["table2", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["key"] for r in rows] == list(TABLE2)


def _strict_json(text):
    """Parse ``text`` as strict JSON (as JavaScript's JSON.parse does): NaN and Infinity are
    refused."""
    def refuse(token):
        raise ValueError(f"{token} is not JSON")
    return json.loads(text, parse_constant=refuse)


def test_json_of_an_overdamped_mode_is_strict_json(capsys):
    """With hull.eta_k = 0.6 the lateral pendulum at 1 m/s is a real root (no period, no
    damping ratio): ``table2 --json`` writes those cells as null, not Python's bare NaN that
    strict parsers refuse (it did before 0.7.17); the text table says ``n/a``."""
    assert _cli(["table2", "--json", "--set", "hull.eta_k=0.6"]) == 0
    rows = {r["key"]: r for r in _strict_json(capsys.readouterr().out)}
    assert rows["lat_pendulum"]["linear_s"] is None
    assert rows["lat_pendulum"]["diff_pct"] is None
    assert rows["lat_pendulum"]["linear_overdamped"] is True
    assert rows["long_pendulum"]["linear_s"] == pytest.approx(rows["long_pendulum"]["theory_s"],
                                                              rel=0.05)
    assert _cli(["table2", "--set", "hull.eta_k=0.6"]) == 0
    assert "n/a" in capsys.readouterr().out


def test_stability_sweep_stops_where_the_tether_breaks(capsys):
    """The baseline's tether (35.6 kN) holds the 50 m/s trim and not the 60 m/s one (39.8 kN):
    ``--wind 40:60:10`` sweeps 40 and 50 m/s and warns where and why it stopped; a sweep of
    speeds none of which it holds is refused with the tension and the strength."""
    assert _cli(["stability", "--wind", "40:60:10", "--json"]) == 0
    captured = capsys.readouterr()
    assert sorted({row["wind_speed_m_s"] for row in json.loads(captured.out)["modes"]}) == [40.0, 50.0]
    assert "the sweep stops at 50 m/s: at U = 60 m/s the trim tension" in captured.err
    assert "tether.strength = 35600 N" in captured.err
    with pytest.raises(TrimLimitError, match="at U = 60 m/s .* exceeds tether.strength"):
        _cli(["stability", "--wind", "60:70:10"])


def test_bench_sweep_reports():
    """The sweep benchmark runs the 41 speeds of Figure 9, all stable, and its derived figures
    follow from its measurement (the time itself belongs to ``aerostat-gym bench``, not to a
    test)."""
    res = bench_sweep(repeats=1)
    assert res["n_speeds"] == 41 and res["all_stable"]
    assert res["per_speed_ms"] == pytest.approx(1e3 * res["linear_sweep_s"] / 41, rel=1e-12)


# --- full tables and scripts (about 7 s together) -----------------------------------------


def test_full_sensitivity_table(base):
    """Every knob evaluates at both ends; the headline movers of the lateral pendulum are the
    yaw-stiffness knobs (CB / CM x, fins, eta_k); Ixx, Ixz and tether drag move no Table 2
    period by more than 1 %."""
    from aerostat_gym.analysis.sensitivity import sensitivity_table

    tab = sensitivity_table(base)
    rows = {r["knob"]: r for r in tab["rows"]}
    assert all("low_pct" in r and "high_pct" in r for r in rows.values())
    top = [r["knob"] for r in tab["rows"][:5]]
    assert {"hull.eta_k", "fins.CL_alpha", "fins.planform_area"} <= set(top)
    # eta_k = 0.5 overdamps the lateral pendulum at 1 m/s (a real root, 2 pi / |lambda| = 184 s,
    # once printed as a period): no period, and the row ranks first
    assert math.isnan(rows["hull.eta_k"]["high_pct"]["lat_pendulum"]) and top[0] == "hull.eta_k"
    for key in ("aerostat.Ixx", "aerostat.Ixz", "tether.Cd_normal"):
        assert rows[key]["max_abs_pct"] < 1.0


def test_scripts_reproduce_into_folder(tmp_path, load_script):
    """The three reproduction scripts run and write their files."""
    for name, extra in (("reproduce_table2", ["--no-sensitivity"]), ("reproduce_figure8", []),
                        ("reproduce_figure9", ["--no-families"])):
        assert load_script(name).main(["--out", str(tmp_path), *extra]) == 0
    for f in ("table2.json", "figure8.png", "figure8_amplitude_scan.csv", "figure8_readings.csv",
              "figure8_decomposition.csv", "figure9.png"):
        assert (tmp_path / f).exists()


def test_length_and_pitch_families_stable(base):
    """Tether lengths 150-375 m and trim pitch -8..0 deg: every mode stable 0..20 m/s. The
    families are relative to the configuration; for the baseline they are the values above."""
    from aerostat_gym.analysis.figures import FAMILIES, family_data, family_values

    assert family_values(base, "tether.length") == (150.0, 225.0, 300.0, 375.0)
    assert family_values(base, "aerostat.trim_pitch_deg") == (-8.0, -4.0, 0.0)
    for name in FAMILIES:
        fam = family_data(base, name, speeds=np.arange(0.0, 20.1, 2.0))
        assert all(d["all_stable"] for d in fam.values()), name


def test_mode_rows_are_json(sweep):
    """Sweep.rows() is plain JSON (no inf/nan; json.dumps with allow_nan=False would raise) that
    round-trips exactly, with one row per tracked mode and speed."""
    rows = sweep.rows()
    text = json.dumps(rows, allow_nan=False)
    assert json.loads(text) == rows
    expected = sum(m is not None for s in ("long", "lat") for _, t in sweep.tracks[s] for m in t)
    assert len(rows) == expected > 0


def test_sensitivity_names_an_end_without_trim_instead_of_calling_it_unstable(base):
    """A nearly neutral aerostat (mass 580 kg: 150 N of net lift) with its CM 0.3 m forward
    has no trim by 2.9 m/s: that end reads NO TRIM with its cells n/a and its error in the
    table, and the row is not called UNSTABLE (its other end is stable everywhere)."""
    from aerostat_gym.analysis.sensitivity import format_sensitivity, sensitivity_table

    light = base.replace(**{"aerostat.mass": 580.0})
    knob = [k for k in default_knobs(light) if k.key == "cm_x_shift"]
    tab = sensitivity_table(light, knob)
    row = tab["rows"][0]
    assert "no equilibrium found" in row["high_result"]["error"]
    assert row["low_result"]["all_stable"] and "high_pct" not in row
    line = [s for s in format_sensitivity(tab).splitlines() if s.startswith(row["label"])][0]
    assert line.endswith("NO TRIM (high)") and "UNSTABLE" not in line
    assert "nan" not in line and line.count("n/a") == 5


def _mode(lam: complex):
    wn, zeta, period = damp_quantities(lam)
    return Mode(lam, np.zeros(1), wn, zeta, period, lam.imag > 0, lam.real < 0 or wn < NEUTRAL_RATE,
                wn < NEUTRAL_RATE)


def test_stability_table_cells():
    """A cell is period (damping ratio) by the closed form of lambda = -0.1 + 1j: omega_n =
    sqrt(1.01), zeta = 0.1 / omega_n = 0.0995, period 2 pi / omega_n = 6.25 s; a real root
    reads 'real (1.000)'; a neutral root (|lambda| below NEUTRAL_RATE) reads 'neutral' whatever
    the sign of its rounding, where its ratio would read +-1."""
    assert _fmt(_mode(complex(-0.1, 1.0))) == "   6.25 (0.100)"
    assert _fmt(_mode(complex(-0.5, 0.0))) == "   real (1.000)"
    for tiny in (0.1 * NEUTRAL_RATE, -0.1 * NEUTRAL_RATE):
        assert _fmt(_mode(complex(tiny, 0.0))) == "        neutral"
    assert _fmt(None) == "              -"
