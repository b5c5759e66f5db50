"""The ranges a Monte Carlo study draws the estimated parameters from, read from where the
project already states them (no third copy).

Two tables exist in the package and they do not agree:

* ``"documented"`` (default): the plausible ranges of :func:`aerostat_gym.analysis.sensitivity.
  default_knobs`, each with its source in the parameter notes (16 knobs, absolute ranges,
  derived knobs such as the CM shift and the air density with the net lift kept);
* ``"randomization"``: :data:`aerostat_gym.envs.config.DEFAULT_RANDOMIZATION`, the relative
  half-ranges that ``randomize=True`` draws per episode (8 parameters, uniform in
  ``nominal * (1 +- rel)``).

They differ, for example the hull cross-flow drag is 0.3-1.2 in the first and 0.96-1.44 in the
second; :func:`range_disagreements` lists every such case so that a report can state it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ..analysis.sensitivity import default_knobs
from ..envs.config import DEFAULT_RANDOMIZATION
from ..params import Params, apply_overrides, load_params

RANGE_SOURCES = ("documented", "randomization")


@dataclass(frozen=True)
class ParameterRange:
    """One uncertain parameter drawn uniformly in [low, high].

    Attributes
    ----------
    key : parameter name (dotted, or a derived knob name such as ``cm_x_shift``).
    low : lower end of the range, in the parameter's unit.
    high : upper end of the range.
    nominal : value in the base parameter set.
    put : returns a parameter set with this parameter at a value.
    override : the dotted parameter name when ``put`` sets only that field (None for a derived
        knob): :func:`~aerostat_gym.scale.montecarlo.sample_params` applies such draws together.
    """

    key: str
    low: float
    high: float
    nominal: float
    put: Callable[[Params, float], Params]
    override: str | None = None


def _documented(params: Params) -> list[ParameterRange]:
    return [ParameterRange(k.key, k.low, k.high, k.get(params), k.put, k.override)
            for k in default_knobs(params)]


def _override(key: str) -> Callable[[Params, float], Params]:
    return lambda p, v: apply_overrides(p, {key: float(v)})


def _randomization(params: Params) -> list[ParameterRange]:
    out = []
    for key, rel in DEFAULT_RANDOMIZATION.items():
        sec, _, name = key.partition(".")
        nominal = float(getattr(getattr(params, sec), name))
        lo, hi = sorted((nominal * (1.0 - rel), nominal * (1.0 + rel)))
        out.append(ParameterRange(key, lo, hi, nominal, _override(key), key))
    return out


def estimated_ranges(params: Params, source: str = "documented") -> list[ParameterRange]:
    """The uncertain parameters of ``params`` and their ranges from one of :data:`RANGE_SOURCES`.

    Parameters
    ----------
    params : base parameter set (nominal values and relative ranges are taken from it).
    source : ``"documented"`` or ``"randomization"``.

    Returns
    -------
    list of :class:`ParameterRange`, in the order the source lists them (the order in which a
    sample applies its values).
    """
    if source == "documented":
        return _documented(params)
    if source == "randomization":
        return _randomization(params)
    raise ValueError(f"unknown range source {source!r}; choose one of {RANGE_SOURCES}")


def range_disagreements(params: Params | None = None) -> list[dict]:
    """Parameters present in both tables whose ranges differ by more than 1 % of the nominal.

    Parameters
    ----------
    params : base parameter set (default: the baseline).

    Returns
    -------
    one dict per parameter: key, nominal, documented (low, high), randomization (low, high).
    """
    params = params or load_params()
    documented = {r.key: r for r in _documented(params)}
    rows = []
    for r in _randomization(params):
        d = documented.get(r.key)
        if d is None:
            rows.append({"key": r.key, "nominal": r.nominal, "documented": None,
                         "randomization": (r.low, r.high)})
            continue
        tol = 0.01 * abs(r.nominal)
        if abs(d.low - r.low) > tol or abs(d.high - r.high) > tol:
            rows.append({"key": r.key, "nominal": r.nominal, "documented": (d.low, d.high),
                         "randomization": (r.low, r.high)})
    return rows
