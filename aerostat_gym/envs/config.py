"""The task's configuration: the environment's constructor arguments, validated once
(:class:`TaskConfig`), with the perturbation presets and the domain-randomisation ranges.
The episode start built from it is :mod:`aerostat_gym.envs.episodes`.
"""

from __future__ import annotations

import difflib
import math
import sys
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field, fields

import numpy as np

from ..checks import is_finite_number, is_number, is_whole
from ..params import (
    MAX_WIND_SPEED,
    SECTIONS,
    InertiaError,
    ParameterError,
    ParameterWarning,
    Params,
    apply_overrides,
    as_params,
    check_inertia,
    check_plausibility,
    parameter_key,
    params_to_dict,
    turbulence_height_warnings,
)
from ..sim import INTEGRATORS
from ..wind.presets import INTENSITY_CLASSES
from ..wind.sizing import sized_turbulence
from . import reward
from .spaces import check_obs_noise, displacement_scale

#: Perturbation presets: maximum along-wind swing and lateral displacement of the aerostat [m]
#: (a rigid rotation of aerostat and tether about the winch), pitch kick about the confluence
#: point [rad], and a 1 - cos gust along the wind drawn with this probability. Amplitudes are
#: drawn uniformly in [-max, max]; with "fixed": True they are applied as given (signed).
#: A preset's displacements are stated for a tether of
#: :data:`~aerostat_gym.envs.spaces.REFERENCE_TETHER_LENGTH` and
#: scale with the configured tether (:func:`displacement_scale`); a dict is taken in metres.
PERTURBATIONS = {
    "none": {"swing": 0.0, "lateral": 0.0, "pitch": 0.0, "gust_probability": 0.0,
             "fixed": False},
    "displacement": {"swing": 10.0, "lateral": 5.0, "pitch": 0.05, "gust_probability": 0.0},
    "gust": {"swing": 0.0, "lateral": 0.0, "pitch": 0.0, "gust_probability": 1.0},
    "mixed": {"swing": 10.0, "lateral": 5.0, "pitch": 0.05, "gust_probability": 0.5},
}
GUST_DEFAULTS = {"gust_amplitude": (1.0, 4.0), "gust_duration": (5.0, 20.0),
                 "gust_onset": (0.0, 30.0)}
#: Estimated parameters randomised by ``randomize=True`` (relative half-ranges).
DEFAULT_RANDOMIZATION = {
    "aerostat.Ixx": 0.3, "aerostat.Iyy": 0.3, "aerostat.Izz": 0.3, "hull.Cdc": 0.2,
    "hull.eta_k": 0.2, "fins.CL_alpha": 0.2, "tether.Cd_normal": 0.2, "aerostat.mass": 0.03,
}


#: Default range of the episode's mean wind speed [m/s].
DEFAULT_WIND_RANGE = (3.0, 15.0)


class TaskError(ValueError):
    """An invalid environment argument (the message names it and the value)."""


def check_range(name, value, lo_min=0.0, hi_max=math.inf):
    """A (low, high) range in [lo_min, hi_max]; a single number is the fixed value (value,
    value)."""
    if isinstance(value, np.ndarray) and value.ndim == 0:  # np.array(10.0): the number it holds
        value = value.item()
    pair = (value, value) if is_number(value) else value
    if not (isinstance(pair, (tuple, list, np.ndarray)) and len(pair) == 2
            and all(is_number(v) for v in pair)):  # "12" is no pair; True is no number
        raise TaskError(f"{name} must be a number or a (low, high) pair, got {value!r}")
    lo, hi = (float(v) for v in pair)
    if not (math.isfinite(lo) and math.isfinite(hi) and lo_min <= lo <= hi <= hi_max):
        top = "" if hi_max == math.inf else f" <= {hi_max:g}"
        raise TaskError(f"{name} must satisfy {lo_min} <= low <= high{top} (finite), got "
                        f"{value!r}")
    return lo, hi


#: [s] the shortest control step: a millisecond is shorter than any integration step the
#: model takes on a real aerostat (5e-324 s overflowed the step count)
MIN_CONTROL_STEP = 1e-3


def check_control_step(value) -> float:
    """The control step [s]: a finite number in (0, 1] (a reel command held longer than 1 s
    cannot act on the pitch and axial-spring modes, ~3 s on the baseline)."""
    if not (is_finite_number(value) and MIN_CONTROL_STEP <= value <= 1.0):
        raise TaskError(f"control_step must be a number in [{MIN_CONTROL_STEP:g}, 1] s (a reel "
                        f"command held longer cannot act on the pitch and axial modes, ~3 s on "
                        f"the baseline), got {value!r}")
    return float(value)


@dataclass(frozen=True)
class TaskConfig:
    """Validated environment arguments (see :class:`aerostat_gym.envs.TetheredAerostatEnv`)."""

    wind_speed: tuple = DEFAULT_WIND_RANGE
    turbulence: object = "moderate"
    turbulence_mix: dict | None = None
    perturbation: object = "mixed"
    tether_length: float | None = None
    n_elements: int | None = None
    integrator: str = "semi-implicit"
    control_step: float = 0.2
    params: object = None
    overrides: dict | None = None
    randomize: object = None
    weathercock: bool = False
    obs_noise: float = 0.0
    reward_weights: dict | None = None
    reward_fn: object = None
    observation: str = "standard"
    wind_bank_size: int = 8
    wind_bank_seed: int = 0
    resolved: dict = field(default_factory=dict, compare=False, repr=False)

    @classmethod
    def from_kwargs(cls, **kwargs) -> TaskConfig:
        """The task from the environment's keyword arguments; a misspelt or unknown argument is
        a :class:`TaskError` that names it, the nearest accepted name and every accepted one."""
        accepted = [f.name for f in fields(cls) if f.name != "resolved"]
        unknown = [k for k in kwargs if k not in accepted]
        if unknown:
            hints = [f"{k!r} (did you mean {close[0]!r}?)" if close else repr(k)
                     for k in unknown for close in [difflib.get_close_matches(k, accepted, 1)]]
            raise TaskError(f"unknown environment argument(s) {', '.join(hints)}; the task "
                            f"accepts {', '.join(accepted)}")
        return cls(**kwargs)

    def __post_init__(self):
        r = self.resolved
        r["wind_speed"] = check_range("wind_speed", self.wind_speed, hi_max=MAX_WIND_SPEED)
        # named at the door, before the parameters load (the gust against the top mean wind too)
        perturbation(self.perturbation, top_speed=r["wind_speed"][1])
        if self.integrator not in INTEGRATORS:
            raise TaskError(f"unknown integrator {self.integrator!r}; choose one of {INTEGRATORS}")
        check_control_step(self.control_step)
        if self.observation not in ("standard", "full"):
            raise TaskError(f"unknown observation {self.observation!r}; choose 'standard' or "
                            "'full'")
        check_obs_noise(self.obs_noise, TaskError)
        try:
            r["weights"] = reward.weights_vector(self.reward_weights)
            reward.check_reward_fn(self.reward_fn)
        except ValueError as exc:
            raise TaskError(str(exc)) from None
        if not is_whole(self.wind_bank_size):
            raise TaskError(f"wind_bank_size must be an integer >= 1, got {self.wind_bank_size!r}")
        if not is_whole(self.wind_bank_seed, 0):  # the bank is part of the task: never drawn afresh
            raise TaskError(f"wind_bank_seed must be an integer >= 0, got {self.wind_bank_seed!r}")
        r["params"] = self._params()
        r["perturbation"] = perturbation(self.perturbation, r["params"].tether.length)
        try:  # the field's heights and extent follow the configured aerostat, tether and winch
            r["turbulence"] = sized_turbulence(r["params"], self.turbulence)
        except (TypeError, ValueError) as exc:
            raise TaskError(f"turbulence: {exc}") from None
        r["turbulence_mix"] = turbulence_mix(self.turbulence_mix, r["turbulence"],
                                             self.turbulence)
        r["randomize"] = self._randomize(r["params"])
        if not isinstance(self.weathercock, (bool, np.bool_)):
            raise TaskError(f"weathercock must be True or False (redraw randomised aerostats "
                            f"that do not weathervane), got {self.weathercock!r}")

    def _params(self) -> Params:
        p = as_params(self.params, TaskError)
        if self.overrides is not None and not isinstance(self.overrides, Mapping):
            raise TaskError("overrides must map dotted parameter names to values, e.g. "
                            f"{{'tether.length': 300.0}}; got {self.overrides!r}")
        over = dict(self.overrides or {})
        if self.tether_length is not None:
            over["tether.length"] = self.tether_length
        if self.n_elements is not None:
            over["tether.n_elements"] = self.n_elements
        moved = apply_overrides(p, over) if over else p
        # the env is a door like the loader: overrides and a Params built by replace() meet the
        # same plausibility bounds as a parameter file
        check_plausibility(moved)
        calm = self.turbulence in (None, "none") and not self.turbulence_mix
        if not calm and not turbulence_height_warnings(p):  # a file's own was warned at load
            for text in turbulence_height_warnings(moved):
                warnings.warn(f"the environment's tether length: {text}", ParameterWarning,
                              stacklevel=_user_stacklevel())
        return moved

    def _randomize(self, params: Params) -> dict:
        if self.randomize is None or self.randomize is False:
            return {}
        spec = DEFAULT_RANDOMIZATION if self.randomize is True else self.randomize
        if not isinstance(spec, dict):
            raise TaskError(f"randomize must be None, True or a dict, got {self.randomize!r}")
        for key, rel in spec.items():
            if not (is_number(rel) and 0 <= rel < 1):
                raise TaskError(f"randomize[{key!r}] must be a relative half-range in [0, 1), "
                                f"got {rel!r}")
            _check_range_ends(params, key, rel)
        _check_inertia_draws(params, spec)
        return dict(spec)

    @property
    def params_resolved(self) -> Params:
        return self.resolved["params"]


def _user_stacklevel() -> int:
    """The ``stacklevel`` that makes a warning raised by this function's caller point at the
    user's line: the first frame whose module is outside this package and gymnasium
    (``gym.make``, the environment's constructor and the dataclass's generated ``__init__``
    sit between)."""
    frame, level = sys._getframe(2), 2
    while frame is not None and frame.f_globals.get("__name__", "").split(".")[0] in (
            "aerostat_gym", "gymnasium"):
        frame, level = frame.f_back, level + 1
    return level


def turbulence_mix(spec, turb, given) -> tuple[tuple[str, ...], np.ndarray] | None:
    """A per-episode draw of the intensity class, validated (``turb`` the resolved turbulence,
    ``given`` the ``turbulence`` argument): ``{class: weight}`` over the
    classes of :data:`aerostat_gym.wind.presets.INTENSITY_CLASSES` (weights finite, >= 0, summing
    to more than 0; returned as probabilities), or None for the task's one class.

    Every episode then reads the shared bank (unit-variance fields with the configured class's
    length scales) at the drawn class's sigmas: exact, since the classes of a wind-scaled model
    differ in sigma alone. So the task's ``turbulence`` must be a wind-scaled class other than
    "none" (the bank's spectral shape), e.g. ``turbulence="light", turbulence_mix={"none": 0.5,
    "light": 0.25, "moderate": 0.25}``.
    """
    if spec is None:
        return None
    if not isinstance(spec, dict) or not spec:
        raise TaskError(f"turbulence_mix must be a non-empty dict {{class: weight}}, got {spec!r}")
    unknown = sorted(str(k) for k in set(spec) - set(INTENSITY_CLASSES))
    if unknown:
        raise TaskError(f"turbulence_mix: unknown intensity class(es) {unknown}; choose from "
                        f"{list(INTENSITY_CLASSES)}")
    for k, w in spec.items():
        if not (is_finite_number(w) and w >= 0):
            raise TaskError(f"turbulence_mix[{k!r}] must be a finite weight >= 0, got {w!r}")
    total = float(sum(spec.values()))
    if total <= 0:
        raise TaskError(f"turbulence_mix weights must not all be zero, got {spec!r}")
    if turb.is_off or not turb.wind_scaled:
        raise TaskError("turbulence_mix needs turbulence to be a wind-scaled class other than "
                        f"'none' (the fields' spectral shape), got turbulence={given!r}")
    classes = tuple(spec)
    return classes, np.array([spec[k] / total for k in classes])


def _check_range_ends(params: Params, key: str, rel: float) -> None:
    """Both ends of a randomisation range must load and be plausible: a range whose end is
    infeasible (no net lift, a tether length outside the winch's limits, ...) or past the
    loader's plausibility bounds (an RK4 safety factor beyond its measured stability edge) is
    refused when the env is made.
    The inertia constraints are joint (an Iyy that is too large with the nominal Izz is a body
    with a larger Izz): :func:`_check_inertia_draws` checks them over the drawn combinations."""
    value = get_parameter(params, key)
    if not is_number(value):
        raise TaskError(f"randomize[{key!r}] must name a scalar number parameter, got {value!r}")
    for end in (1.0 - rel, 1.0 + rel):
        try:
            check_plausibility(apply_overrides(params, {key: value * end}))
        except InertiaError:
            pass
        except ParameterError as exc:
            raise TaskError(f"randomize[{key!r}] = {rel!r} reaches {key} = {value * end:.6g}, "
                            f"which the loader refuses: {exc}") from None


#: the inertia components a randomisation may draw, in :func:`check_inertia`'s order
INERTIA_KEYS = ("aerostat.Ixx", "aerostat.Iyy", "aerostat.Izz", "aerostat.Ixz")
#: a randomisation whose inertia draws are bodies less often than this is refused when made
MIN_INERTIA_ACCEPTANCE = 0.05
#: draws of the fixed-seed estimate of that share
INERTIA_ACCEPTANCE_DRAWS = 2000


def inertia_acceptance(params: Params, spec: Mapping[str, float]) -> tuple[float, str]:
    """Share of the randomisation's independent inertia draws that a body can have (the
    triangle inequalities and a definite tensor, :func:`check_inertia`), estimated from
    :data:`INERTIA_ACCEPTANCE_DRAWS` draws of a fixed generator, with the first refusal's
    message ("" if none). An episode start redraws the others."""
    nominal = np.array([get_parameter(params, k) for k in INERTIA_KEYS])
    rel = np.array([spec.get(k, 0.0) for k in INERTIA_KEYS])
    u = np.random.default_rng(0).uniform(-1.0, 1.0, (INERTIA_ACCEPTANCE_DRAWS, len(INERTIA_KEYS)))
    ok, first = 0, ""
    for row in nominal * (1.0 + rel * u):
        try:
            check_inertia(*row)
            ok += 1
        except InertiaError as exc:
            first = first or str(exc)
    return ok / INERTIA_ACCEPTANCE_DRAWS, first


def _check_inertia_draws(params: Params, spec: Mapping[str, float]) -> None:
    drawn = [k for k in INERTIA_KEYS if spec.get(k)]
    if not drawn:
        return
    share, first = inertia_acceptance(params, spec)
    if share < MIN_INERTIA_ACCEPTANCE:
        raise TaskError(
            f"randomize draws {', '.join(drawn)} independently and only {100 * share:.1f} % of "
            f"those draws are moments of inertia a body can have (e.g. {first}); narrow their "
            f"ranges (at least {100 * MIN_INERTIA_ACCEPTANCE:.0f} % must be)")


def get_parameter(params: Params, key: str):
    """The value of ``section.key`` in a parameter set (TaskError naming an unknown key)."""
    sec, _, name = key.partition(".")
    if sec not in SECTIONS or not hasattr(getattr(params, sec), name):
        try:  # called per reset: the full dictionary only to name the nearest key
            parameter_key(params_to_dict(params), key)
        except ParameterError as exc:
            raise TaskError(f"randomize: {exc}") from None
    return getattr(getattr(params, sec), name)


#: [rad] largest pitch kick: the Z-Y-X Euler kinematics of the state are singular with the
#: nose vertical (theta = +-pi/2), so a larger kick is a flip through the vertical, not a pitch
MAX_PITCH_KICK = math.pi / 2
#: [s] longest gust: a 1 - cos change slower than an hour is a change of the mean wind (whose
#: averaging periods run from 10 min to 1 h), not a gust
MAX_GUST_DURATION = 3600.0
#: [s] latest gust onset: a day is beyond any episode (the registered ones last 120 s); the bound
#: keeps the gust front's start position U_a * onset finite
MAX_GUST_ONSET = 86400.0


def perturbation(spec, tether_length: float | None = None,
                 top_speed: float | None = None) -> dict:
    """A validated perturbation dict from a preset name or a (partial) dict. A preset's swing
    and lateral displacement are scaled to a tether of ``tether_length`` [m]
    (:func:`displacement_scale`; None: as stated, for the reference tether); a dict's are
    taken as given, in metres. Every field is bounded (:func:`_check_displacements`,
    :func:`_check_gust`; with ``top_speed`` [m/s], the task's highest mean wind, also the gust
    on it, :func:`_check_gust_on_wind`): a TaskError names the field, its value and the
    bound."""
    if isinstance(spec, str):
        if spec not in PERTURBATIONS:
            raise TaskError(f"unknown perturbation {spec!r}; choose one of {list(PERTURBATIONS)}"
                            " or pass a dict")
        k = displacement_scale(tether_length)
        spec = {**PERTURBATIONS[spec]}
        spec.update(swing=spec["swing"] * k, lateral=spec["lateral"] * k)
    if not isinstance(spec, dict):
        raise TaskError(f"perturbation must be a preset name or a dict, got {spec!r}")
    out = {**PERTURBATIONS["none"], **GUST_DEFAULTS}
    unknown = sorted(set(spec) - set(out))
    if unknown:
        raise TaskError(f"unknown perturbation key(s) {unknown}; known: {sorted(out)}")
    out.update(spec)
    if not isinstance(out["fixed"], bool):
        raise TaskError(f"perturbation fixed must be True or False, got {out['fixed']!r}")
    _check_displacements(out, tether_length)
    _check_gust(out)
    if top_speed is not None:
        _check_gust_on_wind(out, top_speed)
    return out


def _check_displacements(out: dict, tether_length: float | None) -> None:
    """swing and lateral [m] are arcs of a rigid rotation about the winch, at most the tether's
    length (about a radian: beyond it the aerostat is swung into the ground; unchecked before
    the parameters, and so the length, are known); pitch [rad] at most
    :data:`MAX_PITCH_KICK`. Amplitudes are >= 0 unless ``fixed`` (then signed)."""
    bounds = {"swing": tether_length, "lateral": tether_length, "pitch": MAX_PITCH_KICK}
    units = {"swing": "m", "lateral": "m", "pitch": "rad"}
    for k, top in bounds.items():
        v = out[k]
        if not is_finite_number(v) or (v < 0 and not out["fixed"]):
            raise TaskError(f"perturbation {k} must be a finite number (>= 0 unless fixed), "
                            f"got {v!r}")
        if top is not None and abs(v) > top:
            why = ("the tether length" if k != "pitch" else
                   "pi/2 (the nose vertical, where the Euler kinematics are singular)")
            raise TaskError(f"perturbation {k} = {v!r} {units[k]} exceeds {why}: |{k}| <= "
                            f"{top:g} {units[k]}")


def _check_gust_on_wind(pert: dict, top_speed: float) -> None:
    """The largest gust on the largest mean wind stays within MAX_WIND_SPEED: the gust adds to
    the mean wind, and the model's incompressible aerodynamics end there."""
    gust = pert["gust_amplitude"][1] if pert["gust_probability"] > 0 else 0.0
    if gust + top_speed > MAX_WIND_SPEED:
        raise TaskError(f"perturbation gust_amplitude up to {gust:g} m/s on a mean wind_speed up "
                        f"to {top_speed:g} m/s reaches {gust + top_speed:g} m/s, above "
                        f"{MAX_WIND_SPEED:g} m/s, where the incompressible aerodynamics end")


def _check_gust(out: dict) -> None:
    """gust_probability in [0, 1]; gust_amplitude [m/s] in [0, MAX_WIND_SPEED] (the gust adds
    to the mean wind, whose incompressible aerodynamics end there); gust_duration [s] in
    (0, MAX_GUST_DURATION] (a gust of no length has no shape); gust_onset [s] in
    [0, MAX_GUST_ONSET]."""
    p = out["gust_probability"]
    if not (is_finite_number(p) and 0 <= p <= 1):
        raise TaskError(f"perturbation gust_probability must be a number in [0, 1], got {p!r}")
    out["gust_amplitude"] = check_range("perturbation gust_amplitude [m/s]", out["gust_amplitude"],
                                   hi_max=MAX_WIND_SPEED)
    lo, hi = out["gust_duration"] = check_range("perturbation gust_duration [s]",
                                           out["gust_duration"], hi_max=MAX_GUST_DURATION)
    if lo <= 0:
        raise TaskError(f"perturbation gust_duration must be > 0 s (a gust of no length has no "
                        f"shape), got {out['gust_duration']!r}")
    out["gust_onset"] = check_range("perturbation gust_onset [s]", out["gust_onset"],
                               hi_max=MAX_GUST_ONSET)
