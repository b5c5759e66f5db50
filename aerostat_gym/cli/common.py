"""Options and helpers shared by every command: ``--config``, ``--set`` and ``--json``.

Every command that takes a parameter file uses these, so the configuration path is the same
everywhere: ``--config FILE`` (a physics parameter TOML) then ``--set SECTION.KEY=VALUE``.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
from pathlib import Path

from tqdm import tqdm

from ..params import ParameterError, load_params, shipped_configs
from ..params.files import tomllib


class OneLineParser(argparse.ArgumentParser):
    """argparse that reports a bad option as one line on stderr (naming the option and the
    value) and exits with status 2, instead of the usage block."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message}\n")


def warn(command: str, message: str) -> None:
    """One warning line on stderr, on a line of its own while a progress bar runs."""
    with tqdm.external_write_mode(file=sys.stderr):
        print(f"aerostat-gym {command}: warning: {message}", file=sys.stderr)


def _number(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


def positive_int(text: str) -> int:
    """argparse type: an integer >= 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {text!r}")
    return value


#: the largest seed every consumer takes (SB3's set_random_seed and gymnasium reduce to 32 bits)
MAX_SEED = 2**32 - 1


def seed_int(text: str) -> int:
    """argparse type: a seed, an integer from 0 to 2**32 - 1."""
    try:
        value = int(text)
    except ValueError:
        value = -1
    if not 0 <= value <= MAX_SEED:
        raise argparse.ArgumentTypeError(f"expected a seed, an integer from 0 to 2**32 - 1, got "
                                         f"{text!r}")
    return value


def positive_float(text: str) -> float:
    """argparse type: a finite number > 0."""
    value = _number(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}")
    return value


def nonneg_float(text: str) -> float:
    """argparse type: a finite number >= 0."""
    value = _number(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a number >= 0, got {text!r}")
    return value


def existing_file(text: str) -> str:
    """argparse type: the path of an existing file."""
    if not Path(text).is_file():
        raise argparse.ArgumentTypeError(f"file not found: {text!r}")
    return text


def output_dir(path: str, option: str = "--out") -> Path:
    """The directory a command writes into, created (with its parents) and checked writable
    before the command's work, so that a long run never ends on a path it cannot write."""
    out = Path(path)
    try:
        out.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=out):
            pass
    except OSError as exc:
        raise ValueError(f"{option} {path}: cannot write there ({exc.strerror or exc})") from None
    return out


def output_file(path: str, option: str) -> Path:
    """A file a command will write: its folder created and checked writable before the
    command's work (:func:`output_dir`)."""
    out = Path(path)
    output_dir(str(out.parent), f"{option} {path}: its folder")
    return out


def config_source(text: str) -> str:
    """argparse type of ``--config``: a shipped configuration's name or an existing file."""
    if text in shipped_configs() or Path(text).is_file():
        return text
    raise argparse.ArgumentTypeError(f"neither a shipped configuration "
                                     f"({', '.join(shipped_configs())}) nor a file: {text!r}")


def add_config(p: argparse.ArgumentParser, json: bool = True) -> None:
    """``--config``, ``--set`` and (unless ``json=False``) ``--json`` on a command's parser."""
    p.add_argument("--config", type=config_source,
                   help="parameter TOML file or a shipped configuration's name "
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


# --- the scripts in scripts/ ---------------------------------------------------------------------


def first_seeds(count: int, seeds) -> tuple:
    """The first ``count`` of a study's fixed seed set (``--seeds N``, a smoke run), refused
    outside [2, len(seeds)]: a bootstrap interval needs two episodes."""
    if not 2 <= count <= len(seeds):
        raise SystemExit(f"--seeds must lie in [2, {len(seeds)}], got {count}")
    return tuple(seeds[:count])


def script_description(doc: str) -> str:
    """A script's ``--help`` description: the first paragraph of its docstring, joined (its
    first line alone stops mid-sentence)."""
    return " ".join(doc.strip().split("\n\n")[0].split())


def run_script(main) -> int:
    """Run a script's ``main()`` as the CLI runs a command: a refused input (a ParameterError,
    a PolicyError or another ValueError, a file that cannot be read) is one line on stderr and
    exit status 2, not a traceback. A ``main`` that returns its results (a dict, for the tests
    and the studies that import it) exits 0; one that returns an int exits with it."""
    try:
        result = main()
        return result if isinstance(result, int) and not isinstance(result, bool) else 0
    except (ValueError, RuntimeError, OSError) as exc:
        print(f"{Path(sys.argv[0]).name}: error: {exc}", file=sys.stderr)
        return 2
