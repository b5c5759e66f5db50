"""JSON text that every reader parses: NaN and infinities written as null (JSON has neither;
Python's encoder writes the bare tokens ``NaN`` and ``Infinity``, which strict parsers refuse),
numpy scalars and arrays as plain numbers and lists. A damping ratio of an overdamped mode, a
fit that found no oscillation or a metric of an episode that ended early is such a value."""

from __future__ import annotations

import json
import math

import numpy as np


def plain(value):
    """``value`` as plain JSON data, through dicts, lists, tuples and arrays: numpy scalars as
    Python numbers, every non-finite float as None; anything else as it is (for ``default``)."""
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def dumps(value, **kwargs) -> str:
    """``json.dumps`` of :func:`plain` ``(value)`` (keyword arguments passed on)."""
    return json.dumps(plain(value), **kwargs)
