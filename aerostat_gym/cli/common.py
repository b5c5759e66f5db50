"""Options and helpers shared by every command: ``--config``, ``--set`` and ``--json``.

Every command that takes a parameter file uses these, so the configuration path is the same
everywhere: ``--config FILE`` (a physics parameter TOML) then ``--set SECTION.KEY=VALUE``.
"""

from __future__ import annotations

import argparse

from ..params import ParameterError, load_params, tomllib


def add_config(p: argparse.ArgumentParser) -> None:
    """``--config``, ``--set`` and ``--json`` on a command's parser."""
    p.add_argument("--config", help="parameter TOML file (default: the shipped baseline)")
    p.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override one parameter, e.g. --set tether.length=150 (repeatable)")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")


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
