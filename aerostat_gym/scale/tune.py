"""``aerostat-gym tune``: Ray Tune trials of the project's own training function over seeds and
a hyperparameter space written in YAML.

The space file is keyed by environment id, as the zoo's hyperparameter files are; each entry is
a fixed value or one distribution (dotted keys reach into mappings such as policy_kwargs)::

    TetheredAerostat-v0:
      learning_rate: {loguniform: [1.0e-4, 1.0e-3]}
      n_epochs: {choice: [5, 10]}
      gamma: {uniform: [0.98, 0.999]}
      policy_kwargs.log_std_init: {uniform: [-3.0, -1.0]}
      n_steps: 128                    # fixed override of the base file

The searcher (Optuna's TPE, or Optuna's random sampler) proposes a configuration and Tune's
``Repeater`` runs it once per seed (``__trial_index__`` picks the seed), so every configuration
is trained with every seed and the searcher learns from the mean over seeds. Each trial calls
:func:`aerostat_gym.agents.train.train` with its seed, its CPUs and its torch / numba threads
pinned, and reports the evaluation-suite score at every evaluation; ASHA (time attribute: the
environment steps) may stop trials early. Outputs: ``trials.csv`` (one row per trial),
``tune_results.csv`` / ``.json`` (per configuration: mean and 95 % bootstrap CI over seeds of
the final and of the best suite score) and ``best/`` (the best checkpoint of the best
configuration with its VecNormalize statistics and its hyperparameter YAML).
"""

from __future__ import annotations

import csv
import json
import math
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numba
import numpy as np

from .. import jsonout
from ..agents.hyperparams import PROJECT_BLOCK
from ..agents.protocol_stats import bootstrap_mean_ci
from ..agents.sb3io import vecnormalize_path
from ..agents.train import train
from ..checks import is_whole
from ..extras import require
from .cluster import start_ray, stop_ray

KINDS = ("uniform", "loguniform", "randint", "quniform", "choice")
SEARCHERS = ("optuna", "random")
SCHEDULERS = ("fifo", "asha")
METRIC = "score"
TIME_ATTR = "timesteps"
SEED_INDEX = "__trial_index__"


class TuneSpaceError(ValueError):
    """A malformed search space (the message names the file and the key)."""


# --- the search space ----------------------------------------------------------------------------


def _check_entry(key: str, spec, path) -> None:
    if not isinstance(spec, dict):
        return  # a fixed value
    if len(spec) != 1 or next(iter(spec)) not in KINDS:
        raise TuneSpaceError(f"{path}: {key!r} must be a value or one of {KINDS} as a "
                             f"single-key mapping, got {spec!r}")
    kind, args = next(iter(spec.items()))
    if kind == "choice":
        if not (isinstance(args, list) and args):
            raise TuneSpaceError(f"{path}: {key!r} choice needs a non-empty list, got {args!r}")
        return
    need = 3 if kind == "quniform" else 2
    if not (isinstance(args, list) and len(args) == need
            and all(isinstance(v, (int, float)) for v in args) and args[0] < args[1]):
        raise TuneSpaceError(f"{path}: {key!r} {kind} needs [low, high{', q' if need == 3 else ''}]"
                             f" numbers with low < high, got {args!r}")
    if kind == "loguniform" and args[0] <= 0:
        raise TuneSpaceError(f"{path}: {key!r} loguniform needs low > 0, got {args!r}")


def load_space(path: str | Path, task: str) -> dict:
    """The search space block for ``TetheredAerostat-v0`` in a YAML file, checked.

    Parameters
    ----------
    path : the space YAML.

    Returns
    -------
    {key: fixed value or {kind: arguments}}.
    """
    import yaml

    path = Path(path)
    if not path.is_file():
        raise TuneSpaceError(f"search space file not found: {path}")
    data = yaml.safe_load(path.read_text()) or {}
    if task not in data or not isinstance(data[task], dict):
        raise TuneSpaceError(f"{path} has no mapping for the base file's task {task!r} (found "
                             f"{sorted(data)})")
    space = dict(data[task])
    for key, spec in space.items():
        _check_entry(key, spec, path)
    if not any(isinstance(v, dict) for v in space.values()):
        raise TuneSpaceError(f"{path}: no distribution to search (every entry is fixed)")
    return space


def _scalar(v) -> bool:
    return v is None or isinstance(v, (bool, int, float, str))


def tune_space(space: dict, tune) -> tuple[dict, dict]:
    """Tune domains for the distributions of ``space``.

    Parameters
    ----------
    space : :func:`load_space` output.
    tune : the ``ray.tune`` module.

    Returns
    -------
    (param_space, decode): choices among non-scalar options (lists such as net_arch) are
    searched over their JSON text, and ``decode`` lists those keys.
    """
    out, decode = {}, set()
    for key, spec in space.items():
        if not isinstance(spec, dict):
            continue
        kind, args = next(iter(spec.items()))
        if kind == "choice":
            if not all(_scalar(v) for v in args):
                args, decode = [json.dumps(v) for v in args], decode | {key}
            out[key] = tune.choice(args)
        elif kind == "randint":
            out[key] = tune.randint(int(args[0]), int(args[1]) + 1)  # inclusive high
        elif kind == "quniform" and all(is_whole(a, 0) for a in args):
            # a grid of whole numbers (n_steps, batch_size: counts the training refuses as
            # floats) samples integers, upper end inclusive like quniform's
            out[key] = tune.qrandint(*args)
        else:
            out[key] = getattr(tune, kind)(*args)
    return out, decode


def apply_sample(base: dict, space: dict, sample: dict, decode=()) -> dict:
    """Hyperparameters of one trial: ``base`` with the space's fixed values and the sampled
    ones set (dotted keys set an entry of a nested mapping).

    Parameters
    ----------
    base : the base hyperparameter block.
    space : :func:`load_space` output.
    sample : sampled values by key (other entries, e.g. the seed index, are ignored).
    decode : keys whose sampled value is JSON text.
    """
    hp = json.loads(json.dumps(base))
    values = {k: v for k, v in space.items() if not isinstance(v, dict)}
    values.update({k: (json.loads(sample[k]) if k in decode else sample[k])
                   for k in space if isinstance(space[k], dict)})
    for key, v in values.items():
        *parents, leaf = key.split(".")
        node = hp
        for p in parents:
            node = node.setdefault(p, {})
            if not isinstance(node, dict):
                raise TuneSpaceError(f"{key!r}: {p!r} is not a mapping in the base hyperparameters")
        node[leaf] = v.item() if isinstance(v, np.generic) else v
    return hp


# --- one trial -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class TrialSetup:
    """What every trial shares.

    Attributes
    ----------
    algo : ppo, sac or td3.
    base : base hyperparameter block.
    space : the search space.
    decode : JSON-coded choice keys.
    seeds : training seeds (one trial each per configuration).
    timesteps : environment steps per trial.
    n_envs : environments per trial (None: the YAML's).
    eval_freq : steps between suite evaluations.
    threads : torch / numba threads per trial.
    """

    algo: str
    base: dict
    space: dict
    decode: frozenset
    seeds: tuple
    timesteps: int
    n_envs: int | None
    eval_freq: int
    threads: int
    task: str = "TetheredAerostat-v0"
    project: dict = field(default_factory=dict)


def trial_hyperparams(setup: TrialSetup, sample: dict, decode=()) -> dict:
    """The hyperparameter block one trial trains with: the base, the space's fixed and sampled
    values, and the trial's step budget (and environment count, if set on the command line).

    Parameters
    ----------
    setup : what every trial shares.
    sample : sampled values by key.
    decode : keys whose sampled value is JSON text.
    """
    hp = apply_sample(setup.base, setup.space, sample, decode)
    hp["n_timesteps"] = setup.timesteps
    if setup.n_envs:
        hp["n_envs"] = setup.n_envs
    return hp


def _pin_threads(threads: int) -> None:
    """One BLAS / torch / numba thread pool of the trial's size (no oversubscription when
    several trials share a node)."""
    import torch

    torch.set_num_threads(threads)
    numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))


def run_trial(config: dict, setup: TrialSetup) -> None:
    """Tune's function trainable: train one configuration with one seed, reporting the score.

    Parameters
    ----------
    config : the sampled values and the seed index.
    setup : what every trial shares.
    """
    from ray import tune

    seed = int(setup.seeds[int(config.get(SEED_INDEX, 0))])
    hp = trial_hyperparams(setup, config, setup.decode)
    trial_dir = Path(tune.get_context().get_trial_dir())
    trial_dir.mkdir(parents=True, exist_ok=True)
    cfg_path = trial_dir / "hyperparams_trial.yml"
    _write_hp(cfg_path, hp, setup)
    _pin_threads(setup.threads)

    def report(record: dict, run: Path) -> None:
        metrics = {METRIC: record["score"], TIME_ATTR: record["timesteps"], "seed": seed}
        if not record["best"]:
            tune.report(metrics)
            return
        with tempfile.TemporaryDirectory() as tmp:
            for f in (run / "best_model.zip", vecnormalize_path(run / "best_model.zip")):
                if f.is_file():
                    shutil.copy2(f, tmp)
            tune.report(metrics, checkpoint=tune.Checkpoint.from_directory(tmp))

    train(setup.algo, cfg_path, setup.timesteps, setup.n_envs, seed, trial_dir / "run",
          progress_bar=False, threads=setup.threads, eval_freq=setup.eval_freq, on_eval=report)


def _write_hp(path: Path, hp: dict, setup: TrialSetup) -> None:
    """A trial's hyperparameter file, in the format of the base file (task block, project
    block)."""
    import yaml

    path.write_text(yaml.safe_dump({setup.task: hp, PROJECT_BLOCK: setup.project},
                                   sort_keys=False))


# --- the search ----------------------------------------------------------------------------------


def _searcher(name: str, seed: int, repeat: int):
    require("optuna", "the Optuna searcher", "ray")
    import optuna
    from ray.tune.search import Repeater
    from ray.tune.search.optuna import OptunaSearch

    if name not in SEARCHERS:
        raise ValueError(f"unknown searcher {name!r}; choose one of {SEARCHERS}")
    sampler = (optuna.samplers.TPESampler(seed=seed) if name == "optuna"
               else optuna.samplers.RandomSampler(seed=seed))
    return Repeater(OptunaSearch(sampler=sampler, metric=METRIC, mode="max"), repeat=repeat,
                    set_index=True)


def _scheduler(name: str, timesteps: int, eval_freq: int):
    from ray.tune.schedulers import ASHAScheduler, FIFOScheduler

    if name == "fifo":
        return FIFOScheduler()
    if name == "asha":
        return ASHAScheduler(time_attr=TIME_ATTR, max_t=timesteps,
                             grace_period=min(eval_freq, timesteps), reduction_factor=2)
    raise ValueError(f"unknown scheduler {name!r}; choose one of {SCHEDULERS}")


@dataclass(frozen=True)
class SearchOptions:
    """How to search.

    Attributes
    ----------
    configs : configurations to try (each trained once per seed).
    searcher : optuna (TPE) or random.
    scheduler : fifo or asha.
    search_seed : seed of the sampler.
    cpus_per_trial : CPUs reserved per trial.
    address : cluster to join (None: a local instance).
    workers : CPUs of the local instance (None: the machine's).
    """

    configs: int
    searcher: str = "optuna"
    scheduler: str = "fifo"
    search_seed: int = 0
    cpus_per_trial: float = 1.0
    address: str | None = None
    workers: int | None = None


def run_search(setup: TrialSetup, opts: SearchOptions, out: Path) -> dict:
    """Run the trials, gather the table and copy the best checkpoint.

    Parameters
    ----------
    setup : what every trial shares.
    opts : how to search.
    out : output directory (Ray's trial directories go to ``out/ray``).

    Returns
    -------
    {"trials": [...], "table": [...], "best": {...}, "files": [...]}.
    """
    if opts.configs < 1 or not setup.seeds:
        raise ValueError(f"need --configs >= 1 and at least one seed, got {opts.configs} and "
                         f"{list(setup.seeds)}")
    start = start_ray("Ray Tune", opts.address, opts.workers)
    try:
        tune = require("ray.tune", "Ray Tune", "ray")
        space, decode = tune_space(setup.space, tune)
        setup = TrialSetup(**{**setup.__dict__, "decode": frozenset(decode)})
        results = _fit(setup, opts, space, out.resolve())
    finally:
        stop_ray(start)
    trials = [_trial_row(r, setup) for r in results]
    table = config_table(trials)
    best = _copy_best(trials, table, setup, out)
    files = _write_tables(trials, table, best, out)
    return {"trials": trials, "table": table, "best": best, "files": files}


def _fit(setup: TrialSetup, opts: SearchOptions, space: dict, out: Path):
    from ray import tune

    trainable = tune.with_resources(tune.with_parameters(run_trial, setup=setup),
                                    {"cpu": opts.cpus_per_trial})
    tuner = tune.Tuner(
        trainable, param_space=space,
        tune_config=tune.TuneConfig(
            metric=METRIC, mode="max", num_samples=opts.configs * len(setup.seeds),
            search_alg=_searcher(opts.searcher, opts.search_seed, len(setup.seeds)),
            scheduler=_scheduler(opts.scheduler, setup.timesteps, setup.eval_freq)),
        run_config=tune.RunConfig(
            name="ray", storage_path=str(out), verbose=0,
            checkpoint_config=tune.CheckpointConfig(num_to_keep=1, checkpoint_score_attribute=METRIC,
                                                    checkpoint_score_order="max")))
    return tuner.fit()


def _trial_row(result, setup: TrialSetup) -> dict:
    """One trial: its sampled values (JSON-coded choices decoded), seed, final and best
    score, steps, best checkpoint."""
    cfg = {k: (json.loads(v) if k in setup.decode else v) for k, v in result.config.items()
           if k != SEED_INDEX}
    df = result.metrics_dataframe
    scores = df[METRIC].to_numpy(float) if df is not None and METRIC in df else np.array([])
    ckpt = result.get_best_checkpoint(METRIC, "max") if result.best_checkpoints else None
    return {"config": json.dumps(cfg, sort_keys=True),
            "seed": int(setup.seeds[int(result.config.get(SEED_INDEX, 0))]),
            "final_score": float(scores[-1]) if scores.size else math.nan,
            "best_score": float(scores.max()) if scores.size else math.nan,
            "timesteps": int(df[TIME_ATTR].iloc[-1]) if scores.size else 0,
            "evaluations": int(scores.size),
            "error": str(result.error) if result.error else "",
            "checkpoint": ckpt.path if ckpt is not None else "",
            "trial_dir": str(result.path)}


def config_table(trials: list[dict], n_boot: int = 10_000) -> list[dict]:
    """Per configuration: seeds, mean and 95 % percentile-bootstrap CI over seeds of the final
    and of the best suite score; sorted by mean final score (best first).

    Parameters
    ----------
    trials : rows of :func:`_trial_row` (keys config, seed, final_score, best_score).
    n_boot : bootstrap resamples.
    """
    groups: dict = {}
    for t in trials:
        if math.isfinite(t["final_score"]):
            groups.setdefault(t["config"], []).append(t)
    rows = []
    for cfg, ts in groups.items():
        row = {"config": cfg, "seeds": sorted(t["seed"] for t in ts), "n_seeds": len(ts)}
        for name in ("final_score", "best_score"):
            x = np.array([t[name] for t in ts])
            lo, hi = _seed_interval(x, n_boot)
            row.update({f"{name}_mean": float(x.mean()), f"{name}_ci95_low": lo,
                        f"{name}_ci95_high": hi})
        rows.append(row)
    return sorted(rows, key=lambda r: -r["final_score_mean"])


def _seed_interval(x: np.ndarray, resamples: int) -> tuple[float, float]:
    """95 % percentile-bootstrap interval of the mean over seeds (the rliable-style interval
    of the protocol statistics); a single seed gives the point itself."""
    if x.size == 1:
        return float(x[0]), float(x[0])
    ci = bootstrap_mean_ci(x, resamples=resamples, method="percentile")
    return ci.low, ci.high


def _copy_best(trials: list[dict], table: list[dict], setup: TrialSetup, out: Path) -> dict:
    """Copy the best-scoring checkpoint of the best configuration (by mean final score) to
    ``out/best`` with its VecNormalize statistics and hyperparameters."""
    if not table:
        return {}
    cfg = table[0]["config"]
    cands = [t for t in trials if t["config"] == cfg and t["checkpoint"]]
    if not cands:
        return {"config": cfg}
    top = max(cands, key=lambda t: t["best_score"])
    dest = out / "best"
    if dest.exists():
        shutil.rmtree(dest)
    shutil.copytree(top["checkpoint"], dest)
    _write_hp(dest / "hyperparams.yml", trial_hyperparams(setup, json.loads(cfg)), setup)
    return {"config": cfg, "seed": top["seed"], "best_score": top["best_score"],
            "model": str(dest / "best_model.zip"),
            "vecnormalize": str(vecnormalize_path(dest / "best_model.zip"))}


def _csv(path: Path, rows: list[dict]) -> None:
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def _write_tables(trials: list[dict], table: list[dict], best: dict, out: Path) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    files = []
    if trials:
        _csv(out / "trials.csv", trials)
        files.append(out / "trials.csv")
    if table:
        _csv(out / "tune_results.csv", table)
        files.append(out / "tune_results.csv")
    (out / "tune_results.json").write_text(jsonout.dumps(
        {"table": table, "trials": trials, "best": best}, indent=1))
    files.append(out / "tune_results.json")
    return files
