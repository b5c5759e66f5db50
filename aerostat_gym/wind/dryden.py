"""Dryden turbulence from the MIL forming filters, discretised exactly (no Euler stand-ins).

The forming filters (MIL-F-8785C form, tau = L / V, sqrt(pi) folded in so that they are driven
by unit-intensity white noise, E[xi(t) xi(t + s)] = delta(s)):

    H_u(s) = sigma sqrt(2 tau) / (1 + tau s)
    H_v(s) = H_w(s) = sigma sqrt(tau) (1 + sqrt(3) tau s) / (1 + tau s)^2

are written in state space x' = A x + B xi, y = C x and sampled exactly: x_{k+1} = Phi x_k + w_k
with Phi = exp(A dt) and w_k ~ N(0, Q_d), Q_d = integral_0^dt exp(A s) B B^T exp(A^T s) ds
(Van Loan). The u channel is then the Ornstein-Uhlenbeck recursion
u_{k+1} = phi u_k + sigma sqrt(1 - phi^2) eta_k with phi = exp(-V dt / L_u). The first state is
drawn from the stationary covariance P (A P + P A^T + B B^T = 0), so there is no start-up
transient. The sampled sequence has exactly the autocorrelation of the continuous process at
the sample times, for any dt.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg
from numba import njit


def forming_filter(sigma: float, L: float, V: float, comp: int):
    """State-space (A, B, C) of the Dryden forming filter; L in the 8785C convention [m].

    Notes
    -----
    u: A = [-1/tau], B = [1], C = [sigma sqrt(2 / tau)].
    v, w (controllable form of sigma sqrt(tau) (1 + sqrt(3) tau s) / (1 + tau s)^2):
    A = [[0, 1], [-1/tau^2, -2/tau]], B = [0, 1]^T, C = sigma sqrt(tau) / tau^2 [1, sqrt(3) tau].
    """
    tau = L / V
    if comp == 0:
        return (np.array([[-1.0 / tau]]), np.array([[1.0]]),
                np.array([sigma * math.sqrt(2.0 / tau)]))
    A = np.array([[0.0, 1.0], [-1.0 / tau**2, -2.0 / tau]])
    B = np.array([[0.0], [1.0]])
    C = sigma * math.sqrt(tau) / tau**2 * np.array([1.0, math.sqrt(3.0) * tau])
    return A, B, C


def van_loan(A: np.ndarray, B: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact discretisation (Phi, Q_d) of x' = A x + B xi with unit-intensity white noise xi.

    Notes
    -----
    ``E = expm([[-A, B B^T], [0, A^T]] dt)``; ``Phi = E_22^T``, ``Q_d = Phi E_12``.
    """
    m = A.shape[0]
    M = np.zeros((2 * m, 2 * m))
    M[:m, :m], M[:m, m:], M[m:, m:] = -A, B @ B.T, A.T
    E = scipy.linalg.expm(M * dt)
    Phi = E[m:, m:].T
    Qd = Phi @ E[:m, m:]
    return Phi, 0.5 * (Qd + Qd.T)


def stationary_covariance(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Stationary state covariance P solving A P + P A^T + B B^T = 0."""
    return scipy.linalg.solve_continuous_lyapunov(A, -B @ B.T)


@njit(cache=True)
def _propagate(Phi, Lq, C, x0, eta):
    """y_k = C x_k with x_{k+1} = Phi x_k + Lq eta_k (eta: (n, m) standard normals)."""
    n, m = eta.shape
    y = np.empty(n)
    x = x0.copy()
    xn = np.empty(m)
    for k in range(n):
        acc = 0.0
        for i in range(m):
            acc += C[i] * x[i]
        y[k] = acc
        for i in range(m):
            s = 0.0
            for j in range(m):
                s += Phi[i, j] * x[j] + Lq[i, j] * eta[k, j]
            xn[i] = s
        x[:] = xn
    return y


def dryden_series(n: int, dt: float, V: float, sigma: float, L: float, comp: int,
                  rng: np.random.Generator) -> np.ndarray:
    """n samples at step dt [s] of one Dryden component seen at a point in a wind V [m/s].

    ``L`` is in the 8785C convention [m]. Draws (n + 1) x m standard normals from ``rng``
    (m = 1 for u, 2 for v, w): the first row sets the stationary initial state.
    """
    A, B, C = forming_filter(sigma, L, V, comp)
    Phi, Qd = van_loan(A, B, dt)
    eta = rng.standard_normal((n + 1, A.shape[0]))
    x0 = np.linalg.cholesky(stationary_covariance(A, B)) @ eta[0]
    return _propagate(Phi, _chol_psd(Qd), C, x0, eta[1:])


def _chol_psd(Q: np.ndarray) -> np.ndarray:
    """Cholesky factor of a covariance that may be numerically singular (tiny dt / tau)."""
    d = np.sqrt(np.maximum(np.diag(Q), 0.0))
    scale = np.where(d > 0, d, 1.0)
    R = Q / np.outer(scale, scale) + 1e-14 * np.eye(Q.shape[0])
    return np.linalg.cholesky(R) * scale[:, None]


def dryden_point_field(cfg, V: float, n: int, rng: np.random.Generator) -> np.ndarray:
    """u, v, w at one point (the reference height) as a (1, n, 3) field for ``air_velocity``."""
    Ls = cfg.scales_8785c()
    cols = [dryden_series(n, cfg.dt, V, cfg.sigmas[c], Ls[c], c, rng) for c in range(3)]
    return np.ascontiguousarray(np.stack(cols, axis=-1)[None])
