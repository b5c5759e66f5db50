"""``aerostat-gym train``: Stable-Baselines3 training on the native batched environment.

Hyperparameters come from rl-baselines3-zoo style YAML (one block per environment id; keys:
``n_timesteps``, ``n_envs``, ``policy``, ``normalize`` (bool or VecNormalize kwargs),
``policy_kwargs`` (a mapping), ``env_kwargs``, ``eval_freq``, ``eval_suite``, ``noise_type`` /
``noise_std`` for TD3, the rest passed to the algorithm). Each run directory holds the resolved
parameter TOML, the hyperparameters, the command, the package version, TensorBoard logs,
checkpoints (model + VecNormalize statistics), the best model on the fixed evaluation suite
and the final model.
"""

from __future__ import annotations

import json
import platform
import shlex
import sys
import time
from pathlib import Path

import numpy as np

from .. import __version__
from ..params import dumps_toml
from ..registration import ENV_ID

ALGOS = ("ppo", "sac", "td3")
HYPERPARAMS_DIR = Path("agents/hyperparams")
VECNORM_SUFFIX = "_vecnormalize.pkl"
RESERVED = {"n_timesteps", "n_envs", "policy", "normalize", "env_kwargs", "eval_freq",
            "eval_suite", "noise_type", "noise_std", "policy_kwargs"}


class TrainingError(ValueError):
    """Bad training configuration (the message names the key or file)."""


def load_hyperparams(algo: str, path: str | Path | None = None) -> dict:
    """The block for ``TetheredAerostat-v0`` in the YAML file (default agents/hyperparams/ALGO.yml,
    falling back to the copy shipped in the package)."""
    import yaml

    if algo not in ALGOS:
        raise TrainingError(f"unknown algorithm {algo!r}; choose one of {ALGOS}")
    if path is None:
        path = HYPERPARAMS_DIR / f"{algo}.yml"
        if not path.is_file():
            from importlib import resources

            path = Path(str(resources.files("aerostat_gym").joinpath(f"data/hyperparams/{algo}.yml")))
    path = Path(path)
    if not path.is_file():
        raise TrainingError(f"hyperparameter file not found: {path}")
    data = yaml.safe_load(path.read_text()) or {}
    if ENV_ID not in data:
        raise TrainingError(f"{path} has no block for {ENV_ID!r} (found {sorted(data)})")
    return dict(data[ENV_ID])


def _algorithm(algo: str):
    from stable_baselines3 import PPO, SAC, TD3

    return {"ppo": PPO, "sac": SAC, "td3": TD3}[algo]


def make_training_env(n_envs: int, seed: int, env_kwargs: dict, normalize):
    """The SB3 VecEnv over one compiled batch, wrapped in VecMonitor and VecNormalize."""
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    from ..envs import sb3_vec_env

    venv = VecMonitor(sb3_vec_env(n_envs, seed=seed, **env_kwargs))
    if normalize:
        kw = normalize if isinstance(normalize, dict) else {}
        venv = VecNormalize(venv, **kw)
    return venv


def train(algo: str, config: str | Path | None = None, timesteps: int | None = None,
          n_envs: int | None = None, seed: int = 0, run_dir: str | Path | None = None,
          resume: str | Path | None = None, progress_bar: bool = True, threads: int | None = None,
          eval_freq: int | None = None, on_eval=None) -> Path:
    """Train and return the run directory (see the module docstring). ``on_eval(record, run)``,
    if given, is called after every suite evaluation (``record`` as in evaluations.json, plus
    ``"best"``: whether best_model.zip was just saved)."""
    import torch
    from stable_baselines3.common.callbacks import CallbackList, CheckpointCallback
    from stable_baselines3.common.utils import set_random_seed

    hp = load_hyperparams(algo, config)
    n_envs = int(n_envs or hp.get("n_envs", 8))
    timesteps = int(timesteps or hp.get("n_timesteps", 1e6))
    env_kwargs = dict(hp.get("env_kwargs") or {})
    run = Path(run_dir or f"runs/train/{algo}_seed{seed}_{time.strftime('%Y%m%d-%H%M%S')}")
    run.mkdir(parents=True, exist_ok=True)
    if threads:
        torch.set_num_threads(threads)
    set_random_seed(seed)
    venv = make_training_env(n_envs, seed, env_kwargs, hp.get("normalize", False))
    _write_run_files(run, algo, hp, venv, seed, n_envs, timesteps)
    model = _model(algo, hp, venv, seed, run, resume)
    freq = int(eval_freq or hp.get("eval_freq", 50_000))
    callbacks = CallbackList([
        CheckpointCallback(max(freq // n_envs, 1), str(run / "checkpoints"), name_prefix=algo,
                           save_vecnormalize=True),
        suite_eval_callback(hp.get("eval_suite", "tiny"), max(freq // n_envs, 1), run, on_eval),
    ])
    t0 = time.perf_counter()
    model.learn(total_timesteps=timesteps, callback=callbacks, progress_bar=progress_bar,
                reset_num_timesteps=resume is None, tb_log_name=algo)
    wall = time.perf_counter() - t0
    save_model(model, run / f"{algo}_final.zip")
    summary = {"algo": algo, "timesteps": timesteps, "n_envs": n_envs, "seed": seed,
               "wall_time_s": wall, "steps_per_s": timesteps / wall,
               "machine": platform.processor() or platform.machine(),
               "threads": torch.get_num_threads()}
    (run / "training_summary.json").write_text(json.dumps(summary, indent=2))
    venv.close()
    return run


def suite_eval_callback(suite: str, freq: int, run: Path, on_eval=None):
    """A callback that, every ``freq`` calls, scores the current policy on the fixed suite
    (deterministic actions, the training VecNormalize statistics), logs it, appends it to
    ``evaluations.json`` and saves the best-scoring model (with its statistics) as
    ``best_model.zip``; it scores once more at the end of training."""
    from stable_baselines3.common.callbacks import BaseCallback

    from .baselines import SB3Policy
    from .evaluate import check_suite, suite_score

    check_suite(suite)

    class SuiteEvalCallback(BaseCallback):
        def __init__(self):
            super().__init__(verbose=0)
            self.best, self.history, self.t0 = -np.inf, [], time.perf_counter()

        def _on_step(self) -> bool:
            if self.n_calls % freq == 0:
                self.evaluate_now()
            return True

        def _on_training_end(self) -> None:
            if not self.history or self.history[-1]["timesteps"] != self.num_timesteps:
                self.evaluate_now()

        def evaluate_now(self) -> None:
            score = suite_score(SB3Policy(self.model, self.model.get_env()), suite)
            self.logger.record("eval/suite_score", score)
            self.history.append({"timesteps": int(self.num_timesteps), "score": score,
                                 "wall_time_s": time.perf_counter() - self.t0})
            (Path(run) / "evaluations.json").write_text(json.dumps(self.history, indent=1))
            best = score > self.best
            if best:
                self.best = score
                save_model(self.model, Path(run) / "best_model.zip")
            if on_eval is not None:
                on_eval({**self.history[-1], "best": best}, Path(run))

    return SuiteEvalCallback()


def _tensorboard_dir(run: Path) -> str | None:
    """TensorBoard log directory, or None (with a warning) when tensorboard is not installed."""
    import importlib.util
    import warnings

    if importlib.util.find_spec("tensorboard") is None:
        warnings.warn("tensorboard is not installed (pip install aerostat-gym[train]): training "
                      "runs without TensorBoard logs", stacklevel=3)
        return None
    return str(run / "tb")


def _model(algo, hp, venv, seed, run, resume):
    Algo = _algorithm(algo)
    tb = _tensorboard_dir(run)
    kwargs = {k: v for k, v in hp.items() if k not in RESERVED}
    if hp.get("policy_kwargs"):
        pk = dict(hp["policy_kwargs"])
        kwargs["policy_kwargs"] = pk
    if algo == "td3" and hp.get("noise_type"):
        from stable_baselines3.common.noise import NormalActionNoise

        kwargs["action_noise"] = NormalActionNoise(np.zeros(1), hp.get("noise_std", 0.1) *
                                                   np.ones(1))
    if resume:
        resume = Path(resume)
        if not resume.is_file():
            raise TrainingError(f"checkpoint to resume not found: {resume}")
        model = Algo.load(resume, env=_load_vecnormalize_into(resume, venv), seed=seed,
                          tensorboard_log=tb)
        return model
    return Algo(hp.get("policy", "MlpPolicy"), venv, seed=seed, verbose=0, tensorboard_log=tb,
                **kwargs)


def _load_vecnormalize_into(checkpoint: Path, venv):
    """Restore the VecNormalize statistics saved beside a checkpoint (if both exist)."""
    from stable_baselines3.common.vec_env import VecNormalize

    stats = vecnormalize_path(checkpoint)
    if isinstance(venv, VecNormalize) and stats.is_file():
        return VecNormalize.load(str(stats), venv.venv)
    return venv


def vecnormalize_path(model_path: Path) -> Path:
    """Where the VecNormalize statistics of a saved model live: checkpoints use SB3's
    ``<prefix>_vecnormalize_<steps>_steps.pkl``; our models ``<stem>_vecnormalize.pkl``."""
    model_path = Path(model_path)
    stem = model_path.stem
    if stem.endswith("_steps") and "_" in stem:
        prefix, steps = stem.rsplit("_", 2)[0], stem.rsplit("_", 2)[1]
        return model_path.with_name(f"{prefix}_vecnormalize_{steps}_steps.pkl")
    return model_path.with_name(stem + VECNORM_SUFFIX)


def save_model(model, path: Path) -> None:
    """Save the model and, if it trains on a VecNormalize, its statistics beside it."""
    from stable_baselines3.common.vec_env import VecNormalize

    model.save(str(path))
    env = model.get_env()
    if isinstance(env, VecNormalize):
        env.save(str(vecnormalize_path(path)))


def _write_run_files(run, algo, hp, venv, seed, n_envs, timesteps):
    import yaml

    base = venv
    while hasattr(base, "venv"):
        base = base.venv
    (run / "params.toml").write_text(dumps_toml(base.task.params_resolved))
    (run / "hyperparams.yml").write_text(yaml.safe_dump({ENV_ID: hp}, sort_keys=False))
    (run / "command.txt").write_text(" ".join(shlex.quote(a) for a in sys.argv) + "\n")
    (run / "version.json").write_text(json.dumps({
        "aerostat_gym": __version__, "python": platform.python_version(), "algo": algo,
        "seed": seed, "n_envs": n_envs, "timesteps": timesteps}, indent=2))


def add_train_parser(sub) -> None:
    p = sub.add_parser("train", help="train a winch-control policy with Stable-Baselines3")
    p.add_argument("--algo", choices=ALGOS, default="ppo")
    p.add_argument("--config", help="hyperparameter YAML (default agents/hyperparams/ALGO.yml)")
    p.add_argument("--timesteps", type=int, help="total environment steps (default: the YAML)")
    p.add_argument("--n-envs", type=int, help="parallel environments (default: the YAML)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--run-dir", help="output directory (default runs/train/ALGO_seedS_TIME)")
    p.add_argument("--resume", help="checkpoint .zip to continue from")
    p.add_argument("--eval-freq", type=int, help="evaluate on the suite every N steps")
    p.add_argument("--threads", type=int, help="torch threads (default: torch's)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=_train_command)


def _train_command(args) -> int:
    run = train(args.algo, args.config, args.timesteps, args.n_envs, args.seed, args.run_dir,
                args.resume, not args.no_progress, args.threads, args.eval_freq)
    print(f"run directory: {run}")
    print((run / "training_summary.json").read_text())
    return 0
