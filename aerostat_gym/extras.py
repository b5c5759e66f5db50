"""The optional extras (``train``, ``plot``, ``bench``, ``ray``): import a package of one on
demand, or fail with one line that names the extra to install.

:class:`MissingExtraError` is a RuntimeError, so the CLI reports it as one line and exit status
2; the commands check what they need before any work."""

from __future__ import annotations

import importlib
from types import ModuleType


def install_hint(extra: str) -> str:
    """The install command for an extra, for a pip install and for a checkout."""
    return (f'pip install "aerostat-gym[{extra}]" (in a checkout of the repository: '
            f'pip install -e ".[{extra}]")')


class MissingExtraError(RuntimeError):
    """A command needs a package of the optional extra that is not installed."""


def require(module: str, purpose: str, extra: str, hint: str = "") -> ModuleType:
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


def require_plotting(purpose: str) -> ModuleType:
    """``matplotlib`` (the ``plot`` extra), or :class:`MissingExtraError` naming it; the
    commands call it before their work where ``purpose`` will write figures, so a missing
    extra is one line, not a traceback after the work."""
    return require("matplotlib", purpose, "plot")


def agg_pyplot(purpose: str):
    """``matplotlib.pyplot`` on the file-writing Agg backend (figures are written, not shown),
    or :class:`MissingExtraError` naming the ``plot`` extra; ``purpose`` says what needs it."""
    require_plotting(purpose).use("Agg")
    import matplotlib.pyplot as plt

    return plt
