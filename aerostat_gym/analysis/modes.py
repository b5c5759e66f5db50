"""Modal analysis of the decoupled linear model: modal tables, mode classification, MAC tracking,
and sweeps over wind speed (Figure 9 of [LN02]), tether length and trim pitch.

Each eigenvalue lambda of A_long or A_lat (one per complex-conjugate pair, or a real one) is a
:class:`Mode` with python-control's ``damp`` quantities (natural frequency, damping ratio) and its
eigenvector. The eigenvector's position part (x, z, theta or y, phi, psi) is weighted by the
inertia that goes with each coordinate, which turns |v_i|^2 into each coordinate's share of the
modal kinetic energy. Classification reads those shares and the shape of the tether (sign
changes along the nodes), as [LN02] classified its modes by eye.
"""

from __future__ import annotations

import math
import re
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linear_sum_assignment

from ..params import Params, load_params
from ..physics.core import rotation_matrix
from ..physics.state import StateLayout
from .linear import Decoupled, LinearModel, decouple, linearize
from .trim import Equilibrium, TrimError, find_equilibrium

SETS = ("long", "lat")
#: The decoupled subsets by name, as the reports print them.
SET_NAMES = {"long": "longitudinal", "lat": "lateral"}
#: |lambda| below this [rad/s] (a period above about 17 h) counts as a neutral rigid-body mode:
#: at zero wind the whole system may turn about the vertical through the anchor, a double zero
#: eigenvalue that finite differences split into +-sqrt(rounding), a few 1e-5.
NEUTRAL_RATE = 1e-4
#: The modes of [LN02] Figure 9, per set, plus the yaw mode, which in this model is among the
#: four lowest lateral modes (the paper's yaw is merged into its lateral pendulum).
FIGURE9_MODES = {
    "long": ("pendulum", "pitching", "axial spring", "tether 1st harmonic"),
    "lat": ("pendulum", "rolling", "tether 1st harmonic", "tether 2nd harmonic", "yaw"),
}


def ordinal(k: int) -> str:
    suffix = {1: "st", 2: "nd", 3: "rd"}.get(k if k < 20 else k % 10, "th")
    return f"{k}{suffix}"


@dataclass
class Mode:
    """One mode of a subset.

    Attributes
    ----------
    eigenvalue : lambda (Im >= 0 for a complex pair). vector : eigenvector in the subset's state
    order. wn : natural frequency |lambda| [rad/s]. zeta : -Re(lambda)/|lambda|. period : 2 pi / wn
    [s] (as ``control.damp``; no period for a real eigenvalue: :meth:`natural_period`).
    oscillatory : Im(lambda) != 0. stable : Re(lambda) < 0 or neutral. neutral : |lambda| <
    :data:`NEUTRAL_RATE`. label : classification. energy : kinetic-energy share per state group.
    shape : real-ified transverse tether shape, anchor (0) to confluence point.
    sign_changes : sign changes of the shape along the moving nodes.
    """

    eigenvalue: complex
    vector: np.ndarray
    wn: float
    zeta: float
    period: float
    oscillatory: bool
    stable: bool
    neutral: bool
    label: str = ""
    energy: dict = field(default_factory=dict)
    shape: np.ndarray | None = None
    sign_changes: int = 0

    def natural_period(self) -> float | None:
        """2 pi / omega_n [s] of an oscillatory mode; None for a real eigenvalue, which decays
        or grows without swinging (its 2 pi / |lambda| is no period)."""
        return self.period if self.oscillatory and math.isfinite(self.period) else None

    def describe(self) -> str:
        """One-line text of the mode's timing: "period P s  damping Z" for an oscillatory
        mode; for a real eigenvalue, "real (non-oscillatory), time constant 1/|lambda| s"
        with whether it decays or grows (zeta = +1 or -1 carries no more than that)."""
        if self.oscillatory:
            return f"period {self.period:7.2f} s  damping {self.zeta:.3f}"
        if self.neutral:
            return "real (non-oscillatory), neutral"
        trend = "decays" if self.eigenvalue.real < 0 else "GROWS"
        return f"real (non-oscillatory), {trend} with time constant {1.0 / self.wn:.3g} s"

    def row(self) -> dict:
        """Plain-number summary (for tables and JSON)."""
        return {"label": self.label, "eigenvalue_re": float(self.eigenvalue.real),
                "eigenvalue_im": float(self.eigenvalue.imag), "wn_rad_s": self.wn,
                "zeta": self.zeta, "period_s": self.natural_period(),
                "oscillatory": self.oscillatory,
                "stable": self.stable, "neutral": self.neutral,
                "energy": {k: round(v, 4) for k, v in self.energy.items()}}


# --- classification context ---------------------------------------------------------------------


@dataclass(frozen=True)
class ModeContext:
    """What classification needs to know about one subset's state vector.

    Attributes
    ----------
    subset : "long" or "lat". pos : indices of the position coordinates within the subset
    vector. weights : inertia of each position coordinate (kg or kg m^2). groups : group name ->
    indices into ``pos``. tether : indices into ``pos`` of the moving nodes' transverse
    coordinate, top (node 2) to bottom (node n). top : confluence-point transverse displacement
    as a linear map of the position part. transverse, axial : tether group names.
    """

    subset: str
    pos: np.ndarray
    weights: np.ndarray
    groups: dict
    tether: np.ndarray
    top: np.ndarray
    transverse: str
    axial: str | None


def _leash_jacobian(x_eq: np.ndarray, layout: StateLayout, leash: tuple) -> np.ndarray:
    """d(R(phi, theta, psi) r_l)/d(phi, theta, psi), 3x3: how attitude moves the confluence
    point relative to the CM (central differences of the rotation matrix, step 1e-6 rad)."""
    e0 = x_eq[layout.euler]
    J = np.empty((3, 3))
    for k in range(3):
        d = np.zeros(3)
        d[k] = 1e-6
        J[:, k] = (rotation_matrix(*(e0 + d)) - rotation_matrix(*(e0 - d))) @ np.array(leash) / 2e-6
    return J


def mode_context(params: Params, x_eq: np.ndarray, subset: str) -> ModeContext:
    """Build the :class:`ModeContext` of ``subset`` ("long" or "lat") at the trim ``x_eq``.

    Notes
    -----
    Kinetic-energy weights: tether node mu l_u per direction; aerostat CM m_e,x for inertial X
    (the hull axis is along X within the trim pitch), m_e,y for Y, m_e,z for Z; I_yy for theta,
    I_xx for phi, I_zz for psi.
    """
    lay = StateLayout(params.tether.n_elements)
    n, d, a = lay.n_elements, params.derived, params.aerostat
    m_node = d.mass_per_length * x_eq[lay.winch_length] / n
    J = _leash_jacobian(x_eq, lay, d.leash_position)
    tnodes = np.arange(n - 1)
    if subset == "long":
        # subset order: x (n), xdot (n), z (n), zdot (n), theta, q; aerostat CM last in each block
        pos = np.concatenate([np.arange(n), 2 * n + np.arange(n), [4 * n]])
        w = np.concatenate([np.full(n - 1, m_node), [d.effective_mass[0]],
                            np.full(n - 1, m_node), [d.effective_mass[2]], [a.Iyy]])
        groups = {"tether_x": tnodes, "aerostat_x": np.array([n - 1]),
                  "tether_z": n + tnodes, "aerostat_z": np.array([2 * n - 1]),
                  "pitch": np.array([2 * n])}
        top = np.zeros(pos.size)
        top[n - 1], top[2 * n] = 1.0, J[0, 1]
        return ModeContext("long", pos, w, groups, tnodes, top, "tether_x", "tether_z")
    if subset == "lat":
        # subset order: y (n), ydot (n), phi, p, psi, r
        pos = np.concatenate([np.arange(n), [2 * n, 2 * n + 2]])
        w = np.concatenate([np.full(n - 1, m_node), [d.effective_mass[1]], [a.Ixx, a.Izz]])
        groups = {"tether_y": tnodes, "aerostat_y": np.array([n - 1]),
                  "roll": np.array([n]), "yaw": np.array([n + 1])}
        top = np.zeros(pos.size)
        top[n - 1], top[n], top[n + 1] = 1.0, J[1, 0], J[1, 2]
        return ModeContext("lat", pos, w, groups, tnodes, top, "tether_y", None)
    raise ValueError(f"subset must be 'long' or 'lat', got {subset!r}")


def energy_vector(vector: np.ndarray, ctx: ModeContext) -> np.ndarray:
    """sqrt(m_i) v_i over the position coordinates: |.|^2 is each coordinate's share of the
    modal kinetic energy (up to the common factor |lambda|^2 / 2)."""
    return np.sqrt(ctx.weights) * vector[ctx.pos]


def _realify(v: np.ndarray) -> np.ndarray:
    """Rotate a complex vector by the phase that makes it as real as possible, return Re.

    Notes
    -----
    alpha = arg(sum v_k^2) / 2 maximises ||Re(v e^{-i alpha})||; for a standing-wave mode all
    components then share one phase and the sign pattern is the mode shape.
    """
    alpha = 0.5 * np.angle(np.sum(v * v))
    return np.real(v * np.exp(-1j * alpha))


def count_sign_changes(shape: np.ndarray, threshold: float = 0.1) -> int:
    """Sign changes along ``shape``, ignoring entries below ``threshold`` of its largest |entry|."""
    if shape.size == 0:  # a one-element tether has no moving node
        return 0
    big = shape[np.abs(shape) > threshold * np.max(np.abs(shape))]
    return int(np.sum(np.signbit(big[1:]) != np.signbit(big[:-1])))


def tether_share(energy: dict, ctx: ModeContext) -> float:
    """The tether nodes' share of a mode's kinetic energy (transverse and axial)."""
    return energy[ctx.transverse] + (energy[ctx.axial] if ctx.axial else 0.0)


def tether_name(axial: bool, k: int) -> str:
    """The label of the k-th tether mode: "tether axial k" or "tether k-th harmonic"."""
    return f"tether axial {k}" if axial else f"tether {ordinal(k)} harmonic"


def tether_label(real: np.ndarray, energy: dict, ctx: ModeContext) -> tuple[str, int]:
    """(label, k) of a mode read as a tether mode: the k-th harmonic has k - 1 sign changes
    along the moving nodes, counted on the axial coordinate when the tether's motion is mostly
    along it ("tether axial k"), on the transverse one otherwise ("tether k-th harmonic")."""
    axial = ctx.axial is not None and energy[ctx.axial] > energy[ctx.transverse]
    coord = ctx.groups[ctx.axial] if axial else ctx.tether
    k = count_sign_changes(real[coord]) + 1
    return tether_name(axial, k), k


def classify(vector: np.ndarray, ctx: ModeContext) -> tuple[str, dict, np.ndarray, int]:
    """Name a mode from its eigenvector.

    Returns
    -------
    label, energy shares per group, transverse tether shape (anchor, node n .. node 2,
    confluence point), sign changes along the moving nodes.

    Notes
    -----
    Rules (after [LN02]'s descriptions of its eigenvectors):

    * tether nodes hold most of the kinetic energy -> a tether mode; the k-th harmonic has k - 1
      sign changes along the nodes ("tether axial k" if the longitudinal motion is mostly z);
    * otherwise the aerostat's largest share names it: longitudinal x -> pendulum, z -> axial
      spring, theta -> pitching; lateral y -> pendulum, phi -> rolling, psi -> yaw.
    """
    v = vector[ctx.pos]
    e = ctx.weights * np.abs(v) ** 2
    total = float(np.sum(e)) or 1.0
    energy = {g: float(np.sum(e[idx])) / total for g, idx in ctx.groups.items()}
    real = _realify(v)
    shape = np.concatenate([[0.0], real[ctx.tether][::-1], [real @ ctx.top]])
    if tether_share(energy, ctx) > 0.5:
        label, k = tether_label(real, energy, ctx)
        return label, energy, shape, k - 1
    names = ({"aerostat_x": "pendulum", "aerostat_z": "axial spring", "pitch": "pitching"}
             if ctx.subset == "long" else
             {"aerostat_y": "pendulum", "roll": "rolling", "yaw": "yaw"})
    label = names[max(names, key=lambda g: energy[g])]
    return label, energy, shape, count_sign_changes(real[ctx.tether])


# --- modal tables --------------------------------------------------------------------------------


def damp_quantities(lam: complex) -> tuple[float, float, float]:
    """(wn, zeta, period) of one eigenvalue, as ``control.damp``.

    Notes
    -----
    omega_n = |lambda|, zeta = -Re(lambda) / omega_n, tau_n = 2 pi / omega_n ([LN02]:
    omega_n = sqrt(sigma^2 + omega_d^2), zeta = sin(atan(-sigma / omega_d))).
    """
    wn = float(abs(lam))
    if wn == 0.0:
        return 0.0, 1.0, math.inf
    return wn, float(-lam.real / wn), 2.0 * math.pi / wn


def modal_table(A_sub: np.ndarray, ctx: ModeContext) -> list[Mode]:
    """Eigen-decompose one subset and classify its modes; sorted by natural frequency.

    One :class:`Mode` per complex-conjugate pair (the member with Im > 0) and per real
    eigenvalue, so an n-state subset has n / 2 modes when all are oscillatory; [LN02] counts
    3 n + 3 modes for the 6 n + 6 states, real eigenvalues counted in pairs.
    """
    modes = modes_from_eig(*np.linalg.eig(A_sub), ctx)
    resolve_duplicates(modes, ctx)
    return modes


def modes_from_eig(lam: np.ndarray, V: np.ndarray, ctx: ModeContext) -> list[Mode]:
    """Classified :class:`Mode` objects of eigenvalues ``lam`` and eigenvectors ``V`` (columns,
    first entries in the subset order of ``ctx``), one per conjugate pair, sorted by |lambda|."""
    scale = max(float(np.max(np.abs(lam))), 1.0)
    modes = []
    for k in np.argsort(np.abs(lam), kind="stable"):
        ev = complex(lam[k])
        if ev.imag < -1e-12 * scale:
            continue  # the conjugate partner carries the same mode
        ev = complex(ev.real, max(ev.imag, 0.0)) if abs(ev.imag) <= 1e-12 * scale else ev
        wn, zeta, period = damp_quantities(ev)
        neutral = wn < NEUTRAL_RATE
        label, energy, shape, sc = classify(V[:, k], ctx)
        modes.append(Mode(ev, V[:, k].copy(), wn, zeta, period, ev.imag > 0,
                          ev.real < 0 or neutral, neutral, label, energy, shape, sc))
    return modes


#: The aerostat's own modes in each set and the energy group that names each.
AEROSTAT_MODES = {
    "long": {"pendulum": "aerostat_x", "axial spring": "aerostat_z", "pitching": "pitch"},
    "lat": {"pendulum": "aerostat_y", "rolling": "roll", "yaw": "yaw"},
}


#: A mode that loses a repeated aerostat label is renamed as a tether mode only if the tether
#: carries at least this share of its kinetic energy (else the repeat is kept, as no name fits).
TETHER_SHARE_TO_RENAME = 0.2


def resolve_duplicates(modes: list[Mode], ctx: ModeContext) -> None:
    """Make each aerostat mode's label unique within a set (in place).

    Notes
    -----
    Each of the aerostat's modes exists once per set, but near a frequency crossing the
    aerostat's and the tether's modes mix, so that two modes have the same largest aerostat
    share. Two passes:

    * a missing aerostat label goes to the duplicate-labelled mode that carries most of its
      group (in wind the lateral yaw mode sways the aerostat with the tether, so its largest
      share is y like the pendulum's; at zero wind rolling and the first lateral tether harmonic
      share energy about equally);
    * an aerostat label still held by several oscillatory modes stays with the one that carries
      most of its group; the others are the tether modes they mix with (e.g. the TCOM 32M at
      6-9 m/s: pitching and the first tether harmonic, both 40-50 % pitch, 40-50 % tether), and
      are named by their tether shape when the tether carries at least
      :data:`TETHER_SHARE_TO_RENAME` of their energy and that tether label is free.

    Two real eigenvalues with one label (zero-wind yaw) are one mode and keep it.
    """
    for label, group in AEROSTAT_MODES[ctx.subset].items():
        labels = [m.label for m in modes]
        if label in labels:
            continue
        dup = [m for m in modes if labels.count(m.label) > 1 and m.energy[group] > 0.05]
        if dup:
            max(dup, key=lambda m: m.energy[group]).label = label
    for label, group in AEROSTAT_MODES[ctx.subset].items():
        held = [m for m in modes if m.label == label and m.oscillatory]
        if len(held) < 2:
            continue
        keeper = max(held, key=lambda m: m.energy[group])
        for m in held:
            if m is keeper or tether_share(m.energy, ctx) < TETHER_SHARE_TO_RENAME:
                continue
            name, k = tether_label(_realify(m.vector[ctx.pos]), m.energy, ctx)
            if all(other.label != name for other in modes):
                m.label, m.sign_changes = name, k - 1
    _fill_harmonic_gaps(modes)


_HARMONIC = re.compile(r"tether (?:(\d+)(?:st|nd|rd|th) harmonic|axial (\d+))$")


def _harmonic(label: str) -> tuple[str, int] | None:
    """(family, number) of a tether label ("transverse" or "axial"), None for another label."""
    m = _HARMONIC.match(label)
    if m is None:
        return None
    return ("transverse", int(m[1])) if m[1] else ("axial", int(m[2]))


def _fill_harmonic_gaps(modes: list[Mode]) -> None:
    """Give a repeated tether harmonic's number to a missing neighbour (in place).

    Where the aerostat pitches with the first tether harmonic, the tether's shape under the
    confluence point can change sign once more, and the mode counts as the second harmonic
    beside the true one (3.5 x the baseline on 556 m: 3.10 s and 1.68 s, the closed form's
    first harmonic 3.38 s). Of two oscillatory modes with one number, the longer-period one
    takes the nearest missing lower number, or else the shorter-period one the nearest missing
    higher number (a harmonic's number grows as its period shrinks).
    """
    osc = [m for m in modes if m.oscillatory and _harmonic(m.label)]
    for family in ("transverse", "axial"):
        fam = [m for m in osc if _harmonic(m.label)[0] == family]
        for _ in range(len(fam)):
            numbers = [_harmonic(m.label)[1] for m in fam]
            repeated = sorted({k for k in numbers if numbers.count(k) > 1})
            if not repeated:
                break
            k = repeated[0]
            held = sorted((m for m in fam if _harmonic(m.label)[1] == k), key=lambda m: m.wn)
            lower = [j for j in range(1, k) if j not in numbers]
            higher = [j for j in range(k + 1, max(numbers) + 2) if j not in numbers]
            m, j = (held[0], lower[-1]) if lower else (held[-1], higher[0])
            m.label, m.sign_changes = tether_name(family == "axial", j), j - 1


def count_modes(modes: list[Mode]) -> float:
    """Modes counted as in [LN02]: a complex pair is one mode, two real eigenvalues are one."""
    return sum(1.0 if m.oscillatory else 0.5 for m in modes)


@dataclass
class ModalAnalysis:
    """Linearization, decoupling and both modal tables at one trim."""

    wind_speed: float
    linear: LinearModel
    decoupled: Decoupled
    long: list[Mode]
    lat: list[Mode]

    def all_stable(self) -> bool:
        return all(m.stable for m in self.long + self.lat)

    def find(self, subset: str, label: str) -> Mode | None:
        """Lowest-frequency mode of ``subset`` with this label (the one a sweep's plain track
        holds at this speed, :func:`_lowest_into_plain_lane`)."""
        return next((m for m in getattr(self, subset) if m.label == label), None)


def analyse(params: Params, equilibrium: Equilibrium, eps: float = 1e-5) -> ModalAnalysis:
    """Linearize about ``equilibrium``, decouple, and build both modal tables."""
    lin = linearize(params, equilibrium, eps)
    dec = decouple(lin.A, lin.layout)
    long = modal_table(dec.A_long, mode_context(params, equilibrium.x, "long"))
    lat = modal_table(dec.A_lat, mode_context(params, equilibrium.x, "lat"))
    return ModalAnalysis(equilibrium.wind_speed, lin, dec, long, lat)


# --- MAC tracking --------------------------------------------------------------------------------


def mac(a: np.ndarray, b: np.ndarray) -> float:
    """Modal assurance criterion |a^H b|^2 / ((a^H a)(b^H b)), in [0, 1]."""
    return float(abs(np.vdot(a, b)) ** 2 / (np.vdot(a, a).real * np.vdot(b, b).real))


# --- sweeps --------------------------------------------------------------------------------------


@dataclass
class Sweep:
    """Modal analyses along a parameter (wind speed by default), with tracked modes.

    Attributes
    ----------
    values : swept values. variable : its name. analyses : one :class:`ModalAnalysis` per value.
    tracks : per set, list of (label, [Mode or None per value]). seconds : wall time.
    stop_error : the :class:`TrimError` of the first value with no trim, where a sweep with
    ``stop_without_trim`` ended there (else None).
    """

    values: np.ndarray
    variable: str
    analyses: list
    tracks: dict
    seconds: float
    stop_error: Exception | None = None

    def curve(self, subset: str, label: str, quantity: str = "period",
              oscillatory_only: bool = False) -> np.ndarray:
        """``period``, ``zeta`` or ``wn`` of the tracked mode ``label`` at every value (nan where
        absent, or where the mode is a real eigenvalue and ``oscillatory_only``)."""
        t = next((m for lab, m in self.tracks[subset] if lab == label), None)
        if t is None:
            return np.full(len(self.values), np.nan)
        keep = [m is not None and (m.oscillatory or not oscillatory_only) for m in t]
        return np.array([getattr(m, quantity) if k else np.nan for m, k in zip(t, keep, strict=True)])

    def all_stable(self) -> bool:
        return all(a.all_stable() for a in self.analyses)

    def unstable(self) -> list[dict]:
        """The tracked modes that are unstable at one or more swept values, whether or not a
        table shows their track: per track its set, label, the values where it is unstable
        and, at the one where it grows fastest (largest Re(lambda)), that mode. Empty exactly
        when :meth:`all_stable` (every mode of every analysis lies on one track)."""
        out = []
        for subset in SETS:
            for label, track in self.tracks[subset]:
                bad = [(float(v), m) for v, m in zip(self.values, track, strict=True)
                       if m is not None and not m.stable]
                if bad:
                    value, worst = max(bad, key=lambda item: item[1].eigenvalue.real)
                    out.append({"set": subset, "label": label, "values": [v for v, _ in bad],
                                "worst_value": value, "worst": worst})
        return out

    def rows(self) -> list[dict]:
        """One row per (value, set, tracked mode): label, period, damping, stability."""
        out = []
        for subset in SETS:
            for label, t in self.tracks[subset]:
                for v, m in zip(self.values, t, strict=True):
                    if m is not None:
                        out.append({self.variable: float(v), "set": subset, **m.row(),
                                    "label": label})
        return out


def _lanes_of_label(tables: list[list[Mode]], ctx_list: list[ModeContext], label: str,
                    freq_weight: float = 0.5) -> list[list[Mode | None]]:
    """The modes classified ``label`` at each sweep point, in lanes (one per mode when several
    share the label), continued from point to point by MAC and frequency (Hungarian method,
    cost 1 - MAC + w |ln(omega_a / omega_b)| on the energy-weighted position vectors)."""
    lanes: list[list[Mode | None]] = []
    vecs: list[np.ndarray] = []
    for step, (table, ctx) in enumerate(zip(tables, ctx_list, strict=True)):
        cur = sorted((m for m in table if m.label == label), key=lambda m: m.wn)
        cv = [energy_vector(m.vector, ctx) for m in cur]
        assigned = {}
        if lanes and cur:
            last = [next(m for m in reversed(lane) if m is not None) for lane in lanes]
            cost = np.array([[1.0 - mac(vecs[i], cv[j]) + freq_weight * abs(
                math.log(max(cur[j].wn, 1e-9) / max(last[i].wn, 1e-9)))
                for j in range(len(cur))] for i in range(len(lanes))])
            rows, cols = linear_sum_assignment(cost)
            assigned = {int(j): int(i) for i, j in zip(rows, cols, strict=True)}
        for lane in lanes:
            lane.append(None)
        for j, m in enumerate(cur):
            if j in assigned:
                lanes[assigned[j]][step] = m
                vecs[assigned[j]] = cv[j]
            else:
                lanes.append([None] * step + [m])
                vecs.append(cv[j])
    return lanes


def _mean_wn(lane: list[Mode | None]) -> float:
    """Mean natural frequency of the modes a lane holds [rad/s]."""
    return float(np.mean([m.wn for m in lane if m is not None]))


def _rank_lanes(lanes: list[list[Mode | None]]) -> list[list[Mode | None]]:
    """The non-empty lanes, the most present first (ties: the lower mean frequency first)."""
    held = [lane for lane in lanes if any(m is not None for m in lane)]
    return sorted(held, key=lambda lane: (-sum(m is not None for m in lane), _mean_wn(lane)))


def _slower(a: Mode, b: Mode) -> bool:
    """Whether mode ``a`` has the lower natural frequency; two neutral modes (the split double
    zero of the free yaw at zero wind, whose sizes and signs are rounding) are a tie."""
    return a.wn < b.wn and not (a.neutral and b.neutral)


def _lowest_into_plain_lane(lanes: list[list[Mode | None]]) -> list[list[Mode | None]]:
    """Put, at every point, the label's lowest-frequency mode in the plain lane (``lanes[0]``),
    the mode :meth:`ModalAnalysis.find` returns there (Table 2's); the numbered lanes re-ranked.

    Notes
    -----
    MAC continuity alone can leave the plain lane empty where the label's mode exists, or hold
    another of its modes there. In wind, a long light tether's drag makes the aerostat creep
    back without swinging: a family of overdamped "pendulum" roots beside the swinging mode.
    Continuity may carry the still-air swing into one of those branches, and they can be the
    most present lanes, so the still-air pendulum lost the plain name to a lane that starts at
    the first windy speed (a 0.004x aerostat on 1906 m: "pendulum (3)" on a 0-30 m/s grid, the
    plain one on 0-5 m/s), and the stability table showed nothing at 0 m/s. The rule reads one
    point alone, so the plain track never depends on the grid and names the mode Table 2 reads.
    The displaced mode (or gap) takes the moved mode's place in its lane, so every mode stays
    on one track.
    """
    plain, others = lanes[0], lanes[1:]
    for step, mode in enumerate(plain):
        held = [lane for lane in others if lane[step] is not None]
        if not held:
            continue
        donor = min(held, key=lambda lane: lane[step].wn)
        if mode is None or _slower(donor[step], mode):
            plain[step], donor[step] = donor[step], mode
    return [plain] + _rank_lanes(others)


def _ranked_lanes_of_label(tables: list[list[Mode]], ctx_list: list[ModeContext],
                           label: str) -> list[list[Mode | None]]:
    """The lanes of ``label`` (:func:`_lanes_of_label`), the plain one first.

    Notes
    -----
    The most present lane is the plain one, and for the aerostat's own labels it holds the
    label's lowest-frequency mode at each point (:func:`_lowest_into_plain_lane`). Tether
    labels keep MAC continuity's lanes: they are read from sign changes along the tether,
    which a high harmonic can fool (3600 m^3 on 1000 m at 20 m/s: a 0.42 s, 100 % tether mode
    counts as the first harmonic, whose own track turns into a real eigenvalue there as its
    damping passes 1).
    """
    lanes = _rank_lanes(_lanes_of_label(tables, ctx_list, label))
    if label in AEROSTAT_MODES[ctx_list[0].subset]:
        return _lowest_into_plain_lane(lanes)
    return lanes


def label_tracks(tables: list[list[Mode]], ctx_list: list[ModeContext]
                 ) -> list[tuple[str, list]]:
    """Tracks of a sweep, labelled by eigenvector shape at every point.

    Notes
    -----
    Each point's modes are classified on their own (:func:`classify` and
    :func:`resolve_duplicates`, exactly as a single-speed analysis labels them), so the label of
    a mode at a speed never depends on the other speeds of the grid. A track is the sequence of
    the modes carrying one label; where several modes share a label at a point, MAC continuity
    sorts them into lanes, the most present keeping the plain label and the others getting
    (2), (3), except that for an aerostat label (pendulum, pitching, ...) the plain track holds
    the label's lowest-frequency mode at every point, Table 2's (:func:`_ranked_lanes_of_label`):
    a still-air swing never drops to a numbered track behind overdamped branches of its label,
    whatever the grid. Tracks are returned in order of mean natural frequency.
    """
    out = []
    for label in dict.fromkeys(m.label for table in tables for m in table):
        lanes = _ranked_lanes_of_label(tables, ctx_list, label)
        out += [(label if k == 0 else f"{label} ({k + 1})", lane) for k, lane in enumerate(lanes)]
    return sorted(out, key=lambda item: _mean_wn(item[1]))


def sweep_analyses(analyses: list[ModalAnalysis], params_list: list[Params], values,
                   variable: str, seconds: float) -> Sweep:
    """Track the modes of a list of analyses (one per swept value) into a :class:`Sweep`."""
    tracks = {}
    for subset in SETS:
        ctxs = [mode_context(p, a.linear.x_eq, subset) for p, a in zip(params_list, analyses, strict=True)]
        tables = [getattr(a, subset) for a in analyses]
        tracks[subset] = label_tracks(tables, ctxs)
    return Sweep(np.asarray(values, float), variable, analyses, tracks, seconds)


def wind_sweep(params: Params | None = None, speeds=None, eps: float = 1e-5,
               stop_without_trim: bool = False) -> Sweep:
    """Trim, linearize and analyse at every wind speed (continuation from the previous trim).

    Parameters
    ----------
    params : parameters (default baseline). speeds : wind speeds [m/s] (default 0:20:0.5, the
    41 speeds of [LN02] Figure 9), increasing. eps : finite-difference step.
    stop_without_trim : end the sweep at the first speed with no trim (a small aerostat blown
    down past what its tether holds) instead of raising :class:`TrimError`; the sweep then
    holds the speeds below it (none trimmed: the error is raised).
    """
    params = params or load_params()
    speeds = np.arange(0.0, 20.0 + 1e-9, 0.5) if speeds is None else np.asarray(speeds, float)
    t0 = time.perf_counter()
    analyses, eq, stop_error = [], None, None
    for u in speeds:
        try:
            eq = find_equilibrium(params, float(u), guess=eq)
        except TrimError as exc:
            if not (stop_without_trim and analyses):
                raise
            stop_error = exc
            break
        analyses.append(analyse(params, eq, eps))
    sweep = sweep_analyses(analyses, [params] * len(analyses), speeds[: len(analyses)],
                           "wind_speed_m_s", time.perf_counter() - t0)
    sweep.stop_error = stop_error
    return sweep

