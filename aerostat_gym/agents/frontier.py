"""Swing-recovery runs of winch policies in the environment, and the damping-versus-reel-speed
frontier (pendulum damping ratio against the peak reel set-point a swing asks for).

One run (:func:`swing_response`): ``TetheredAerostat-v0`` in steady wind (no turbulence), the
aerostat and tether swung rigidly about the winch by ``swing`` metres along the wind (fixed, not
drawn, no pitch kick), the policy in the loop at the 0.2 s control step for ``duration``
seconds. The pendulum damping ratio is fitted to the along-wind CM displacement
(:func:`aerostat_gym.agents.metrics.fit_damped_sinusoid`); the peak reel speed and the peak
set-point come from the winch state and the action.

Brake logic: the winch's own (:func:`aerostat_gym.sim.winch.brake_wanted`): the brake is
applied on an exact-zero set-point or after ``winch.brake_dwell`` (10 s) inside the stand-still
band ``winch.brake_speed`` (0.002 m/s), so a controller's small commands reach the drum.
``brake_speed`` and ``brake_dwell`` override those two parameters for a run (``brake_speed=0``:
only an exact zero brakes; ``brake_speed=0.02, brake_dwell=0``: the dead band of 0.2).

The frontier (``scripts/winch_frontier.py`` runs it): :func:`frontier_table` formats one row
per run as Markdown; :func:`plot_frontier` draws one panel per wind speed (damping of the
sinusoid-plus-drift fit against peak reel speed; matplotlib is imported there, lazily), with
:func:`modal_peak_limit`'s linear end of the modal line and, where a modal run saturates the
winch (:func:`saturated_speeds`), that end as the authority bound.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..analysis.linear import propagate
from ..envs.vector import TetheredAerostatVectorEnv
from ..extras import agg_pyplot
from ..physics.state import S_X
from .metrics import fit_damped_sinusoid
from .metrics_drift import fit_pendulum_with_drift
from .modal import design_modal
from .sb3io import policy_obs


@dataclass
class SwingRun:
    """Histories and figures of one swing-recovery run.

    Attributes
    ----------
    wind_speed : float
        Mean wind speed [m/s].
    swing : float
        Initial along-wind swing [m].
    time : numpy.ndarray
        Sample times [s] (control steps).
    x : numpy.ndarray
        Along-wind CM displacement from trim [m].
    length : numpy.ndarray
        Paid-out length minus trim [m].
    reel_speed : numpy.ndarray
        Winch reel speed v_w [m/s].
    set_point : numpy.ndarray
        Commanded set-point, action times max_speed [m/s] (one per step).
    zeta : float
        Pendulum damping ratio fitted to ``x``.
    period : float
        Natural period of that fit [s].
    r2 : float
        Coefficient of determination of that fit.
    ended : str or None
        Termination reason, None for a full run.
    zeta_drift : float
        Pendulum damping ratio of the sinusoid-plus-drift fit
        (:func:`aerostat_gym.agents.metrics_drift.fit_pendulum_with_drift`).
    """

    wind_speed: float
    swing: float
    time: np.ndarray
    x: np.ndarray
    length: np.ndarray
    reel_speed: np.ndarray
    set_point: np.ndarray
    zeta: float
    period: float
    r2: float
    ended: str | None
    zeta_drift: float = math.nan

    @property
    def peak_reel_speed(self) -> float:
        return float(np.max(np.abs(self.reel_speed)))

    @property
    def peak_set_point(self) -> float:
        return float(np.max(np.abs(self.set_point)))

    @property
    def length_wander(self) -> float:
        """Largest |L - L_trim| over the run [m]."""
        return float(np.max(np.abs(self.length)))

    def row(self) -> dict:
        return {"wind_speed": self.wind_speed, "swing_m": self.swing, "zeta": self.zeta,
                "zeta_drift": self.zeta_drift,
                "period_s": self.period, "fit_r2": self.r2,
                "peak_reel_speed_m_s": self.peak_reel_speed,
                "peak_set_point_m_s": self.peak_set_point,
                "length_wander_m": self.length_wander, "ended": self.ended}


def brake_overrides(brake_speed: float | None = None, brake_dwell: float | None = None
                    ) -> dict | None:
    """Parameter overrides of the winch's brake logic (None where neither is given)."""
    out = {}
    if brake_speed is not None:
        out["winch.brake_speed"] = float(brake_speed)
    if brake_dwell is not None:
        out["winch.brake_dwell"] = float(brake_dwell)
    return out or None


def swing_env(wind_speed: float, swing: float, brake_speed: float | None = None,
              obs_noise: float = 0.0, params=None, control_step: float = 0.2,
              duration: float = 180.0, num_envs: int = 1, brake_dwell: float | None = None
              ) -> TetheredAerostatVectorEnv:
    """The vector environment of a swing-recovery run (full observation, steady wind)."""
    overrides = brake_overrides(brake_speed, brake_dwell)
    return TetheredAerostatVectorEnv(
        num_envs=num_envs, max_episode_steps=int(round(duration / control_step)),
        observation="full", control_step=control_step, turbulence="none",
        wind_speed=(wind_speed, wind_speed), params=params, overrides=overrides,
        obs_noise=obs_noise,
        perturbation={"swing": float(swing), "lateral": 0.0, "pitch": 0.0, "fixed": True})


def swing_response(policy, wind_speed: float, swing: float, *, brake_speed: float | None = None,
                   brake_dwell: float | None = None, obs_noise: float = 0.0, seed: int = 0,
                   params=None, duration: float = 180.0, control_step: float = 0.2) -> SwingRun:
    """Run ``policy`` through one swing recovery and fit its pendulum damping.

    Parameters
    ----------
    policy : object
        Anything with SB3's ``predict(observation, state, episode_start, deterministic)``.
    wind_speed : float
        Mean wind speed [m/s].
    swing : float
        Initial along-wind swing of aerostat and tether [m].
    brake_speed, brake_dwell : float or None
        Overrides of winch.brake_speed and winch.brake_dwell (None: the configured brake logic).
    obs_noise : float
        Sensor noise std in the environment's scaled units.
    seed : int
        Reset seed (draws the sensor noise).
    params : Params or None
        Environment parameters (default: the shipped baseline).
    duration : float
        Length of the run [s].
    control_step : float
        Control step [s].

    Returns
    -------
    SwingRun
    """
    if not (math.isfinite(swing) and swing > 0):
        raise ValueError(f"swing must be finite and > 0 [m], got {swing!r}")
    env = swing_env(wind_speed, swing, brake_speed, obs_noise, params, control_step, duration,
                    brake_dwell=brake_dwell)
    obs, _ = env.reset(seed=[seed], options={"wind_speed": [wind_speed]})
    b, lay = env.batch, env.batch.layout
    vmax = float(b.params.winch.max_speed)
    ix, iL, iv = lay.at(S_X), lay.winch_length, lay.winch_speed
    steps = env.max_episode_steps
    x, L, v, sp = (np.zeros(steps + 1) for _ in range(4))
    x[0], L[0], v[0] = _sample(b, ix, iL, iv)
    state, start, ended, k_end = None, np.ones(1, bool), None, steps
    for k in range(1, steps + 1):
        action, state = policy.predict(policy_obs(policy, obs), state=state, episode_start=start,
                                       deterministic=True)
        start[:] = False
        a = np.asarray(action, np.float32).reshape(-1, 1)
        sp[k - 1] = float(np.clip(a[0, 0], -1.0, 1.0)) * vmax
        obs, _, term, trunc, info = env.step(a)
        x[k], L[k], v[k] = _sample(b, ix, iL, iv)
        if term[0]:
            ended, k_end = str(info["termination"][0]), k
            break
    env.close()
    t = np.arange(k_end + 1) * control_step
    fit = fit_damped_sinusoid(t, x[:k_end + 1])
    drift = fit_pendulum_with_drift(t, x[:k_end + 1])
    return SwingRun(float(wind_speed), float(swing), t, x[:k_end + 1], L[:k_end + 1],
                    v[:k_end + 1], sp[:k_end], fit.zeta, fit.period, fit.r2, ended, drift.zeta)


def _sample(b, ix: int, iL: int, iv: int) -> tuple[float, float, float]:
    """(along-wind CM displacement, length deviation, reel speed) of slot 0 of a batch."""
    return (b.state[0, ix] - b.trim_state[0, ix], b.state[0, iL] - b.trim_state[0, iL],
            b.state[0, iv])


def initial_state(wind_speed: float, swing: float, params=None) -> tuple[np.ndarray, np.ndarray]:
    """(x0, x_trim): the environment's start of a swing-recovery run and its trim (6n+8)."""
    env = swing_env(wind_speed, swing, params=params)
    env.reset(seed=[0], options={"wind_speed": [wind_speed]})
    x0, xt = env.batch.state[0].copy(), env.batch.trim_state[0].copy()
    env.close()
    return x0, xt


def initial_deviation(wind_speed: float, swing: float, params=None) -> np.ndarray:
    """The environment's start of a swing-recovery run as a deviation from trim (6n+8)."""
    x0, xt = initial_state(wind_speed, swing, params)
    return x0 - xt


def linear_response(Acl: np.ndarray, K: np.ndarray, dx0: np.ndarray, steps: int
                    ) -> tuple[np.ndarray, np.ndarray]:
    """(states, set-points) of the discrete closed loop x_{k+1} = Acl x_k, v_k = -K x_k."""
    X = propagate(Acl, dx0, steps)
    return X, -(X[:-1] @ K)


def modal_linear_peak(design, dx0_full: np.ndarray, duration: float = 180.0) -> float:
    """Peak |v_set| [m/s] the linear closed loop of a :class:`~aerostat_gym.agents.modal.
    ModalDesign` asks for from the start ``dx0_full`` (full layout; the subset is used)."""
    steps = int(round(duration / design.dt))
    _, v = linear_response(design.closed_loop_matrix, design.K_subset,
                           dx0_full[design.index], steps)
    return float(np.max(np.abs(v)))


def linear_fit_zeta(Acl: np.ndarray, K: np.ndarray, dx0: np.ndarray, i_x: int,
                    duration: float = 180.0, dt: float = 0.2) -> tuple[float, float]:
    """Pendulum damping ratios that :func:`fit_damped_sinusoid` and
    :func:`~aerostat_gym.agents.metrics_drift.fit_pendulum_with_drift` find in the linear
    closed loop's along-wind CM displacement (state ``i_x`` of ``dx0``'s layout) from ``dx0``.

    Notes
    -----
    This is the like-for-like linear value for a nonlinear run's fitted damping: the
    single-mode fit is biased low where the pendulum is well damped and other slow modes (the
    length loop, the LQR's integral) share the record, by 0.6 % (LQR, 5 m/s), 6 % (LQR,
    10 m/s), 22 % (LQR, 15 m/s) and 5-12 % (modal at 10-15 m/s) against the eigenvalue.
    """
    steps = int(round(duration / dt))
    X, _ = linear_response(Acl, K, dx0, steps)
    t = np.arange(steps + 1) * dt
    return (fit_damped_sinusoid(t, X[:, i_x]).zeta,
            fit_pendulum_with_drift(t, X[:, i_x]).zeta)


def modal_peak_limit(params, wind_speed: float, swing: float, peak: float = 1.0,
                     tol: float = 1e-3, dt: float = 0.2) -> tuple[float, float]:
    """(zeta, peak set-point): the largest modal pendulum damping whose linear closed loop asks
    for at most ``peak`` [m/s] from a ``swing`` [m] along-wind start, by bisection on zeta
    between the open-loop value and 0.99 (the peak set-point grows with zeta).

    This is the modal controller's own frontier end at the winch's speed limit, not a bound
    over every controller.
    """
    dx0 = initial_deviation(wind_speed, swing, params)
    first = design_modal(params, wind_speed, 0.5, dt)
    lo = float(first.lqr.mode("pendulum", "open").zeta) + 1e-3
    hi = 0.99

    def peak_at(z):
        return modal_linear_peak(design_modal(params, wind_speed, z, dt, lqr=first.lqr), dx0)

    if peak_at(lo) > peak:
        return lo, peak_at(lo)
    if peak_at(hi) <= peak:
        return hi, peak_at(hi)
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if peak_at(mid) <= peak else (lo, mid)
    return lo, peak_at(lo)


# --- the frontier table and figure -----------------------------------------------------------

#: Marker, colour and legend label of each baseline in the frontier figure (learned policies:
#: stars; modal: a line).
BASELINE_MARKERS = {"passive": ("s", "black", "passive (braked winch)"),
                    "tension": ("^", "tab:green", "tension feedback"),
                    "lqr": ("D", "tab:red", "LQR (full state)"),
                    "lqg": ("v", "tab:purple", "LQG (sensor noise)"),
                    "modal_lqg": ("h", "tab:brown", "modal on a Kalman filter (sensor noise)"),
                    "modal_lqg_shaped": ("p", "tab:gray",
                                         "the same, 1 s low-pass + deadband (sensor noise)"),
                    "modal_lqg_lowpass": ("P", "tab:blue",
                                          "the same, 1 s low-pass only (sensor noise)")}
#: Colours the learned policies take in turn.
LEARNED_COLOURS = ("gold", "tab:orange", "tab:pink", "tab:cyan", "tab:olive")
#: Legend names of learned policies known by name (others: their name).
LEARNED_LABELS = {"shipped": "shipped PPO"}
#: Relative margin below the speed limit at which a run counts as saturating the winch.
SATURATION_RTOL = 1e-3


def _num(value, fmt: str) -> str:
    """``value`` in ``fmt``, blank where it is None or NaN."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return format(value, fmt)


def frontier_table(rows: list[dict]) -> str:
    """The frontier rows as a Markdown table (one row per run).

    Each row needs ``wind_speed``, ``policy``, ``designed_zeta`` (None where the policy has no
    design value), ``zeta``, ``zeta_drift``, ``peak_reel_speed_m_s``, ``peak_set_point_m_s`` and
    ``length_wander_m``.
    """
    lines = ["| U [m/s] | policy | designed ζ | measured ζ: 1-mode fit | measured ζ: drift fit | "
             "peak reel speed [m/s] | peak set-point [m/s] | length wander [m] |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['wind_speed']:g} | {r['policy']} | {_num(r['designed_zeta'], '.3f')} "
                     f"| {_num(r['zeta'], '.3f')} | {_num(r['zeta_drift'], '.3f')} | "
                     f"{r['peak_reel_speed_m_s']:.3f} | {r['peak_set_point_m_s']:.3f} | "
                     f"{r['length_wander_m']:.2f} |")
    return "\n".join(lines)


def modal_fractions(rows: list[dict], fit: str = "zeta") -> list[dict]:
    """Each non-modal run's damping as a fraction of the modal controller's curve at the same
    peak reel speed: the modal runs at one wind speed, sorted by peak reel speed, are
    interpolated linearly in (peak reel speed, ``fit``) (held at the ends); a fraction of 0.9
    at a peak reel speed within the curve's range is "90 % of the modal controller's damping at
    equal peak reel speed". ``fit``: "zeta" (single-mode fit) or "zeta_drift"."""
    out = []
    for U in sorted({float(r["wind_speed"]) for r in rows}):
        curve = sorted((r["peak_reel_speed_m_s"], r[fit]) for r in rows
                       if r.get("kind") == "modal" and float(r["wind_speed"]) == U
                       and math.isfinite(r[fit]))
        if not curve:
            continue
        v, z = np.array(curve).T
        for r in rows:
            if r.get("kind") == "modal" or float(r["wind_speed"]) != U:
                continue
            ref = float(np.interp(r["peak_reel_speed_m_s"], v, z))
            out.append({"wind_speed": U, "policy": r["policy"],
                        "peak_reel_speed_m_s": r["peak_reel_speed_m_s"], fit: r[fit],
                        "modal_at_same_peak": ref, "fraction": r[fit] / ref,
                        "within_curve": bool(v[0] <= r["peak_reel_speed_m_s"] <= v[-1])})
    return out


def saturates(row: dict, max_speed: float = 1.0) -> bool:
    """Whether a run's reel speed reached the winch's speed limit (within SATURATION_RTOL)."""
    return row["peak_reel_speed_m_s"] >= (1.0 - SATURATION_RTOL) * max_speed


def saturated_speeds(rows: list[dict], max_speed: float = 1.0) -> list[float]:
    """Wind speeds at which a measured modal run drives the winch to its speed limit: there the
    modal line's linear end at the limit is the winch's authority bound, not just the end of
    one controller's curve."""
    return sorted({float(r["wind_speed"]) for r in rows
                   if r.get("kind") == "modal" and saturates(r, max_speed)})


def plot_frontier(rows: list[dict], limits: list[dict], out, max_speed: float = 1.0,
                  swing: float | None = None):
    """Draw the frontier figure (one panel per wind speed) and save it to ``out`` (PNG).

    Parameters
    ----------
    rows : list of dict
        Runs as in :func:`frontier_table`, with ``kind`` one of 'passive', 'baseline', 'modal'
        or 'learned'. y is the sinusoid-plus-drift fit (``zeta_drift``), x the peak reel speed.
    limits : list of dict
        Per wind speed the modal line's linear end at the speed limit: ``wind_speed``,
        ``zeta``, ``peak_set_point_m_s`` and ``authority`` (True: the winch saturates there, the
        end is drawn as a horizontal bound as well).
    out : str or Path
        PNG file to write.
    max_speed : float
        The winch's speed limit [m/s] (dashed vertical line).
    swing : float or None
        Initial swing [m], for the title.

    Returns
    -------
    matplotlib.figure.Figure
        The figure (closed to pyplot; its ``axes`` are the panels).
    """
    plt = agg_pyplot("the frontier figure")
    speeds = sorted({float(r["wind_speed"]) for r in rows} | {float(b["wind_speed"])
                                                              for b in limits})
    learned = list(dict.fromkeys(r["policy"] for r in rows if r["kind"] == "learned"))
    fig, axes = plt.subplots(1, len(speeds), figsize=(11, 3.9), squeeze=False)
    axes = axes[0]
    handles = {}

    def keep(label, h):
        handles.setdefault(label, h)

    for ax, U in zip(axes, speeds, strict=True):
        here = [r for r in rows if float(r["wind_speed"]) == U]
        bound = next((b for b in limits if float(b["wind_speed"]) == U), None)
        ys = _draw_modal(ax, here, bound, max_speed, keep)
        ys += _draw_policies(ax, here, learned, keep)
        keep(f"winch limit {max_speed:g} m/s", ax.axvline(max_speed, color="grey", ls="--", lw=1))
        _frame_panel(ax, U, ys, max_speed)
    axes[0].set_ylabel("pendulum ζ, sinusoid + drift fit\n(within 5 % of the linear "
                       "eigenvalues)", fontsize=9)
    rows_of_legend = _legend(fig, handles)
    title = "Pendulum damping against peak reel speed"
    if swing is not None:
        title += f" ({swing:g} m along-wind swing, steady wind, shipped winch)"
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0.13 if rows_of_legend > 1 else 0.07, 1, 1))
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return fig


def _draw_modal(ax, here: list[dict], bound: dict | None, max_speed: float, keep) -> list:
    """One panel's modal controller: its curve (hollow where the winch saturates), its linear
    end at the speed limit and, where the winch saturates, the authority bound. Returns the
    damping ratios drawn."""
    ys = []
    if bound is not None and bound.get("authority"):
        h = ax.axhline(bound["zeta"], color="tab:blue", ls=":", lw=1.5)
        ax.axhspan(bound["zeta"], 1.5, color="tab:blue", alpha=0.08, lw=0)
        keep("authority bound (winch saturates)", h)
    modal = sorted((r for r in here if r["kind"] == "modal"), key=lambda r: r["designed_zeta"])
    free = [r for r in modal if not saturates(r, max_speed)]
    sat = [r for r in modal if saturates(r, max_speed)]
    if free:
        (h,) = ax.plot([r["peak_reel_speed_m_s"] for r in free], [r["zeta_drift"] for r in free],
                       "-o", color="tab:blue", ms=5, zorder=3)
        keep("modal controller", h)
    if sat:
        link = free[-1:] + sat
        ax.plot([r["peak_reel_speed_m_s"] for r in link], [r["zeta_drift"] for r in link],
                ":", color="tab:blue", lw=1, zorder=2)
        (h,) = ax.plot([r["peak_reel_speed_m_s"] for r in sat], [r["zeta_drift"] for r in sat],
                       "o", mfc="white", mec="tab:blue", ms=5, zorder=3)
        keep("modal, winch saturated (not linear)", h)
    ys += [r["zeta_drift"] for r in modal]
    if bound is not None:
        (h,) = ax.plot([bound["peak_set_point_m_s"]], [bound["zeta"]], "P", ms=10,
                       color="tab:blue", mec="white", mew=0.8, zorder=4)
        # below the limit: the design range's end (zeta 0.99) asks for less than the limit
        short = bound["peak_set_point_m_s"] < 0.99 * max_speed
        ax.annotate(f"ζ {'≥ ' if short else ''}{bound['zeta']:.2f}",
                    (bound["peak_set_point_m_s"], bound["zeta"]),
                    xytext=(-6, 6), textcoords="offset points", ha="right", fontsize=8,
                    color="tab:blue")
        ys.append(bound["zeta"])
        keep("modal limit (linear)", h)
    return ys


def _draw_policies(ax, here: list[dict], learned: list[str], keep) -> list:
    """One panel's passive winch, baselines and learned policies, a marker each. Returns the
    damping ratios drawn."""
    ys = []
    for r in here:
        if r["kind"] in ("passive", "baseline"):
            m, c, label = BASELINE_MARKERS.get(r["policy"], ("o", "grey", r["policy"]))
            (h,) = ax.plot([r["peak_reel_speed_m_s"]], [r["zeta_drift"]], m, color=c, ms=7,
                           mec="white", mew=0.6, zorder=5)
            keep(label, h)
        elif r["kind"] == "learned":
            c = LEARNED_COLOURS[learned.index(r["policy"]) % len(LEARNED_COLOURS)]
            (h,) = ax.plot([r["peak_reel_speed_m_s"]], [r["zeta_drift"]], "*", color=c,
                           ms=14, mec="black", mew=0.6, zorder=6)
            keep(f"{LEARNED_LABELS.get(r['policy'], r['policy'])} (learned)", h)
        else:
            continue
        ys.append(r["zeta_drift"])
    return ys


def _frame_panel(ax, U: float, ys: list, max_speed: float) -> None:
    """Limits (the y range of what is drawn), title and labels of one panel."""
    ys = [y for y in ys if y is not None and math.isfinite(y)]
    if ys:
        lo, hi = min(ys), max(ys)
        pad = max(hi - lo, 0.05)
        ax.set_ylim(lo - 0.06 * pad, hi + 0.12 * pad)
    ax.set_xlim(-0.03, 1.05 * max_speed)
    ax.set_title(f"U = {U:g} m/s", fontsize=10)
    ax.set_xlabel("peak reel speed [m/s]")
    ax.grid(alpha=0.3)
    ax.tick_params(labelsize=8)


def _legend(fig, handles: dict) -> int:
    """The figure's legend below the panels, baselines first; returns its number of rows."""
    order = [label for _, _, label in BASELINE_MARKERS.values()]
    order += [k for k in handles if k.endswith("(learned)")]
    order += ["modal controller", "modal, winch saturated (not linear)", "modal limit (linear)",
              "authority bound (winch saturates)"]
    labels = [k for k in order if k in handles] + [k for k in handles if k not in order]
    ncol = min(len(labels), 5)
    fig.legend([handles[k] for k in labels], labels, loc="lower center", ncol=ncol, fontsize=8,
               frameon=False)
    return math.ceil(len(labels) / ncol) if labels else 0
