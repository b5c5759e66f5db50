"""The optional ``ray`` extra: import it on demand, or fail with one line that names it."""

from __future__ import annotations

import importlib
from types import ModuleType

EXTRA = "ray"
INSTALL_HINT = f'pip install -e ".[{EXTRA}]"  (or pip install "aerostat-gym[{EXTRA}]")'


class MissingExtraError(RuntimeError):
    """A command needs a package of the optional extra that is not installed."""


def require(module: str, command: str) -> ModuleType:
    """Import ``module`` or raise :class:`MissingExtraError` naming the extra to install.

    Parameters
    ----------
    module : dotted module name, e.g. ``"ray"`` or ``"optuna"``.
    command : the command that needs it (for the message).

    Returns
    -------
    the imported module.
    """
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise MissingExtraError(
            f"{command} needs the optional '{EXTRA}' extra ({module} is not importable: {exc}); "
            f"install it with: {INSTALL_HINT}") from None
