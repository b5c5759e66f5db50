"""Command-line front end of the Ray integration: ``tune`` and ``montecarlo``.

The main CLI calls :func:`add_tune_parser` and :func:`add_montecarlo_parser`. Handlers return
an exit status; bad input raises ValueError and a missing extra raises
:class:`~aerostat_gym.extras.MissingExtraError` (a RuntimeError), both of which the main
CLI prints as one line and turns into exit status 2.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from .. import jsonout
from ..agents.hyperparams import ALGOS, load_hyperparams
from ..extras import require, require_plotting
from ..resources import shipped_path
from ..scale.bench import format_throughput, throughput
from ..scale.mc_report import summarize, write_outputs
from ..scale.montecarlo import (
    PERIOD_KEYS,
    SWEEP_SPEEDS,
    check_samples,
    evaluate_sample,
    run_ray,
    run_serial,
)
from ..scale.ranges import RANGE_SOURCES, estimated_ranges
from ..scale.tune import SCHEDULERS, SEARCHERS, SearchOptions, TrialSetup, load_space, run_search
from .common import config_label, positive_float, positive_int, seed_int

# the stability commands' parsing of --wind, --config and --set, shared rather than copied
from .stability import parse_speeds
from .stability import stability_params as params_from_args


def add_montecarlo_parser(sub) -> None:
    """Register ``aerostat-gym montecarlo``.

    Parameters
    ----------
    sub : the main parser's subparsers object.
    """
    p = sub.add_parser("montecarlo", help="Monte Carlo stability study over the estimated "
                       "parameters (Ray tasks, or --serial)")
    p.add_argument("--samples", type=positive_int, default=100, help="parameter sets (default 100)")
    p.add_argument("--seed", type=seed_int, default=0, help="sampling seed (default 0)")
    p.add_argument("--serial", action="store_true", help="run in this process, without Ray")
    p.add_argument("--address", help="join this Ray cluster (e.g. auto, HOST:6379, "
                   "ray://HOST:10001) instead of starting a local one")
    p.add_argument("--workers", type=positive_int, help="CPUs of the local Ray instance (default: all)")
    p.add_argument("--batch-size", type=positive_int, help="parameter sets per Ray task")
    p.add_argument("--wind", help="wind speeds START:STOP[:STEP] [m/s] (default 0.5:20:0.5, "
                   "the Figure 9 grid without U = 0)")
    p.add_argument("--ranges", choices=RANGE_SOURCES, default="documented",
                   help="documented plausible ranges (sensitivity table, default) or the "
                   "domain-randomisation half-ranges")
    p.add_argument("--config", help="base parameter TOML (default: the shipped baseline)")
    p.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override one base parameter (repeatable)")
    p.add_argument("--out", help="output directory (default runs/montecarlo/seedS_nN)")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.add_argument("--no-plot", action="store_true", help="skip the figure")
    p.add_argument("--bench", action="store_true", help="measure serial vs Ray throughput "
                   "and Ray start-up on --samples sets, print them, write nothing else")
    p.add_argument("--repeats", type=positive_int, default=3, help="--bench: alternated serial and "
                   "Ray runs (default 3)")
    p.set_defaults(func=montecarlo_command)


def add_tune_parser(sub) -> None:
    """Register ``aerostat-gym tune``.

    Parameters
    ----------
    sub : the main parser's subparsers object.
    """
    p = sub.add_parser("tune", help="Ray Tune: multi-seed hyperparameter search with the "
                       "project's training function")
    add_tune_arguments(p)
    p.set_defaults(func=run_tune_command)


def _speeds(text: str | None) -> np.ndarray:
    return np.asarray(SWEEP_SPEEDS, float) if text is None else parse_speeds(text)


def _progress(done: int, n: int) -> None:
    if done == n or done % max(1, n // 20) == 0:
        print(f"  {done}/{n} parameter sets", file=sys.stderr, flush=True)


def montecarlo_command(args: argparse.Namespace) -> int:
    """Run the study (or its throughput benchmark) and print the summary."""
    check_samples(args.samples)
    if not (args.bench or args.no_plot):
        require_plotting("the Monte Carlo figure (--no-plot skips it)")
    base = params_from_args(args)
    ranges = estimated_ranges(base, args.ranges)
    speeds = _speeds(args.wind)
    if args.bench:
        res = throughput(base, ranges, args.samples, args.seed, speeds, args.workers or 2,
                         args.batch_size, args.repeats)
        print(jsonout.dumps(res, indent=2) if args.json else format_throughput(res))
        return 0
    if args.serial:
        study = run_serial(base, ranges, args.samples, args.seed, speeds, _progress)
    else:
        study = run_ray(base, ranges, args.samples, args.seed, speeds, args.address,
                        args.workers, args.batch_size, _progress)
    study.meta["ranges"] = args.ranges
    study.meta["configuration"] = config_label(args)
    nominal = evaluate_sample(base, ranges, np.array([r.nominal for r in ranges]), study.speeds)
    summary = summarize(study, nominal)
    out = Path(args.out or f"runs/montecarlo/seed{args.seed}_n{args.samples}")
    files = write_outputs(study, summary, out, plot=not args.no_plot)
    if args.json:
        print(jsonout.dumps(summary, indent=1, default=float))
    else:
        print(format_summary(summary))
        print("wrote " + ", ".join(str(f) for f in files))
    return 0


def _pct(x: float) -> str:
    return f"{100 * x:5.1f}" if math.isfinite(x) else "  -  "


def format_summary(s: dict) -> str:
    """The study's summary as text."""
    ev = s["stable_everywhere"]
    lo, hi = ev["ci95"]
    lines = [
        f"Monte Carlo on {s['meta'].get('configuration', 'baseline')}: {s['samples']} parameter "
        f"sets ({s['meta'].get('ranges', 'documented')} "
        f"ranges, seed {s['seed']}), {s['backend']}: {s['seconds']:.1f} s, "
        f"{s['sets_per_s']:.2f} sets/s",
        f"stable at every wind speed: {ev['count']}/{s['samples']} = {100 * ev['fraction']:.1f} %"
        f" (95 % CI {100 * lo:.1f}-{100 * hi:.1f} %); complete sweeps {s['complete']}, "
        f"failed {s['n_errors']}",
    ]
    if s["rejected_draws"]:
        lines.append(f"redrawn: {s['rejected_draws']} draws that are no valid aerostat (first: "
                     f"{s['rejections'][0]})")
    lines += _probability_lines(s)
    lines.append("Table 2 periods at 1 m/s [s]: median [5 %, 95 %] (sets where the mode "
                 "oscillates)")
    for key in PERIOD_KEYS:
        d = s["periods_s"][key]
        if d["n"]:
            lines.append(f"  {key:14s} {d['p50']:8.3f} [{d['p5']:.3f}, {d['p95']:.3f}]  "
                         f"n = {d['n']}")
    z = s["min_zeta"]
    if z["n"]:
        lines.append(f"smallest damping ratio: median {z['p50']:.4f} [5 %: {z['p5']:.4f}, "
                     f"95 %: {z['p95']:.4f}]; {z['divergences']} sets with a divergence "
                     "(a real positive eigenvalue, zeta = -1)")
    lines.append("parameters vs instability: r (unstable somewhere; '-' when every set is "
                 "stable), Spearman rho (max Re lambda), unstable rate in the low / high fifth "
                 "of the range")
    if not s["correlations"]:
        lines.append(f"  none: the correlations need 2 complete sweeps, {s['complete']} ran")
    elif s["stable_everywhere"]["fraction_of_complete"] == 0:
        lines.append(f"  r '-': all {s['complete']} complete sweeps are unstable somewhere (r "
                     "needs both outcomes)")
    for r in s["correlations"]:
        lines.append(f"  {r['parameter']:26s} r {_corr(r['r_unstable'], '+.3f')}  rho "
                     f"{_corr(r['rho_max_real'], '+.3f')}  {_pct(r['unstable_rate_low_fifth'])} %"
                     f" / {_pct(r['unstable_rate_high_fifth'])} %")
    lines += [_mode_instability_line(m, s["samples"]) for m in s["mode_instabilities"]]
    return "\n".join(lines)


def _corr(value: float, spec: str) -> str:
    """A correlation, or '-' where it is undefined (an outcome or a parameter is constant)."""
    return format(value, spec) if math.isfinite(value) else f"{'-':>6s}"


def _mode_instability_line(m: dict, samples: int) -> str:
    """Where a mode is unstable, counted as the probability table counts (every set, at the
    speeds its sweep reached), and the parameter its instability follows over the complete
    sweeps, or why none can be named. Where a sweep failed, the line says what it counts."""
    u = m["speeds_m_s"]
    partial = m["complete"] < samples
    count = (f"{m['samples_unstable']} of {samples} sets (failed sweeps counted up to where "
             "they failed)" if partial else f"{m['samples_unstable']} sets")
    over = f" over the {m['complete']} complete sweeps" if partial else ""
    follows = (f"follows {m['top_parameter']} (r {m['r']:+.2f}{over})"
               if m["top_parameter"] is not None else f"no parameter named: {m['no_r']}")
    return (f"  unstable {m['mode']}: {count}, at {len(u)} speeds in {min(u):g}-{max(u):g} m/s; "
            f"{follows}")


def _probability_lines(s: dict) -> list[str]:
    """P(stable) in percent at the speeds where some mode is below 100 %, for 'all modes' and
    every mode that is ever below 100 %."""
    table: dict = {}
    for r in s["stability"]:
        table.setdefault(r["mode"], {})[r["wind_speed_m_s"]] = r["p_stable"]
    shown = [m for m, row in table.items()
             if m == "all modes" or any(math.isfinite(v) and v < 1 for v in row.values())]
    speeds = [u for u in s["speeds_m_s"] if any(table[m][u] < 1 for m in shown)]
    if not speeds:
        return ["probability of stability: 100 % for every mode at every speed of the sweep"]
    out = ["probability of stability [%] where it is below 100 % (100 % at every other speed)",
           f"  {'U [m/s]':>8s}" + "".join(f"{m:>26s}" for m in shown)]
    for u in speeds:
        out.append(f"  {u:8g}" + "".join(f"{_pct(table[m][u]):>26s}" for m in shown))
    return out


# --- tune ----------------------------------------------------------------------------------------


def add_tune_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``aerostat-gym tune``.

    Parameters
    ----------
    p : the tune subparser.
    """
    p.add_argument("--algo", choices=ALGOS, default="ppo", help="Stable-Baselines3 algorithm")
    p.add_argument("--hyperparams", metavar="YAML",
                   help="base hyperparameter file (default: the shipped hyperparams/ALGO.yml)")
    p.add_argument("--space", metavar="YAML",
                   help="search space YAML, keyed by the base file's task id (default: the "
                   "shipped hyperparams/ALGO_space.yml, for ppo)")
    p.add_argument("--seeds", type=seed_int, nargs="+", default=[0, 1, 2, 3, 4],
                   help="training seeds; every configuration runs each (default 0-4)")
    p.add_argument("--configs", type=positive_int, default=4, help="configurations to try (default 4)")
    p.add_argument("--searcher", choices=SEARCHERS, default="optuna",
                   help="how configurations are proposed (Ray Tune search algorithm)")
    p.add_argument("--scheduler", choices=SCHEDULERS, default="fifo",
                   help="trial scheduler (fifo: every trial runs to the end)")
    p.add_argument("--search-seed", type=seed_int, default=0, help="seed of the sampler")
    p.add_argument("--timesteps", type=positive_int, help="steps per trial (default: the YAML)")
    p.add_argument("--n-envs", type=positive_int, help="environments per trial (default: the YAML)")
    p.add_argument("--eval-freq", type=positive_int, help="steps between suite evaluations (default: "
                   "the YAML)")
    p.add_argument("--cpus-per-trial", type=positive_float, default=1.0,
                   help="CPUs Ray reserves for each trial")
    p.add_argument("--threads", type=positive_int, default=1, help="torch / numba threads per trial")
    p.add_argument("--address", help="join this Ray cluster instead of starting a local one")
    p.add_argument("--workers", type=positive_int, help="CPUs of the local Ray instance (default: all)")
    p.add_argument("--out", default="runs/tune", help="output directory (default runs/tune)")
    p.add_argument("--json", action="store_true", help="print the results as JSON")


def shipped_space(algo: str) -> Path:
    """The shipped search space of ``algo`` (``hyperparams/ALGO_space.yml``), for the shipped
    base file's task."""
    try:
        return shipped_path("hyperparams", f"{algo}_space.yml")
    except FileNotFoundError:
        raise ValueError(f"--space: no search space ships for {algo}; pass --space YAML") from None


def setup_from_args(args: argparse.Namespace) -> TrialSetup:
    """The shared trial setup from the command line (reads both YAML files)."""
    task, base, project = load_hyperparams(args.algo, args.hyperparams)
    space = load_space(args.space or shipped_space(args.algo), task)
    timesteps = int(args.timesteps or base.get("n_timesteps", 1e6))
    if timesteps < 1 or args.threads < 1:
        raise ValueError(f"--timesteps and --threads must be >= 1, got {timesteps}, {args.threads}")
    return TrialSetup(args.algo, base, space, frozenset(), tuple(args.seeds), timesteps,
                      args.n_envs, int(args.eval_freq or project.get("eval_freq", 50_000)),
                      args.threads, task, project)


def run_tune_command(args: argparse.Namespace) -> int:
    """``aerostat-gym tune``: run the search and print the per-configuration table."""
    require("ray.tune", "the hyperparameter search (Ray Tune)", "ray")
    require("optuna", "the hyperparameter search (Optuna)", "ray")
    require("stable_baselines3", "training", "train")
    setup = setup_from_args(args)
    opts = SearchOptions(args.configs, args.searcher, args.scheduler, args.search_seed,
                         args.cpus_per_trial, args.address, args.workers)
    res = run_search(setup, opts, Path(args.out))
    if args.json:
        print(jsonout.dumps({k: res[k] for k in ("table", "best")}, indent=1))
        return 0
    print(format_table(res["table"]))
    if res["best"].get("model"):
        print(f"best checkpoint (seed {res['best']['seed']}, score {res['best']['best_score']:.3f}):"
              f" {res['best']['model']} with {res['best']['vecnormalize']}")
    print("wrote " + ", ".join(str(f) for f in res["files"]))
    return 0


def format_table(table: list[dict]) -> str:
    """Per-configuration table as text."""
    lines = [f"{'final score (95 % CI)':>30s} {'best score (95 % CI)':>30s} seeds  configuration"]
    for r in table:
        f = (f"{r['final_score_mean']:9.3f} [{r['final_score_ci95_low']:.3f}, "
             f"{r['final_score_ci95_high']:.3f}]")
        b = (f"{r['best_score_mean']:9.3f} [{r['best_score_ci95_low']:.3f}, "
             f"{r['best_score_ci95_high']:.3f}]")
        lines.append(f"{f:>30s} {b:>30s} {r['n_seeds']:5d}  {r['config']}")
    return "\n".join(lines)
