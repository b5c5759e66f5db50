"""Condensed Markdown tables of a protocol result (:func:`aerostat_gym.agents.protocol.protocol`,
or its JSON as written by ``aerostat-gym evaluate --suite report``): the README's view of the
report suite, one metric per table and one column per policy, each cell ``mean [95 % CI]`` with
a mark for the paired verdict against the reference policy (the full per-cell tables stay in
``protocol.md``)."""

from __future__ import annotations

from .protocol import aggregate_markdown, interval_text

#: Mark of a paired verdict against the reference policy (no mark: indistinguishable).
MARKS = {"better": " ▲", "worse": " ▼", "indistinguishable": "", "n/a": " ?"}
RECOVER_SPEEDS = (5.0, 10.0, 15.0)
GUSTY_SPEEDS = (4.0, 8.0, 12.0, 16.0)
#: (heading, [(scenario, metric, scale, digits, speeds)]) of the condensed view.
VIEW = (
    ("Pendulum damping ratio (longitudinal; lateral for `recover_cross`)",
     [("recover", "pendulum_zeta", 1.0, 3, RECOVER_SPEEDS),
      ("recover_small", "pendulum_zeta", 1.0, 3, RECOVER_SPEEDS),
      ("recover_combined", "pendulum_zeta", 1.0, 3, RECOVER_SPEEDS),
      ("recover_cross", "lateral_pendulum_zeta", 1.0, 3, RECOVER_SPEEDS)]),
    ("Pitch damping ratio", [("recover", "pitch_zeta", 1.0, 3, RECOVER_SPEEDS)]),
    ("RMS along-wind displacement [m]",
     [("gusty_light", "rms_x_m", 1.0, 1, GUSTY_SPEEDS), ("gusty", "rms_x_m", 1.0, 1, GUSTY_SPEEDS),
      ("gusty_severe", "rms_x_m", 1.0, 1, GUSTY_SPEEDS)]),
    ("Peak winch tension [kN]",
     [("gusty", "peak_tension_N", 1e-3, 2, GUSTY_SPEEDS),
      ("gusty_severe", "peak_tension_N", 1e-3, 2, GUSTY_SPEEDS)]),
)


def label(policy: str) -> str:
    """Column label: an SB3 model file's stem reads as the shipped policy's name."""
    return "shipped PPO" if policy.startswith("ppo_tethered_aerostat") else policy


def cell_text(cell: dict, policy: str, metric: str, scale: float, digits: int,
              reference: str = "passive") -> str:
    """``mean [low, high]`` (no interval where it rounds to a point) and the verdict mark."""
    text = interval_text(cell["policies"][policy][metric], scale, digits)
    if policy != reference:
        text += MARKS[cell["paired"][policy][reference][metric]["verdict"]]
    return text


def metric_table(proto: dict, rows, reference: str = "passive") -> str:
    """One Markdown table: a row per (scenario, wind speed) of ``rows``, a column per policy."""
    policies = list(proto["cells"][0]["policies"])
    lines = ["| scenario | U [m/s] | " + " | ".join(label(p) for p in policies) + " |",
             "|---|---|" + "---|" * len(policies)]
    for scenario, metric, scale, digits, speeds in rows:
        for cell in proto["cells"]:
            if cell["scenario"] == scenario and cell["wind_speed"] in speeds:
                lines.append(f"| `{scenario}` | {cell['wind_speed']:g} | " + " | ".join(
                    cell_text(cell, p, metric, scale, digits, reference) for p in policies) + " |")
    return "\n".join(lines)


def condensed(proto: dict, reference: str = "passive") -> str:
    """Every table of :data:`VIEW` that has rows in ``proto``, then the aggregate."""
    parts = []
    for heading, rows in VIEW:
        table = metric_table(proto, rows, reference)
        if table.count("\n") > 1:
            parts.append(f"{heading}:\n\n{table}")
    parts.append(f"Aggregate:\n\n{aggregate_markdown(proto, label)}")
    return "\n\n".join(parts) + "\n"
