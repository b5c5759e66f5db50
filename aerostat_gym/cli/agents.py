"""Agent commands: ``train``, ``evaluate`` and ``demo``."""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

from ..agents.evaluate import SUITES
from ..agents.report import comparison_table, jsonable, run_evaluations, write_report
from ..agents.train import ALGOS, train
from ..analysis.modes import analyse
from ..analysis.trim import find_equilibrium
from ..params import load_params
from .common import add_config, config_label, params_from_args

SHIPPED_POLICY = "agents/ppo_tethered_aerostat.zip"


def add_train_parser(sub) -> None:
    p = sub.add_parser("train", help="train a winch-control policy with Stable-Baselines3")
    p.add_argument("--algo", choices=ALGOS, default="ppo")
    p.add_argument("--hyperparams", help="hyperparameter YAML (default agents/hyperparams/ALGO.yml)")
    p.add_argument("--timesteps", type=int, help="total environment steps (default: the YAML)")
    p.add_argument("--n-envs", type=int, help="parallel environments (default: the YAML)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--run-dir", help="output directory (default runs/train/ALGO_seedS_TIME)")
    p.add_argument("--resume", help="checkpoint .zip to continue from")
    p.add_argument("--eval-freq", type=int, help="evaluate on the suite every N steps")
    p.add_argument("--threads", type=int, help="torch threads (default: torch's)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_config(p, json=False)
    p.set_defaults(func=_train_command)


def _train_command(args) -> int:
    params = params_from_args(args) if (args.config or args.set) else None
    run = train(args.algo, args.hyperparams, args.timesteps, args.n_envs, args.seed, args.run_dir,
                args.resume, not args.no_progress, args.threads, args.eval_freq, params=params)
    print(f"run directory: {run}")
    print((run / "training_summary.json").read_text())
    return 0


def add_evaluate_parser(sub) -> None:
    p = sub.add_parser("evaluate", help="evaluate policies on a frozen seed suite")
    p.add_argument("--policy", action="append", required=True,
                   help="passive, tension, lqr or PATH.zip (repeat to compare)")
    p.add_argument("--suite", choices=list(SUITES), default="tiny")
    p.add_argument("--out", default="runs/evaluate", help="report directory")
    p.add_argument("--json", action="store_true", help="print the metrics as JSON")
    p.add_argument("--no-plots", action="store_true")
    add_config(p, json=False)
    p.set_defaults(func=_evaluate_command)


def _evaluate_command(args) -> int:
    results = run_evaluations(args.policy, args.suite, progress=not args.json,
                              params=params_from_args(args))
    md = write_report(results, args.out, f"Evaluation on suite `{args.suite}`",
                      "aerostat-gym " + " ".join(sys.argv[1:]), plots=not args.no_plots)
    if args.json:
        print(json.dumps(jsonable(results), indent=1))
    else:
        print(md.read_text())
        print(f"\nreport: {md}")
    return 0


def add_demo_parser(sub) -> None:
    p = sub.add_parser("demo", help="the main job: trim, stability summary, shipped policy vs "
                                    "baselines on the tiny suite, report in runs/demo/")
    p.add_argument("--wind", type=float, default=10.0, help="wind speed of the summary [m/s]")
    p.add_argument("--policy", default=SHIPPED_POLICY, help="policy to compare (default: shipped)")
    p.add_argument("--out", default="runs/demo")
    p.add_argument("--suite", choices=list(SUITES), default="tiny", help="evaluation suite")
    add_config(p, json=False)
    p.set_defaults(func=_demo_command)


def _demo_command(args) -> int:
    t0 = time.perf_counter()
    params = params_from_args(args)
    policies = ["passive", "lqr"]
    if params == load_params() or args.policy != SHIPPED_POLICY:
        policies.append(_shipped(args.policy))  # the shipped policy was trained on the baseline
    eq = find_equilibrium(params, args.wind)
    s = eq.summary
    print(f"aerostat-gym demo: {config_label(args)}, L = {params.tether.length:g} m, "
          f"U = {args.wind:g} m/s")
    x, _, z = s["aerostat_position_m"]
    print(f"  trim: CM x = {x:.1f} m, z = {z:.1f} m, blow-by {s['blow_by_deg']:.2f} deg, "
          f"pitch {s['pitch_deg']:.2f} deg, winch tension {s['winch_tension_N'] / 1e3:.2f} kN")
    ana = analyse(params, eq)
    print(f"  linear stability: all modes stable = {ana.all_stable()}")
    for subset, label in (("long", "pendulum"), ("long", "pitching"), ("long", "axial spring"),
                          ("lat", "pendulum"), ("lat", "rolling")):
        m = ana.find(subset, label)
        if m is not None:
            name = {"long": "longitudinal", "lat": "lateral"}[subset]
            print(f"    {name:12s} {label:13s} period {m.period:7.2f} s  damping {m.zeta:.3f}")
    results = run_evaluations(policies, args.suite, params=params)
    md = write_report(results, args.out, "aerostat-gym demo", "aerostat-gym demo "
                      + " ".join(sys.argv[1:]))
    print()
    print(comparison_table(results, "recover"))
    print(f"\nreport: {md} ({time.perf_counter() - t0:.0f} s)")
    return 0


def _shipped(path: str) -> str:
    if Path(path).is_file():
        return path
    raise FileNotFoundError(f"policy not found: {path} (run from the repository root, where "
                            "agents/ holds the shipped policy, or pass --policy PATH.zip)")



def add_agent_parsers(sub) -> None:
    """Register ``train``, ``evaluate`` and ``demo``."""
    add_train_parser(sub)
    add_evaluate_parser(sub)
    add_demo_parser(sub)
