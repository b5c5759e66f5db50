"""Trim: the steady equilibrium of the tethered aerostat in a steady mean wind.

``find_equilibrium(params, wind_speed)`` solves F(X) = 0 with the compiled right-hand side
(all velocities zero, winch braked): the generalized forces on every tether node and on the
aerostat (force in body axes, moment about the CM) vanish. Newton's method with a central
finite-difference Jacobian and a minimum-norm least-squares step (at zero wind the yaw angle
is undetermined; the min-norm step leaves it where it is) and a backtracking line search
that keeps a step where it lowers the largest generalized force or, failing that, shortens the
next Newton correction (:func:`_step_accepted`: the force test alone creeps where the lower
tether is nearly slack).

The cost grows gently with the number of elements n. Node j's generalized force depends only
on nodes j - 1, j, j + 1 (and the top node's on the aerostat), so the Jacobian is banded with
a dense aerostat border: perturbing every third node together gives all its node columns in 9
pairs of evaluations, plus 6 for the aerostat, whatever n (a column-by-column Jacobian costs
6 n + 12 evaluations). Beyond ``DENSE_UNKNOWNS`` unknowns the Newton step is solved by sparse
LU (O(n)) instead of the dense least-squares solve (O(n^3)), falling back to it when the
sparse matrix is singular.
The start is the exact zero-wind solution (a vertical tether with each element stretched by
its own tension), continued in wind speed in steps of at most ``max_step`` m/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse
import scipy.sparse.linalg

from ..checks import is_finite_number
from ..params import MAX_WIND_SPEED, Params, load_params, paid_out_weight, profile_factor
from ..physics.core import rotation_matrix
from ..physics.state import S_Z
from ..sim import Model

REL_TOL = 1e-9
#: Largest Newton system solved densely (min-norm least squares); larger ones use sparse LU.
DENSE_UNKNOWNS = 100


class TrimError(RuntimeError):
    """No equilibrium was found (the message says where and how close it came)."""


@dataclass
class Equilibrium:
    """A trimmed state and its summary (SI units; angles in degrees in ``summary``)."""

    x: np.ndarray
    wind_speed: float
    params: Params
    residual: float
    iterations: int
    summary: dict


def _unknown_index(model: Model) -> np.ndarray:
    lay = model.layout
    nodes = np.arange(3 * lay.n_nodes)
    return np.concatenate([nodes, np.arange(lay.cm_pos.start, lay.cm_pos.stop),
                           np.arange(lay.euler.start, lay.euler.stop)])


def _residual(model: Model, x: np.ndarray) -> np.ndarray:
    """Generalized forces [N, N m / aerostat length] at a zero-velocity state x."""
    lay = model.layout
    dx = model.rhs(x)
    d = model.params.derived
    L = x[lay.winch_length]
    m_node = d.mass_per_length * L / model.n
    node_f = m_node * dx[lay.node_vel]
    R = rotation_matrix(*x[lay.euler])
    body_f = np.array(d.effective_mass) * (R.T @ dx[lay.cm_vel])
    a = model.params.aerostat
    moment = a.inertia_tensor @ dx[lay.rates] / a.length
    return np.concatenate([node_f, body_f, moment])


def zero_wind_state(params: Params, length: float | None = None) -> np.ndarray:
    """Exact equilibrium at zero wind: a vertical tether with elements stretched by their own
    tension, the aerostat at the configured trim pitch, facing into the configured wind."""
    model = Model(params, 0.0)
    lay, d, n = model.layout, params.derived, model.n
    L = params.tether.length if length is None else length
    l_u = L / n
    g = params.environment.g
    m_node = d.mass_per_length * l_u
    # element e carries the net lift minus the weight of the nodes above its midpoint
    T = d.net_lift - m_node * g * (np.arange(n) + 0.5)
    lengths = l_u * (1.0 + T / d.EA)
    anchor = np.array(params.tether.anchor_position)
    z_nodes = anchor[2] + np.cumsum(lengths[::-1])[::-1]  # height of node e (top = node 0)
    x = np.zeros(lay.size)
    for j in range(1, n):
        x[3 * (j - 1):3 * j] = [anchor[0], anchor[1], z_nodes[j]]
    th = math.radians(params.aerostat.trim_pitch_deg)
    psi = math.radians(params.wind.direction_deg) + math.pi
    x[lay.euler] = [0.0, th, psi]
    R = rotation_matrix(0.0, th, psi)
    confluence = np.array([anchor[0], anchor[1], z_nodes[0]])
    x[lay.cm_pos] = confluence - R @ np.array(d.leash_position)
    x[lay.winch_length] = L
    return x


def _column_groups(model: Model, n_unknowns: int) -> list[np.ndarray]:
    """Positions (within the unknowns) perturbed together: coordinate k of every third node,
    then each aerostat unknown alone."""
    n_nodes = model.layout.n_nodes
    groups = [np.array([3 * j + k for j in range(c, n_nodes, 3)], dtype=np.int64)
              for c in range(min(3, n_nodes)) for k in range(3)]
    groups += [np.array([c]) for c in range(3 * n_nodes, n_unknowns)]
    return [g for g in groups if g.size]


def _rows_of(model: Model, col: int, n_rows: int) -> np.ndarray:
    """Residual rows that unknown ``col`` can change: its node and the two neighbours, plus
    the aerostat rows for the top node; every row for an aerostat unknown."""
    n_nodes = model.layout.n_nodes
    if col >= 3 * n_nodes:
        return np.arange(n_rows)
    j = col // 3
    rows = np.arange(3 * max(j - 1, 0), 3 * min(j + 2, n_nodes))
    return np.concatenate([rows, np.arange(3 * n_nodes, n_rows)]) if j == 0 else rows


def _jacobian(model: Model, x: np.ndarray, idx: np.ndarray, steps: np.ndarray, r_size: int):
    """Central finite-difference Jacobian by column groups (module docstring)."""
    J = np.zeros((r_size, idx.size))
    for group in _column_groups(model, idx.size):
        xp, xm = x.copy(), x.copy()
        xp[idx[group]] += steps[group]
        xm[idx[group]] -= steps[group]
        diff = _residual(model, xp) - _residual(model, xm)
        for col in group:
            rows = _rows_of(model, int(col), r_size)
            J[rows, col] = diff[rows] / (2 * steps[col])
    return J


def _newton_step(J: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Minimum-norm least-squares step for small systems, sparse LU for large ones."""
    if J.shape[1] > DENSE_UNKNOWNS:
        try:
            dz = scipy.sparse.linalg.spsolve(scipy.sparse.csc_matrix(J), -r)
            if np.all(np.isfinite(dz)):
                return dz
        except RuntimeError:  # exactly singular: fall back to the min-norm solve
            pass
    return np.linalg.lstsq(J, -r, rcond=1e-13)[0]


def _step_accepted(J: np.ndarray, dz: np.ndarray, lam: float, rel: float, rn: np.ndarray,
                   reln: float) -> bool:
    """Whether the damped Newton step lam dz (relative residual rel -> reln, new residual rn)
    is kept: where it lowers the largest generalized force, else where it passes Deuflhard's
    natural monotonicity test, the next Newton correction from this Jacobian being shorter,
    |J^-1 F(x + lam dz)| <= (1 - lam / 4) |dz| (metres and radians).

    The second test is what a nearly slack lower tether needs: its lateral stiffness T / l is
    tiny beside its axial one EA / l (0.2 against 35 000 N/m for 6 N in the baseline's 30 m
    elements), so a lateral correction d that cures a force (T / l) d also stretches the element
    by d^2 / (2 l), an axial force (EA / l) d^2 / (2 l) far above it (d = 5 cm: 1.5 N against
    0.01 N). The next correction, an axial d^2 / (2 l), undoes it: Newton converges with full
    steps, but a force decrease admits steps of 1/64 to 1/8 only, and the iteration creeps
    until the continuation stalls (aerostat.mass = 587.9 kg on the baseline: at 0.078 m/s).
    The force test comes first, so a trim whose full steps lower the force (the baseline's,
    1 to 30 m/s) takes the same path as with that test alone."""
    if not np.all(np.isfinite(rn)):
        return False
    if reln < rel:
        return True
    return bool(np.linalg.norm(_newton_step(J, rn)) <= (1.0 - lam / 4) * np.linalg.norm(dz))


def _newton(model: Model, x: np.ndarray, tol: float, max_iter: int) -> tuple[np.ndarray, float, int]:
    idx = _unknown_index(model)
    scale = model.params.derived.buoyancy
    steps = np.where(np.isin(idx, np.arange(model.layout.euler.start, model.layout.euler.stop)),
                     1e-7, 1e-5)
    r = _residual(model, x)
    if not np.all(np.isfinite(r)):
        return x, math.inf, 0
    rel = np.max(np.abs(r)) / scale
    for it in range(max_iter):
        if rel <= tol:
            return x, rel, it
        J = _jacobian(model, x, idx, steps, r.size)
        if not np.all(np.isfinite(J)):
            return x, rel, it
        dz = _newton_step(J, r)
        lam = 1.0
        for _ in range(30):
            xn = x.copy()
            xn[idx] += lam * dz
            rn = _residual(model, xn)
            reln = np.max(np.abs(rn)) / scale
            if _step_accepted(J, dz, lam, rel, rn, reln):
                break
            lam *= 0.5
        else:
            return x, rel, it
        x, r, rel = xn, rn, reln
    return x, rel, max_iter


def _continue(solve, x: np.ndarray, s: float, target: float, step: float, max_step: float,
              min_step: float, tol: float) -> tuple[np.ndarray, float, float, int, float | None]:
    """Newton continued in a parameter from the solution ``x`` at ``s`` to ``target``: a step
    ``solve(next, x)`` -> (x, relative residual, iterations) is accepted where the residual is
    within ``tol``, after which the step doubles (up to ``max_step``), and halved on a failure.
    Returns (x, s, residual, iterations, stalled): ``stalled`` is None where ``target`` was
    reached, else the value that still failed when the step fell below ``min_step``."""
    rel, its = 0.0, 0
    while True:
        nxt = min(s + step, target) if target >= s else max(s - step, target)
        xn, rel, it = solve(nxt, x.copy())
        its += it
        if rel <= tol:
            x, s = xn, nxt
            if s == target:
                return x, s, rel, its, None
            step = min(max_step, 2 * step)
        else:
            step /= 2
            if step < min_step:
                return x, s, rel, its, nxt


def _continue_in_wind(model: Model, x: np.ndarray, u: float, wind_speed: float,
                      max_step: float, tol: float) -> tuple[np.ndarray, float, int]:
    """Newton continued in wind speed from the equilibrium ``x`` at ``u`` to ``wind_speed`` in
    steps of at most ``max_step`` (halved on failure down to 1/64 of it): (x, residual,
    iterations); TrimError where it stalls."""

    def solve(target: float, x0: np.ndarray):
        model.set_wind(target)
        return _newton(model, x0, tol, 40)

    x, u, rel, its, stalled = _continue(solve, x, u, wind_speed, max_step, max_step,
                                        max_step / 64, tol)
    if stalled is not None:
        height = float(x[model.layout.at(S_Z)])  # the last equilibrium's
        raise TrimError(f"no equilibrium found at U = {stalled:.3f} m/s"
                        f"{at_height(model.params, stalled, height)} (continuing from "
                        f"{u:.3f} m/s): relative residual {rel:.2e} > {tol:.0e}")
    return x, rel, its


def at_height(params: Params, wind_speed: float, height: float) -> str:
    """Where the mean profile is not uniform, `` at wind.reference_height = 10 m (V m/s at the
    aerostat's height of z m: wind.profile = ..., its shape parameter)`` to follow ``at U =
    ... m/s`` in a message (the speed a trim is continued in is the one at the reference
    height, which a steep profile multiplies many times at the aerostat); else ``""``."""
    w = params.wind
    if w.profile == "uniform":
        return ""
    shape = (f"wind.shear_exponent = {w.shear_exponent:g}" if w.profile == "power"
             else f"wind.roughness_length = {w.roughness_length:g} m")
    return (f" at wind.reference_height = {w.reference_height:g} m "
            f"({wind_speed * profile_factor(params, height):.4g} m/s at the aerostat's height "
            f"of {height:.0f} m: wind.profile = '{w.profile}', {shape})")


#: Where the tether weighs more than this share of the net lift, a failed continuation in wind
#: is retried by continuation in the tether's weight (:func:`_continue_in_tether_weight`). With
#: a small margin of net lift over tether weight the lower tether carries almost no tension in
#: light wind, so its lateral stiffness (tension / element length) is tiny beside its axial one
#: (EA / element length): the trim there is ill-conditioned, and a lighter tether is a second
#: path to it. (With :func:`_step_accepted` the continuation in wind reaches these trims itself,
#: down to a margin of 0.01 N on the baseline; where both paths fail the error names the margin.)
LIFT_MARGIN_SHARE = 0.5
#: Smallest continuation step in the tether's weight (share of the way to the real tether).
_WEIGHT_STEP_MIN = 1.0 / 256


def _continue_in_tether_weight(params: Params, wind_speed: float, max_step: float, tol: float,
                               length: float | None,
                               cause: TrimError | None) -> tuple[np.ndarray, float, int]:
    """Trim at ``wind_speed`` with a lighter tether (weighing LIFT_MARGIN_SHARE of the net lift,
    whose trim is well conditioned), then continue the tether's density back to its own value
    at that wind speed, in adaptive steps. Raises TrimError naming the net-lift margin where
    this fails too (after ``cause``, the continuation in wind's failure, where there was one)."""
    d, rho = params.derived, params.tether.density
    weight = paid_out_weight(params, length)
    f = LIFT_MARGIN_SHARE * d.net_lift / weight

    def lighter(s: float) -> Params:  # s = 0: the light tether, s = 1: the real one
        return params if s >= 1.0 else params.replace(**{"tether.density": rho * (f + (1 - f) * s)})

    def fail(where: str) -> TrimError:
        margin = d.net_lift - weight
        if margin > 0:
            why = (f"the net lift ({d.net_lift:.1f} N) exceeds the weight of the tether "
                   f"({weight:.1f} N) by only {margin:.1f} N ({100 * margin / d.net_lift:.1f} % "
                   "of the net lift), so the lower tether is nearly slack in light wind and the "
                   "trim is ill-conditioned")
        else:  # in still air the winch tension would be the margin: only the wind can lift it
            why = (f"the net lift ({d.net_lift:.1f} N) is below the weight of the tether paid "
                   f"out ({weight:.1f} N) by {-margin:.1f} N, so only the wind's lift can hold "
                   "the tether off the ground")
        return TrimError(
            f"{f'{cause}; ' if cause else ''}{why}; continuing from a lighter tether at "
            f"U = {wind_speed:g} m/s "
            f"{where}. A lighter aerostat (aerostat.mass), a larger one (aerostat.volume) or a "
            "shorter or lighter tether (length, tether.length, tether.density, tether.diameter) "
            "widens the margin")

    try:
        start = Model(lighter(0.0), 0.0)
        x, rel, its = _continue_in_wind(start, zero_wind_state(start.params, length), 0.0,
                                        wind_speed, max_step, tol)
    except TrimError:
        raise fail("failed too") from cause
    def solve(share: float, x0: np.ndarray):
        model = Model(lighter(share), 0.0)
        model.set_wind(wind_speed)
        return _newton(model, x0, tol, 40)

    x, s, rel, more, stalled = _continue(solve, x, 0.0, 1.0, 0.25, 0.5, _WEIGHT_STEP_MIN, tol)
    if stalled is not None:
        raise fail(f"stalled at {100 * s:.1f} % of the way to this tether's weight "
                   f"(relative residual {rel:.2e} > {tol:.0e})") from cause
    return x, rel, its + more


def find_equilibrium(params: Params | None = None, wind_speed: float = 0.0,
                     guess: Equilibrium | None = None, max_step: float = 1.0,
                     tol: float = REL_TOL, length: float | None = None) -> Equilibrium:
    """Trim in a steady mean wind of ``wind_speed`` m/s (profile and direction from params).

    Parameters
    ----------
    params : Params (default baseline). wind_speed : mean speed at the reference height [m/s].
    guess : a nearby equilibrium (same params) to continue from; default the zero-wind state.
    max_step : largest continuation step in wind speed [m/s].
    tol : relative residual, max |generalized force| / buoyancy.
    length : tether length paid out [m] (default ``tether.length``).

    Raises
    ------
    TrimError if Newton fails to reach ``tol`` even with continuation steps of 1/64 of
    ``max_step`` (and, without a guess and where the tether weighs more than
    LIFT_MARGIN_SHARE of the net lift, also by continuation from a lighter tether at the
    target wind speed; the message then gives the net-lift margin; where the tether paid out
    weighs at least the net lift, that continuation is the only path, and in still air there
    is no equilibrium at all), or if the solution has a
    slack tether, the aerostat on or below the ground or tether below the ground (where the
    lift cannot carry the tether paid out: :func:`_check_flying`).
    """
    params = params or load_params()
    if not (is_finite_number(wind_speed) and 0 <= wind_speed <= MAX_WIND_SPEED):
        raise ValueError(f"wind_speed must be a number in [0, {MAX_WIND_SPEED:g}] m/s (the "
                         f"model's incompressible aerodynamics end near Mach 0.3), got "
                         f"{wind_speed!r}")
    model = Model(params, 0.0)
    weight = paid_out_weight(params, length)
    if guess is None and weight >= params.derived.net_lift:
        # No still-air equilibrium to continue from: the vertical line would leave the winch in
        # compression (net lift - weight <= 0). Only the wind's lift can carry it.
        _check_wind_can_lift(params, wind_speed, weight)
        x, rel, its = _continue_in_tether_weight(params, wind_speed, max_step, tol, length, None)
    else:
        if guess is None:
            x, u0 = zero_wind_state(params, length), 0.0
        else:
            x, u0 = guess.x.copy(), guess.wind_speed
        try:
            x, rel, its = _continue_in_wind(model, x, u0, wind_speed, max_step, tol)
        except TrimError as exc:
            if guess is not None or weight <= LIFT_MARGIN_SHARE * params.derived.net_lift:
                raise
            x, rel, its = _continue_in_tether_weight(params, wind_speed, max_step, tol, length,
                                                     exc)
    model.set_wind(wind_speed)
    summary = trim_summary(model, x, wind_speed)
    _check_flying(model, x, summary, wind_speed)
    return Equilibrium(x=x, wind_speed=float(wind_speed), params=params, residual=float(rel),
                       iterations=its, summary=summary)


def _check_wind_can_lift(params: Params, wind_speed: float, weight: float) -> None:
    """TrimError at once in still air where the tether paid out weighs at least the net lift:
    the vertical line's tension at the winch, net lift - weight, would not be positive."""
    if wind_speed == 0.0:
        raise TrimError(
            f"no equilibrium in still air: the net lift ({params.derived.net_lift:.1f} N) does "
            f"not exceed the weight of the tether paid out ({weight:.1f} N), so only the wind's "
            "lift could hold the tether off the ground. Less tether (length), a lighter one "
            "(tether.density, tether.diameter) or a lighter or larger aerostat (aerostat.mass, "
            "aerostat.volume) can")


def _check_flying(model: Model, x: np.ndarray, summary: dict, wind_speed: float) -> None:
    """TrimError where the solution is not a flying equilibrium: a slack element, the aerostat
    on or below the ground, or tether below the ground. The last is the model's answer where
    the net lift and the wind's lift cannot carry all of the tether paid out: having no ground,
    the lumped tether leaves the winch downwards and hangs in a sag below it, where a real one
    would lie on the ground (the baseline with aerostat.mass = 587.9 kg, 72.5 N of net lift,
    on 400 m of tether, 93.2 N, at 1 m/s: 72 m below)."""
    height = x[model.layout.at(S_Z)]
    if summary["min_tension_N"] <= 0 or height <= 0:
        raise TrimError(f"the solution at U = {wind_speed} m/s is not a flying equilibrium "
                        f"(min tension {summary['min_tension_N']:.1f} N, height {height:.1f} m)")
    depth = -float(model.node_positions(x)[:, 2].min())
    if depth > 0:
        p, length = model.params, float(x[model.layout.winch_length])
        weight = paid_out_weight(p, length)
        raise TrimError(
            f"the solution at U = {wind_speed:g} m/s hangs the tether {depth:.1f} m below the "
            f"ground: the net lift ({p.derived.net_lift:.1f} N) and the wind's lift cannot hold "
            f"the {length:g} m of tether paid out ({weight:.1f} N) off the ground. Less tether "
            "(length), a lighter one (tether.density, tether.diameter), a lighter or larger "
            "aerostat (aerostat.mass, aerostat.volume) or more wind can")


def trim_summary(model: Model, x: np.ndarray, wind_speed: float) -> dict:
    """Aerostat position, blow-by angle, attitude, end tensions and tether elevation at the winch."""
    lay = model.layout
    nodes = model.node_positions(x)
    top, bottom = model.end_tensions(x)
    rel = nodes[0] - nodes[-1]
    blow_by = math.degrees(math.atan2(math.hypot(rel[0], rel[1]), rel[2]))
    low = nodes[-2] - nodes[-1]
    elevation = math.degrees(math.atan2(low[2], math.hypot(low[0], low[1])))
    phi, th, psi = x[lay.euler]
    return {
        "wind_speed_m_s": float(wind_speed),
        "aerostat_position_m": [float(v) for v in x[lay.cm_pos]],
        "confluence_point_m": [float(v) for v in nodes[0]],
        "blow_by_deg": blow_by,
        "pitch_deg": math.degrees(th),
        "roll_deg": math.degrees(phi),
        "yaw_deg": math.degrees(psi),
        "top_tension_N": top,
        "winch_tension_N": bottom,
        "min_tension_N": float(model.tensions(x).min()),
        "elevation_at_winch_deg": elevation,
        "tether_length_m": float(x[lay.winch_length]),
    }


class TrimLimitError(ValueError):
    """A trim the configured tether cannot hold (its tension is above the tether strength)."""


def largest_trim_tension(top_tension, winch_tension):
    """The tension that decides whether the tether holds a trim: the larger of its two ends
    (in practice the top end: the tether's weight makes its tension fall from the confluence
    point to the winch, by up to mu g L on a long heavy tether). Scalars or arrays. Every check of a
    trim against ``tether.strength`` uses it (:func:`limit_warnings`, the environment's wind
    range), so the sweep, the evaluator and the environment agree where the tether breaks."""
    return np.maximum(top_tension, winch_tension)


def limit_warnings(params: Params, summary: dict) -> list[str]:
    """What the configured winch and tether cannot do at this trim, as warnings.

    Raises :class:`TrimLimitError` when the trim's largest tension reaches the tether's breaking
    strength (no such equilibrium exists: the tether breaks). Warns when the winch-end tension
    exceeds the motor's force limit (the winch holds on its brake and cannot reel in) or the
    safe working load (the over-tension event fires at rest).
    """
    T_w = summary["winch_tension_N"]
    T_max = float(largest_trim_tension(summary["top_tension_N"], T_w))
    U = summary["wind_speed_m_s"]
    where = f"at U = {U:g} m/s" + at_height(params, U, summary["aerostat_position_m"][2])
    t, w = params.tether, params.winch
    if T_max >= t.strength:
        raise TrimLimitError(f"{where} the trim tension {T_max:.0f} N exceeds "
                             f"tether.strength = {t.strength:.0f} N: the tether breaks")
    out = []
    if T_w > w.max_motor_force:
        out.append(f"{where} the winch tension {T_w:.0f} N exceeds "
                   f"winch.max_motor_force = {w.max_motor_force:.0f} N: the winch holds on its "
                   "brake and cannot reel in")
    if T_max > w.safe_working_load:
        out.append(f"{where} the trim tension {T_max:.0f} N exceeds "
                   f"winch.safe_working_load = {w.safe_working_load:.0f} N")
    return out
