"""Options and helpers shared by every command: ``--config``, ``--set`` and ``--json``.

Every command that takes a parameter file uses these, so the configuration path is the same
everywhere: ``--config FILE`` (a physics parameter TOML) then ``--set SECTION.KEY=VALUE``.
"""

from __future__ import annotations

import argparse

from ..params import ParameterError, load_params, shipped_configs, tomllib


def add_config(p: argparse.ArgumentParser, json: bool = True) -> None:
    """``--config``, ``--set`` and (unless ``json=False``) ``--json`` on a command's parser."""
    p.add_argument("--config", help="parameter TOML file or a shipped configuration's name "
                   f"({', '.join(shipped_configs())}; default: the baseline)")
    p.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override one parameter, e.g. --set tether.length=150 (repeatable)")
    if json:
        p.add_argument("--json", action="store_true", help="print JSON instead of text")


def config_label(args) -> str:
    """How the configuration was given, for headers: the file or name, plus the overrides."""
    label = getattr(args, "config", None) or "baseline"
    sets = getattr(args, "set", None) or []
    return label + "".join(f" --set {s}" for s in sets)


def parse_overrides(items: list[str]) -> dict:
    """``--set SECTION.KEY=VALUE`` items as a dict; values are read as TOML (bare strings too)."""
    out = {}
    for item in items:
        if "=" not in item:
            raise ParameterError(f"--set expects SECTION.KEY=VALUE, got {item!r}")
        key, raw = item.split("=", 1)
        try:
            out[key.strip()] = tomllib.loads(f"v = {raw}")["v"]
        except tomllib.TOMLDecodeError:
            out[key.strip()] = raw  # a bare string
    return out


def params_from_args(args, **extra):
    """The parameter set of ``--config`` and ``--set``, plus overrides from other options
    (``extra``: {"section.key": value}, ignored where the value is None)."""
    over = parse_overrides(getattr(args, "set", []) or [])
    over.update({k: v for k, v in extra.items() if v is not None})
    return load_params(getattr(args, "config", None), over or None)
