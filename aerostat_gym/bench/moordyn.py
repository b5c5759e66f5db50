"""Peer comparison with MoorDyn v2 (issue 2, item 5): speed and static agreement of the tether.

:func:`compare_with_moordyn` builds a MoorDyn v2 input file for ONE line equal to our tether
(same unstretched length, number of segments, diameter, mass per length, EA, internal damping,
normal drag) between a fixed anchor at our origin and a fixed top end at our trim confluence
point for U = 10 m/s, blows a steady uniform "current" of 10 m/s along +X through it with the
fluid density of air, runs it, and runs our tether alone with the same fixed top
(``Model(..., fixed_aerostat=True)``). It returns wall times and real-time factors of both
codes, the real-time factors of our full aerostat + tether system, and the static agreement
(node positions and end tensions) once both have settled.

MoorDyn settings and why (MoorDyn-C 2.7, the PyPI package ``moordyn``; semantics checked in
``source/Line.cpp``):

- Frame: MoorDyn's z is 0 at the water surface, and nodes above it get neither drag nor
  buoyancy. The whole line must therefore stay submerged: the water depth is set to the top
  end height + 100 m and everything is shifted down by that depth, so the anchor sits on the
  seabed at (0, 0, -depth) and the top end 100 m below the surface. Results are shifted back.
  MoorDyn's node 0 is end A (the anchor here) and node N end B (the top); ours run top to
  bottom, so MoorDyn's node order is reversed before comparing.
- Internal damping: MoorDyn's segment damping force is ``c A (ldot / l)`` with ``c = BA / A``
  for BA >= 0, i.e. BA [N s] multiplies the strain rate, exactly our per-element ``b`` in
  T = EA eps + b deps/dt. So BA = ``params.derived.damping_b`` (positive). A negative BA would
  be a damping ratio, but MoorDyn converts it with ``zeta l sqrt(EA m)``, half our critical
  damping ``2 l sqrt(EA m)``, so the ratio is not passed.
- Drag: MoorDyn's transverse drag is 0.5 rho Cd d l |v_n| v_n (crossflow principle, sin^2 of
  the flow angle) and the axial drag 0.5 rho CdAx pi d l |v_t| v_t on the surface area. Cd is
  our Cd_normal. Our tangential drag is 0.5 rho Cd_normal d l |v|^2 f_t(phi); matching it in
  purely axial flow (phi = 0) gives CdAx = Cd_normal f_t(0) / pi (= 0.0077 for the baseline).
  At the trim the flow is ~86 deg to the tether, where MoorDyn's axial drag (cos^2 phi) is
  ~45x smaller than ours (f_t(phi)); the difference is ~0.5 N of axial load on the whole
  tether (0.015 % of the tension), so the phi = 0 match is kept as the definition-level
  choice (matching at the trim angle would need CdAx ~ 0.3, a value with no meaning elsewhere).
- Ca = CaAx = 0 (our tether has no added mass), EI = 0 (no bending), rho = 1.225, g from the
  parameters. Current: ``Currents = 1`` (steady profile, MoorDyn reads ``current_profile.txt``
  next to the input file) with 10 m/s along +X at every depth; that it acts is checked from
  MoorDyn's nodal drag (total x drag against the crossflow estimate).
- Time step: MoorDyn's default (CFL 0.5 with RK2, dt = 14 ms here) diverges to NaN within
  0.2 s: RK2 is not stable on the lightly damped axial modes at that step. Two stable runs are
  timed: the default scheme RK2 at ``simulation.rk4_safety`` (our own margin) times its linear
  stability bound on the axial chain's eigenvalues (bound ~1.6 ms, dt ~1.4 ms), and RK4 at
  our own RK4 step (~5.8 ms). The faster of the two is the reference for the speed ratios (the
  conservative choice for our claim).
- Initial state: MoorDyn's own (a static solve in still fluid: its IC generation does not
  apply the current), then the dynamics settle under the current. Ours starts from the
  straight chord between the two ends, at rest, so both codes reach the steady state through
  their own dynamics. Timing covers the Step loop (MoorDyn) and ``Model.advance`` (ours) only,
  single thread, the shortest of several runs after a warm-up for both codes (the least
  disturbed by other load on the machine).
"""

from __future__ import annotations

import contextlib
import math
import os
import tempfile
import time

import numpy as np

from ..analysis.trim import find_equilibrium
from ..params import Params, load_params
from ..sim import BRAKED, Model, simulate

WIND = 10.0
RHO_AIR = 1.225
SUBMERGENCE = 100.0  # m of "water" above the top end in the MoorDyn frame
STEP_CHUNK = 1.0  # s advanced per MoorDyn Step call (a coupling step; per-call overhead is negligible)



def _import_moordyn():
    try:
        import moordyn
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "the MoorDyn comparison needs the MoorDyn v2 Python package: pip install moordyn"
        ) from exc
    return moordyn


@contextlib.contextmanager
def _captured_c_output(path: str):
    """Redirect the process's stdout/stderr (file descriptors 1, 2: MoorDyn's C++ console output)
    to a file while the block runs."""
    import sys

    for s in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            s.flush()
    saved = [os.dup(1), os.dup(2)]
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
    try:
        os.dup2(fd, 1)
        os.dup2(fd, 2)
        yield
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for f in (*saved, fd):
            os.close(f)


def _version() -> str:
    try:
        from importlib.metadata import version

        return version("moordyn")
    except Exception:  # pragma: no cover
        return "2.x"


def _tail(path: str, n: int = 1500) -> str:
    try:
        with open(path, errors="replace") as f:
            return f.read()[-n:]
    except OSError:
        return ""


def axial_cdt(params: Params) -> float:
    """MoorDyn's CdAx matching our tangential drag in purely axial flow: Cd_normal f_t(0) / pi."""
    return params.tether.Cd_normal * params.tether.loading_ft[0] / math.pi


def loading_functions(params: Params, phi: float) -> tuple[float, float]:
    """Our tether loading functions (f_n, f_t) at the flow angle phi in [0, pi/2] (as in the
    compiled core)."""
    f0, f1, f2, f3, f4 = params.tether.loading_fn
    c, s = math.cos(phi), math.sin(phi)
    fn = f0 + f1 * c + f2 * s + f3 * (2.0 * c * c - 1.0) + f4 * 2.0 * s * c
    ft = sum(a * phi**k for k, a in enumerate(params.tether.loading_ft))
    return fn, ft


def differences(params: Params, phi: float, wind: float = WIND) -> str:
    """The modelling differences between the two codes, with their size at flow angle phi."""
    t, rho = params.tether, params.environment.rho_air
    fn, ft = loading_functions(params, phi)
    q = 0.5 * rho * t.diameter * wind**2 * t.length  # N per unit coefficient, whole tether
    axial_ours = q * t.Cd_normal * ft
    axial_md = q * axial_cdt(params) * math.pi * math.cos(phi) ** 2
    return (
        "Modelling differences between the two codes: "
        "(1) drag: ours uses loading functions f_n(phi), f_t(phi) on each element's midpoint "
        "relative velocity, half to each end node; MoorDyn uses constant Cd and CdAx with the "
        "crossflow principle (sin^2 phi, cos^2 phi) on each node's velocity and tangent (mean of "
        f"the adjacent segments). At the trim flow angle phi = {math.degrees(phi):.1f} deg, "
        f"f_n = {fn:.4f} vs sin^2 = {math.sin(phi) ** 2:.4f} (normal drag {100 * (fn / math.sin(phi) ** 2 - 1):+.1f} %), "
        f"and the axial drag on the whole tether is {axial_ours:.2f} N (ours) vs {axial_md:.3f} N "
        "(MoorDyn, CdAx = Cd_normal f_t(0)/pi, matched in purely axial flow). "
        "(2) buoyancy: MoorDyn applies the fluid's buoyancy to the line, "
        f"{100 * rho / t.density:.2f} % of its weight ({rho * params.derived.tether_area * params.environment.g * t.length:.2f} N "
        "in total); ours has none. "
        "(3) damping: both a per-segment dashpot on the strain rate, BA = b (N s); MoorDyn's is not "
        "clipped when a segment is slack, ours (tension-only) is; no effect on the static state. "
        "MoorDyn's negative-BA damping ratio would use half our critical damping, so it is not used. "
        "(4) time integration: MoorDyn RK2 (its default) and RK4 with fixed point ends; ours RK4 "
        f"and the semi-implicit scheme ({params.simulation.semi_implicit_dt * 1e3:.0f} ms). "
        "(5) initial state: MoorDyn's still-fluid static solve (its IC generation ignores the "
        "current); ours the straight chord at rest. "
        "(6) MoorDyn's fluid ends at its surface z = 0, so its line runs 100 m below that surface "
        "(shifted back for the comparison); added mass (Ca = CaAx = 0) and bending (EI = 0) are off "
        "in both."
    )


def rk2_stable_dt(params: Params, safety: float | None = None) -> float:
    """``safety`` (default ``simulation.rk4_safety``) times the largest RK2 step that is linearly
    stable on the tether's axial chain (n - 1 free nodes between fixed ends, element stiffness
    EA / l_u and dashpot c* = b / l_u): bisection on max |1 + z + z^2 / 2| <= 1 over its
    eigenvalues z = lambda h."""
    d = params.derived
    n = params.tether.n_elements
    k, c, m = d.EA / d.element_length, d.dashpot, d.element_mass
    K = 2.0 * np.eye(n - 1) - np.eye(n - 1, k=1) - np.eye(n - 1, k=-1)
    Z = np.zeros_like(K)
    lam = np.linalg.eigvals(np.block([[Z, np.eye(n - 1)], [-k / m * K, -c / m * K]]))

    def amp(h: float) -> float:
        z = lam * h
        return float(np.abs(1.0 + z + 0.5 * z * z).max())

    lo, hi = 0.0, 4.0 / float(np.abs(lam).max())
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if amp(mid) <= 1.0 + 1e-12 else (lo, mid)
    s = params.simulation.rk4_safety if safety is None else safety
    return s * lo


def moordyn_input(params: Params, top: np.ndarray, depth: float, dt: float | None,
                  scheme: str | None, tmax_ic: float = 10.0, top_attachment: str = "Fixed",
                  mass_per_length: float | None = None) -> str:
    """Text of the MoorDyn v2 input file: one line, anchor on the seabed at (0, 0, -depth),
    top end at ``top`` shifted down by ``depth``, ``top_attachment`` "Fixed" or "Coupled" (its
    position and velocity then come with each Step call). ``dt`` / ``scheme`` None leave
    MoorDyn's defaults (CFL 0.5, RK2). ``mass_per_length`` None is ours."""
    t, d = params.tether, params.derived
    mass = d.mass_per_length if mass_per_length is None else float(mass_per_length)
    ax, ay, az = (float(v) for v in params.tether.anchor_position)
    top = [float(v) for v in top]  # plain floats: repr of numpy scalars is not a number
    depth = float(depth)
    return f"""--------------------- MoorDyn Input File ------------------------------------
aerostat-gym tether in air (generated by aerostat_gym.bench.moordyn)
---------------------- LINE TYPES ----------------------------------------------
TypeName   Diam    Mass/m     EA     BA/-zeta    EI    Cd    Ca    CdAx    CaAx
(name)     (m)     (kg/m)     (N)    (N-s/-)   (N-m^2) (-)   (-)   (-)     (-)
tether  {t.diameter!r}  {mass!r}  {d.EA!r}  {d.damping_b!r}  0.0  {t.Cd_normal!r}  0.0  {axial_cdt(params)!r}  0.0
---------------------- POINTS ---------------------------------------
ID   Attachment  X    Y    Z    Mass   Volume  CdA    Ca
(#)   (word/ID)  (m)  (m)  (m)  (kg)   (m^3)   (m^2)  (-)
1     Fixed   {ax!r}  {ay!r}  {az - depth!r}  0  0  0  0
2     {top_attachment}   {top[0]!r}  {top[1]!r}  {top[2] - depth!r}  0  0  0  0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (ID)     (ID)      (m)       (-)      (-)
1     tether     1        2        {t.length!r}  {t.n_elements}  -
---------------------- OPTIONS -----------------------------------------
0      writeLog
{params.environment.g!r}   g
{params.environment.rho_air!r}   rho
{depth!r}   WtrDpth
{"" if scheme is None else f"{scheme}   tScheme"}
{"" if dt is None else f"{float(dt)!r}   dtM"}
1      Currents
{tmax_ic!r}   TmaxIC
1      disableOutput
1      disableOutTime
------------------------- need this line -------------------------------------
"""


def current_profile(speed: float, depth: float) -> str:
    """``current_profile.txt`` (3 header lines, then z ux uy uz): uniform ``speed`` along +X."""
    return ("--------------------- MoorDyn steady currents File ---------------------\n"
            "uniform current standing in for the mean wind (aerostat_gym.bench.moordyn)\n"
            "z (m), ux (m/s), uy (m/s), uz (m/s)\n"
            f"{-(depth + 1000.0)!r} {speed!r} 0.0 0.0\n"
            f"0.0 {speed!r} 0.0 0.0\n")


def _write_inputs(params: Params, top: np.ndarray, workdir: str, dt: float | None,
                  scheme: str | None) -> float:
    """Write ``lines.txt`` and ``current_profile.txt`` into ``workdir``; returns the depth."""
    depth = float(top[2]) - float(params.tether.anchor_position[2]) + SUBMERGENCE
    with open(os.path.join(workdir, "lines.txt"), "w") as f:
        f.write(moordyn_input(params, top, depth, dt, scheme))
    with open(os.path.join(workdir, "current_profile.txt"), "w") as f:
        f.write(current_profile(WIND, depth))
    return depth


def _probe_default_step(md, params: Params, top: np.ndarray, workdir: str,
                        seconds: float = 1.0) -> dict:
    """Run MoorDyn with its default time step (CFL 0.5) and scheme for ``seconds``; report the
    step it chose and whether it diverged (MoorDyn raises on NaN)."""
    _write_inputs(params, top, workdir, None, None)
    log = os.path.join(workdir, "console_default.txt")
    dt, diverged = float("nan"), False
    # MoorDyn reads current_profile.txt from the input file's folder
    with _captured_c_output(log):
        system = md.Create(os.path.join(workdir, "lines.txt"))
        try:
            md.Init(system, [], [])
            with contextlib.suppress(Exception):
                import cmoordyn  # moordyn.GetDt() drops the return value in 2.7.2

                dt = float(cmoordyn.get_dt(system))
            try:
                md.Step(system, [], [], 0.0, seconds)
            except RuntimeError:
                diverged = True
        finally:
            md.Close(system)
    return {"dt_s": dt, "diverged_within_s": seconds if diverged else None}


def _run_moordyn(md, params: Params, top: np.ndarray, duration: float, scheme: str, dt: float,
                 workdir: str, repeats: int) -> dict:
    """Run MoorDyn ``repeats`` times from its own initial state; shortest wall time of the Step
    loop, and the settled state of the last run (our frame, nodes top to bottom)."""
    depth = _write_inputs(params, top, workdir, dt, scheme)
    log = os.path.join(workdir, f"console_{scheme}.txt")
    nchunks = max(1, math.ceil(duration / STEP_CHUNK - 1e-9))
    chunk = duration / nchunks
    walls = []
    for _ in range(repeats + 1):  # the first run warms up (not timed)
        try:
            with _captured_c_output(log):
                system = md.Create(os.path.join(workdir, "lines.txt"))
                try:
                    if md.Init(system, [], []) != 0:
                        raise RuntimeError("MoorDyn initialization failed:\n" + _tail(log))
                    line = md.GetLine(system, 1)
                    N = md.GetLineN(line)
                    mid_x = []
                    t = 0.0
                    t0 = time.perf_counter()
                    for _k in range(nchunks):
                        md.Step(system, [], [], t, chunk)
                        t += chunk
                        if t > duration - 5.0 - 1e-9:  # record the last 5 s (settling check)
                            wall_paused = time.perf_counter()
                            mid_x.append(md.GetLineNodePos(line, N // 2))
                            t0 += time.perf_counter() - wall_paused
                    walls.append(time.perf_counter() - t0)
                    pos = np.array([md.GetLineNodePos(line, i) for i in range(N + 1)])[::-1]
                    fnet = np.array([md.GetLineNodeForce(line, i) for i in (0, N)])
                    drag = np.array([md.GetLineNodeDrag(line, i) for i in range(N + 1)])
                finally:
                    md.Close(system)
        except RuntimeError as exc:
            raise RuntimeError(f"MoorDyn run failed ({scheme}, dt = {dt:.3g} s): {exc}\n"
                               + _tail(log)) from exc
    pos[:, 2] += depth
    wall = float(np.min(walls[1:]))
    return {
        "scheme": scheme,
        "dt_s": dt,
        "wall_s": wall,
        "real_time_factor": duration / wall,
        "node_pos": pos,
        # same definitions as Model.end_tensions: top = the net force of the top node (segment
        # plus its half weight and drag, MoorDyn's FairTen); bottom = segment tension plus the
        # half weight, without the half-segment drag (MoorDyn's AnchTen includes it)
        "top_tension_N": float(np.linalg.norm(fnet[1])),
        "bottom_tension_N": float(np.linalg.norm(fnet[0] - drag[0])),
        "anchor_tension_native_N": float(np.linalg.norm(fnet[0])),
        "drag_x_total_N": float(drag[:, 0].sum()),
        "settle_drift_m": float(np.ptp(np.array(mid_x), axis=0).max()) if mid_x else float("nan"),
    }


def _chord_state(model: Model, x_trim: np.ndarray) -> np.ndarray:
    """The trim state with the free tether nodes on the straight chord, at rest."""
    x = x_trim.copy()
    nodes = model.node_positions(x_trim)
    n = model.n
    top, bottom = nodes[0], nodes[n]
    lay = model.layout
    x[lay.node_pos] = np.concatenate([top + (bottom - top) * k / n for k in range(1, n)]) \
        if n > 1 else x[lay.node_pos]
    x[lay.node_vel] = 0.0
    return x


def _time_advance(model: Model, x0: np.ndarray, duration: float, integrator: str,
                  repeats: int) -> float:
    """Shortest wall time of ``repeats`` calls of ``Model.advance`` over ``duration``
    (compiled and warmed up beforehand)."""
    y = x0.copy()
    model.advance(y, 0.0, 1.0, BRAKED, integrator)  # compile / warm up
    walls = []
    for _ in range(repeats):
        y = x0.copy()
        t0 = time.perf_counter()
        model.advance(y, 0.0, duration, BRAKED, integrator)
        walls.append(time.perf_counter() - t0)
    return float(np.min(walls))


def compare_with_moordyn(quick: bool = False) -> dict:
    """Compare our tether with MoorDyn v2 on the same line (see the module docstring).

    Parameters
    ----------
    quick : 20 s runs instead of 60 s (the static state has settled well before either).

    Returns
    -------
    dict with
    - ``duration_s``, ``wind_m_s``, ``confluence_point_m`` (the fixed top end);
    - ``moordyn``: per scheme (``"rk2"``, the default scheme at its stable step, and ``"rk4"``
      at our RK4 step) ``dt_s``, ``wall_s``, ``real_time_factor``; ``moordyn_reference``: the
      faster of the two, used for the ratios; ``moordyn_dt_s``, ``moordyn_wall_s``,
      ``moordyn_real_time_factor`` (that reference); ``moordyn_default``: MoorDyn's default
      step (CFL 0.5) and whether it diverged within 1 s;
    - ``ours_tether``: per integrator (``"rk4"``, ``"semi-implicit"``) ``dt_s``, ``wall_s``,
      ``real_time_factor`` of the tether alone with the top fixed;
    - ``ours_full_rtf``: real-time factors of the full aerostat + tether system;
    - ``speed_ratio``: per integrator, ours full-system RTF / MoorDyn reference RTF for the
      tether alone; ``speed_ratio_vs_moordyn_rk2``: the same against MoorDyn's default scheme;
      ``speed_target_met`` (ratio >= 10, per integrator);
    - ``static``: after the run, against MoorDyn (reference run): ``max_node_diff_m``,
      ``rms_node_diff_m`` over the free nodes and their ``*_pct_length``, per our integrator
      (``"rk4"``, ``"semi-implicit"``), with ``top_tension_N`` and ``bottom_tension_N`` of each
      code and the relative differences ``top_tension_rel_diff`` and
      ``bottom_tension_rel_diff`` (ours / MoorDyn - 1); ``position_target_met`` (< 0.5 %);
    - ``settle_drift_m``: largest motion of the middle node over the last 5 s, each code;
    - ``current_check``: MoorDyn's total x drag against the crossflow estimate;
    - ``moordyn_settings`` and ``differences`` (text).
    """
    md = _import_moordyn()
    duration = 20.0 if quick else 60.0
    repeats = 7
    p = load_params(overrides={"environment.rho_air": RHO_AIR})
    eq = find_equilibrium(p, WIND)
    top = np.array(eq.summary["confluence_point_m"], dtype=float)

    # --- MoorDyn ------------------------------------------------------------------------------
    dt_rk2 = rk2_stable_dt(p)
    tether = Model(p, wind=WIND, fixed_aerostat=True)
    dt_rk4 = tether.rk4_dt()
    runs = {}
    with tempfile.TemporaryDirectory(prefix="aerostat_moordyn_") as tmp:
        runs["rk2"] = _run_moordyn(md, p, top, duration, "RK2", dt_rk2, tmp, repeats)
        runs["rk4"] = _run_moordyn(md, p, top, duration, "RK4", dt_rk4, tmp, repeats)
        default = _probe_default_step(md, p, top, tmp)
    ref_key = max(runs, key=lambda k: runs[k]["real_time_factor"])
    ref = runs[ref_key]

    expected_drag, drag_ratio, phi = _current_check(p, top, ref["drag_x_total_N"])

    # --- ours: tether alone (top fixed), then the full aerostat + tether ------------------------
    x0 = _chord_state(tether, eq.x)
    ours, static = {}, {}
    for integ in ("rk4", "semi-implicit"):
        wall = _time_advance(tether, x0, duration, integ, repeats)
        dt = dt_rk4 if integ == "rk4" else p.simulation.semi_implicit_dt
        ours[integ] = {"dt_s": dt, "wall_s": wall, "real_time_factor": duration / wall}
        static[integ] = _static_against(tether, x0, duration, integ, ref)
    full = Model(p, wind=WIND)
    full_rtf = {integ: duration / _time_advance(full, eq.x, duration, integ, repeats)
                for integ in ("rk4", "semi-implicit")}

    ratio = {k: v / ref["real_time_factor"] for k, v in full_rtf.items()}
    ratio_rk2 = {k: v / runs["rk2"]["real_time_factor"] for k, v in full_rtf.items()}
    return {
        "duration_s": duration,
        "wind_m_s": WIND,
        "confluence_point_m": top.tolist(),
        "moordyn": {k: {kk: v[kk] for kk in ("dt_s", "wall_s", "real_time_factor")}
                    for k, v in runs.items()},
        "moordyn_reference": ref_key,
        "moordyn_dt_s": ref["dt_s"],
        "moordyn_wall_s": ref["wall_s"],
        "moordyn_real_time_factor": ref["real_time_factor"],
        "moordyn_default": default,
        "ours_tether": ours,
        "ours_full_rtf": full_rtf,
        "speed_ratio": ratio,
        "speed_ratio_vs_moordyn_rk2": ratio_rk2,
        "speed_target_met": {k: bool(v >= 10.0) for k, v in ratio.items()},
        "static": static,
        "settle_drift_m": {"moordyn": ref["settle_drift_m"],
                           **{k: v["settle_drift_m"] for k, v in static.items()}},
        "current_check": {"moordyn_drag_x_N": ref["drag_x_total_N"],
                          "crossflow_estimate_N": expected_drag, "ratio": drag_ratio},
        "moordyn_settings": _settings(p, dt_rk2, dt_rk4, default, duration, repeats),
        "differences": differences(p, phi),
    }


def _current_check(p: Params, top: np.ndarray, drag_x: float) -> tuple[float, float, float]:
    """(expected x drag [N], MoorDyn's x drag over it, the chord's angle phi to the flow):
    MoorDyn's total x drag against 0.5 rho Cd d L U^2 sin^3(phi), phi the chord's angle to the
    flow (+X): |D_n| = 0.5 rho Cd d U^2 sin^2 phi per length, its x part sin phi of that. A
    ratio outside (0.8, 1.2) means MoorDyn's current does not act as set (a RuntimeError)."""
    chord = top - np.asarray(p.tether.anchor_position, float)
    phi = math.acos(min(1.0, abs(chord[0]) / float(np.linalg.norm(chord))))
    t = p.tether
    expected = (0.5 * p.environment.rho_air * t.Cd_normal * t.diameter * t.length * WIND**2
                * (math.sin(phi) ** 2) ** 1.5)
    ratio = drag_x / expected
    if not 0.8 < ratio < 1.2:
        raise RuntimeError(f"MoorDyn's current does not act as set: x drag {drag_x:.1f} N, "
                           f"expected ~{expected:.1f} N")
    return expected, ratio, phi


def _static_against(tether: Model, x0: np.ndarray, duration: float, integrator: str,
                    ref: dict) -> dict:
    """Our tether-only run's final shape and end tensions against MoorDyn's reference run."""
    L = tether.params.tether.length
    tr = simulate(tether.params, x0, duration, wind=WIND, integrator=integrator, model=tether,
                  output_dt=1.0)
    if tr.status != "ok":
        raise RuntimeError(f"our tether-only run ({integrator}) ended with status {tr.status!r}")
    diff = np.linalg.norm(tr.node_pos[-1][1:-1] - ref["node_pos"][1:-1], axis=1)
    last5 = tr.node_pos[tr.time > duration - 5.0 - 1e-9][:, tether.n // 2]
    top_o, bot_o = float(tr.top_tension[-1]), float(tr.winch_tension[-1])
    return {
        "max_node_diff_m": float(diff.max()),
        "rms_node_diff_m": float(np.sqrt(np.mean(diff**2))),
        "max_node_diff_pct_length": float(100.0 * diff.max() / L),
        "rms_node_diff_pct_length": float(100.0 * np.sqrt(np.mean(diff**2)) / L),
        "top_tension_N": {"ours": top_o, "moordyn": ref["top_tension_N"]},
        "bottom_tension_N": {"ours": bot_o, "moordyn": ref["bottom_tension_N"]},
        "top_tension_rel_diff": top_o / ref["top_tension_N"] - 1.0,
        "bottom_tension_rel_diff": bot_o / ref["bottom_tension_N"] - 1.0,
        "moordyn_anchor_tension_native_N": ref["anchor_tension_native_N"],
        "settle_drift_m": float(np.ptp(last5, axis=0).max()),
        "position_target_met": bool(diff.max() / L < 0.005),
    }


def _settings(p: Params, dt_rk2: float, dt_rk4: float, default: dict, duration: float,
              repeats: int) -> str:
    """The comparison's MoorDyn settings, in words (the report's ``moordyn_settings``)."""
    return (
        f"MoorDyn {_version()}: 1 line, {p.tether.n_elements} segments, "
        f"L = {p.tether.length} m, d = {p.tether.diameter} m, "
        f"m = {p.derived.mass_per_length:.6g} kg/m, "
        f"EA = {p.derived.EA:.6g} N, BA = b = {p.derived.damping_b:.6g} N s, EI = 0, "
        f"Cd = {p.tether.Cd_normal}, CdAx = Cd f_t(0)/pi = {axial_cdt(p):.4g}, Ca = CaAx = 0, "
        f"rho = {RHO_AIR}, g = {p.environment.g}, steady uniform current {WIND} m/s along +X "
        f"(Currents = 1), fixed ends, line {SUBMERGENCE:.0f} m below the surface; "
        f"RK2 (default scheme) at dt = {dt_rk2:.4g} s (rk4_safety x its linear stability bound; "
        f"the default CFL 0.5 step, {default['dt_s']:.4g} s, "
        f"{'diverges' if default['diverged_within_s'] else 'does not diverge'} within 1 s), "
        f"RK4 at our dt = {dt_rk4:.4g} s; "
        f"Step calls of {duration / max(1, math.ceil(duration / STEP_CHUNK - 1e-9)):.3g} s; "
        f"shortest of {repeats} timed runs after a warm-up, both codes"
    )
