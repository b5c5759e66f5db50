"""Output-feedback LQG (aerostat_gym.agents.lqg): measurement model, estimator convergence at
the designed rate on the linear model, policy interface, and the nonlinear closed-loop damping
with sensor noise. Every assertion states its tolerance.

Measured on the shipped baseline at 10 m/s (filter designed for obs_noise = 0.01): slowest
estimator pole 0.9913 (time constant 23.0 s); environment, 10 m swing, obs_noise = 0.01,
brake dead band off: pendulum damping 0.325 against the LQR's linear prediction 0.344.
"""

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from aerostat_gym.agents.frontier import swing_response
from aerostat_gym.agents.lqg import (
    MEASURED,
    WIND_CHANNEL,
    LQGPolicy,
    LQGSchedule,
    design_lqg,
    measurement_noise,
)
from aerostat_gym.agents.policies import load_policy
from aerostat_gym.agents.sb3io import read_wrappers
from aerostat_gym.envs.spaces import CHANNELS, N_OBS
from aerostat_gym.params import load_params
from aerostat_gym.resources import SHIPPED_POLICY, shipped_path
from aerostat_gym.sim import Model

DT = 0.2
NOISE = 0.01


@pytest.fixture(scope="module")
def params():
    return load_params()


@pytest.fixture(scope="module")
def schedule(params):
    return LQGSchedule(params, speeds=np.array([10.0]), dt=DT, obs_noise=NOISE)


def _obs(y, U):
    """Standard observation (float64) carrying the SI measurements y and the wind speed U."""
    obs = np.zeros(N_OBS)
    for k, i in enumerate(MEASURED.values()):
        obs[i] = y[k] / CHANNELS[i].scale
    obs[WIND_CHANNEL] = U / CHANNELS[WIND_CHANNEL].scale
    return obs


def test_estimation_error_decays_at_designed_rate(params, schedule):
    """Linear plant x+ = Ad x + Bd u, y = C x (noise-free), the policy in the loop from a 2 m
    along-wind CM offset. The implemented filter's error e_k = x_k - x^_k equals
    ((I - L C) Ad)^k (I - L C) x_0 to 1e-6 of the error's size at that step (measured 5e-8: the
    error is a difference of states up to 1e4 times larger, so rounding accumulates), in the
    coordinates of the three slowest estimator modes (eigenvalues z_i of (I - L C) Ad) the
    error after 300 steps (60 s) is |z_i|^300 times its start within 1e-4 (relative); after
    180 s the error norm is below 5 % of its start."""
    d = schedule.designs[0]
    pol = LQGPolicy(params, dt=DT, schedule=schedule)
    lay = d.lqr.linear.layout
    x = np.zeros(d.index.size)
    x[list(d.index).index(lay.cm_pos.start)] = 2.0
    M, IL = d.error_matrix, np.eye(x.size) - d.L @ d.C
    e_ref = IL @ x
    state, errs, refs = None, [], []
    for k in range(901):
        a, state = pol.predict(_obs(d.C @ x, 10.0), state, episode_start=np.array([k == 0]))
        errs.append(x - state[0, :x.size])
        refs.append(e_ref.copy())
        e_ref = M @ e_ref
        x = d.Ad @ x + d.Bd[:, 0] * float(a[0]) * params.winch.max_speed
    errs, refs = np.array(errs), np.array(refs)
    scale = np.max(np.abs(refs), axis=1, keepdims=True)
    assert np.max(np.abs(errs - refs) / scale) < 1e-6
    z, V = np.linalg.eig(M)
    q = np.linalg.solve(V, errs[1:].T)  # modal coordinates of the error, steps 1..900
    for i in np.argsort(-np.abs(z))[:3]:  # the three slowest estimator modes
        ratio = q[i, 300] / q[i, 0]
        assert abs(ratio) == pytest.approx(abs(z[i]) ** 300, rel=1e-4)
    norms = np.linalg.norm(errs, axis=1)
    assert norms[900] < 0.05 * norms[0]


def test_measurement_rows(params, schedule):
    """Direct channels are unit rows; the tension row predicts the nonlinear winch-end tension
    change of a 0.1 m length change within 1 %; R is (sigma scale)^2 (exact)."""
    d = schedule.designs[0]
    for r, name in enumerate(MEASURED):
        if name != "dtension":
            assert np.sum(d.C[r] == 1.0) == 1 and np.sum(d.C[r] != 0.0) == 1
    lay = d.lqr.linear.layout
    model = Model(params, wind=10.0)
    x = d.lqr.x_trim.copy()
    x[lay.winch_length] += 0.1
    dT = model.end_tensions(x)[1] - model.end_tensions(d.lqr.x_trim)[1]
    j = list(d.index).index(lay.winch_length)
    assert d.C[list(MEASURED).index("dtension"), j] * 0.1 == pytest.approx(dT, rel=0.01)
    R = measurement_noise(0.02)
    assert R[0, 0] == pytest.approx((0.02 * 10.0) ** 2, rel=1e-12)


def test_separation_closed_loop_poles(schedule):
    """Separation principle: the poles of the joint plant + estimator loop are the LQR's and
    the estimator's (matched one to one within 1e-8). In the coordinates (x, e-) with e- the
    a-priori error, x+ = (Ad - Bd K) x + Bd K (I - L C) e- and e-+ = Ad (I - L C) e-; the
    spectrum of Ad (I - L C) is that of (I - L C) Ad."""
    d = schedule.designs[0]
    n = d.index.size
    Ad, Bd, K, L, C = d.Ad, d.Bd, d.K[None, :], d.L, d.C
    # error coordinates: x+ = (Ad - Bd K) x + Bd K e-, e+ = (I - L C) Ad e (exact algebra)
    IL = np.eye(n) - L @ C
    J = np.block([[Ad - Bd @ K, Bd @ K @ IL], [np.zeros((n, n)), Ad @ IL]])
    z = np.linalg.eigvals(J)
    expected = np.concatenate([np.linalg.eigvals(Ad - Bd @ K), d.estimator_poles])
    cost = np.abs(expected[:, None] - z[None, :])
    r, c = linear_sum_assignment(cost)
    assert np.max(cost[r, c]) < 1e-8


def test_policy_interface(params, schedule):
    """Standard observation in, (1,) or (N, 1) float32 actions in [-1, 1] out; the state carries
    estimate, integral, wind estimate and last set-point; short observations are refused."""
    pol = LQGPolicy(params, dt=DT, schedule=schedule)
    assert pol.obs_dim == N_OBS
    obs = _obs(np.zeros(len(MEASURED)), 10.0).astype(np.float32)
    a, s = pol.predict(obs)
    assert a.shape == (1,) and a.dtype == np.float32 and s.shape == (1, pol.n + 3)
    assert a[0] == 0.0 and s[0, pol.n + 1] == pytest.approx(10.0, rel=1e-6)
    A, S = pol.predict(np.stack([obs] * 3))
    assert A.shape == (3, 1) and S.shape == (3, pol.n + 3)
    with pytest.raises(ValueError, match="standard observation"):
        pol.predict(np.zeros(5))
    with pytest.raises(ValueError, match="obs_noise"):
        design_lqg(params, 10.0, obs_noise=-1.0)
    with pytest.raises(ValueError, match="obs_noise"):
        design_lqg(params, 10.0, obs_noise=True)


def test_nonlinear_damping_with_sensor_noise(params, schedule):
    """Environment, 10 m/s, 10 m swing, sensor noise obs_noise = 0.01 (scaled units), the
    winch's brake logic on: the LQG's fitted pendulum damping is within 20 % of the LQR's linear
    prediction (0.344)."""
    pol = LQGPolicy(params, dt=DT, schedule=schedule)
    run = swing_response(pol, 10.0, 10.0, obs_noise=NOISE, seed=3)
    pred = schedule.designs[0].lqr.mode("pendulum").zeta
    assert run.ended is None and run.r2 > 0.99
    assert run.zeta == pytest.approx(pred, rel=0.20)


@pytest.fixture(scope="module")
def modal_schedule(params):
    return LQGSchedule(params, speeds=np.array([10.0, 15.0]), dt=DT, obs_noise=NOISE,
                       gains="modal")


def test_modal_gains_are_the_modal_design(params, modal_schedule):
    """gains="modal": the state gain on the estimate is the modal design's over the same subset
    (to 1e-12 relative), with no length integral, and the state-feedback poles of the subset
    are the modal design's expected ones (pendulum placed at the designed ratio, every other
    mode where it was) within the modal design's own placement tolerance (1e-6)."""
    from aerostat_gym.agents.modal import PLACEMENT_TOL, design_modal, pole_set_distance

    for d in modal_schedule.designs:
        m = design_modal(params, d.wind_speed, dt=DT)
        assert np.allclose(d.K, m.K[d.index], rtol=1e-12, atol=1e-12 * np.abs(m.K).max())
        assert d.K_integral == 0.0
        poles = np.linalg.eigvals(d.Ad - d.Bd @ d.K[None, :])
        assert pole_set_distance(poles, m.expected_poles()) < PLACEMENT_TOL
        assert d.summary()["pendulum"]["closed"]["zeta"] == pytest.approx(m.zeta, abs=1e-12)
    with pytest.raises(ValueError, match="gains"):
        design_lqg(params, 10.0, gains="pid")


@pytest.mark.parametrize("wind_speed", [10.0, 15.0])
def test_modal_lqg_damping_with_sensor_noise(params, modal_schedule, wind_speed):
    """Environment, 10 m swing, obs_noise = 0.01, brake logic on: the modal gains on the
    Kalman estimate keep the privileged modal controller's damping. Measured (seed 3): single-
    mode fit 0.547 at 10 m/s and 0.755 at 15 m/s against the designed 0.60 and 0.85 (the fit
    reads the privileged modal controller 0.545 and 0.755, see tests/test_modal.py); asserted
    within 20 % of the designed ratio, like the modal controller's own test."""
    pol = LQGPolicy(params, dt=DT, schedule=modal_schedule)
    run = swing_response(pol, wind_speed, 10.0, obs_noise=NOISE, seed=3)
    designed = {10.0: 0.60, 15.0: 0.85}[wind_speed]
    assert run.ended is None and run.r2 > 0.99
    assert run.zeta == pytest.approx(designed, rel=0.20)
    assert np.max(np.abs(run.set_point)) <= params.winch.max_speed


def test_estimate_features_filter_the_sensor_noise(params, modal_schedule):
    """LQGPolicy.estimate_features (what a residual with observe_estimate reads): in the linear
    regime (1 m swing, calm air, 10 m/s) the measured channels reconstructed from the estimate,
    C x^, are closer to the noise-free channels than the measurement itself. A noisy and a
    noise-free environment on the same seeds, driven by the same commands (the filter's own),
    fly the same trajectory, so the noise-free one is the truth. Measured (4 seeds, 120 s after
    the first 5 s): reconstruction RMS error 0.0026 / 0.0010 / 0.0006 on dx / dz / dlength and
    0.0083-0.0099 on vx, vz, pitch, q, tension against the measurement's 0.0100; asserted: at
    most the measurement's on every channel (5 % slack: the estimator trusts the rate and
    tension channels, ~1.0x), at most a third of it on the displacements and the length. The
    last feature is the set-point sent, as a fraction of the winch's top speed."""
    from aerostat_gym.agents.lqg import ESTIMATE_FEATURES
    from aerostat_gym.envs.vector import TetheredAerostatVectorEnv

    kw = dict(num_envs=4, max_episode_steps=700, perturbation={"swing": 1.0, "fixed": True},
              turbulence="none", wind_speed=(10.0, 10.0))
    noisy = TetheredAerostatVectorEnv(obs_noise=NOISE, **kw)
    clean = TetheredAerostatVectorEnv(obs_noise=0.0, **kw)
    seeds = [1, 2, 3, 4]
    y, _ = noisy.reset(seed=seeds)
    truth, _ = clean.reset(seed=seeds)
    pol = LQGPolicy(params, dt=DT, schedule=modal_schedule)
    channels = list(MEASURED.values())
    state, start, err_meas, err_est = None, np.ones(4, bool), [], []
    for k in range(625):
        action, state = pol.predict(y, state=state, episode_start=start)
        start[:] = False
        features = pol.estimate_features(state)
        assert features.shape == (4, len(ESTIMATE_FEATURES)) and features.dtype == np.float32
        np.testing.assert_allclose(features[:, -1], action[:, 0], rtol=1e-6)
        if k >= 25:
            err_meas.append(y[:, channels] - truth[:, channels])
            err_est.append(features[:, :-1] - truth[:, channels])
        y = noisy.step(action)[0]
        truth = clean.step(action)[0]
    rms_meas = np.sqrt(np.mean(np.square(err_meas), axis=(0, 1)))
    rms_est = np.sqrt(np.mean(np.square(err_est), axis=(0, 1)))
    np.testing.assert_allclose(rms_meas, NOISE, rtol=0.05)
    assert np.all(rms_est <= 1.05 * rms_meas), dict(zip(MEASURED, rms_est, strict=True))
    for name in ("dx", "dz", "dlength"):
        i = list(MEASURED).index(name)
        assert rms_est[i] <= rms_meas[i] / 3, (name, rms_est[i])


def test_modal_lqg_and_the_shipped_base_are_designed_up_to_the_wind_range(params):
    """wind_range=(20, 25) continues the default 2-16 m/s table to 26 m/s (the baseline's
    motor holds the trim to 26 m/s): at 25 m/s the gains are the design at 25 m/s, to the last
    bit, not the 16 m/s ones clamped (40 % apart in norm when written), and inside 2-16 m/s the
    table is the default's row for row. The shipped residual's base (modal_lqg at the noise it
    was trained with) gets the same table."""
    noise = read_wrappers(shipped_path(SHIPPED_POLICY))["residual"]["obs_noise"]
    high = load_policy("modal_lqg", wind_range=(20, 25), obs_noise=noise).schedule
    default = load_policy("modal_lqg", obs_noise=noise).schedule
    assert high.speeds.tolist() == [float(u) for u in range(2, 27)]
    assert load_policy("modal_lqg", wind_range=(3, 16), obs_noise=noise).schedule is default
    for k in default.tables:
        assert np.array_equal(high.tables[k][:default.speeds.size], default.tables[k]), k
    U = np.array([25.0])
    k25, k16 = high.lookup(U, ["K"])["K"][0], default.lookup(U, ["K"])["K"][0]
    reference = design_lqg(params, 25.0, DT, noise, gains="modal").K
    assert np.max(np.abs(k25 - reference)) <= 1e-9 * np.max(np.abs(reference))
    assert np.array_equal(k16, default.tables["K"][-1])
    assert np.linalg.norm(k25 - k16) > 0.2 * np.linalg.norm(k16)
    base = load_policy("shipped", wind_range=(20, 25)).residual[0]
    assert base.schedule is high
