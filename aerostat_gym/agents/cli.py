"""Agent commands of the CLI: ``train``, ``evaluate`` and ``demo``."""

from __future__ import annotations


def add_agent_parsers(sub) -> None:
    from .report import add_demo_parser, add_evaluate_parser
    from .train import add_train_parser

    add_train_parser(sub)
    add_evaluate_parser(sub)
    add_demo_parser(sub)
