"""The still-air closed forms Table 2 judges any aerostat against: the rigid aerostat on a
straight elastic tether (analysis.still_air) and the heavy hanging string
(analysis.reference.hanging_chain_periods), each checked against an independent calculation
written out here."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from aerostat_gym.analysis.reference import (
    LIGHT_TETHER,
    hanging_chain_periods,
    tether_mass_periods,
)
from aerostat_gym.analysis.still_air import COORDINATES, still_air_matrices, still_air_modes
from aerostat_gym.params import load_params
from aerostat_gym.scaling import scale_aerostat


@pytest.fixture(scope="module")
def base():
    return load_params()


def test_still_air_stiffness_closed_form(base):
    """Swing stiffness (B - m g - mu g L / 2) L per radian and stretch stiffness EA / L
    (rel 1e-12); both matrices symmetric, the mass matrix positive definite; yaw about the
    vertical has no stiffness (one zero eigenvalue of K, |.| < 1e-9 of the largest)."""
    M, K = still_air_matrices(base)
    d, L, g = base.derived, base.tether.length, base.environment.g
    swing = (d.net_lift - 0.5 * d.mass_per_length * g * L) * L
    i = {c: k for k, c in enumerate(COORDINATES)}
    assert K[i["swing_x"], i["swing_x"]] == pytest.approx(swing, rel=1e-12)
    assert K[i["swing_y"], i["swing_y"]] == pytest.approx(swing, rel=1e-12)
    assert K[i["stretch"], i["stretch"]] == pytest.approx(d.EA / L, rel=1e-12)
    assert np.allclose(M, M.T, rtol=0, atol=1e-9 * np.abs(M).max())
    assert np.allclose(K, K.T, rtol=0, atol=1e-9 * np.abs(K).max())
    assert np.linalg.eigvalsh(M).min() > 0.0
    eig = np.abs(np.linalg.eigvals(K))
    assert np.sum(eig < 1e-9 * eig.max()) == 1


def _planar_pendulum(p):
    """Independent pitch-plane model with an inextensible tether: coordinates (tether angle,
    hull pitch), positions written out in the x-z plane, energies differentiated numerically.
    Returns (pendulum, pitching) periods [s]."""
    a, d, g = p.aerostat, p.derived, p.environment.g
    L, mu = p.tether.length, d.mass_per_length
    th0 = math.radians(a.trim_pitch_deg)
    leash = np.array([d.leash_position[0], d.leash_position[2]])
    cb = np.array([a.cb_position[0], a.cb_position[2]])

    def rotate(th, v):  # body (x, z) to inertial (x, up); theta < 0 nose up
        return v[0] * np.array([math.cos(th), -math.sin(th)]) + v[1] * np.array([math.sin(th), math.cos(th)])

    def points(q):
        c = L * np.array([math.sin(q[0]), math.cos(q[0])])
        return c + rotate(th0 + q[1], -leash), c + rotate(th0 + q[1], cb - leash)

    def potential(q):
        cm, cb_ = points(q)
        return a.mass * g * cm[1] - d.buoyancy * cb_[1] + mu * L * g * 0.5 * L * math.cos(q[0])

    h = 1e-4
    eye = np.eye(2) * h
    K = np.array([[(potential(eye[i] + eye[j]) - potential(eye[i] - eye[j])
                    - potential(-eye[i] + eye[j]) + potential(-eye[i] - eye[j])) / (4 * h * h)
                   for j in range(2)] for i in range(2)])
    J = np.column_stack([(points(eye[i])[0] - points(-eye[i])[0]) / (2 * h) for i in range(2)])
    to_body = np.array([[math.cos(th0), -math.sin(th0)], [math.sin(th0), math.cos(th0)]])
    Jb = to_body @ J
    M = Jb.T @ np.diag([d.effective_mass[0], d.effective_mass[2]]) @ Jb
    M += np.diag([mu * L ** 3 / 3, a.Iyy])
    w2 = np.sort(np.real(np.linalg.eigvals(np.linalg.solve(M, K))))
    return 2 * math.pi / math.sqrt(w2[0]), 2 * math.pi / math.sqrt(w2[1])


@pytest.mark.parametrize("factor, length, pitch", [(1.0, 300.0, -4.0), (3.5, 33.0, -12.0),
                                                   (0.73, 40.0, 1.3)])
def test_still_air_pendulum_and_pitching_match_a_planar_model(base, factor, length, pitch):
    """With a stiff tether (E x 1e6, so the stretch decouples) the longitudinal pendulum and
    the pitching of still_air_modes are those of a planar two-coordinate model written out
    independently (rel 1e-5): the baseline, and a 3.5x hull on 33 m and a 0.73x hull on 40 m,
    where the hull's turning makes the pendulum 25 % and 11 % longer than the point mass's."""
    p = scale_aerostat(base, factor, length, trim_pitch_deg=pitch)
    p = p.replace(**{"tether.youngs_modulus": p.tether.youngs_modulus * 1e6})
    pendulum, pitching = _planar_pendulum(p)
    got = still_air_modes(p)
    assert got["long_pendulum"] == pytest.approx(pendulum, rel=1e-5)
    assert got["pitching"] == pytest.approx(pitching, rel=1e-5)


def _shooting_pendulum(p, tip_mass):
    """Independent heavy-string pendulum: (T y')' + mu w^2 y = 0 integrated from the winch
    (y = 0, y' = 1) with T(s) = T_w + mu g s, and the lowest w where T(L) y'(L) = m w^2 y(L)."""
    d, g, L = p.derived, p.environment.g, p.tether.length
    mu, top = d.mass_per_length, d.net_lift
    bottom = top - mu * g * L

    def mismatch(w):
        def f(s, z):  # z = (y, T y')
            return [z[1] / (bottom + mu * g * s), -mu * w * w * z[0]]
        sol = solve_ivp(f, (0.0, L), [0.0, bottom], rtol=1e-11, atol=1e-12)
        y, ty = sol.y[:, -1]
        return ty - tip_mass * w * w * y

    rayleigh = 2 * math.pi / tether_mass_periods(p)["long_pendulum"]
    return 2 * math.pi / brentq(mismatch, 0.5 * rayleigh, rayleigh * (1 + 1e-9), xtol=1e-13)


def test_hanging_chain_against_shooting_and_rayleigh(base):
    """A tether weighing 0.53 of the net lift (density x 20): the Bessel solution equals a
    shooting integration of the string equation (rel 1e-7), and its period is 3.41 % longer
    than the straight-tether Rayleigh estimate's (which bounds the frequency from above); a light
    tether (below LIGHT_TETHER) returns the Rayleigh estimate itself."""
    heavy = base.replace(**{"tether.density": base.tether.density * 20})
    got = hanging_chain_periods(heavy)
    want = _shooting_pendulum(heavy, heavy.derived.effective_mass[0])
    assert got["long_pendulum"] == pytest.approx(want, rel=1e-7)
    ratio = got["long_pendulum"] / tether_mass_periods(heavy)["long_pendulum"]
    assert ratio == pytest.approx(1.0341, abs=2e-4)
    light = base.replace(**{"tether.density": base.tether.density * 0.2})
    d = light.derived
    assert d.mass_per_length * light.environment.g * light.tether.length < LIGHT_TETHER * d.net_lift
    assert hanging_chain_periods(light)["lat_pendulum"] == tether_mass_periods(light)["lat_pendulum"]
