"""Files the installed package ships beside its code, found relative to the package (never to
the working directory), so every command works from any directory after ``pip install``.

- ``aerostat_gym/data/``: the baseline parameter file.
- ``aerostat_gym.shipped``: the repository's top-level ``agents/`` folder (hyperparameter YAML,
  the shipped policies with their normalisation statistics, their training curves and reports),
  installed under that name by ``pyproject.toml`` so that the package carries it and no
  top-level ``agents`` module is installed (other PyPI packages use that name).
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

SHIPPED_PACKAGE = "aerostat_gym.shipped"
#: The default policy of ``aerostat-gym demo`` and ``evaluate --policy shipped``.
SHIPPED_POLICY = "ppo_tethered_aerostat.zip"


def shipped_root() -> Path:
    """The folder the shipped agents data lives in (the repository's ``agents/`` when the
    package is installed in editable mode)."""
    return Path(str(resources.files(SHIPPED_PACKAGE)))


def shipped_path(*parts: str) -> Path:
    """Path of a shipped file, e.g. ``shipped_path("hyperparams", "ppo.yml")``.

    Raises FileNotFoundError (one line, naming the file and where it was looked for).
    """
    path = shipped_root().joinpath(*parts)
    if not path.is_file():
        raise FileNotFoundError(f"shipped file {'/'.join(parts)} not found in the package data "
                                f"({shipped_root()}); reinstall aerostat-gym")
    return path
