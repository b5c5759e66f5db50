"""The parameter table: every input with its value, unit, description and the status of the
value as given (the user's comment, USER for a changed value, else the baseline's)."""

from __future__ import annotations

import dataclasses
from dataclasses import fields
from typing import Any

from .files import BASELINE_NAME, config_text, load_params, tomllib
from .model import Params, params_from_dict
from .schema import SECTIONS, USER


def parameter_table(p: Params | None = None) -> list[dict]:
    """Rows (name, value, unit, status, description) of every input, for reports and the CLI.

    The status follows the value: the status comment of the user's own file where it has one
    (:attr:`Params.provenance`), USER for a value set by an override or one that differs from
    the shipped baseline without a comment, and the baseline's status (dataclass metadata)
    for a value equal to the baseline's.
    """
    p = p or load_params()
    base = _baseline_values()
    prov = dict(p.provenance)
    rows = _raw_rows(p)
    for r in rows:
        r["status"] = _status(r, prov, base)
    return rows


def _status(row: dict, provenance: dict, baseline: dict) -> str:
    name = row["name"]
    stated = provenance.get(name) or provenance.get(name.split(".panels[")[0] + ".panels")
    if stated is not None:
        return stated
    return row["status"] if baseline.get(name) == row["value"] else USER


def _baseline_values() -> dict:
    """{name: value} of the shipped baseline (parsed once)."""
    if not _BASELINE_VALUES:
        text, _ = config_text(BASELINE_NAME)
        base = params_from_dict(tomllib.loads(text))
        _BASELINE_VALUES.update({r["name"]: r["value"] for r in _raw_rows(base)})
    return _BASELINE_VALUES


_BASELINE_VALUES: dict = {}


def _raw_rows(p: Params) -> list[dict]:
    rows = []
    for sec in SECTIONS:
        obj = getattr(p, sec)
        for f in fields(obj):
            if f.name == "panels":
                for i, pan in enumerate(obj.panels):
                    rows.extend(_row(f"fins.panels[{i}].{g.name}", getattr(pan, g.name), g)
                                for g in fields(pan))
            else:
                rows.append(_row(f"{sec}.{f.name}", getattr(obj, f.name), f))
    return rows


def _row(name: str, value: Any, f: dataclasses.Field) -> dict:
    m = f.metadata
    return {"name": name, "value": value, "unit": m["unit"], "status": m["status"], "description": m["doc"]}
