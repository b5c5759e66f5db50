"""Strict conversion of one section of a parameter file (a TOML table) into its dataclass:
unknown and missing keys, and each value against its field's type and check."""

from __future__ import annotations

import dataclasses
import difflib
import math
from dataclasses import fields
from typing import Any

from ..checks import is_finite_number, is_number, is_whole
from .schema import (
    BOOL,
    COEFFS,
    EFFICIENCY,
    FRACTION,
    INT_GE1,
    MAX_ELEMENTS,
    NONNEG,
    POSITIVE,
    STALL,
    VEC3,
    FinPanel,
    FinParams,
    ParameterError,
)


def check_value(name: str, value: Any, f: dataclasses.Field) -> Any:
    """Coerce and check one value against its field's declared type and constraint."""
    check = f.metadata["check"]
    if check == VEC3:
        if not (isinstance(value, (list, tuple)) and len(value) == 3 and all(map(is_number, value))):
            raise ParameterError(f"{name} must be a list of 3 numbers, got {value!r}")
        value = tuple(float(v) for v in value)
        if not all(math.isfinite(v) for v in value):
            raise ParameterError(f"{name} must be finite, got {value!r}")
        return value
    if check == COEFFS:
        size = f.metadata["size"]
        if not (isinstance(value, (list, tuple)) and value and all(map(is_number, value))):
            raise ParameterError(f"{name} must be a list of {size} numbers, got {value!r}")
        if len(value) != size:
            raise ParameterError(f"{name} needs {size} coefficients, got {len(value)}: {value!r}")
        value = tuple(float(v) for v in value)
        bad = [i for i, v in enumerate(value) if not math.isfinite(v)]
        if bad:
            raise ParameterError(f"{name} must be finite, got {value[bad[0]]!r} at index {bad[0]}")
        return value
    if f.type in ("str", str):
        if not isinstance(value, str):
            raise ParameterError(f"{name} must be a string, got {value!r}")
        return value
    if check == BOOL:
        if not isinstance(value, bool):
            raise ParameterError(f"{name} must be true or false, got {value!r}")
        return value
    if check == INT_GE1:
        if not is_whole(value, 1, MAX_ELEMENTS):
            typed = " (write it without a decimal point)" if (
                is_finite_number(value) and value == int(value) and 1 <= value <= MAX_ELEMENTS) else ""
            raise ParameterError(f"{name} must be an integer >= 1 and <= {MAX_ELEMENTS}, got "
                                 f"{value!r}{typed}")
        return int(value)
    if not is_number(value):
        raise ParameterError(f"{name} must be a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise ParameterError(f"{name} must be finite, got {value!r}")
    if check == POSITIVE and value <= 0:
        raise ParameterError(f"{name} must be > 0, got {value!r}")
    if check == NONNEG and value < 0:
        raise ParameterError(f"{name} must be >= 0, got {value!r}")
    if check == STALL and not 0 < value < 90:
        raise ParameterError(f"{name} must lie in (0, 90) deg, got {value!r}")
    if check == FRACTION and not 0 <= value <= 1:
        raise ParameterError(f"{name} must lie in [0, 1], got {value!r}")
    if check == EFFICIENCY and not 0 < value <= 1:
        raise ParameterError(f"{name} must lie in (0, 1], got {value!r}")
    return value


def build_section(cls: type, name: str, table: Any) -> Any:
    if not isinstance(table, dict):
        raise ParameterError(f"[{name}] must be a table, got {table!r}")
    known = {f.name: f for f in fields(cls)}
    unknown = sorted(set(table) - set(known))
    if unknown:
        hints = [k + did_you_mean(k, known) for k in unknown]
        raise ParameterError(f"unknown key(s) in [{name}]: {', '.join(hints)}")
    missing = sorted(set(known) - set(table))
    if missing:
        raise ParameterError(f"missing key(s) in [{name}]: {', '.join(missing)}")
    values = {}
    for key, f in known.items():
        if cls is FinParams and key == "panels":
            values[key] = _build_panels(table[key])
        else:
            values[key] = check_value(f"{name}.{key}", table[key], f)
    return cls(**values)


def _build_panels(panels: Any) -> tuple:
    if not isinstance(panels, list) or not panels:
        raise ParameterError(f"fins.panels must be a non-empty array of tables, got {panels!r}")
    return tuple(build_section(FinPanel, f"fins.panels[{i}]", p) for i, p in enumerate(panels))


def did_you_mean(name: str, known) -> str:
    """`` (did you mean 'X'?)`` for the known name nearest a misspelt one (case ignored:
    ``cd_c`` finds ``Cdc``), or an empty string."""
    lower = {k.lower(): k for k in known}
    close = difflib.get_close_matches(name.lower(), list(lower), 1)
    return f" (did you mean {lower[close[0]]!r}?)" if close else ""
