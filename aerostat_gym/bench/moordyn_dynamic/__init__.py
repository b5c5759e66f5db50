"""Dynamic peer comparison with MoorDyn v2 (issue 20): the tether in motion, top end driven.

The static comparison (:mod:`aerostat_gym.bench.moordyn`) holds the top end fixed; here the top end
follows a prescribed path from the settled trim shape and the two codes' node positions and end
tensions are compared sample by sample. Same line, same fluid and the same drag model choices as
the static comparison: one line of n = 10 segments in air (rho = 1.225), the steady uniform
10 m/s "current" standing in for the wind, MoorDyn's line 100 m below its water surface (frame
shift, undone for the comparison), BA = b, Cd = Cd_normal, CdAx = Cd_normal f_t(0) / pi,
Ca = CaAx = 0, EI = 0 (see :mod:`aerostat_gym.bench.moordyn` for why each).

Cases (:func:`standard_cases`)
------------------------------
- Sinusoidal top motion r_top(t) = r_trim + A sin(2 pi t / T) d_hat from t = 0, d_hat along the
  wind (+X), across it (+Y) and vertical (+Z), T the longitudinal pendulum period, the first
  tether harmonic and the axial spring period of :func:`aerostat_gym.analysis.reference
  .reference_periods` (41.0 s, 1.68 s, 3.00 s at rho = 1.225), A = 1 m and 5 m. Compared over the
  60 s after the first cycle.
- Reel: the unstretched length grows at 1 m/s for 10 s (paid out, top end held). MoorDyn 2.7 has
  the API: ``SetLineUnstretchedLength`` / ``SetLineUnstretchedLengthVel`` (C:
  ``MoorDyn_SetLineUnstretchedLength[Vel]``); with a rate set, each Step ramps the length
  linearly, L = L_step_start + t_local Ldot, and every segment's l = L / N and the node masses and
  volumes follow (``Line::setUnstretchedLength``, ``Line::updateUnstretchedLength``). Reeling
  *in* 10 m with the top end held would stretch the line by 10 m (~35 kN, the tether's
  strength), so the length is paid out. Compared over 60 s from the start.
- Drop: the top end falls 20 m in 2 s (cosine ramp, up to 15.7 m/s, faster than the line falls
  in air), is held 3 s and rises back in 4 s (up to 7.9 m/s): the line goes slack and snaps taut
  again. Compared over 60 s from the start.

How the top end is driven
-------------------------
- Ours: the tether-only model (``Model(..., fixed_aerostat=True)``, the aerostat's derivatives
  are zeroed) with the aerostat's CM position and velocity overwritten before every right-hand
  side evaluation so that the confluence point (CM + R r_l, the attitude held at the trim, rates
  zero) sits on the path: :func:`driven_rk4` at every RK4 stage time (the path's exact position
  and velocity), :func:`driven_si` before every semi-implicit step (position at the step start,
  the secant velocity over the step, which is what that scheme's position update
  x_{k+1} = x_k + h v_{k+1} needs for the top to land on the path). For the reel case the
  unstretched length L and its rate (the winch states, braked so the core leaves them alone) are
  overwritten the same way.
- MoorDyn: point 2 is ``Coupled``; every Step call of one MoorDyn time step h gives it the path
  position at the step start and the secant velocity, and MoorDyn moves it linearly within the
  step (``Point::updateFairlead``: r = r_start + rd t_local), so it is on the path at every step
  boundary.

Both codes first settle for ``settle`` seconds with the top end at the trim (MoorDyn from its own
still-fluid initial state, ours from the straight chord with RK4, the start of both our
integrators, as in the static comparison); the drive starts at t = 0 after that.

Time steps
----------
Outputs every 0.05 s. Ours: RK4 at h = 0.05 / 9 = 5.56 ms (0.86 x its axial stability bound at
300 m), semi-implicit at ``simulation.semi_implicit_dt`` = 0.05 s. MoorDyn RK4 (the reference) at
0.05 / 18 = 2.78 ms, and checked converged by a second run at half that step (its difference
from the reference is reported per case: ``moordyn_step_check``).

Figures
-------
Over each case's window, for each of our integrators against MoorDyn: node positions (the n - 1
free nodes) RMS and max distance as % of L; top and bottom tension RMS difference as % of
MoorDyn's mean tension over the window, and the phase lag (positive: ours lags) of the harmonic
of the drive period (first or second, whichever dominates MoorDyn's tension: motion across the
wind swings the tension at twice the drive frequency) from a least-squares fit (sinusoidal
cases) or from the peak of the cross-correlation (reel, drop); the slack segments (stretched length <= unstretched, the
definition shared by both codes' elastic law) of each code; the wall time of each code for the
whole case (drive plus window, best of ``repeats``, the settle excluded) and the speed ratio
MoorDyn wall / ours wall. MoorDyn's wall time includes one Python Step call per MoorDyn step
(that is how a coupled top end is driven with its Python API).

Named modelling differences and their switches (``variant`` of :func:`prepare`)
-------------------------------------------------------------------------------
- ``"crossflow_drag"`` (drag law only): ours with f_n(phi) = sin^2 phi (loading_fn = [0.5, 0,
  0, -0.5, 0]) and f_t = 0, MoorDyn with CdAx = 0: the same crossflow law on both sides, our
  element-midpoint lumping kept.
- ``"moordyn_drag"`` (drag law and lumping, our side): MoorDyn's nodal drag
  (:func:`moordyn_node_drag`: each node's own velocity and the tangent through its neighbours,
  Cd sin^2 and CdAx cos^2) replaces ours (loading functions on each element's midpoint
  velocity, half to each end node) in the node accelerations (``driven._apply_moordyn_drag``).
- ``"no_buoyancy"`` (buoyancy, MoorDyn's side): its line mass per length raised by
  rho_air A, so its submerged weight equals our weight (its inertia rises by 0.15 %).
- ``"moordyn_slack_rule"`` (damping clip, our side): MoorDyn's segment force
  (:func:`moordyn_segment_tension`: the elastic part only when stretched, the dashpot always, so
  it can push, and no unstretched-length rate in the strain rate) replaces our tension-only
  T = max(EA eps + c* deps/dt, 0).
- ``"moordyn_drag_and_slack_rule"``: both of ours together: the two codes then integrate the
  same equations and what is left is time discretization.
- ``"no_damping"``: internal damping off in both codes (BA = b = 0), another way to remove the
  clip; the undamped snap loads are then far from converged in either code, so it is not used
  for the explanations.

The our-side switches act in :func:`driven_rk4` only (the semi-implicit step has no such hook;
its columns stay the unswitched scheme). With MoorDyn's drag switched in, the smoke case (no
slack) agrees to 0.002 % of the mean tension.

Modules
-------
``cases`` (the paths and the standard cases), ``driven`` (our tether with its top end driven,
compiled, and MoorDyn's rules as switches), ``runs`` (each code on one case), ``report`` (the
settings and tables in words), ``compare`` (the comparison and the whole study). Their public
names are importable from this package.
"""

from .cases import (
    DIRECTIONS,
    DROP,
    K_AMP,
    K_DIR,
    K_DROP_D,
    K_DROP_T,
    K_HOLD_T,
    K_KIND,
    K_L0,
    K_LEVER,
    K_OMEGA,
    K_REEL_T,
    K_REEL_V,
    K_RISE_T,
    K_TOP,
    PATH_SIZE,
    REEL,
    SINE,
    WINDOW,
    DrivenCase,
    DynamicBenchError,
    drop_case,
    path_displacement,
    path_length,
    standard_cases,
)
from .compare import (
    EXPLAIN_VARIANTS,
    POSITION_TARGET_PCT,
    TENSION_TARGET_PCT,
    compare_runs,
    correlation_lag,
    harmonic_fit,
    harmonic_lag,
    run_case,
    run_dynamic_comparison,
)
from .driven import (
    CM_POS,
    CM_VEL,
    LENGTH,
    LENGTH_RATE,
    NO_SWAP,
    RATES,
    SWAP_NODAL_DRAG,
    SWAP_SEGMENT_RULE,
    driven_rk4,
    driven_si,
    moordyn_node_drag,
    moordyn_segment_tension,
    node_unit,
    our_node_drag,
)
from .report import (
    format_report,
    format_table,
    settings_text,
)
from .runs import (
    MOORDYN_SUBSTEPS,
    OUTPUT_DT,
    RK4_SUBSTEPS,
    SETTLE,
    VARIANTS,
    Setup,
    prepare,
    run_moordyn,
    run_ours,
    step_call_overhead,
)

__all__ = [
    "CM_POS", "CM_VEL", "DIRECTIONS", "DROP", "DrivenCase", "DynamicBenchError",
    "EXPLAIN_VARIANTS", "K_AMP", "K_DIR", "K_DROP_D", "K_DROP_T", "K_HOLD_T", "K_KIND", "K_L0",
    "K_LEVER", "K_OMEGA", "K_REEL_T", "K_REEL_V", "K_RISE_T", "K_TOP", "LENGTH", "LENGTH_RATE",
    "MOORDYN_SUBSTEPS", "NO_SWAP", "OUTPUT_DT", "PATH_SIZE", "POSITION_TARGET_PCT", "RATES",
    "REEL", "RK4_SUBSTEPS", "SETTLE", "SINE", "SWAP_NODAL_DRAG", "SWAP_SEGMENT_RULE", "Setup",
    "TENSION_TARGET_PCT", "VARIANTS", "WINDOW", "compare_runs", "correlation_lag", "driven_rk4",
    "driven_si", "drop_case", "format_report", "format_table", "harmonic_fit", "harmonic_lag",
    "moordyn_node_drag", "moordyn_segment_tension", "node_unit", "our_node_drag",
    "path_displacement", "path_length", "prepare", "run_case", "run_dynamic_comparison",
    "run_moordyn", "run_ours", "settings_text", "standard_cases", "step_call_overhead",
]
