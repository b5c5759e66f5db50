"""Command-line interface: ``aerostat-gym <command> [options]``.

Commands: ``trim`` (equilibrium summary), ``params`` (every parameter with its unit and status),
``bench`` (speed and accuracy figures), ``wind`` (turbulence statistics), ``stability``,
``table2`` and ``sensitivity`` (linear stability analysis), ``train``, ``evaluate`` and ``demo``
(winch-control agents), ``tune`` and ``montecarlo`` (Ray, the optional extra). Errors in user
input print one clear line and exit with status 2.

One module per group of commands (``model``, ``wind``, ``stability``, ``agents``), each with an
``add_*_parsers`` function; ``common`` holds the options they share.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from pathlib import Path

from .. import __version__
from ..params import ParameterError
from .agents import add_agent_parsers
from .common import OneLineParser, warn
from .model import add_model_parsers
from .scale import add_montecarlo_parser, add_tune_parser
from .stability import add_stability_parsers
from .wind import add_wind_parser

DESCRIPTION = ("Tethered-aerostat simulator (Lambert & Nahon 2002), linear stability analysis and "
               "winch-control agents. Run 'aerostat-gym COMMAND --help' for a command's options.")


class DefaultsFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Appends "(default: ...)" to an option's help unless the help already says what the
    default is (e.g. "default: the YAML's"), so no option shows two defaults."""

    def _get_help_string(self, action):
        text = action.help or ""
        if "default" in text.lower():
            return text
        return super()._get_help_string(action)


class Parser(OneLineParser):
    """Every command's parser shows each option's default in its help, and reports a bad
    option as one line on stderr with exit status 2."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", DefaultsFormatter)
        super().__init__(*args, **kwargs)


def build_parser() -> argparse.ArgumentParser:
    ap = Parser(prog="aerostat-gym", description=DESCRIPTION)
    ap.add_argument("--version", action="version", version=f"aerostat-gym {__version__}",
                    help="print the version and exit")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=Parser,
                            metavar="COMMAND")
    add_model_parsers(sub)
    add_wind_parser(sub)
    add_stability_parsers(sub)
    add_agent_parsers(sub)
    add_tune_parser(sub)
    add_montecarlo_parser(sub)
    return ap


PACKAGE_DIR = str(Path(__file__).resolve().parents[1])


def one_line_warnings(command: str):
    """A ``warnings.showwarning`` that prints the package's own warnings as one line, like its
    errors (``aerostat-gym COMMAND: warning: ...``), each text once (the same condition is often
    found by two layers, e.g. a command's check and the environment it builds), and others as
    Python does."""
    default, said = warnings.showwarning, set()

    def show(message, category, filename, lineno, file=None, line=None):
        if str(Path(filename).resolve()).startswith(PACKAGE_DIR):
            if str(message) not in said:
                said.add(str(message))
                warn(command, str(message))
        else:
            default(message, category, filename, lineno, file, line)

    return show


def _attach_dashed_values(argv: list[str]) -> list[str]:
    """``--wind -5:10:1`` as ``--wind=-5:10:1``: argparse takes a value that starts with a dash
    and is not a plain negative number for an option, and would answer "expected one argument"
    instead of the range check's message naming the value."""
    out: list[str] = []
    for arg in argv:
        if out and out[-1] == "--wind" and arg[:1] == "-" and arg[1:2].isdigit():
            out[-1] = f"--wind={arg}"
        else:
            out.append(arg)
    return out


def main(argv: list[str] | None = None) -> int:
    argv = _attach_dashed_values(sys.argv[1:] if argv is None else list(argv))
    args = build_parser().parse_args(argv)
    with warnings.catch_warnings():
        warnings.showwarning = one_line_warnings(args.command)
        try:
            return args.func(args)
        except BrokenPipeError:  # the reader closed the pipe (| head): nothing to report
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            return 0
        except (ParameterError, ValueError, RuntimeError, OSError) as exc:
            print(f"aerostat-gym {args.command}: error: {exc}", file=sys.stderr)
            return 2


if __name__ == "__main__":
    sys.exit(main())
