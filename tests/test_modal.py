"""Modal (pendulum pole-placement) controller: exact placement on the linear model, untouched
modes, schedule and policy, and the nonlinear closed-loop damping in the environment. Every
assertion states its tolerance.

Measured on the shipped baseline (dt = 0.2 s, default zeta schedule 0.20 / 0.60 / 0.85 at
5 / 10 / 15 m/s, 30 s length loop), pendulum damping ratio fitted to the along-wind CM
displacement of a swing recovery in the environment with the winch's brake logic on (dwell
brake, 10 s inside 0.002 m/s), single-mode fit / sinusoid-plus-drift fit:
10 m/s, 1 m: 0.568 / 0.599; 10 m/s, 10 m: 0.545 / 0.611 at a peak reel speed of 0.715 m/s;
15 m/s, 1 m: 0.741 / 0.848; 15 m/s, 10 m: 0.755 / 0.872 at 0.443 m/s. The same single-mode fit
applied to the linear closed loop's response gives 0.568 (10 m/s) and 0.746 (15 m/s): the gap to
the designed value is the fit (the 30 s length mode and the tether modes under the pendulum),
not the nonlinearity. (With the 0.2 dead band, 0.02 m/s and no dwell, 15 m/s at 1 m gave
0.561: the brake cut the tail.)
"""

import numpy as np
import pytest

from aerostat_gym.agents.frontier import (
    initial_deviation,
    linear_response,
    modal_linear_peak,
    modal_peak_limit,
    swing_response,
)
from aerostat_gym.agents.metrics import fit_damped_sinusoid
from aerostat_gym.agents.modal import (
    ModalPolicy,
    ModalSchedule,
    default_zeta,
    design_modal,
    pendulum_target,
)
from aerostat_gym.envs.spaces import OBS_FULL_STATE, OBS_FULL_WIND
from aerostat_gym.params import load_params

DT = 0.2


@pytest.fixture(scope="module")
def params():
    return load_params()


@pytest.fixture(scope="module")
def designs(params):
    return {U: design_modal(params, U, dt=DT) for U in (5.0, 10.0, 15.0)}


@pytest.mark.parametrize("U", [5.0, 10.0, 15.0])
def test_closed_loop_poles_equal_designed(designs, U):
    """Every closed-loop discrete pole of the longitudinal + winch model equals its designed
    value within 1e-6 (one-to-one matching): the pendulum pair at zeta(U) and the open-loop
    natural frequency, the length pole at exp(-dt / 30 s), all others at their open-loop
    values (measured error ~5e-13)."""
    d = designs[U]
    z = np.linalg.eigvals(d.closed_loop_matrix)
    assert d.placement_error() < 1e-6
    # the designed pendulum pole itself, from the closed-loop spectrum
    zp = pendulum_target(d.wn, default_zeta(U), DT)
    assert np.min(np.abs(z - zp)) < 1e-6
    assert np.min(np.abs(z - np.exp(-DT / 30.0))) < 1e-6
    s = np.log(z[np.argmin(np.abs(z - zp))]) / DT
    assert -s.real / abs(s) == pytest.approx(default_zeta(U), abs=1e-6)


@pytest.mark.parametrize("U", [5.0, 10.0, 15.0])
def test_unmoved_modes_keep_open_loop_poles(designs, U):
    """Pitching and axial-spring poles of the closed loop equal their open-loop values within
    1e-6 in z, and the gain moves nothing it should not: K v_j = 0 to 1e-9 (relative to |K|)
    for every right eigenvector v_j of the unmoved modes."""
    d = designs[U]
    z = np.linalg.eigvals(d.closed_loop_matrix)
    for label in ("pitching", "axial spring"):
        zo = np.exp(d.lqr.mode(label, "open").eigenvalue * DT)
        assert np.min(np.abs(z - zo)) < 1e-6
    A = d.lqr.linear.A_free[np.ix_(d.index, d.index)]
    lam, V = np.linalg.eig(A)
    keep = np.setdiff1d(np.arange(lam.size), d.moved)
    Kv = np.abs(d.K_subset @ V[:, keep]) / np.linalg.norm(V[:, keep], axis=0)
    assert np.max(Kv) < 1e-9 * np.linalg.norm(d.K_subset)


def test_lateral_and_integral_gains_zero(designs):
    """The design touches only the longitudinal and winch states: lateral and integral gains
    are exactly 0."""
    d = designs[10.0]
    lay = d.lqr.linear.layout
    assert np.all(d.K[lay.lateral_indices()] == 0.0)
    assert d.K[-1] == 0.0


def test_linear_peak_set_point_within_winch_limit(params, designs):
    """Frontier on the linear model: a 10 m along-wind swing asks for a peak set-point within
    1 m/s at every design speed (measured 0.707, 0.716, 0.459 m/s at 5, 10, 15 m/s)."""
    for U, d in designs.items():
        peak = modal_linear_peak(d, initial_deviation(U, 10.0, params))
        assert 0.3 < peak < 1.0, (U, peak)


def test_schedule_and_policy(params):
    """A two-speed schedule interpolates the gain linearly (1e-12) and the policy's action is
    -K(U) dx / max_speed (1e-6, float32 observation)."""
    sch = ModalSchedule(params, speeds=np.array([10.0, 11.0]), dt=DT)
    np.testing.assert_allclose(sch.gain(10.5), 0.5 * (sch.gains[0] + sch.gains[1]), atol=1e-12)
    assert sch.pendulum_zeta[0, 1] == pytest.approx(default_zeta(10.0), abs=1e-12)
    pol = ModalPolicy(params, dt=DT, schedule=sch)
    d = sch.designs[0]
    lay = d.lqr.linear.layout
    obs = np.zeros(OBS_FULL_STATE + lay.size, np.float32)
    obs[OBS_FULL_WIND] = 10.0
    obs[OBS_FULL_STATE + lay.cm_pos.start] = 2.0
    a, _ = pol.predict(obs)
    assert a[0] == pytest.approx(d.command(obs[OBS_FULL_STATE:].astype(float))
                                 / params.winch.max_speed, abs=1e-6)


def test_bad_target_named(params):
    """zeta outside (0, 1) and a non-positive length time are refused, naming the argument."""
    with pytest.raises(ValueError, match="zeta"):
        design_modal(params, 10.0, zeta=1.2)
    with pytest.raises(ValueError, match="length_time"):
        design_modal(params, 10.0, zeta=0.5, length_time=0.0)


def _nonlinear(params, U, swing):
    sch = ModalSchedule(params, speeds=np.array([U]), dt=DT)
    run = swing_response(ModalPolicy(params, dt=DT, schedule=sch), U, swing)  # brake logic on
    d = sch.designs[0]
    X, _ = linear_response(d.closed_loop_matrix, d.K_subset,
                           initial_deviation(U, swing, params)[d.index], run.time.size - 1)
    ix = list(d.index).index(d.lqr.linear.layout.cm_pos.start)
    return run, d, fit_damped_sinusoid(run.time, X[:, ix])


def test_nonlinear_damping_10ms_10m(params):
    """Environment, 10 m/s, 10 m swing, brake logic on: fitted pendulum damping within 20 %
    of the designed 0.60 (measured 0.545) and within 5 % of the same fit of the linear closed
    loop (measured 0.568); the sinusoid-plus-drift fit within 5 % of the designed value
    (measured 0.611); at least 0.5 at a peak reel speed within 1 m/s (measured 0.715)."""
    run, d, lin = _nonlinear(params, 10.0, 10.0)
    assert run.ended is None and run.r2 > 0.99
    assert run.zeta == pytest.approx(d.zeta, rel=0.20)
    assert run.zeta_drift == pytest.approx(d.zeta, rel=0.05)  # measured 0.611
    assert run.zeta == pytest.approx(lin.zeta, rel=0.05)
    assert run.zeta >= 0.5 and run.peak_reel_speed < 1.0


@pytest.mark.parametrize("U, swing, floor", [(10.0, 1.0, 0.5), (15.0, 1.0, 0.7),
                                             (15.0, 10.0, 0.7)])
def test_nonlinear_damping_other_cases(params, U, swing, floor):
    """The other three cases of the acceptance grid, brake logic on: within 20 % of the
    designed zeta and 5 % of the linear closed loop's fit, above the floor (measured 0.568,
    0.741, 0.755 against designed 0.60, 0.85, 0.85); the drift fit within 5 % of the designed
    value (measured 0.599, 0.848, 0.872)."""
    run, d, lin = _nonlinear(params, U, swing)
    assert run.ended is None
    assert run.zeta == pytest.approx(d.zeta, rel=0.20)
    assert run.zeta_drift == pytest.approx(d.zeta, rel=0.05)
    assert run.zeta == pytest.approx(lin.zeta, rel=0.05)
    assert run.zeta >= floor and run.peak_reel_speed < 1.0


def test_modal_limit_at_winch_speed_5ms(params):
    """The modal frontier's end at 5 m/s: the largest designed pendulum damping whose linear
    closed loop asks for at most 1 m/s from a 10 m swing is 0.222 (bisection to 1e-3; asserted
    to 0.003), with its peak set-point within 1 m/s (measured 0.994). 10 and 15 m/s give 0.803
    and >= 0.99 (not asserted here: same code path)."""
    zeta, peak = modal_peak_limit(params, 5.0, 10.0)
    assert zeta == pytest.approx(0.222, abs=0.003)
    assert 0.95 < peak <= 1.0


def test_below_the_schedule_the_gains_fade_and_the_swing_decays():
    """At 1 m/s, under the default schedule's lowest design speed (2 m/s), the modal and the
    modal-LQG gains are the 2 m/s ones times (1 / 2)^2 (rel 1e-12); the filter's tables are not
    faded. On the 10 m swing the modal controller then damps the pendulum at least as well as
    the braked winch (measured 0.041 against 0.034; on the unfaded 2 m/s gains the reel
    saturates and the swing grew, -0.031) and reels at most 0.8 of its top speed (0.60)."""
    from aerostat_gym.agents.evaluate import episode_metrics, run_scenario
    from aerostat_gym.agents.lqg import LQGSchedule
    from aerostat_gym.agents.policies import load_policy

    p = load_params()
    modal = load_policy("modal", params=p)
    lowest = modal.schedule.speeds[0]
    assert lowest == 2.0
    np.testing.assert_allclose(modal.schedule.gain(1.0), 0.25 * modal.schedule.gains[0],
                               rtol=1e-12, atol=0)
    lqg = LQGSchedule(p, speeds=[2.0, 3.0], gains="modal", obs_noise=0.01)
    low, node = lqg.lookup(np.array([1.0])), lqg.lookup(np.array([2.0]))
    np.testing.assert_allclose(low["K"], 0.25 * node["K"], rtol=1e-12, atol=0)
    np.testing.assert_allclose(low["K_integral"], 0.25 * node["K_integral"], rtol=1e-12, atol=0)
    np.testing.assert_array_equal(low["L"], node["L"])
    zeta = {}
    for name in ("passive", "modal"):
        ep = run_scenario(load_policy(name, params=p), "recover", [1.0], [0],
                          env_kwargs={"obs_noise": 0.0})
        m = episode_metrics(ep, 0)
        zeta[name] = m["pendulum_zeta"]
        assert m["ended"] is None
    assert zeta["modal"] >= zeta["passive"] > 0, zeta
    assert m["peak_reel_speed_m_s"] <= 0.8 * p.winch.max_speed, m
