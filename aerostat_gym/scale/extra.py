"""The optional ``ray`` extra: import it on demand, or fail with one line that names it."""

from __future__ import annotations

import importlib
from types import ModuleType

EXTRA = "ray"


def install_hint(extra: str = EXTRA) -> str:
    """The install command for an extra, run in the repository root."""
    return f'pip install -e ".[{extra}]" in the repository root'


class MissingExtraError(RuntimeError):
    """A command needs a package of the optional extra that is not installed."""


def require(module: str, purpose: str, extra: str = EXTRA, hint: str = "") -> ModuleType:
    """Import ``module`` or raise :class:`MissingExtraError` naming the extra to install.

    Parameters
    ----------
    module : dotted module name, e.g. ``"ray"`` or ``"optuna"``.
    purpose : what needs it, for the message (e.g. "running the study on Ray").
    extra : the optional extra that provides it.
    hint : appended to the message (e.g. an alternative that needs no extra).

    Returns
    -------
    the imported module.
    """
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise MissingExtraError(
            f"{purpose} needs the optional '{extra}' extra ({module} is not importable: {exc}); "
            f"install it with: {install_hint(extra)}{hint}") from None
