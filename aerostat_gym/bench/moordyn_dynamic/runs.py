"""Each code on one case: our tether-only model (RK4 and semi-implicit, driven) and MoorDyn
(coupled top end), from the same settled start."""

from __future__ import annotations

import ctypes
import math
import os
import tempfile
import time
from dataclasses import dataclass

import numpy as np

from ...analysis.trim import find_equilibrium
from ...params import Params, load_params
from ...physics.integrators import OK
from ...physics.state import (
    node_force_offset,
    tension_offset,
)
from ...sim import BRAKED, Model
from ..moordyn import (
    RHO_AIR,
    SUBMERGENCE,
    WIND,
    _captured_c_output,
    _chord_state,
    _tail,
    axial_cdt,
    current_profile,
    moordyn_input,
)
from .cases import K_DIR, K_TOP, SINE, DrivenCase, DynamicBenchError, path_displacement, path_length
from .driven import (
    LENGTH,
    NO_SWAP,
    SWAP_NODAL_DRAG,
    SWAP_SEGMENT_RULE,
    driven_rk4,
    driven_si,
    moordyn_node_drag,
    moordyn_segment_tension,
    node_unit,
    our_node_drag,
)

OUTPUT_DT = 0.05  # s between compared samples (= the semi-implicit step)
RK4_SUBSTEPS = 9  # our RK4 steps per output interval: h = 5.56 ms
MOORDYN_SUBSTEPS = 18  # MoorDyn RK4 steps per output interval: h = 2.78 ms


SETTLE = 30.0  # s with the top end held at the trim before the drive starts


VARIANTS = ("baseline", "crossflow_drag", "moordyn_drag", "no_buoyancy", "moordyn_slack_rule",
            "moordyn_drag_and_slack_rule", "no_damping")
#: our-side switches (bits of the swap vector's flags) per variant
_SWAPS = {"moordyn_drag": 2, "moordyn_slack_rule": 1, "moordyn_drag_and_slack_rule": 3}


# --- our side --------------------------------------------------------------------------------


def _variant_params(variant: str) -> tuple[Params, Params, float | None]:
    """(our parameters, MoorDyn's parameters, MoorDyn's mass per length or None) of a variant."""
    if variant not in VARIANTS:
        raise DynamicBenchError(f"unknown variant {variant!r}; choose one of {VARIANTS}")
    base = {"environment.rho_air": RHO_AIR}
    if variant == "crossflow_drag":
        base |= {"tether.loading_fn": [0.5, 0.0, 0.0, -0.5, 0.0],
                 "tether.loading_ft": [0.0] * 6}
    if variant == "no_damping":
        base |= {"tether.damping_ratio": 0.0}
    p = load_params(overrides=base)
    mass = None
    if variant == "no_buoyancy":
        mass = p.derived.mass_per_length + RHO_AIR * p.derived.tether_area
    return p, p, mass


@dataclass
class Setup:
    """The shared starting point of a variant: parameters, trim top end, our settled state."""

    params: Params
    md_params: Params
    md_mass: float | None
    swap: np.ndarray
    model: Model
    top: np.ndarray
    lever: np.ndarray
    x_settled: np.ndarray
    settle: float


def prepare(variant: str = "baseline", settle: float = SETTLE) -> Setup:
    """Parameters of ``variant``, the trim top end at U = 10 m/s and our tether settled there.

    Parameters
    ----------
    variant : str
        One of ``VARIANTS``.
    settle : float
        Seconds our tether settles (RK4, top end held) from the straight chord [s].
    """
    if not (math.isfinite(settle) and settle > 0):
        raise DynamicBenchError(f"settle must be finite and > 0 s, got {settle!r}")
    p, pmd, mass = _variant_params(variant)
    eq = find_equilibrium(p, WIND)
    model = Model(p, wind=WIND, fixed_aerostat=True)
    lay = model.layout
    top = model.node_positions(eq.x)[0]
    lever = eq.x[lay.cm_pos] - top
    x = _chord_state(model, eq.x)
    h = OUTPUT_DT / RK4_SUBSTEPS
    hold = DrivenCase("hold", SINE, period=1.0).pack(top, lever, p.tether.length)
    swap = np.array([_SWAPS.get(variant, 0), WIND, 0.0, 0.0, axial_cdt(pmd)])
    if driven_rk4(x, -settle, h, round(settle / h), hold, BRAKED, model.p, model.wp, model.wf,
                  model.work, swap) != OK:
        raise RuntimeError("our tether did not settle at the trim (non-finite state)")
    return Setup(p, pmd, mass, swap, model, top, lever, x, settle)


def _end_tensions(model: Model, x: np.ndarray, swap: np.ndarray) -> tuple[float, float]:
    """Top and bottom tension (:meth:`Model.end_tensions`), with the end elements' axial force
    and the top node's drag from MoorDyn's rules where ``swap`` asks."""
    flags = int(swap[0])
    if not flags:
        return model.end_tensions(x)
    w = model._forces(x)
    n, p = model.n, model.p
    T0, F = tension_offset(n), node_force_offset(n)
    top = w[F:F + 3].copy()
    T_bot, e_bot = w[T0 + n - 1], np.array(node_unit(w, n - 1, n)[:3])
    if flags & SWAP_SEGMENT_RULE:
        T_top, *e_top = moordyn_segment_tension(x, p, w, 0)
        top -= (T_top - w[T0]) * np.array(e_top)
        T_bot, *e_bot = moordyn_segment_tension(x, p, w, n - 1)
    if flags & SWAP_NODAL_DRAG:
        top += np.array(moordyn_node_drag(x, p, w, 0, swap)) - np.array(our_node_drag(x, p, w, 0))
    half_weight = 0.5 * model.params.derived.mass_per_length * x[model.layout.winch_length] / n
    bottom = T_bot * np.asarray(e_bot) - np.array([0.0, 0.0, half_weight * model.params.environment.g])
    return float(np.linalg.norm(top)), float(np.linalg.norm(bottom))


def _segment_slack(nodes: np.ndarray, length: float) -> int:
    """Number of segments whose stretched length is at most the unstretched one."""
    seg = np.linalg.norm(np.diff(nodes, axis=0), axis=1)
    return int(np.count_nonzero(seg <= length / (len(nodes) - 1)))


def run_ours(setup: Setup, path: np.ndarray, case: DrivenCase, integrator: str,
              repeats: int) -> dict:
    """Our driven run sampled every OUTPUT_DT, and its best wall time (no outputs) over the
    whole case."""
    m = setup.model
    fn, nsub = ((driven_rk4, RK4_SUBSTEPS) if integrator == "rk4"
                else (driven_si, max(1, round(OUTPUT_DT / setup.params.simulation.semi_implicit_dt))))
    h = OUTPUT_DT / nsub
    n_out = round(case.duration / OUTPUT_DT)
    x = setup.x_settled.copy()
    o = m.layout.cm_pos.start
    swap = setup.swap if integrator == "rk4" else NO_SWAP
    args = (BRAKED, m.p, m.wp, m.wf, m.work, swap)
    nodes, top, bottom, slack = [], [], [], []
    for k in range(n_out + 1):
        if k > 0 and fn(x, (k - 1) * OUTPUT_DT, h, nsub, path, *args) != OK:
            raise RuntimeError(f"our {integrator} run of {case.name!r} became non-finite "
                               f"at t = {k * OUTPUT_DT:.2f} s")
        pos = m.node_positions(x)
        nodes.append(pos)
        top_t, bot_t = _end_tensions(m, x, swap)
        top.append(top_t)
        bottom.append(bot_t)
        slack.append(_segment_slack(pos, x[o + LENGTH]))
    walls = []
    for _ in range(repeats):
        y = setup.x_settled.copy()
        t0 = time.perf_counter()
        fn(y, 0.0, h, nsub * n_out, path, *args)
        walls.append(time.perf_counter() - t0)
    return {"nodes": np.array(nodes), "top": np.array(top), "bottom": np.array(bottom),
            "slack": np.array(slack), "dt_s": h, "wall_s": float(min(walls))}


# --- MoorDyn's side --------------------------------------------------------------------------


def _moordyn_schedule(path: np.ndarray, h: float, nsteps: int) -> tuple:
    """Per MoorDyn step k: top position at t_k, the secant velocity over the step, and the
    secant rate of the unstretched length (our frame, t_k = k h)."""
    t = np.arange(nsteps + 1) * h
    s = np.array([path_displacement(path, tk)[0] for tk in t])
    L = np.array([path_length(path, tk)[0] for tk in t])
    d = path[K_DIR:K_DIR + 3]
    pos = path[K_TOP:K_TOP + 3] + s[:-1, None] * d
    vel = (np.diff(s) / h)[:, None] * d
    # rounded: the secant of a linear ramp carries rounding noise, and every change of the
    # rate costs a call of MoorDyn's setter
    return pos, vel, np.round(np.diff(L) / h, 9)


def _write_moordyn_inputs(setup: Setup, h: float, workdir: str) -> float:
    """``lines.txt`` (coupled top point, RK4 at step h) and ``current_profile.txt`` in
    ``workdir``; returns the depth of the frame shift."""
    p = setup.md_params
    depth = float(setup.top[2]) - float(p.tether.anchor_position[2]) + SUBMERGENCE
    with open(os.path.join(workdir, "lines.txt"), "w") as f:
        f.write(moordyn_input(p, setup.top, depth, h, "RK4", top_attachment="Coupled",
                              mass_per_length=setup.md_mass))
    with open(os.path.join(workdir, "current_profile.txt"), "w") as f:
        f.write(current_profile(WIND, depth))
    return depth


def step_call_overhead(md, setup: Setup, seconds: float = 20.0, repeats: int = 3) -> dict:
    """MoorDyn's wall time with the top end held for ``seconds``: one Step call per MoorDyn
    step (as the driven cases need) against one Step call per second (MoorDyn stepping
    internally); best of ``repeats``. Their ratio is the share of the Python call per step."""
    h = OUTPUT_DT / MOORDYN_SUBSTEPS
    walls = {"per_step_s": [], "per_second_s": []}
    with tempfile.TemporaryDirectory(prefix="aerostat_moordyn_dyn_") as tmp:
        depth = _write_moordyn_inputs(setup, h, tmp)
        top0 = (setup.top - np.array([0.0, 0.0, depth])).tolist()
        for _ in range(repeats):
            for key, chunk in (("per_step_s", h), ("per_second_s", 1.0)):
                with _captured_c_output(os.path.join(tmp, "console.txt")):
                    system = md.Create(os.path.join(tmp, "lines.txt"))
                    try:
                        md.Init(system, top0, [0.0, 0.0, 0.0])
                        t, n = 0.0, round(seconds / chunk)
                        t0 = time.perf_counter()
                        for _k in range(n):
                            md.Step(system, top0, [0.0, 0.0, 0.0], t, chunk)
                            t += chunk
                        walls[key].append(time.perf_counter() - t0)
                    finally:
                        md.Close(system)
    out = {k: float(min(v)) for k, v in walls.items()}
    out["ratio"] = out["per_step_s"] / out["per_second_s"]
    out["simulated_s"] = seconds
    return out


def run_moordyn(md, setup: Setup, path: np.ndarray, case: DrivenCase, substeps: int,
                 workdir: str, record: bool) -> dict:
    """One MoorDyn run: settle with the top end held, then the drive; sampled every OUTPUT_DT
    when ``record`` (else timed: the Step loop of the drive only)."""
    h = OUTPUT_DT / substeps
    shift = np.array([0.0, 0.0, _write_moordyn_inputs(setup, h, workdir)])
    n_out = round(case.duration / OUTPUT_DT)
    nsteps = n_out * substeps
    pos, vel, Ld = _moordyn_schedule(path, h, nsteps)
    pos = (pos - shift).tolist()
    vel = vel.tolist()
    top0 = (setup.top - shift).tolist()
    log = os.path.join(workdir, "console.txt")
    out = {"nodes": [], "top": [], "bottom": [], "slack": [], "dt_s": h}
    try:
        with _captured_c_output(log):
            system = md.Create(os.path.join(workdir, "lines.txt"))
            try:
                if md.Init(system, top0, [0.0, 0.0, 0.0]) != 0:
                    raise RuntimeError("MoorDyn initialization failed:\n" + _tail(log))
                line = md.GetLine(system, 1)
                N = md.GetLineN(line)
                t = -setup.settle
                for _ in range(round(setup.settle / h)):
                    md.Step(system, top0, [0.0, 0.0, 0.0], t, h)
                    t += h
                if record:
                    _sample_moordyn(md, line, N, shift, out)
                rate = 0.0
                t0 = time.perf_counter()
                for k in range(nsteps):
                    if Ld[k] != rate:
                        rate = float(Ld[k])
                        _set_length_rate(md, line, rate)
                    md.Step(system, pos[k], vel[k], t, h)
                    t += h
                    if record and (k + 1) % substeps == 0:
                        _sample_moordyn(md, line, N, shift, out)
                out["wall_s"] = time.perf_counter() - t0
            finally:
                md.Close(system)
    except RuntimeError as exc:
        raise RuntimeError(f"MoorDyn run of {case.name!r} failed (RK4, dt = {h:.3g} s): {exc}\n"
                           + _tail(log)) from exc
    for key in ("nodes", "top", "bottom", "slack"):
        out[key] = np.array(out[key])
    return out


def _set_length_rate(md, line, rate: float) -> None:
    """``SetLineUnstretchedLengthVel``. The 2.7.2 binding returns None without a new reference
    (measured: ``sys.getrefcount(None)`` falls by one per call, and the interpreter aborts at
    exit with "Fatal Python error: none_dealloc"), so the reference it takes is given back, for
    good (a reference held in a list would be released at exit and abort just the same)."""
    md.SetLineUnstretchedLengthVel(line, rate)
    ctypes.pythonapi.Py_IncRef(ctypes.py_object(None))


def _sample_moordyn(md, line, N: int, shift: np.ndarray, out: dict) -> None:
    """Append MoorDyn's node positions (our frame and order, top first), end tensions (the
    definitions of the static comparison, :mod:`aerostat_gym.bench.moordyn`) and slack segment count."""
    nodes = np.array([md.GetLineNodePos(line, i) for i in range(N, -1, -1)]) + shift
    out["nodes"].append(nodes)
    out["top"].append(float(np.linalg.norm(md.GetLineNodeForce(line, N))))
    f0 = np.asarray(md.GetLineNodeForce(line, 0)) - np.asarray(md.GetLineNodeDrag(line, 0))
    out["bottom"].append(float(np.linalg.norm(f0)))
    out["slack"].append(_segment_slack(nodes, md.GetLineUnstretchedLength(line)))
