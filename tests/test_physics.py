"""Physics core: closed-form limits, conservation laws, symmetry, convergence, robustness.

Every assertion states its reference and tolerance.
"""

import math

import numpy as np
import pytest

from aerostat_gym.analysis.energy import mechanical_energy
from aerostat_gym.analysis.signals import zero_crossing_period
from aerostat_gym.analysis.trim import find_equilibrium
from aerostat_gym.params import ParameterError, load_params
from aerostat_gym.physics.core import _hull
from aerostat_gym.sim import Model, SimulationError, events, simulate

AERO_OFF = {"hull.CD0": 0.0, "hull.Cdc": 0.0, "hull.eta_k": 0.0, "fins.CL_alpha": 0.0,
            "fins.CD0": 0.0, "tether.Cd_normal": 0.0, "tether.damping_ratio": 0.0,
            "fins.post_stall": "flat"}  # the Viterna normal force does not scale with CL_alpha


@pytest.fixture(scope="module")
def base():
    return load_params()


@pytest.fixture(scope="module")
def trim0(base):
    return find_equilibrium(base, 0.0)


def test_zero_wind_trim_closed_form(base, trim0):
    """Zero wind: vertical tether, top tension B - mg, bottom B - mg - tether weight (rel 1e-6),
    computed here from the raw parameters (B = rho_air g V; the weight of L metres of a line of
    density rho_t and diameter d), pitch = configured trim pitch (1e-6 rad)."""
    a, env, t, s = base.aerostat, base.environment, base.tether, trim0.summary
    net_lift = (env.rho_air * a.volume - a.mass) * env.g
    weight = t.density * math.pi * t.diameter ** 2 / 4.0 * t.length * env.g
    assert s["blow_by_deg"] < 1e-6
    assert s["top_tension_N"] == pytest.approx(net_lift, rel=1e-6)
    assert s["winch_tension_N"] == pytest.approx(net_lift - weight, rel=1e-6)
    assert abs(math.radians(s["pitch_deg"]) - math.radians(base.aerostat.trim_pitch_deg)) < 1e-6
    assert trim0.residual <= 1e-9


def test_zero_wind_is_a_fixed_point(base, trim0):
    """The zero-wind trim is a fixed point of the full RHS: every acceleration below 1e-8 m/s^2."""
    dx = Model(base, 0.0).rhs(trim0.x)
    assert np.max(np.abs(dx)) < 1e-8


def test_energy_conserved_without_dissipation():
    """Drag, aerodynamics and tether damping off, winch braked: the total mechanical energy
    (kinetic with added mass, gravity, buoyancy, elastic) drifts by < 1e-6 of the perturbation
    energy over 60 s with RK4 at dt = 0.25 ms (a far stricter measure than relative to |E|).
    The small step matters: RK4 damps the highest tether mode (440 rad/s) by (omega h)^6 / 72
    per step, which at the default 5 ms step dissipates the few 1e-6 of the perturbation energy
    that the initial kick puts into those modes."""
    p = load_params(overrides=AERO_OFF)
    eq = find_equilibrium(p, 0.0)
    m = Model(p, 0.0)
    lay = m.layout
    x0 = eq.x.copy()
    x0[lay.cm_vel] = [0.3, 0.2, 0.05]
    x0[lay.rates] = [0.01, 0.02, 0.01]
    e_eq, e0 = mechanical_energy(m, eq.x), mechanical_energy(m, x0)
    tr = simulate(p, x0, 60.0, wind=0.0, dt=2.5e-4, output_dt=1.0, model=m)
    drift = max(abs(mechanical_energy(m, s) - e0) for s in tr.states)
    assert tr.status == "ok"
    assert drift / (e0 - e_eq) < 1e-6, drift / (e0 - e_eq)
    assert drift / abs(e0) < 1e-9


def test_energy_decays_with_damping(base, trim0):
    """Still air, braked winch: nothing does work on the system, and drag and the tether's
    dashpots only dissipate, so the perturbation energy (36.0 J) never rises, sampled every
    0.5 s (the dissipation law). Its 60 s value is the stored 0.53252 of the start (rel 2e-5:
    the tether dashpots alone move it to 0.53300, drag far more)."""
    m = Model(base, 0.0)
    x0 = trim0.x.copy()
    x0[m.layout.cm_vel] = [0.3, 0.2, 0.05]
    tr = simulate(base, x0, 60.0, wind=0.0, output_dt=0.5, model=m)
    e = np.array([mechanical_energy(m, s) for s in tr.states]) - mechanical_energy(m, trim0.x)
    assert e[0] == pytest.approx(35.972, rel=1e-4)
    assert np.all(np.diff(e) < 0.0)
    assert e[-1] / e[0] == pytest.approx(0.53252, rel=2e-5)


def test_mirror_symmetry(base):
    """Mirror-image lateral perturbations (y, v, roll, yaw, p, r negated) give mirror-image
    trajectories at U = 10 m/s: lateral states opposite, longitudinal equal, to 1e-9."""
    eq = find_equilibrium(base, 10.0)
    lay = Model(base).layout
    lat = lay.lateral_indices()
    xa = eq.x.copy()
    xa[lay.cm_pos.start + 1] += 0.3
    xa[lay.euler.start] += 0.02
    xa[lay.rates.start + 2] += 0.01
    xb = eq.x.copy()
    xb[lat] = 2 * eq.x[lat] - xa[lat]
    ta = simulate(base, xa, 20.0, wind=10.0, output_dt=1.0)
    tb = simulate(base, xb, 20.0, wind=10.0, output_dt=1.0)
    # mirror about the trim: lateral deviations opposite (yaw about pi), longitudinal equal
    dev_a = ta.states[:, lat] - eq.x[lat]
    dev_b = tb.states[:, lat] - eq.x[lat]
    np.testing.assert_allclose(dev_a, -dev_b, atol=1e-9)
    lon = lay.longitudinal_indices()
    np.testing.assert_allclose(ta.states[:, lon], tb.states[:, lon], atol=1e-9)
    assert np.max(np.abs(dev_a[:, 0])) > 1e-3  # the perturbation really moved the tether


def _periods(length, n=10, integrator="rk4"):
    # the winch's limits widened so that every length tested lies inside them
    top = max(400.0, length)
    p = load_params(overrides={"tether.length": length, "tether.n_elements": n,
                               "winch.max_length": top, "winch.total_line_length": top,
                               "wind.turbulence_reference_height": length})  # still air
    eq = find_equilibrium(p, 0.0)
    lay = Model(p).layout
    x = eq.x.copy()
    x[lay.cm_pos.start] += 0.5
    tr = simulate(p, x, 240.0, wind=0.0, output_dt=0.1, integrator=integrator)
    pend = zero_crossing_period(tr.time, tr.cm_pos[:, 0])
    x = eq.x.copy()
    x[lay.cm_vel.start + 2] += 0.01
    tr = simulate(p, x, 30.0, wind=0.0, output_dt=0.01, integrator=integrator)
    axial = zero_crossing_period(tr.time, tr.cm_pos[:, 2])
    return p, pend, axial


def test_free_decay_periods_match_paper_theory():
    """U = 0, L = 300 m: pendulum within 3 % of [LN02] Table 2 theory 43.9 s, axial spring
    within 3 % of 2.96 s."""
    _, pend, axial = _periods(300.0)
    assert pend == pytest.approx(43.9, rel=0.03), pend
    assert axial == pytest.approx(2.96, rel=0.03), axial


@pytest.mark.parametrize("length", [150.0, 600.0])
def test_free_decay_periods_scale_with_length(length):
    """The same formulas at L = 150 and 600 m: axial spring 2 pi sqrt(m_ez L / EA) within 1 %;
    pendulum 2 pi sqrt(m_ex L_eff / (B - mg)) within 3 %, with L_eff = L + |z_l| (the
    confluence point hangs 11.55 m below the CM, so the pendulum is that much longer)."""
    p, pend, axial = _periods(length)
    d = p.derived
    t_axial = 2 * math.pi * math.sqrt(d.effective_mass[2] * length / d.EA)
    t_pend = 2 * math.pi * math.sqrt(d.effective_mass[0] * (length + abs(p.aerostat.leash_z)) / d.net_lift)
    assert axial == pytest.approx(t_axial, rel=0.01), (axial, t_axial)
    assert pend == pytest.approx(t_pend, rel=0.03), (pend, t_pend)


def test_trim_exists_for_every_speed(base):
    """Trim converges (relative residual <= 1e-9) for U = 0 ... 25 m/s in 0.5 m/s steps, each
    continued from the previous one; blow-by grows with wind speed."""
    eq, blow = None, []
    for u in np.arange(0.0, 25.01, 0.5):
        eq = find_equilibrium(base, float(u), guess=eq)
        assert eq.residual <= 1e-9
        blow.append(eq.summary["blow_by_deg"])
    assert np.all(np.diff(blow[1:]) > 0)


def test_trim_from_scratch_equals_continued(base):
    """A single call at 12 m/s (internal continuation from zero wind) reaches the same state as
    the sweep, to 1e-6 m."""
    a = find_equilibrium(base, 12.0)
    b = find_equilibrium(base, 12.0, guess=find_equilibrium(base, 11.0))
    np.testing.assert_allclose(a.x, b.x, atol=1e-6)


def test_convergence_in_number_of_elements():
    """n = 5, 10, 20, 40 at U = 10 m/s: the aerostat trim position settles, each refinement
    changing it less than the previous one; the pendulum and axial periods at U = 0 also."""
    pos, pend, axial = [], [], []
    for n in (5, 10, 20, 40):
        p = load_params(overrides={"tether.n_elements": n})
        pos.append(find_equilibrium(p, 10.0).x[Model(p).layout.cm_pos])
        if n <= 20:
            _, tp, ta = _periods(300.0, n, integrator="semi-implicit")
            pend.append(tp)
            axial.append(ta)
    d = [np.linalg.norm(pos[i + 1] - pos[i]) for i in range(3)]
    assert d[0] > d[1] > d[2], d
    assert d[2] < 0.05  # metres, at n = 20 -> 40
    assert abs(pend[2] - pend[1]) < abs(pend[1] - pend[0]) + 0.05  # s (sampling resolution)
    assert abs(axial[2] - axial[1]) <= abs(axial[1] - axial[0]) + 0.01


def test_hull_zero_alpha_limit_is_finite(base, trim0):
    """alpha -> 0 (body aligned with the flow) gives finite forces: no 0/0 in the hull terms."""
    p = base.replace(**{"aerostat.trim_pitch_deg": 0.0})
    m = Model(p, 10.0)
    x = find_equilibrium(p, 0.0).x.copy()
    x[m.layout.euler] = [0.0, 0.0, math.pi]
    assert np.all(np.isfinite(m.rhs(x)))


def test_hull_force_at_small_incidence_is_the_closed_form(base):
    """Jones and DeLaurier at 10 m/s from the raw parameters (q = rho V^2 / 2 = 57.35 Pa,
    S = volume^(2/3), kp = (k3 - k1) eta_k). At alpha = 0: drag q CD0 S alone, no lift, no
    moment. At alpha = 1e-6: the potential lift and nose moment, linear in alpha, plus the
    crossflow drag's, quadratic: F_z = -q alpha (2 kp I1 + Cdc J1 alpha) and
    M = -q alpha (2 kp I3 + Cdc J2 alpha), to rel 1e-9 (the next terms are O(alpha^2)
    relative; the crossflow term is 6e-5 of the moment here, so the test sees it)."""
    a, h, rho = base.aerostat, base.hull, base.environment.rho_air
    q, kp = 0.5 * rho * 10.0 ** 2, (a.k3 - a.k1) * h.eta_k
    packed = Model(base, 10.0).p
    fx, fy, fz, my, mz = _hull(10.0, 0.0, 0.0, packed)
    assert fx == pytest.approx(-q * h.CD0 * a.volume ** (2.0 / 3.0), rel=1e-12)
    assert (fy, fz, my, mz) == (0.0, 0.0, 0.0, 0.0)
    alpha = 1e-6
    fx, fy, fz, my, mz = _hull(10.0 * math.cos(alpha), 0.0, 10.0 * math.sin(alpha), packed)
    assert fz == pytest.approx(-q * alpha * (2.0 * kp * h.I1 + h.Cdc * h.J1 * alpha), rel=1e-9)
    assert my == pytest.approx(-q * alpha * (2.0 * kp * h.I3 + h.Cdc * h.J2 * alpha), rel=1e-9)
    assert fy == 0.0 and mz == 0.0


def test_semi_implicit_tracks_rk4(base):
    """Semi-implicit (dt = 0.05 s) against RK4 over 60 s at U = 10 m/s from a 1 m, 0.02 rad
    perturbation: aerostat position within 0.1 m and attitude within 0.01 rad (first-order
    method; measured figures are printed by `aerostat-gym bench`)."""
    eq = find_equilibrium(base, 10.0)
    lay = Model(base).layout
    x = eq.x.copy()
    x[lay.cm_pos.start] += 1.0
    x[lay.euler.start + 1] += 0.02
    a = simulate(base, x, 60.0, wind=10.0, integrator="rk4", output_dt=0.5)
    b = simulate(base, x, 60.0, wind=10.0, integrator="semi-implicit", output_dt=0.5)
    assert np.max(np.abs(a.cm_pos - b.cm_pos)) < 0.1
    assert np.max(np.abs(a.euler - b.euler)) < 0.01


def test_invalid_inputs_raise_clear_errors(base, trim0):
    m = Model(base)
    with pytest.raises(SimulationError, match="x0 contains non-finite"):
        bad = trim0.x.copy()
        bad[3] = np.nan
        simulate(base, bad, 1.0)
    with pytest.raises(SimulationError, match="shape"):
        simulate(base, trim0.x[:-1], 1.0)
    with pytest.raises(SimulationError, match="duration"):
        simulate(base, trim0.x, -1.0)
    with pytest.raises(SimulationError, match="unknown integrator"):
        simulate(base, trim0.x, 1.0, integrator="euler")
    with pytest.raises(SimulationError, match="winch input must be finite"):
        simulate(base, trim0.x, 1.0, u=[np.inf, 0.0])
    with pytest.raises(SimulationError, match="wind speed"):
        Model(base, float("nan"))
    with pytest.raises(ValueError, match="wind_speed"):
        find_equilibrium(base, -3.0)
    assert m.layout.size == 6 * 10 + 8


def test_tether_break_is_reported(base, trim0):
    """A 3 kN tether (above the 2.6 kN still-air tension, so it loads, but below the 3.8 kN
    trim at 15 m/s) hit by a sudden 15 m/s wind breaks: reported as status 'break' with the
    time and the tension, not an exception. (A tether weaker than the net lift is refused when
    the parameters are loaded.)"""
    weak = base.replace(**{"tether.strength": 3000.0, "winch.safe_working_load": 1000.0})
    tr = simulate(weak, trim0.x, 5.0, wind=15.0)
    assert tr.status == "break"
    end = tr.events[-1]
    assert end["event"] == "break" and "exceeded" in end["message"]
    assert end["threshold"] == 3000.0 and 3000.0 < end["value"] < 3100.0  # 3049 N
    # the gust loads the line within half a second (re-run at finer steps, the break stands)
    assert end["time"] == pytest.approx(0.5) == tr.time[-1]


def test_fully_slack_tether_is_reported(base, trim0):
    """The aerostat thrown down at 5 m/s slackens every element: reported as 'slack' events
    within the first 0.5 s, the run goes on to the end (status 'ok', no break), and the tether
    re-tensions: the winch tension at 3 s is at least half its static value."""
    m = Model(base, 0.0)
    x = trim0.x.copy()
    x[m.layout.cm_vel.start + 2] = -5.0
    x[m.layout.node_vel] = np.tile([0.0, 0.0, -5.0], m.layout.n_nodes) * np.repeat(
        np.linspace(0.9, 0.1, m.layout.n_nodes), 3)
    tr = simulate(base, x, 3.0, wind=0.0, integrator="semi-implicit")
    slack = [e["time"] for e in tr.events if e["event"] == "slack"]
    assert slack and slack[0] <= 0.5
    assert tr.status == "ok" and tr.time[-1] == pytest.approx(3.0)
    assert tr.winch_tension[-1] > 0.5 * trim0.summary["winch_tension_N"]


def test_numerical_failure_is_reported_not_raised(base, trim0):
    """RK4 at 0.05 s, 90 times its stability step, blows up within the second output
    interval: a numerical failure, 'diverged' (a state past the physical bounds of
    sim.events, as an environment would end the episode), reported with the interval's end
    time; the run keeps only the good samples."""
    strong = base.replace(**{"tether.strength": 1e300})  # so 'break' cannot fire first
    tr = simulate(strong, trim0.x, 2.0, wind=10.0, integrator="rk4", dt=0.05)
    assert tr.status == "diverged"
    assert tr.events[-1]["event"] == "diverged" and "numerical failure" in tr.events[-1]["message"]
    assert tr.events[-1]["time"] == pytest.approx(tr.time[-1] + 0.1)
    assert np.all(np.isfinite(tr.states)) and tr.time[-1] < 1.0


def test_a_ground_strike_ends_a_run(base, trim0, monkeypatch):
    """A CM below the ground-strike height ends the run as it ends an episode: status
    'ground_strike' at the first interval (the trim's CM is at 312.3 m, the strike height
    raised here above it), the last sample kept, the height in the message."""
    monkeypatch.setattr(events, "ground_height", lambda params: 400.0)
    tr = simulate(base, trim0.x, 2.0, wind=0.0)
    assert tr.status == "ground_strike" and tr.time[-1] == pytest.approx(0.1)
    assert tr.events[-1]["event"] == "ground_strike"
    assert "came down to 312.3" in tr.events[-1]["message"] and "(400 m)" in tr.events[-1]["message"]


def test_a_start_outside_the_winch_limits_is_refused(base):
    """Leaving the winch's length limits ends a run, so x0 must start inside them."""
    x = find_equilibrium(base, 0.0, length=100.0).x
    with pytest.raises(SimulationError, match=r"tether length 100 m is outside the winch's "
                       r"limits \[150, 400\] m"):
        simulate(base, x, 1.0, wind=0.0)


def test_trim_failure_is_an_error():
    """No equilibrium (net lift 52 N cannot hold up the 70 N tether) is a clear error, never a
    wrong answer: refused when the parameters are loaded, naming the fields."""
    with pytest.raises(ParameterError, match="cannot lift its tether"):
        load_params(overrides={"aerostat.mass": 590.0})
