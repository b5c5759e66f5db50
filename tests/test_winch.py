"""Ground winch and variable-length tether (issue 5): every assertion states its tolerance.

Trims are at U = 10 m/s on the baseline (L0 = 300 m) unless stated.
"""

import math

import numpy as np
import pytest
from scipy.linalg import expm

from aerostat_gym.analysis.linear import ACTUATORS, U_FREE, input_jacobian
from aerostat_gym.analysis.manoeuvre import length_hold_law, reel_manoeuvre
from aerostat_gym.analysis.trim import find_equilibrium
from aerostat_gym.params import ParameterError, load_params
from aerostat_gym.physics.packing import P_MU
from aerostat_gym.sim import Model, SimulationError, simulate
from aerostat_gym.sim.winch import WinchController, WinchInputError, motor_force

INTEGRATORS = ("rk4", "semi-implicit")
U = 10.0


@pytest.fixture(scope="module")
def base():
    return load_params()


@pytest.fixture(scope="module")
def trim10(base):
    return find_equilibrium(base, U)


# --- variable length and mass bookkeeping --------------------------------------------------------


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_constant_reel_out_changes_length_by_v_t(base, trim10, integrator):
    """Reel out at v = 0.8 m/s: once the speed loop has settled (10 s, 33 time constants) the
    length grows by v t over the next 40 s to 1e-9 relative; the tether mass aloft plus on the
    drum stays at mu * total_line_length to 1e-12 relative, and the mass aloft is exactly the
    lumped model's (n nodes' worth of mu L / n) at every sample."""
    v = 0.8
    tr = simulate(base, trim10.x, 50.0, wind=U, integrator=integrator, output_dt=0.5, u=[v, 0.0])
    assert tr.status == "ok"
    k = int(round(10.0 / 0.5))
    dL, dt = tr.length[-1] - tr.length[k], tr.time[-1] - tr.time[k]
    assert abs(dL - v * dt) / (v * dt) < 1e-9, (dL - v * dt) / (v * dt)
    wc = WinchController(base)
    total = tr.mass_aloft + tr.mass_on_drum
    np.testing.assert_allclose(total, wc.total_mass, rtol=1e-12, atol=0)
    m = Model(base, U)
    lumped = m.n * (m.p[P_MU] * tr.length / m.n)  # (n - 1) interior nodes + two half nodes
    np.testing.assert_allclose(tr.mass_aloft, lumped, rtol=1e-12, atol=0)
    assert tr.mass_on_drum[-1] == pytest.approx(tr.mass_on_drum[0] - wc.mu * (tr.length[-1] - 300.0),
                                                rel=1e-12)


def test_lumped_model_carries_the_paid_out_mass(base):
    """Zero-wind static check that the compiled model weighs what the bookkeeping says: at
    L = 350 m the winch tension equals the net lift minus the weight of the mass aloft
    (mu L g), to 1e-6 relative."""
    eq = find_equilibrium(base, 0.0, length=350.0)
    wc = WinchController(base)
    expected = base.derived.net_lift - float(wc.mass_aloft(350.0)) * base.environment.g
    assert eq.summary["winch_tension_N"] == pytest.approx(expected, rel=1e-6)


def test_drum_must_hold_the_line(base):
    """total_line_length below max_length is a clear error naming both fields, raised when the
    parameters are loaded (issue 14), before any winch is built."""
    with pytest.raises(ParameterError, match="total_line_length.*max_length"):
        base.replace(**{"winch.total_line_length": 350.0})


# --- brake: the fixed-length model ---------------------------------------------------------------


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_brake_equals_fixed_length_model(base, trim10, integrator):
    """Reel out to about 330 m, brake on the way (the aerostat still moving), then hold 40 s.
    The braked run equals, to 1e-12 (absolute, SI units), the fixed-length model configured
    at that length (tether.length = L_b, default braked input) from the same state, and also
    the run with very different drivetrain parameters: with the brake holding, the winch has
    no influence. L and v_w stay exactly constant."""
    out = simulate(base, trim10.x, 30.0, wind=U, integrator=integrator, output_dt=0.5,
                   u=[1.0, 0.0])
    xb = out.states[-1].copy()
    m = Model(base, U)
    xb[m.layout.winch_speed] = 0.0  # as the brake clamps
    Lb = float(xb[m.layout.winch_length])
    fixed = base.replace(**{"tether.length": Lb})
    other = base.replace(**{"winch.equivalent_mass": 5000.0, "winch.coulomb_friction": 900.0,
                            "winch.speed_time_constant": 2.0, "winch.max_motor_force": 100.0})
    ref = simulate(fixed, xb, 40.0, wind=U, integrator=integrator, output_dt=0.5)
    runs = [simulate(base, xb, 40.0, wind=U, integrator=integrator, output_dt=0.5, u=[0.7, 1.0]),
            simulate(base.replace(**{"winch.brake_dwell": 0.0}), xb, 40.0, wind=U,
                     integrator=integrator, output_dt=0.5, u=[0.001, 0.0]),
            simulate(other, xb, 40.0, wind=U, integrator=integrator, output_dt=0.5, u=[0.0, 0.0])]
    assert np.ptp(ref.cm_pos[:, 0]) > 0.1  # the aerostat really moves during the hold
    for tr in runs:
        assert tr.brake.all()
        np.testing.assert_allclose(tr.states, ref.states, rtol=0, atol=1e-12)
        assert np.all(tr.length == Lb) and np.all(tr.reel_speed == 0.0)


def test_brake_from_motion_decelerates_then_clamps(base, trim10):
    """Brake commanded while reeling out at 1 m/s: the speed loop first decelerates (never
    faster than max_acceleration, 1e-9), the brake clamps once |v_w| <= brake_hold_speed
    (v_w then exactly 0) and L stays fixed from then on."""
    w = base.winch

    def u(t, x):
        return [1.0, 0.0] if t < 10.0 else [1.0, 1.0]

    tr = simulate(base, trim10.x, 20.0, wind=U, output_dt=0.1, u=u)
    k = int(round(10.0 / 0.1))
    dv = np.diff(tr.reel_speed[k:]) / 0.1
    clamp = np.argmax(tr.brake[k:])  # first braked interval after the command
    assert clamp > 0  # not at once: the drum was moving at 1 m/s
    assert np.all(np.abs(dv[:clamp]) <= w.max_acceleration * (1 + 1e-9))
    assert abs(tr.reel_speed[k + clamp]) <= w.brake_hold_speed
    assert np.all(tr.brake[k + clamp:])
    assert np.all(tr.reel_speed[k + clamp + 1:] == 0.0)
    assert np.all(tr.length[k + clamp + 1:] == tr.length[k + clamp + 1])


# --- limits -------------------------------------------------------------------------------------


def _commands(rng, n, vmax):
    """n control steps of random commands, each held 1-50 steps: 10 % brake commands, 10 %
    zero set-points (auto brake), the rest uniform in +-1.5 vmax (a third of them clipped)."""
    out = []
    while len(out) < n:
        r = rng.random()
        if r < 0.1:
            u = [rng.uniform(-2.0, 2.0), 1.0]
        elif r < 0.2:
            u = [0.0, 0.0]
        else:
            u = [rng.uniform(-1.5, 1.5) * vmax, 0.0]
        out += [u] * int(rng.integers(1, 51))
    return out[:n]


def _random_run(params, x0, seed, integrator, control_dt=0.1, sub=10):
    """Drive the winch as the environment will: WinchController once per control step, the
    model advanced in `sub` pieces to inspect speed, acceleration and motor force inside it."""
    m = Model(params, U)
    lay, wc = m.layout, WinchController(params)
    x, t, h = x0.copy(), 0.0, control_dt / sub
    worst = {"v": 0.0, "a": 0.0, "a_fd": 0.0, "F": 0.0, "bound": 0}
    cmds = _commands(np.random.default_rng(seed), 1000, params.winch.max_speed)
    for u in cmds:
        cmd = wc.command(u, x)
        ui = cmd.as_input()
        for _ in range(sub):
            if not cmd.brake:
                worst["a"] = max(worst["a"], abs(m.rhs(x, ui, t)[lay.winch_speed]))
                F = abs(motor_force(m, x, ui, t))
                worst["F"] = max(worst["F"], F)
                worst["bound"] += F >= params.winch.max_motor_force * (1 - 1e-12)
            v0 = x[lay.winch_speed]
            status, _ = m.advance(x, t, h, ui, integrator)
            assert status == 0
            t += h
            worst["a_fd"] = max(worst["a_fd"], abs(x[lay.winch_speed] - v0) / h)
            worst["v"] = max(worst["v"], abs(x[lay.winch_speed]))
    expected_clips = sum(1 for v, b in cmds if b == 0.0 and abs(v) > params.winch.max_speed)
    return worst, wc.n_clipped, expected_clips


# baseline (force limit far away) and a heavy drum with a motor force limit that binds on
# every hard acceleration but still exceeds the tension (the motor keeps its authority)
FORCE_BOUND = {"winch.equivalent_mass": 1500.0, "winch.max_motor_force": 4000.0}


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("variant", ["baseline", "force-bound"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_limits_hold_under_random_setpoints(base, trim10, integrator, variant, seed):
    """1000 random commands of 0.1 s at U = 10 m/s: |v_w| <= max_speed, |dv_w/dt| <=
    max_acceleration (from the RHS and from finite differences over 10 ms) and |F_m| <=
    max_motor_force, each to 1e-12 relative; every clipped set-point counted. In the
    force-bound variant the force limit is reached (checked) and the other limits still hold."""
    p = base if variant == "baseline" else base.replace(**FORCE_BOUND)
    w = p.winch
    worst, n_clipped, expected = _random_run(p, trim10.x, seed, integrator)
    assert worst["v"] <= w.max_speed * (1 + 1e-12)
    assert worst["v"] > 0.99 * w.max_speed  # the sequence does reach the speed limit
    assert worst["a"] <= w.max_acceleration * (1 + 1e-12)
    assert worst["a_fd"] <= w.max_acceleration * (1 + 1e-12)
    assert worst["F"] <= w.max_motor_force * (1 + 1e-12)
    if variant == "force-bound":
        assert worst["bound"] > 100
    assert n_clipped == expected > 50


def test_length_limits_stop_the_drum(base, trim10):
    """Full-speed reel-out toward max_length = 310 m and reel-in toward min_length = 290 m:
    the length never passes the limit (1e-9 m) and ends within 1 cm of it (stopping profile
    of the compiled speed loop)."""
    p = base.replace(**{"winch.max_length": 310.0, "winch.min_length": 290.0,
                        "winch.total_line_length": 310.0})
    up = simulate(p, trim10.x, 40.0, wind=U, output_dt=0.1, u=[1.0, 0.0])
    down = simulate(p, trim10.x, 40.0, wind=U, output_dt=0.1, u=[-1.0, 0.0])
    assert up.length.max() <= 310.0 + 1e-9 and up.length[-1] > 310.0 - 0.01
    assert down.length.min() >= 290.0 - 1e-9 and down.length[-1] < 290.0 + 0.01
    assert up.mass_on_drum.min() >= 0.0


# --- the manoeuvre ------------------------------------------------------------------------------


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_reel_out_and_back_returns_to_trim(base, integrator):
    """Reel out 50 m at the speed limit and back in 10 m/s wind: stable (status ok, finite),
    reaches L0 + 50 m (0.5 m), never exceeds the speed limit, and once settled (the last
    100 s of a 300 s settling phase) the aerostat stays within 0.1 m of the trim at L0."""
    res = reel_manoeuvre(base, U, 50.0, integrator=integrator, settle=300.0)
    tr, eq = res.trajectory, res.equilibrium
    assert tr.status == "ok" and np.all(np.isfinite(tr.states))
    assert tr.length.max() == pytest.approx(350.0, abs=0.5)
    assert np.abs(tr.reel_speed).max() <= base.winch.max_speed * (1 + 1e-12)
    lay = Model(base).layout
    last = tr.time >= tr.time[-1] - 100.0
    dev = np.linalg.norm(tr.cm_pos[last] - eq.x[lay.cm_pos], axis=1)
    assert dev.max() < 0.1, dev.max()
    assert tr.brake[-1] and abs(tr.length[-1] - 300.0) < 0.05
    assert not any(e["event"] in ("break", "over_tension", "winch_slack") for e in tr.events)


def test_manoeuvre_script_writes_png(tmp_path, load_script):
    """The script shim runs end to end (short settle) and writes the PNG."""
    mod = load_script("winch_manoeuvre")
    out = tmp_path / "m.png"
    assert mod.main(["--distance", "5", "--hold", "2", "--settle", "5", "--integrator",
                     "semi-implicit", "--out", str(out)]) == 0
    assert out.stat().st_size > 10_000


# --- the input matrix B -------------------------------------------------------------------------


def _jacobian(model, x, u):
    A = np.empty((x.size, x.size))
    for j in range(x.size):
        h = 1e-6 * max(1.0, abs(x[j]))
        xp, xm = x.copy(), x.copy()
        xp[j] += h
        xm[j] -= h
        A[:, j] = (model.rhs(xp, u) - model.rhs(xm, u)) / (2 * h)
    return A


def test_input_column_matches_step_response(base, trim10):
    """B's winch column (central differences of the RHS in v_set, brake released) is 1/tau in
    the v_w row and zero elsewhere (1e-6); with A by central differences, the linear response
    to a 0.025 m/s set-point step matches the nonlinear simulate over the first second within
    2 % of each channel's peak: L, v_w, aerostat position, attitude, tether node positions and
    the winch tension."""
    m = Model(base, U)
    lay, x0 = m.layout, trim10.x
    B = input_jacobian(m, x0, U_FREE.copy(), ACTUATORS, 1e-3)[:, 0]
    expect = np.zeros_like(B)
    expect[lay.winch_speed] = 1.0 / base.winch.speed_time_constant
    np.testing.assert_allclose(B, expect, rtol=0, atol=1e-6)
    A = _jacobian(m, x0, np.zeros(2))
    d = 0.025  # above brake_speed, so the brake stays released
    tr = simulate(base, x0, 1.0, wind=U, u=[d, 0.0], output_dt=0.01)
    assert not tr.brake.any()
    n = x0.size
    M = np.zeros((n + 1, n + 1))
    M[:n, :n], M[:n, n] = A, B * d
    lin = np.array([expm(M * t)[:n, n] for t in tr.time])
    nl = tr.states - x0
    groups = {"L": [lay.winch_length], "v_w": [lay.winch_speed], "cm": lay.cm_pos,
              "euler": lay.euler, "nodes": lay.node_pos}
    for name, idx in groups.items():
        err = np.abs(nl[:, idx] - lin[:, idx]).max() / np.abs(lin[:, idx]).max()
        assert err < 0.02, (name, err)
    T0 = m.end_tensions(x0)[1]
    T_lin = np.array([m.end_tensions(x0 + dx)[1] for dx in lin]) - T0
    T_nl = tr.load_cell - T0
    assert np.abs(T_nl - T_lin).max() / np.abs(T_lin).max() < 0.02


# --- inputs and events --------------------------------------------------------------------------


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_nonfinite_setpoint_is_a_clear_error(base, trim10, bad):
    """A NaN or infinite set-point (or brake flag) is an error naming the value, from the
    controller (WinchInputError) and from simulate (SimulationError), never a silent clip."""
    wc = WinchController(base)
    x = trim10.x.copy()
    with pytest.raises(WinchInputError, match=f"v_set = {bad!r}"):
        wc.command(bad, x)
    with pytest.raises(WinchInputError, match="brake"):
        wc.command([0.5, bad], x)
    with pytest.raises(SimulationError, match="winch input must be finite"):
        simulate(base, x, 1.0, wind=U, u=lambda t, s: [bad if t > 0.3 else 0.5, 0.0])
    np.testing.assert_array_equal(x, trim10.x)


def test_setpoint_beyond_limit_is_clipped_and_counted(base, trim10):
    """A 2.5 m/s set-point (limit 1 m/s) for 5 s: applied as 1 m/s, all 50 intervals counted
    as clipped, the reel speed never above the limit."""
    tr = simulate(base, trim10.x, 5.0, wind=U, output_dt=0.1, u=[2.5, 0.0])
    assert tr.clipped_count == 50
    assert np.all(tr.v_set == base.winch.max_speed) and np.all(tr.v_set_requested == 2.5)
    assert tr.reel_speed.max() <= base.winch.max_speed


def test_winch_events_and_load_cell(base, trim10):
    """Load cell = winch-end tension; with thresholds set inside the manoeuvre's tension range
    the over-tension and slack onsets are reported with value and threshold; the thresholds
    travel with the trajectory."""
    T_trim = trim10.summary["winch_tension_N"]
    p = base.replace(**{"winch.safe_working_load": T_trim + 300.0,
                        "winch.slack_tension": T_trim - 300.0})
    law = length_hold_law(lambda t: 310.0 if t < 15.0 else 300.0, 1.0, 1.0,
                          Model(p).layout.winch_length)
    tr = simulate(p, trim10.x, 40.0, wind=U, output_dt=0.1, u=law)
    np.testing.assert_array_equal(tr.load_cell, tr.winch_tension)
    names = [e["event"] for e in tr.events]
    assert "over_tension" in names and "winch_slack" in names
    for e in tr.events:
        if e["event"] == "winch_slack":
            assert e["value"] < e["threshold"] == p.winch.slack_tension
        if e["event"] == "over_tension":
            assert e["value"] > e["threshold"] == p.winch.safe_working_load
    assert tr.thresholds == {"slack_tension": T_trim - 300.0, "safe_working_load": T_trim + 300.0,
                             "strength": 35.6e3}
    assert tr.status == "ok"


def test_a_manoeuvre_past_the_winch_limits_is_refused_at_the_door(base):
    """1e9 m of reel-out ran for minutes; a negative hold ran and said 'ok': both named."""
    with pytest.raises(ValueError, match=r"distance must keep the tether within the winch's "
                       r"limits \[150, 400\] m from the trim's 300 m: \[-150, 100\] m"):
        reel_manoeuvre(base, 10.0, 1e9)
    with pytest.raises(ValueError, match=r"hold must be a finite time >= 0 s, got -1"):
        reel_manoeuvre(base, 10.0, -50.0, hold=-1.0)


def test_a_negative_distance_reels_in_first_and_back(base):
    """distance -20 m: the length reaches the trim's 300 m - 20 m (the brake's overshoot, 15 cm,
    as reeling out overshoots), holds it to 1 mm until the reel-in time, then returns to 300 m
    to 1 mm (the schedule divided the signed distance by the speed: it reeled in for 10 s
    only and reached 290 m; -150 m gave a negative duration)."""
    res = reel_manoeuvre(base, 10.0, -20.0, hold=20.0, settle=60.0)
    tr = res.trajectory
    assert tr.status == "ok"
    assert res.reel_in_time == pytest.approx(20.0 / base.winch.max_speed + 20.0)
    assert tr.length.min() == pytest.approx(280.0, abs=0.2)
    held = tr.length[np.searchsorted(tr.time, res.reel_in_time) - 1]
    assert held == pytest.approx(280.0, abs=1e-3)
    assert tr.length[-1] == pytest.approx(300.0, abs=1e-3)
