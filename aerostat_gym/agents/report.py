"""Evaluation reports: Markdown tables, PNG plots and JSON of evaluation results."""

from __future__ import annotations

import json
import math
from collections import Counter
from pathlib import Path

import numpy as np

from .. import jsonout
from ..checks import is_number
from ..extras import agg_pyplot
from ..resources import SHIPPED_POLICY
from . import protocol as proto_mod
from .evaluate import SCENARIOS, describe_suite, evaluate_policy
from .policies import BASELINES
from .protocol_stats import bootstrap_mean_ci

COLUMNS = [  # (key, header, format)
    ("pendulum_zeta", "pend. zeta", "{:.3f}"), ("pendulum_period_s", "pend. T [s]", "{:.1f}"),
    ("lateral_pendulum_zeta", "lat. pend. zeta", "{:.3f}"),
    ("lateral_pendulum_period_s", "lat. pend. T [s]", "{:.1f}"),
    ("pitch_zeta", "pitch zeta", "{:.3f}"), ("pitch_period_s", "pitch T [s]", "{:.2f}"),
    ("settling_time_s", "5 % settle [s]", "{:.0f}"), ("rms_x_m", "RMS x [m]", "{:.2f}"),
    ("rms_pitch_rad", "RMS pitch [deg]", "deg"), ("peak_tension_N", "peak T [kN]", "kN"),
    ("rms_tension_N", "RMS T [kN]", "kN"), ("winch_energy_J", "winch energy [kJ]", "kN"),
    ("peak_reel_speed_m_s", "peak reel [m/s]", "{:.2f}"), ("return", "return", "{:.0f}"),
]
#: The columns of each pendulum a free-response scenario fits ("x": longitudinal, "y":
#: lateral; :attr:`~aerostat_gym.agents.evaluate.Scenario.pendulums`).
PENDULUM_COLUMNS = {"x": {"pendulum_zeta", "pendulum_period_s"},
                    "y": {"lateral_pendulum_zeta", "lateral_pendulum_period_s"}}


def _fmt(value, fmt: str) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "n/a"
    if fmt == "deg":
        return f"{math.degrees(value):.2f}"
    if fmt == "kN":
        return f"{value / 1e3:.2f}"
    return fmt.format(value)


#: Damped-sinusoid fits and settling times mean something only for a free response.
FREE_RESPONSE_ONLY = {"pendulum_zeta", "pendulum_period_s", "pitch_zeta", "pitch_period_s",
                      "settling_time_s"}


def comparison_table(results: list[dict], scenario: str) -> str:
    """Markdown table: one row per (wind speed, policy), averaged over the scenario's seeds,
    with the fits of the pendulums the scenario swings (the gusty scenario shows no fitted
    damping: its response is forced, not free), then a line per policy and wind speed whose
    episodes terminated (their RMS and peak figures are n/a)."""
    cols = scenario_columns(scenario)
    head = "| U [m/s] | policy | " + " | ".join(h for _, h, _ in cols) + " |"
    lines = [head, "|" + "---|" * (len(cols) + 2)]
    speeds = sorted({e["wind_speed"] for r in results for e in r["scenarios"][scenario]["episodes"]})
    ended = []
    for u in speeds:
        for r in results:
            eps = [e for e in r["scenarios"][scenario]["episodes"] if e["wind_speed"] == u]
            cells = [_fmt(_mean(eps, k), f) for k, _, f in cols]
            lines.append(f"| {u:g} | {r['label']} | " + " | ".join(cells) + " |")
            reasons = Counter(e["ended"] for e in eps if e.get("ended"))
            if reasons:
                ended.append(f"- {r['label']} at {u:g} m/s: " + ", ".join(
                    f"{n} of {len(eps)} episodes ended by {why}" for why, n in reasons.items()))
    if ended:
        lines += ["", "Terminated (no RMS or peak figures for those episodes):", *ended]
    return "\n".join(lines)


def scenario_columns(scenario: str) -> list:
    """:data:`COLUMNS` for one scenario: the fits only of the pendulums it swings."""
    sc = SCENARIOS.get(scenario)
    pendulums = sc.pendulums if sc is not None else ()
    skip = set().union(*(PENDULUM_COLUMNS[k] for k in PENDULUM_COLUMNS if k not in pendulums))
    if not pendulums:
        skip |= FREE_RESPONSE_ONLY
    return [c for c in COLUMNS if c[0] not in skip]


def _mean(eps: list[dict], key: str) -> float:
    vals = [e[key] for e in eps if isinstance(e.get(key), (int, float))]
    vals = [v for v in vals if math.isfinite(v)]
    return float(np.mean(vals)) if vals else float("nan")


def lqr_predictions(results: list[dict]) -> str:
    """Each model-based controller's linear closed-loop prediction (the design at the schedule
    speed nearest the run's, named in its own column) next to what the nonlinear runs
    identified, in ``recover``."""
    lines = []
    for r in results:
        for e in r["scenarios"].get("recover", {}).get("episodes", []):
            pred = e.get("predicted")
            if not pred:
                continue
            p, q = pred.get("pendulum", {}), pred.get("pitching", {})
            cells = [_zeta(p, "open"), _zeta(p, "closed"), _fmt(e["pendulum_zeta"], "{:.3f}"),
                     _zeta(q, "closed"), _fmt(e["pitch_zeta"], "{:.3f}")]
            lines.append(f"| {e['wind_speed']:g} | {r['label']} | "
                         f"{_fmt(pred.get('design_wind_speed'), '{:g}')} | " + " | ".join(cells)
                         + " |")
    if not lines:
        return ""
    return ("| U [m/s] | policy | design U [m/s] | pendulum zeta, braked (linear) | pendulum "
            "zeta, closed loop (linear) | pendulum zeta (nonlinear fit) | pitching zeta, closed "
            "loop (linear) | pitch zeta (nonlinear fit) |\n|---|---|---|---|---|---|---|---|\n"
            + "\n".join(lines))


def _zeta(mode: dict, loop: str) -> str:
    return _fmt(mode.get(loop, {}).get("zeta"), "{:.3f}")


#: Pendulum damping-ratio differences below this are called "within tolerance", not better or
#: worse: the recover scenario is one deterministic episode per wind speed, and the damped-sinusoid
#: fit of the braked winch differs from its linear eigenvalue by about this much (0.285 fitted
#: against 0.277 linear at 10 m/s).
ZETA_TOLERANCE = 0.01


def verdicts(results: list[dict]) -> list[str]:
    """Plain statements: where each learned policy damps the pendulum better than passive and
    LQR by more than :data:`ZETA_TOLERANCE`, worse by more than it, or within it."""
    by = {r["label"]: r for r in results}
    out = []
    for r in results:
        if r["label"] in BASELINES:
            continue
        for ref in ("passive", "lqr"):
            if ref not in by:
                continue
            if "recover" not in r["scenarios"]:
                continue
            for e in r["scenarios"]["recover"]["episodes"]:
                u = e["wind_speed"]
                seed = e.get("seed", 0)
                if seed != min(x.get("seed", 0) for x in r["scenarios"]["recover"]["episodes"]):
                    continue  # one line per wind speed (several seeds: see protocol.md)
                f = next(x for x in by[ref]["scenarios"]["recover"]["episodes"]
                         if x["wind_speed"] == u and x.get("seed", 0) == seed)
                d = e["pendulum_zeta"] - f["pendulum_zeta"]
                word = ("better" if d > ZETA_TOLERANCE else "worse" if d < -ZETA_TOLERANCE
                        else f"within the {ZETA_TOLERANCE} tolerance")
                out.append(f"- {r['label']} vs {ref} at {u:g} m/s: pendulum zeta "
                           f"{e['pendulum_zeta']:.3f} vs {f['pendulum_zeta']:.3f}: {word}")
    return out


def score_and_damping(results: list[dict]) -> str:
    """One sentence reconciling the score (mean return) with the recover-scenario damping: which
    policy each ranks first, and why they may differ."""
    best_score = max(results, key=lambda r: r["score"])["label"]
    zeta = {r["label"]: _mean(r["scenarios"]["recover"]["episodes"], "pendulum_zeta")
            for r in results if "recover" in r["scenarios"]}
    if not zeta:
        return ""
    best_zeta = max(zeta, key=lambda k: zeta[k] if math.isfinite(zeta[k]) else -math.inf)
    if best_zeta == best_score:
        return f"The score and the pendulum damping both rank {best_score} first."
    return (f"The score (mean return) ranks {best_score} first; the pendulum damping ranks "
            f"{best_zeta} first: the return also charges the length wander and the winch effort "
            "(reward terms `length`, `effort`, `effort_rate`), which the damping ratio ignores.")


def plot_training_curve(history: list[dict], out: Path, title: str = "") -> Path:
    """The training curve: suite score (mean return on the evaluation suite) against
    environment steps and against wall time, from ``evaluations.json``'s records."""
    plt = agg_pyplot("the training curve")

    steps = np.array([h["timesteps"] for h in history], float)
    wall = np.array([h["wall_time_s"] for h in history], float)
    score = np.array([h["score"] for h in history], float)
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), sharey=True)
    axes[0].plot(steps / 1e6, score, "o-", ms=3)
    axes[0].set_xlabel("environment steps [millions]")
    axes[1].plot(wall, score, "o-", ms=3)
    axes[1].set_xlabel("wall time [s]")
    axes[0].set_ylabel("suite score (mean return)")
    for ax in axes:
        ax.grid(alpha=0.3)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    path = Path(out) / "training_curve.png"
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def plot(results: list[dict], out: Path) -> list[Path]:
    """Time histories of every policy overlaid (recover scenario) and damping ratios side by side."""
    plt = agg_pyplot("writing the report's plots (--no-plots skips them)")

    paths = []
    if "recover" not in results[0]["scenarios"]:
        return paths
    rec = results[0]["scenarios"]["recover"]["histories"]
    first = [i for i in range(len(rec.speeds)) if rec.seeds[i] == rec.seeds[0]]
    speeds = rec.speeds[first]  # one episode per wind speed: the first seed's
    fig, axes = plt.subplots(3, len(speeds), figsize=(4.2 * len(speeds), 8), squeeze=False,
                             sharex=True)
    for j, u in enumerate(speeds):
        for r in results:
            h = r["scenarios"]["recover"]["histories"]
            i = first[j]
            axes[0, j].plot(h.time, h.x[i], label=r["label"])
            axes[1, j].plot(h.time, np.degrees(h.pitch[i]))
            axes[2, j].plot(h.time, h.reel_speed[i])
        axes[0, j].set_title(f"recover, U = {u:g} m/s")
        axes[2, j].set_xlabel("time [s]")
    axes[0, 0].set_ylabel("along-wind displacement [m]")
    axes[1, 0].set_ylabel("pitch from trim [deg]")
    axes[2, 0].set_ylabel("reel speed [m/s]")
    axes[0, 0].legend(fontsize=8)
    fig.tight_layout()
    paths.append(out / "time_histories.png")
    fig.savefig(paths[-1], dpi=90)
    plt.close(fig)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    width = 0.8 / len(results)
    for k, r in enumerate(results):
        eps = [r["scenarios"]["recover"]["episodes"][i] for i in first]
        xs = np.arange(len(eps)) + k * width
        axes[0].bar(xs, [e["pendulum_zeta"] for e in eps], width, label=r["label"])
        axes[1].bar(xs, [e["pitch_zeta"] for e in eps], width, label=r["label"])
    for ax, name in zip(axes, ("longitudinal pendulum", "pitch"), strict=True):
        ax.set_xticks(np.arange(len(speeds)) + 0.4 - width / 2, [f"{u:g} m/s" for u in speeds])
        ax.set_ylabel("identified damping ratio")
        ax.set_title(name)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    paths.append(out / "damping_ratios.png")
    fig.savefig(paths[-1], dpi=90)
    plt.close(fig)
    return paths


def write_report(results: list[dict], out: str | Path, title: str, command: str,
                 plots: bool = True, preamble: list[str] | None = None) -> Path:
    """Write report.md, report.json and the PNGs into ``out``; returns the Markdown path.
    ``preamble``: Markdown lines placed after the command line (e.g. the demo's summary)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    tether_length = results[0].get("tether_length_m")
    suite_lines = describe_suite(results[0]["suite"], results[0].get("speeds"), tether_length)
    parts = [f"# {title}", "", f"Command: `{command}`", "", *(preamble or []),
             f"Suite `{results[0]['suite']}` (control step 0.2 s):", "", suite_lines, "",
             "Scores (mean episode return, default reward): " +
             ", ".join(f"{r['label']} {r['score']:.0f}" for r in results) + ". " +
             score_and_damping(results), ""]
    for scenario in results[0]["scenarios"]:
        parts += [f"## {scenario}", "", comparison_table(results, scenario), ""]
    pred = lqr_predictions(results)
    if pred:
        parts += ["## Model-based controllers: linear prediction vs nonlinear simulation", "",
                  pred, ""]
    v = verdicts(results)
    if v:
        parts += ["## Learned policy vs baselines (pendulum damping, recover)", "", *v, ""]
    if plots:
        for p in plot(results, out):
            parts += [f"![{p.stem}]({p.name})", ""]
    if "params_toml" in results[0]:
        (out / "params.toml").write_text(results[0]["params_toml"])
        parts += [f"Parameters: `params.toml` (tether {results[0]['tether_length_m']:g} m).", ""]
    proto = protocol_for(results)
    if proto is not None:
        parts += ["Protocol tables (means and paired 95 % intervals over the seeds, aggregate "
                  "IQM): `protocol.md`, data `protocol.json`.", ""]
        (out / "protocol.md").write_text(
            "\n".join([f"# Evaluation protocol: suite `{results[0]['suite']}`", "",
                       f"Command: `{command}`", "",
                       suite_lines, "", proto_mod.protocol_markdown(proto, tether_length=tether_length)]))
        (out / "protocol.json").write_text(proto_mod.dumps(proto))
    md = out / "report.md"
    md.write_text("\n".join(parts))
    (out / "report.json").write_text(jsonout.dumps(jsonable(results, proto), indent=1))
    return md


def protocol_for(results: list[dict]) -> dict | None:
    """The protocol's statistics (:func:`aerostat_gym.agents.protocol.protocol`) where they
    mean something: the report suites, or two or more policies on a suite with two or more
    seeds in some cell; else None."""
    suite = results[0]["suite"]
    seeds = max(len({e["seed"] for e in d["episodes"]})
                for d in results[0]["scenarios"].values())
    if suite.startswith("report") or (len(results) >= 2 and seeds >= 2):
        return proto_mod.protocol(results)
    return None


def jsonable(results: list[dict], proto: dict | None = None) -> list[dict]:
    """The results as JSON-ready data: per scenario the episodes and, per wind speed, the mean
    of every metric over the seeds with its 95 % bootstrap interval (``cells``); with the
    protocol's statistics ``proto``, per scenario also ``paired``: per wind speed the paired
    differences of this policy against every baseline (metric -> diff, ci, verdict)."""
    out = []
    for r in results:
        r2 = {k: v for k, v in r.items() if k != "scenarios"}
        r2["scenarios"] = {s: {"episodes": d["episodes"], "cells": cell_means(d["episodes"])}
                           for s, d in r["scenarios"].items()}
        if proto is not None:
            for c in proto["cells"]:
                r2["scenarios"][c["scenario"]].setdefault("paired", []).append(
                    {"wind_speed": c["wind_speed"], **c["paired"].get(r["label"], {})})
        out.append(r2)
    return out


#: Seeds from which a cell's interval is studentized (the protocol's default method).
STUDENTIZED_MIN_SEEDS = proto_mod.STUDENTIZED_MIN_SEEDS


def cell_means(episodes: list[dict]) -> list[dict]:
    """Per wind speed: ``n_seeds`` and, for every numeric metric, its mean over the seeds and
    ``<metric>_ci``, its 95 % bootstrap interval
    (:func:`aerostat_gym.agents.protocol_stats.bootstrap_mean_ci`): studentized from
    :data:`STUDENTIZED_MIN_SEEDS` seeds, percentile below (with two or three seeds the
    studentized interval degenerates: most resamples have no spread); with one seed, or one
    finite value, the interval is the value itself."""
    cells = []
    for u in sorted({e["wind_speed"] for e in episodes}):
        eps = [e for e in episodes if e["wind_speed"] == u]
        cell = {"wind_speed": u, "n_seeds": len(eps)}
        for key in eps[0]:
            vals = [e[key] for e in eps]
            if key in ("wind_speed", "seed") or not all(map(is_number, vals)):
                continue
            x = np.array([v for v in vals if math.isfinite(v)], dtype=float)
            if x.size == 0:
                continue
            if x.size == 1 or np.ptp(x) == 0.0:
                cell[key], cell[key + "_ci"] = float(x[0]), [float(x[0]), float(x[0])]
            else:
                method = "studentized" if x.size >= STUDENTIZED_MIN_SEEDS else "percentile"
                cell.update(bootstrap_mean_ci(x, method=method).as_dict(key))
        cells.append(cell)
    return cells


def given_labels(labels: list[str], policies: list[str]) -> list[str]:
    """The user's names for ``policies`` (one each, in order), checked: as many as policies,
    non-empty, distinct. They keep apart models evaluated in separate runs that would all be
    labelled by their file stem (``ppo_final``), so that the runs can be read back together
    (:func:`load_results` refuses a label twice)."""
    if len(labels) != len(policies):
        raise ValueError(f"--label: {len(labels)} label(s) for {len(policies)} --policy; give "
                         "one per --policy, in the same order")
    blank = [i + 1 for i, lab in enumerate(labels) if not lab.strip()]
    if blank:
        raise ValueError(f"--label: label {blank[0]} is empty")
    twice = sorted({lab for lab in labels if labels.count(lab) > 1})
    if twice:
        raise ValueError(f"--label: {twice[0]!r} is given twice; labels must be distinct")
    return list(labels)


def run_evaluations(policies: list[str], suite: str, progress: bool = True,
                    params=None, speeds=None, labels=None) -> list[dict]:
    """Evaluate every policy on ``suite`` (at ``speeds`` if given) in the environment of
    ``params`` (default baseline), labelled ``labels`` (default :func:`policy_labels`)."""
    labels = policy_labels(policies) if labels is None else given_labels(labels, policies)
    results = []
    for name, label in zip(_progress(policies, progress, "evaluating"), labels, strict=True):
        r = evaluate_policy(name, suite, params=params, speeds=speeds)
        r["label"] = label
        results.append(r)
    return results


def load_results(paths, labels=()) -> dict:
    """{label: result} from the ``report.json`` files of ``aerostat-gym evaluate`` runs (the
    studies that pool several runs read them back this way). A label found twice, or one of
    ``labels`` found nowhere, is a ValueError naming it."""
    results = {}
    for path in paths:
        for r in json.loads(Path(path).read_text()):
            if r["label"] in results:
                raise ValueError(f"label {r['label']!r} appears twice in {list(map(str, paths))}")
            for scenario in r["scenarios"].values():
                scenario["episodes"] = [_nan_for_null(ep) for ep in scenario["episodes"]]
            results[r["label"]] = r
    missing = [lab for lab in labels if lab not in results]
    if missing:
        raise ValueError(f"not in {list(map(str, paths))}: {missing}; labels there: "
                         f"{list(results)}")
    return results


#: The fields of an episode record that hold text or None, not a number.
EPISODE_TEXT_FIELDS = ("ended",)


def _nan_for_null(episode: dict) -> dict:
    """An episode record read back from JSON: a metric that was NaN (no fit, an episode that
    ended early) is written as null (:mod:`aerostat_gym.jsonout`) and is NaN again here."""
    return {k: math.nan if v is None and k not in EPISODE_TEXT_FIELDS else v
            for k, v in episode.items()}


def policy_labels(policies: list[str]) -> list[str]:
    """The label of each policy in tables: a baseline's name, the shipped policy's file stem, a
    saved model's file stem, or (where two models share a stem, e.g. ``ppo_final.zip`` of two
    runs) its run directory and stem. The same policy twice is refused."""
    if len(set(policies)) != len(policies):
        raise ValueError(f"a policy is listed twice: {policies}")
    stems = [Path(n).stem if n.endswith(".zip") else (
        Path(SHIPPED_POLICY).stem if n == "shipped" else n) for n in policies]
    return [f"{Path(n).parent.name}/{st}" if stems.count(st) > 1 and n.endswith(".zip") else st
            for n, st in zip(policies, stems, strict=True)]


def _progress(items, enabled: bool, desc: str):
    if not enabled:
        return items
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover
        return items
    return tqdm(items, desc=desc)


def emit_table(markdown: str, rows, markdown_path=None, json_path=None) -> None:
    """Print a study's Markdown table and write it (and its rows as JSON, NaN as null) where
    asked: the common tail of the study scripts."""
    print(markdown)
    if markdown_path:
        Path(markdown_path).write_text(markdown)
    if json_path:
        Path(json_path).write_text(proto_mod.dumps(rows))
