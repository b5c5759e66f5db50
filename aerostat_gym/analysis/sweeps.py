"""Sweeps of the modal analysis along a parameter: wind speed (Figure 9 of [LN02]), tether
length, trim pitch; the modes tracked from one value to the next into labelled lanes (by label,
frequency rank and the MAC of :mod:`aerostat_gym.analysis.modes`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from ..params import Params, load_params
from .modes import (
    AEROSTAT_MODES,
    SETS,
    ModalAnalysis,
    Mode,
    ModeContext,
    analyse,
    energy_vector,
    mac,
    mode_context,
)
from .trim import TrimError, find_equilibrium


@dataclass
class Sweep:
    """Modal analyses along a parameter (wind speed by default), with tracked modes.

    Attributes
    ----------
    values : swept values. variable : its name. analyses : one :class:`ModalAnalysis` per value.
    tracks : per set, list of (label, [Mode or None per value]). seconds : wall time.
    """

    values: np.ndarray
    variable: str
    analyses: list
    tracks: dict
    seconds: float

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
    analyses, eq = [], None
    for u in speeds:
        try:
            eq = find_equilibrium(params, float(u), guess=eq)
        except TrimError:
            if not (stop_without_trim and analyses):
                raise
            break
        analyses.append(analyse(params, eq, eps))
    return sweep_analyses(analyses, [params] * len(analyses), speeds[: len(analyses)],
                          "wind_speed_m_s", time.perf_counter() - t0)

