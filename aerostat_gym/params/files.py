"""Parameter files: loading a TOML file or a shipped configuration (with the status comments
and the load-time warnings), and writing one."""

from __future__ import annotations

import dataclasses
import difflib
import os
import warnings
from importlib import resources
from pathlib import Path
from typing import Any

try:  # Python >= 3.11 (the parser of every parameter file: imported from here)
    import tomllib
except ModuleNotFoundError:  # pragma: no cover
    import tomli as tomllib  # type: ignore[no-redef]

from .model import Params, apply_overrides, params_from_dict, params_to_dict, validated
from .plausible import check_plausibility, hull_integral_warnings, plausibility_warnings
from .schema import STATUSES, ParameterError, ParameterWarning
from .steps import SEMI_IMPLICIT_REFERENCE_DT, advised_semi_implicit_dt

BASELINE_NAME = "aeros_flightcam"


def shipped_configs() -> tuple[str, ...]:
    """Names of the parameter files shipped in aerostat_gym/data (loadable by name)."""
    data = resources.files("aerostat_gym").joinpath("data")
    return tuple(sorted(f.name[:-5] for f in data.iterdir() if f.name.endswith(".toml")))


def config_text(path: str | Path | None) -> tuple[str, str]:
    """(TOML text, source name) of a path, a shipped configuration's name, or the baseline."""
    if path is None:
        path = BASELINE_NAME
    if isinstance(path, Params):
        raise ParameterError("load_params takes a TOML path or a shipped configuration's name, "
                             "got a Params (already loaded: use it, or .replace(...) for changes)")
    if not isinstance(path, (str, os.PathLike)):
        raise ParameterError(f"load_params takes a TOML path or a shipped configuration's name "
                             f"({', '.join(shipped_configs())}), got {type(path).__name__}"
                             + ("; for a dict of sections use params_from_dict"
                                if isinstance(path, dict) else ""))
    if not Path(path).is_file() and str(path) in shipped_configs():
        return resources.files("aerostat_gym").joinpath(f"data/{path}.toml").read_text(), str(path)
    path = Path(path)
    if path.is_dir():
        raise ParameterError(f"{path} is a folder: give a parameter file (.toml) in it, or a "
                             f"shipped configuration ({', '.join(shipped_configs())})")
    if not path.is_file():
        raise ParameterError(f"parameter file not found: {path} (shipped configurations: "
                             f"{', '.join(shipped_configs())})")
    try:  # TOML is UTF-8 by its specification, whatever the machine's locale
        # utf-8-sig: a byte-order mark (Windows editors write one) is dropped, not parsed
        return path.read_bytes().decode("utf-8-sig"), str(path)
    except UnicodeDecodeError as exc:
        raise ParameterError(f"{path}: not UTF-8 text (TOML files are UTF-8): byte "
                             f"{exc.object[exc.start]:#04x} at offset {exc.start}") from None
    except OSError as exc:
        raise ParameterError(f"{path}: cannot be read: {exc.strerror}") from None


def load_params(path: str | Path | None = None, overrides: dict[str, Any] | None = None) -> Params:
    """Load parameters from a TOML file, or a shipped configuration by name (``"tcom_32m"``;
    default: the baseline), and apply overrides."""
    text, source = config_text(path)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{source}: invalid TOML: {exc}") from exc
    p = params_from_dict(data)
    p = dataclasses.replace(p, provenance=tuple(sorted(status_comments(text).items())))
    p = apply_overrides(p, overrides) if overrides else p
    check_plausibility(p)
    warn_at_load(p, source)
    for slip in status_slips(text):
        warnings.warn(f"{source}: {slip}", ParameterWarning, stacklevel=2)
    return p


def as_params(p: Params | str | Path | None, error: type[ValueError] = ParameterError) -> Params:
    """Parameters given as a Params, a TOML path or a shipped configuration's name, or None
    (the baseline); anything else is ``error`` naming its type. One door for the environment
    and the controllers' designs."""
    if p is None or isinstance(p, (str, os.PathLike)):
        return load_params(p)
    if not isinstance(p, Params):
        raise error(f"params must be a Params, a TOML path or None, got {type(p).__name__}")
    return validated(p)


def warn_at_load(p: Params, source: str) -> None:
    """Warn (:class:`ParameterWarning`) when a loaded file holds values that run but invite
    numerical failures (once, at the door: not on every override)."""
    advised = advised_semi_implicit_dt(p)
    if p.simulation.semi_implicit_dt > advised * (1.0 + 1e-9):
        warnings.warn(
            f"{source}: simulation.semi_implicit_dt = {p.simulation.semi_implicit_dt:g} s is "
            f"longer than {advised:.3g} s, the shorter of the baseline's "
            f"{SEMI_IMPLICIT_REFERENCE_DT:g} s scaled to this {p.aerostat.length:.3g} m hull "
            "(aerostat.length; sqrt of the length ratio) and the explicit bound of the drag on "
            f"this {1000 * p.tether.diameter:.3g} mm tether (tether.diameter): episodes in "
            "strong turbulence may end as numerical_divergence (the baseline scaled to 0.1x "
            "its volume, severe turbulence, random reeling: 1 in 40,000 steps at 50 ms, none "
            f"at 34 ms). Set simulation.semi_implicit_dt <= {advised:.3g}, or use "
            "integrator='rk4'",
            ParameterWarning, stacklevel=3)
    for text in hull_integral_warnings(p):
        warnings.warn(f"{source}: {text}: check the hull integrals (docs/parameters.md, "
                      "section 1c)", ParameterWarning, stacklevel=3)
    for text in plausibility_warnings(p):
        warnings.warn(f"{source}: {text} (docs/parameters.md, section 1k)", ParameterWarning,
                      stacklevel=3)


def status_comments(text: str) -> dict[str, str]:
    """The status word (SOURCED, DERIVED, ESTIMATE, CALIB or USER) of every ``key = value  #
    ... STATUS ...`` line of a parameter TOML, as {"section.key": status}; fin panels are named
    ``fins.panels[i].key``."""
    out, section, panel = {}, "", -1
    for line in text.splitlines():
        body = line.split("#", 1)[0].strip()
        if body.startswith("[[fins.panels]]"):
            panel += 1
            section = f"fins.panels[{panel}]"
            continue
        if body.startswith("["):
            section = body.strip("[]").strip()
            continue
        if "=" not in body or "#" not in line:
            continue
        comment = line.split("#", 1)[1]
        found = [w.strip("(),:;") for w in comment.split() if w.strip("(),:;") in STATUSES]
        if found:
            out[f"{section}.{body.split('=', 1)[0].strip()}"] = found[0]
    return out


def status_slips(text: str) -> list[str]:
    """A warning text for every parameter line whose comment has no status word but a word
    close to one (``SORCED``, ``ESTIMATED``, ``CALIBRATED``): the value would silently keep
    the baseline's status, or USER."""
    out = []
    for number, line in enumerate(text.splitlines(), 1):
        body, _, comment = line.partition("#")
        if "=" not in body or not comment:
            continue
        words = [w.strip("(),:;.") for w in comment.split()]
        if any(w in STATUSES for w in words):
            continue
        for w in (w for w in words if len(w) >= 4 and w.isupper()):
            near = [s for s in STATUSES
                    if w.startswith(s) or difflib.SequenceMatcher(None, w, s).ratio() >= 0.75]
            if near:
                out.append(f"line {number}: {w!r} is no status word (did you mean {near[0]!r}? "
                           f"one of {', '.join(STATUSES)}); "
                           f"{body.split('=', 1)[0].strip()} takes the baseline's status (USER "
                           "where its value differs)")
                break
    return out


def default_params(**overrides: Any) -> Params:
    """The baseline case; keyword overrides use ``__`` for the dot: ``tether__length=150``."""
    return load_params(overrides={k.replace("__", "."): v for k, v in overrides.items()} or None)


def dumps_toml(p: Params) -> str:
    """Serialise the inputs to TOML (used to store the resolved parameters of every run)."""

    def fmt(v: Any) -> str:
        if isinstance(v, str):
            return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(fmt(x) for x in v) + "]"
        return repr(v)

    data = params_to_dict(p)
    lines = []
    for sec, table in data.items():
        lines.append(f"[{sec}]")
        for k, v in table.items():
            if k != "panels":
                lines.append(f"{k} = {fmt(v)}")
        lines.append("")
        if sec == "fins":
            for pan in table["panels"]:
                lines.append("[[fins.panels]]")
                lines.extend(f"{k} = {fmt(v)}" for k, v in pan.items())
                lines.append("")
    return "\n".join(lines)
