"""The whole parameter set (:class:`Params`) and its strict conversions to and from nested
dicts; overrides by dotted name."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from .constraints import check_constraints
from .derived import Derived
from .fields import build_section, did_you_mean
from .schema import (
    SECTIONS,
    USER,
    AerostatParams,
    EnvironmentParams,
    FinParams,
    HullParams,
    ParameterError,
    SimulationParams,
    TetherParams,
    WinchParams,
    WindParams,
)


@dataclass(frozen=True)
class Params:
    """All parameters of one tethered-aerostat system. Immutable; use :meth:`replace`."""

    environment: EnvironmentParams
    aerostat: AerostatParams
    hull: HullParams
    fins: FinParams
    tether: TetherParams
    winch: WinchParams
    wind: WindParams
    simulation: SimulationParams
    #: Status of each value as the user's file states it ("section.key" -> SOURCED, ..., USER),
    #: read from the status comments of the TOML and set to USER by overrides; not compared.
    provenance: tuple = field(default=(), compare=False, repr=False)

    def replace(self, **dotted: Any) -> Params:
        """Return a copy with single values replaced, e.g. ``replace(**{"tether.length": 150})``."""
        return apply_overrides(self, dotted)

    @property
    def derived(self) -> Derived:
        return Derived.from_params(self)


def params_from_dict(data: dict) -> Params:
    """Build :class:`Params` from a nested dict (the parsed TOML), strictly."""
    if not isinstance(data, dict):
        raise ParameterError("parameter data must be a table")
    unknown = sorted(set(data) - set(SECTIONS))
    if unknown:
        hints = [k + did_you_mean(k, SECTIONS) for k in unknown]
        raise ParameterError(f"unknown section(s): {', '.join(hints)}")
    missing = [s for s in SECTIONS if s not in data]
    if missing:
        raise ParameterError(f"missing section(s): {', '.join(missing)}")
    p = Params(**{name: build_section(cls, name, data[name]) for name, cls in SECTIONS.items()})
    check_constraints(p)
    return p


def params_to_dict(p: Params) -> dict:
    """Nested plain dict of all inputs (round-trips through :func:`params_from_dict`)."""
    out = {}
    for name in SECTIONS:
        sec = dataclasses.asdict(getattr(p, name))
        out[name] = {k: (list(v) if isinstance(v, tuple) and k != "panels" else v) for k, v in sec.items()}
    out["fins"]["panels"] = [
        {**pan, "cp_position": list(pan["cp_position"])} for pan in out["fins"]["panels"]
    ]
    return out


def parameter_key(data: dict, key: str) -> tuple[str, str]:
    """``(section, name)`` of a dotted parameter name (``"hull.Cdc"``) in a parameter
    dictionary (:func:`params_to_dict`); an unknown one is a ParameterError naming the nearest
    known name."""
    sec, dot, name = str(key).partition(".")
    if dot and sec in SECTIONS and name in data[sec]:
        return sec, name
    hint = did_you_mean(str(key), [f"{s}.{k}" for s in SECTIONS for k in data[s]])
    if not hint:
        hint = f" (use 'section.key', sections: {', '.join(SECTIONS)})"
    raise ParameterError(f"unknown parameter {key!r}{hint}")


def apply_overrides(p: Params, overrides: dict[str, Any]) -> Params:
    """Replace single values by dotted name (``"tether.length"``), with the same checks as loading."""
    if not isinstance(overrides, Mapping):
        raise ParameterError("overrides must map dotted parameter names to values, e.g. "
                             f"{{'tether.length': 300.0}}; got {overrides!r}")
    data = params_to_dict(p)
    for key, value in overrides.items():
        sec, name = parameter_key(data, key)
        data[sec][name] = list(value) if isinstance(value, tuple) else value
    new = params_from_dict(data)
    prov = dict(p.provenance)
    prov.update({key: USER for key in overrides})
    return dataclasses.replace(new, provenance=tuple(sorted(prov.items())))


def validated(p: Params) -> Params:
    """``p`` after the loader's field and cross checks: a Params built with
    ``dataclasses.replace`` (rather than :meth:`Params.replace`) skips them, and a zero
    element count or a string for g would otherwise fail deep in the model."""
    params_from_dict(params_to_dict(p))
    return p
