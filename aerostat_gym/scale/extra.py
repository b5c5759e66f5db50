"""The optional ``ray`` extra: import it on demand, or fail with one line that names it."""

from __future__ import annotations

import importlib
from types import ModuleType

EXTRA = "ray"


def install_hint(extra: str = EXTRA) -> str:
    """The install command for an extra, from a checkout or from the index."""
    return f'pip install -e ".[{extra}]" (or pip install "aerostat-gym[{extra}]")'


class MissingExtraError(RuntimeError):
    """A command needs a package of the optional extra that is not installed."""


def require(module: str, command: str, extra: str = EXTRA) -> ModuleType:
    """Import ``module`` or raise :class:`MissingExtraError` naming the extra to install.

    Parameters
    ----------
    module : dotted module name, e.g. ``"ray"`` or ``"optuna"``.
    command : the command that needs it (for the message).
    extra : the optional extra that provides it.

    Returns
    -------
    the imported module.
    """
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise MissingExtraError(
            f"{command} needs the optional '{extra}' extra ({module} is not importable: {exc}); "
            f"install it with: {install_hint(extra)}") from None
