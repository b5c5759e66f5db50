"""Agent commands: ``train``, ``evaluate`` and ``demo``."""

from __future__ import annotations

import math
import sys
import time

from .. import jsonout
from ..agents.evaluate import SUITES, cells_wind_range, suite_cells
from ..agents.hyperparams import ALGOS
from ..agents.policies import BASELINES, SHIPPED, load_policy
from ..agents.report import (
    comparison_table,
    given_labels,
    jsonable,
    protocol_for,
    run_evaluations,
    write_report,
)
from ..agents.train import train
from ..analysis.modes import SET_NAMES, analyse
from ..analysis.trim import find_equilibrium
from ..envs.batch import trim_table
from ..envs.config import TaskConfig
from ..extras import require_plotting
from ..params import load_params
from ..registration import TASKS
from .common import (
    add_config,
    config_label,
    nonneg_float,
    output_dir,
    params_from_args,
    positive_int,
    seed_int,
)
from .stability import eigenvalue_text


def add_train_parser(sub) -> None:
    p = sub.add_parser("train", help="train a winch-control policy with Stable-Baselines3",
                       description="Train on the task the hyperparameter file is keyed by "
                       f"(one of {', '.join(TASKS)}).")
    p.add_argument("--algo", choices=ALGOS, default="ppo", help="Stable-Baselines3 algorithm")
    p.add_argument("--hyperparams", metavar="YAML",
                   help="rl-zoo3 hyperparameter file, or a shipped one's name such as "
                   "ppo_realistic.yml (default: the shipped ALGO.yml)")
    p.add_argument("--timesteps", type=positive_int,
                   help="total environment steps (default: the YAML's)")
    p.add_argument("--n-envs", type=positive_int, help="parallel environments (default: the YAML's)")
    p.add_argument("--seed", type=seed_int, default=0, help="training seed")
    p.add_argument("--run-dir", help="output directory (default runs/train/ALGO_seedS_TIME)")
    p.add_argument("--resume", metavar="ZIP", help="checkpoint to continue from")
    p.add_argument("--eval-freq", type=positive_int,
                   help="environment steps between suite evaluations (default: the YAML's)")
    p.add_argument("--threads", type=positive_int, help="torch threads (default: torch's own)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_config(p, json=False)
    p.set_defaults(func=_train_command)


def _train_command(args) -> int:
    params = params_from_args(args) if (args.config or args.set) else None
    run = train(args.algo, args.hyperparams, args.timesteps, args.n_envs, args.seed,
                args.run_dir, args.resume, not args.no_progress, args.threads, args.eval_freq,
                params=params)
    print(f"run directory: {run}")
    print((run / "training_summary.json").read_text())
    return 0


def add_evaluate_parser(sub) -> None:
    p = sub.add_parser("evaluate", help="evaluate policies on a frozen seed suite")
    p.add_argument("--policy", action="append", required=True,
                   help=f"{', '.join(BASELINES)}, shipped or PATH.zip (repeat to compare)")
    p.add_argument("--suite", choices=list(SUITES), default="tiny",
                   help="frozen seed suite (scenario: wind speeds, seeds); 'report' is the "
                   "protocol of the README's baseline table (writes protocol.md)")
    p.add_argument("--speeds", type=nonneg_float, nargs="+", metavar="U",
                   help="run every scenario of the suite at these mean wind speeds [m/s] "
                   "instead of its own (same seeds, noise and durations; the baselines are "
                   "scheduled over the range that covers them)")
    p.add_argument("--label", action="append", metavar="NAME",
                   help="name of each --policy in the tables and report.json, one per --policy "
                   "in order (default: a baseline's name, a model's file stem, or its run "
                   "directory and stem where two stems clash); keeps models evaluated in "
                   "separate runs apart when the runs are read back together")
    p.add_argument("--out", default="runs/evaluate", help="report directory")
    p.add_argument("--json", action="store_true", help="print the metrics as JSON")
    p.add_argument("--no-plots", action="store_true", help="write no PNG plots")
    add_config(p, json=False)
    p.set_defaults(func=_evaluate_command)


def _check_policies(names) -> None:
    """Refuse an unknown name or a missing or corrupt policy file before any work (the
    baselines are designed per run, so only the learned policies are loaded here; the shipped
    ones last, so a mistyped path is named at once, not after a shipped policy's load)."""
    for name in sorted(names, key=lambda n: n in SHIPPED):
        if name in BASELINES:
            continue
        try:
            load_policy(name)
        except (ValueError, OSError) as exc:
            raise ValueError(f"--policy {name}: {exc}") from None


def _check_suite_winds(suite: str, speeds, params) -> None:
    """Refuse, before any episode, a suite whose wind speeds (its own or ``--speeds``) include
    one whose trim the configured tether cannot hold, naming the way out."""
    try:
        winds = cells_wind_range(suite_cells(suite, speeds), params)
        trim_table(TaskConfig.from_kwargs(wind_speed=winds, params=params))
    except ValueError as exc:
        if speeds is not None:
            raise ValueError(f"--speeds: {exc}") from None
        raise ValueError(f"--suite {suite}: {exc}; run its scenarios at wind speeds this "
                         "aerostat holds with --speeds U [U ...]") from None


def _evaluate_command(args) -> int:
    if not args.no_plots:
        require_plotting("writing evaluate's plots (--no-plots skips them)")
    if args.label is not None:
        given_labels(args.label, args.policy)
    _check_policies(args.policy)
    params = params_from_args(args)
    _check_suite_winds(args.suite, args.speeds, params)
    out = output_dir(args.out)
    results = run_evaluations(args.policy, args.suite, progress=not args.json, params=params,
                              speeds=args.speeds, labels=args.label)
    md = write_report(results, out, f"Evaluation on suite `{args.suite}`",
                      "aerostat-gym " + " ".join(sys.argv[1:]), plots=not args.no_plots)
    if args.json:
        print(jsonout.dumps(jsonable(results, protocol_for(results)), indent=1))
    else:
        for scenario in results[0]["scenarios"]:
            print(f"{scenario}:\n{comparison_table(results, scenario)}\n")
        print(f"report (Markdown, {'' if args.no_plots else 'plots, '}JSON): {md}")
        if (md.parent / "protocol.md").is_file():
            print(f"protocol (per-cell CIs, paired verdicts, aggregate IQM): "
                  f"{md.parent / 'protocol.md'}")
    return 0


def add_demo_parser(sub) -> None:
    p = sub.add_parser("demo", help="the main job: trim, stability summary, shipped policy vs "
                                    "baselines on the tiny suite (baselines only on a "
                                    "non-baseline aerostat), report in runs/demo/")
    p.add_argument("--wind", type=nonneg_float, default=10.0,
                   help="wind speed of the summary [m/s]")
    p.add_argument("--policy", default="shipped",
                   help="policy to compare with passive and lqr: shipped, a baseline's "
                   "name or PATH.zip")
    p.add_argument("--out", default="runs/demo", help="report directory")
    p.add_argument("--suite", choices=list(SUITES), default="tiny", help="evaluation suite")
    p.add_argument("--speeds", type=nonneg_float, nargs="+", metavar="U",
                   help="run the suite's scenarios at these mean wind speeds [m/s] instead of "
                   "its own (as evaluate --speeds)")
    add_config(p, json=False)
    p.set_defaults(func=_demo_command)


def _demo_command(args) -> int:
    t0 = time.perf_counter()
    require_plotting("writing the demo's report plots")
    _check_policies([args.policy])
    params = params_from_args(args)
    policies = ["passive", "lqr"]
    # the shipped policy was trained on the baseline aerostat: on another one it is left out
    shipped_left_out = args.policy == "shipped" and params != load_params()
    if not shipped_left_out and args.policy not in policies:
        policies.append(args.policy)
    _check_suite_winds(args.suite, args.speeds, params)
    out = output_dir(args.out)
    summary = demo_summary(params, args.wind, config_label(args))
    if shipped_left_out:
        summary.append("  shipped policy left out: it was trained on the baseline aerostat; "
                       "this run compares the baselines (passive, lqr) only (--policy "
                       "PATH.zip adds a policy trained on this aerostat)")
    print("\n".join(summary))
    results = run_evaluations(policies, args.suite, params=params, speeds=args.speeds)
    md = write_report(results, out, "aerostat-gym demo",
                      "aerostat-gym demo " + " ".join(sys.argv[1:]),
                      preamble=["## Trim and linear stability", "", "```", *summary, "```", ""])
    for scenario in results[0]["scenarios"]:
        print(f"\n{scenario}:\n{comparison_table(results, scenario)}")
    print(f"\nreport (Markdown, plots, JSON): {md} ({time.perf_counter() - t0:.0f} s)")
    return 0


#: The modes the demo's summary always lists: [LN02] Table 2's four and the axial spring.
DEMO_MODES = (("long", "pendulum"), ("long", "pitching"), ("long", "axial spring"),
              ("lat", "pendulum"), ("lat", "rolling"))


def demo_summary(params, wind: float, label: str = "baseline") -> list[str]:
    """The demo's trim and linear-stability summary, as lines of text: the modes of
    :data:`DEMO_MODES` and then every unstable mode, so that "all modes stable = False" always
    names its culprits."""
    eq = find_equilibrium(params, wind)
    s = eq.summary
    x, _, z = s["aerostat_position_m"]
    lines = [f"aerostat-gym demo: {label}, L = {params.tether.length:g} m, U = {wind:g} m/s",
             f"  trim: CM x = {x:.1f} m, z = {z:.1f} m, blow-by {s['blow_by_deg']:.2f} deg, "
             f"pitch {s['pitch_deg']:.2f} deg, winch tension {s['winch_tension_N'] / 1e3:.2f} kN"]
    ana = analyse(params, eq)
    lines.append(f"  linear stability: all modes stable = {ana.all_stable()}")
    for subset, label_ in DEMO_MODES:
        m = ana.find(subset, label_)
        if m is not None:
            name = SET_NAMES[subset]
            lines.append(f"    {name:12s} {label_:13s} {m.describe()}")
    return lines + unstable_mode_lines(ana)


def unstable_mode_lines(ana) -> list[str]:
    """One line per unstable mode of a :class:`ModalAnalysis`, listed above or not: its set,
    label, eigenvalue and the time its amplitude takes to double, ln 2 / Re(lambda) (the
    growth of a real root and the envelope of an oscillatory one alike)."""
    return [f"    UNSTABLE {SET_NAMES[subset]:12s} {m.label:13s} lambda = "
            f"{eigenvalue_text(m.eigenvalue)} 1/s, doubles in "
            f"{math.log(2.0) / m.eigenvalue.real:.3g} s"
            for subset in ("long", "lat") for m in getattr(ana, subset) if not m.stable]


def add_agent_parsers(sub) -> None:
    """Register ``train``, ``evaluate`` and ``demo``."""
    add_train_parser(sub)
    add_evaluate_parser(sub)
    add_demo_parser(sub)
