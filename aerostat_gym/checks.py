"""What counts as a number at the doors where a user hands one in (parameter files and
overrides, task arguments, hyperparameter blocks, statistics options): one rule for all of them,
so that ``True`` is never read as 1 and a NumPy scalar is read like the Python number it holds.

Each door keeps its own range and its own error class, which names the value.
"""

from __future__ import annotations

import math
import numbers


def is_number(value) -> bool:
    """A real number: a Python or NumPy int or float, not a bool (NaN and infinities included,
    for doors that name them apart)."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def is_finite_number(value) -> bool:
    """A real number (:func:`is_number`) that is neither NaN nor infinite."""
    return is_number(value) and math.isfinite(value)


def is_whole(value, low: int = 1, high: int | None = None) -> bool:
    """An integer (Python or NumPy, not a bool) in [low, high] (no upper end when ``high`` is
    None). A float, even an integral one, is not whole here: a count typed as 2.0 is refused."""
    return (isinstance(value, numbers.Integral) and not isinstance(value, bool)
            and low <= value and (high is None or value <= high))
