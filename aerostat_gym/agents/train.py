"""``aerostat-gym train``: Stable-Baselines3 training on the native batched environment.

Hyperparameters come from rl-baselines3-zoo YAML that the zoo itself reads unchanged (read and
checked by :mod:`aerostat_gym.agents.hyperparams`): a block per registered task id (keys
``n_timesteps``, ``n_envs``, ``policy``, ``normalize`` (a bool or the zoo's string ``"dict(norm_obs=..., norm_reward=...)"``; the discount ``gamma`` is added, as
the zoo does), ``policy_kwargs``, ``noise_type`` / ``noise_std`` for TD3, the rest passed to the
algorithm), trained on that task's registered conditions. Keys the zoo does not know live in a
separate top-level block ``aerostat_gym``:

- ``eval_freq``: environment steps between evaluations on the suite; ``eval_suite``: its name;
  ``env_kwargs``: environment arguments over the task's registered ones (e.g. ``turbulence``,
  ``perturbation``, ``randomize: true``, ``obs_noise``).
- ``frame_stack: K``: the policy sees the last K (normalised) observations, SB3's
  VecFrameStack on top of VecNormalize (the zoo's order), so that a feed-forward policy can
  see the pendulum's phase and rate.
- ``residual: {base: lqg, scale: 0.3}``: the action sent to the environment is
  clip(base + scale * action, -1, 1), with ``base`` a baseline that reads the standard
  observation (``lqg``, ``modal_lqg`` or ``tension``; the privileged ``lqr`` and ``modal``
  are refused),
  designed for the training configuration and the training sensor noise, keeping its own
  state and reset at every episode start (:mod:`aerostat_gym.agents.residual`). With
  ``observe_estimate: true`` (Kalman-filter bases) the policy also reads the base's estimate:
  the measured channels the filter reconstructs and the base's command. With ``relief: R``
  the base carries a one-sided tension relief of R winch top speeds per net lift of load-cell
  tension above trim (:class:`aerostat_gym.agents.policies.TensionRelief`; since 0.7.18).
- ``score_reward: true`` (or ``{floor: F}``): train on the evaluator's score, each episode's
  rewards divided by the braked winch's return on the same episode
  (:mod:`aerostat_gym.agents.score_reward`), so that a calm 1 m swing weighs as much as a
  turbulent high-wind episode, as in the aggregate score. Training only: the saved policy is
  run as any other.
- ``asymmetric_critic: true`` (PPO): the critic reads the privileged full state (the training
  environments give ``observation="full"``), the actor only the standard channels and the
  residual base's estimate (:mod:`aerostat_gym.agents.asymmetric`); the value function is
  discarded at deployment, so the policy still acts on the sensors alone.

Algorithms: ``ppo``, ``sac``, ``td3`` (Stable-Baselines3) and ``rppo`` (sb3-contrib's
RecurrentPPO, an LSTM policy, ``policy: MlpLstmPolicy``).

Normalisation: VecNormalize divides by sqrt(var + epsilon) and clips at ``clip_obs`` (10).
A channel constant in training (wind_y, wind_z in calm air: var ~ 3e-11) then has a scale of
1e-4, so any movement at evaluation saturates it at +-10. Give a floor with the zoo's own
key, ``normalize: "dict(norm_obs=True, norm_reward=True, epsilon=1.0e-4)"`` (a standard
deviation of at least 0.01 in the observation's scaled units: the sensor noise level).

Each run directory holds the resolved parameter TOML, the hyperparameters, the command, the
package version, TensorBoard logs, checkpoints (model + VecNormalize statistics), the best
model on the fixed evaluation suite and the final model; a model trained with a frame stack or
a residual base has ``<stem>_wrappers.json`` beside it (its checkpoints: ``checkpoints/
wrappers.json``), which ``load_policy`` (and so
``aerostat-gym evaluate --policy``) reads to rebuild the same stack and base.
"""

from __future__ import annotations

import json
import platform
import shlex
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from .. import __version__, jsonout
from ..checks import is_finite_number, is_whole
from ..envs.batch import held_wind_top
from ..envs.config import TaskConfig
from ..envs.sb3 import sb3_vec_env
from ..extras import require
from ..params import as_params, dumps_toml
from ..registration import TASKS
from .asymmetric import actor_channels
from .asymmetric import policy_class as asymmetric_policy_class
from .evaluate import check_suite, held_suite_speeds, suite_score
from .hyperparams import (
    ALGO_CLASSES,
    PROJECT_BLOCK,
    RESERVED,
    TrainingError,
    algorithm_class,
    check_hyperparams,
    load_hyperparams,
    refused,
)
from .hyperparams import ALGO_RANGES as ALGO_RANGES  # this and the other 'as' imports: importable
from .hyperparams import ALGOS as ALGOS  # from train as before hyperparams.py (0.7.15 and earlier)
from .hyperparams import COUNT as COUNT
from .hyperparams import HYPERPARAMETER_RANGES as HYPERPARAMETER_RANGES
from .hyperparams import NON_NEGATIVE as NON_NEGATIVE
from .hyperparams import NORMALIZE_RANGES as NORMALIZE_RANGES
from .hyperparams import OPTIONAL_POSITIVE as OPTIONAL_POSITIVE
from .hyperparams import POSITIVE as POSITIVE
from .hyperparams import PROJECT_KEYS as PROJECT_KEYS
from .hyperparams import normalize_kwargs as normalize_kwargs
from .policies import residual_base_policy
from .report import plot_training_curve
from .residual import check_residual, residual_shaper, residual_vec_env
from .sb3io import (
    FOLDER_WRAPPERS,
    PolicyError,
    SB3Policy,
    clean_wrappers,
    find_vecnormalize,
    save_model,
    saved_algorithm,
    vecnormalize_path,
    write_wrappers,
)
from .score_reward import check_score_reward, score_reward_vec_env


def check_resume(algo: str, resume) -> Path:
    """The checkpoint to continue from: a Stable-Baselines3 model that ``algo`` saved."""
    try:
        found = saved_algorithm(resume, "checkpoint to resume")
    except PolicyError as exc:
        raise TrainingError(str(exc)) from None
    if found is not None and found != ALGO_CLASSES[algo]:
        saved_by = next((a for a, name in ALGO_CLASSES.items() if name == found), found)
        raise TrainingError(f"the checkpoint to resume {resume} is a {found} model, but the "
                            f"algorithm is {algo} ({ALGO_CLASSES[algo]}): resume it with "
                            f"--algo {saved_by}")
    return Path(resume)




def wrapper_spec(project: dict, env_kwargs: dict) -> dict:
    """The validated wrapper options of a project block: {"frame_stack": K, "residual":
    {"base", "scale", "obs_noise"}} (the residual's sensor noise is the training
    environment's, which its base is designed for)."""
    k = project.get("frame_stack", 1)
    if not is_whole(k, 1, 64):
        raise TrainingError(f"frame_stack must be an integer in [1, 64], got {k!r}")
    spec = {"frame_stack": k}
    if project.get("residual") is not None:
        try:
            res = check_residual(project["residual"])
        except PolicyError as exc:
            raise TrainingError(str(exc)) from None
        spec["residual"] = {**res, "obs_noise": float(env_kwargs.get("obs_noise", 0.0))}
    return spec


def residual_base(spec: dict, env_kwargs: dict):
    """The base policy of a residual spec, designed for the training configuration (None
    without a residual)."""
    res = spec.get("residual")
    if not res:
        return None
    return residual_base_policy(res, as_params(env_kwargs.get("params")),
                                float(env_kwargs.get("control_step", 0.2)), res["obs_noise"])


def make_training_env(n_envs: int, seed: int, env_kwargs: dict, normalize: dict | None,
                      wrappers: dict | None = None, base=None, stats=None,
                      score_reward: dict | None = None):
    """The SB3 VecEnv over one compiled batch, wrapped in VecMonitor (raw returns), (with a
    validated ``score_reward`` option) the rewards in score units, (with a residual spec in
    ``wrappers``) the residual wrapper on ``base``, (with VecNormalize keyword arguments)
    VecNormalize, its statistics loaded from ``stats`` if that file is given, and (with
    ``frame_stack`` > 1) VecFrameStack."""
    from stable_baselines3.common.vec_env import VecFrameStack, VecMonitor, VecNormalize

    wrappers = wrappers or {}
    venv = VecMonitor(sb3_vec_env(n_envs, seed=seed, **env_kwargs))
    if score_reward is not None:
        venv = score_reward_vec_env(venv, score_reward)
    if wrappers.get("residual"):
        res = wrappers["residual"]
        venv = residual_vec_env(venv, base,
                                residual_shaper(res, float(env_kwargs.get("control_step", 0.2))),
                                observe_estimate=res.get("observe_estimate", False))
    if normalize is not None:
        if stats is not None and Path(stats).is_file():
            venv = VecNormalize.load(str(stats), venv)
        else:
            venv = VecNormalize(venv, **normalize)
    if wrappers.get("frame_stack", 1) > 1:
        venv = VecFrameStack(venv, wrappers["frame_stack"])
    return venv


def run_policy(model, wrappers: dict, base=None, dt: float = 0.2) -> SB3Policy:
    """The model as a policy object with the same observation pipeline and command path as in
    training, at control step ``dt`` [s] (the evaluation suites')."""
    res = wrappers.get("residual")
    return SB3Policy(model, find_vecnormalize(model.get_env()),
                     frame_stack=wrappers.get("frame_stack", 1),
                     residual=(base, residual_shaper(res, dt)) if res else None,
                     observe_estimate=bool(res and res.get("observe_estimate", False)))


def _count(name: str, value) -> int:
    """A step or environment count: an integer >= 1 (0 and negatives are refused, not read as
    'use the default')."""
    if not (is_finite_number(value) and value == int(value) and value >= 1):
        raise TrainingError(f"{name} must be an integer >= 1, got {value!r}")
    return int(value)


def train(algo: str, hyperparams: str | Path | None = None, timesteps: int | None = None,
          n_envs: int | None = None, seed: int = 0, run_dir: str | Path | None = None,
          resume: str | Path | None = None, progress_bar: bool = True, threads: int | None = None,
          eval_freq: int | None = None, params=None, on_eval=None) -> Path:
    """Train and return the run directory (see the module docstring).

    ``hyperparams`` is the YAML file (default: the shipped one for ``algo``); ``params`` the
    physics configuration (a Params, a TOML path or a shipped name; default the baseline), used
    by the training environments and the suite evaluations and written to ``params.toml`` in
    the run directory. ``on_eval(record, run)``, if given, is called after every suite
    evaluation (``record`` as in evaluations.json, plus ``"best"``: whether best_model.zip was
    just saved).
    """
    require("stable_baselines3", "training", "train")
    import torch
    from stable_baselines3.common.callbacks import CallbackList, CheckpointCallback
    from stable_baselines3.common.utils import set_random_seed

    task_id, hp, project = load_hyperparams(algo, hyperparams)
    n_envs = _count("n_envs", hp.get("n_envs", 8) if n_envs is None else n_envs)
    timesteps = _count("timesteps", hp.get("n_timesteps", 1e6) if timesteps is None else timesteps)
    normalize = check_hyperparams(algo, hp)
    resume = check_resume(algo, resume) if resume else None
    env_kwargs = {**TASKS[task_id][0], **(project.get("env_kwargs") or {})}
    if params is not None:
        env_kwargs["params"] = params
        env_kwargs["wind_speed"] = held_training_winds(env_kwargs)
    run = Path(run_dir or f"runs/train/{algo}_seed{seed}_{time.strftime('%Y%m%d-%H%M%S')}")
    if threads:
        torch.set_num_threads(threads)
    set_random_seed(seed)
    wrappers = wrapper_spec(project, env_kwargs)
    base = residual_base(wrappers, env_kwargs)
    try:
        score = check_score_reward(project.get("score_reward"))
    except PolicyError as exc:
        raise TrainingError(str(exc)) from None
    asymmetric = check_asymmetric(project.get("asymmetric_critic", False), algo,
                                  hp.get("policy", "MlpPolicy"), wrappers)
    if asymmetric:  # the critic's privileged channels
        env_kwargs["observation"] = "full"
    venv = make_training_env(n_envs, seed, env_kwargs, normalize, wrappers, base,
                             stats=vecnormalize_path(resume) if resume else None,
                             score_reward=score)
    try:  # the run directory is made once the model is built: a refused start leaves none
        model = _model(algo, hp, venv, seed, run, resume,
                       actor_only=_actor_channels(venv, wrappers, base) if asymmetric else None)
        make_run_dir(run)
    except TrainingError:
        venv.close()
        raise
    _write_run_files(run, algo, task_id, {task_id: hp, PROJECT_BLOCK: project}, venv, seed,
                     n_envs, timesteps)
    freq = _count("eval_freq", eval_freq or project.get("eval_freq", 50_000))
    suite_cb = suite_eval_callback(project.get("eval_suite", "tiny"), max(freq // n_envs, 1),
                                   run, env_kwargs.get("params"), on_eval, wrappers, base)
    write_wrappers(run / "checkpoints" / FOLDER_WRAPPERS, wrappers)
    callbacks = [CheckpointCallback(max(freq // n_envs, 1), str(run / "checkpoints"),
                                    name_prefix=algo, save_vecnormalize=True), suite_cb]
    if progress_bar:
        callbacks.append(progress_callback(timesteps, suite_cb))
    t0 = time.perf_counter()
    model.learn(total_timesteps=timesteps, callback=CallbackList(callbacks),
                reset_num_timesteps=resume is None, tb_log_name=algo)
    wall = time.perf_counter() - t0
    save_model(model, run / f"{algo}_final.zip", wrappers)
    summary = {"algo": algo, "task": task_id, "timesteps": timesteps, "n_envs": n_envs,
               "seed": seed, "wrappers": clean_wrappers(wrappers),
               "wall_time_s": wall, "steps_per_s": timesteps / wall,
               "machine": platform.processor() or platform.machine(),
               "threads": torch.get_num_threads()}
    (run / "training_summary.json").write_text(jsonout.dumps(summary, indent=2))
    if suite_cb.history:
        plot_training_curve(suite_cb.history, run, f"{algo} on {task_id}, seed {seed}: score on "
                            f"the '{project.get('eval_suite', 'tiny')}' suite")
    venv.close()
    return run


def held_training_winds(env_kwargs: dict) -> tuple[float, float]:
    """The task's wind range (``env_kwargs["wind_speed"]``, default DEFAULT_WIND_RANGE), its top
    lowered, with a warning, to the highest wind whose trim the tether of
    ``env_kwargs["params"]`` holds (:func:`~aerostat_gym.envs.batch.held_wind_top`): a small
    aerostat on a long tether trains on the winds it can fly in."""
    task = TaskConfig.from_kwargs(**{k: env_kwargs[k] for k in ("wind_speed", "params")
                                     if k in env_kwargs})
    lo, hi = task.resolved["wind_speed"]
    top = held_wind_top(task.params_resolved, lo, hi)
    if top < hi:
        warnings.warn(f"wind_speed ({lo:g}, {hi:g}) m/s: this configuration's tether holds the "
                      f"trim only up to {top:g} m/s; training on ({lo:g}, {top:g})", stacklevel=3)
    return lo, top


def suite_eval_callback(suite: str, freq: int, run: Path, params=None, on_eval=None,
                        wrappers: dict | None = None, base=None):
    """A callback that, every ``freq`` calls, scores the current policy on the fixed suite
    (deterministic actions, the training VecNormalize statistics, the frame stack and residual
    base of ``wrappers``), logs it, appends it to
    ``evaluations.json`` and saves the best-scoring model (with its statistics) as
    ``best_model.zip``; it scores once more at the end of training."""
    from stable_baselines3.common.callbacks import BaseCallback

    check_suite(suite)
    speeds = held_suite_speeds(suite, params)
    if speeds is not None:
        warnings.warn(f"eval_suite {suite!r}: this configuration's tether cannot hold every "
                      f"wind of the suite; its scenarios run at {speeds} m/s", stacklevel=2)

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
            score = suite_score(run_policy(self.model, wrappers or {}, base), suite,
                                params=params, speeds=speeds)
            self.logger.record("eval/suite_score", score)
            self.history.append({"timesteps": int(self.num_timesteps), "score": score,
                                 "wall_time_s": time.perf_counter() - self.t0})
            (Path(run) / "evaluations.json").write_text(jsonout.dumps(self.history, indent=1))
            best = score > self.best
            if best:
                self.best = score
                save_model(self.model, Path(run) / "best_model.zip", wrappers)
            if on_eval is not None:
                on_eval({**self.history[-1], "best": best}, Path(run))

    return SuiteEvalCallback()


def progress_callback(total: int, suite_cb):
    """A progress bar over the requested steps (it stops at ``total`` even when the last
    rollout overshoots), showing the mean return of the last 100 episodes and the latest suite
    evaluation score."""
    from stable_baselines3.common.callbacks import BaseCallback
    from tqdm import tqdm

    class ProgressCallback(BaseCallback):
        def _on_training_start(self) -> None:
            self.bar = tqdm(total=total, unit="step", desc="training")
            self.start = self.num_timesteps

        def _on_step(self) -> bool:
            done = min(self.num_timesteps - self.start, total)
            self.bar.update(done - self.bar.n)
            if self.n_calls % 50 == 0:
                self.bar.set_postfix(self.status(), refresh=False)
            return True

        def status(self) -> dict:
            out = {}
            episodes = self.model.ep_info_buffer
            if episodes:
                out["return"] = f"{np.mean([e['r'] for e in episodes]):.1f}"
            if suite_cb.history:
                out["eval"] = f"{suite_cb.history[-1]['score']:.1f}"
            return out

        def _on_training_end(self) -> None:
            self.bar.set_postfix(self.status())
            self.bar.close()

    return ProgressCallback()


def _tensorboard_dir(run: Path) -> str | None:
    """TensorBoard log directory, or None (with a warning) when tensorboard is not installed."""
    import importlib.util
    import warnings

    if importlib.util.find_spec("tensorboard") is None:
        warnings.warn("tensorboard is not installed (pip install aerostat-gym[train]): training "
                      "runs without TensorBoard logs", stacklevel=3)
        return None
    return str(run / "tb")


def check_asymmetric(flag, algo: str, policy: str, wrappers: dict) -> bool:
    """The validated ``asymmetric_critic`` option: a boolean, for PPO's MlpPolicy without a
    frame stack."""
    if not isinstance(flag, bool):
        raise TrainingError(f"asymmetric_critic must be true or false, got {flag!r}")
    if flag and (algo != "ppo" or policy != "MlpPolicy"):
        raise TrainingError(f"asymmetric_critic is an option of PPO's MlpPolicy (actor and "
                            f"critic networks apart); got algo {algo!r}, policy {policy!r}")
    if flag and wrappers.get("frame_stack", 1) > 1:
        raise TrainingError("asymmetric_critic cannot be combined with frame_stack")
    return flag


def _actor_channels(venv, wrappers: dict, base) -> list[int]:
    """The channels an asymmetric actor reads in the training observation."""
    observe = (wrappers.get("residual") or {}).get("observe_estimate", False)
    return actor_channels(venv.observation_space.shape[0], base.n_features if observe else 0)


def make_run_dir(run: Path) -> None:
    """Create the run directory (and its parents), or a TrainingError naming it."""
    try:
        run.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise TrainingError(f"cannot create the run directory {run}: "
                            f"{exc.strerror or exc}") from None


def _model(algo, hp, venv, seed, run, resume, actor_only=None):
    """The SB3 model (``actor_only``: the channels of an asymmetric actor-critic's actor), or
    the one in the checkpoint ``resume``; a hyperparameter the algorithm refuses is a
    TrainingError naming the algorithm and its message, a checkpoint it cannot continue one
    naming the checkpoint."""
    tb = _tensorboard_dir(run)
    if resume:  # the VecNormalize statistics saved beside it are already in venv
        try:
            return algorithm_class(algo).load(resume, env=venv, seed=seed, tensorboard_log=tb)
        except (TypeError, ValueError, AssertionError, KeyError, AttributeError) as exc:
            raise TrainingError(f"cannot continue the checkpoint {resume} on this training "
                                f"configuration: {type(exc).__name__}: {exc}") from None
    try:
        return _build_model(algo, hp, venv, seed, tb, actor_only)
    except (TypeError, ValueError, AssertionError, KeyError) as exc:
        raise refused(algo, f"{type(exc).__name__}: {exc}") from None


def _build_model(algo, hp, venv, seed, tb, actor_only):
    Algo = algorithm_class(algo)
    kwargs = {k: v for k, v in hp.items() if k not in RESERVED}
    if hp.get("policy_kwargs") or actor_only:
        pk = dict(hp.get("policy_kwargs") or {})
        if actor_only:
            pk["actor_channels"] = actor_only
        kwargs["policy_kwargs"] = pk
    if algo == "td3" and hp.get("noise_type"):
        from stable_baselines3.common.noise import NormalActionNoise

        kwargs["action_noise"] = NormalActionNoise(np.zeros(1), hp.get("noise_std", 0.1) *
                                                   np.ones(1))
    policy = hp.get("policy", "MlpLstmPolicy" if algo == "rppo" else "MlpPolicy")
    if actor_only:
        policy = asymmetric_policy_class()
    return Algo(policy, venv, seed=seed, verbose=0, tensorboard_log=tb, **kwargs)


def _write_run_files(run, algo, task_id, blocks, venv, seed, n_envs, timesteps):
    import yaml

    base = venv
    while hasattr(base, "venv"):
        base = base.venv
    (run / "params.toml").write_text(dumps_toml(base.task.params_resolved))
    (run / "hyperparams.yml").write_text(yaml.safe_dump(blocks, sort_keys=False))
    (run / "command.txt").write_text(recorded_command() + "\n")
    (run / "version.json").write_text(json.dumps({
        "aerostat_gym": __version__, "python": platform.python_version(), "algo": algo,
        "task": task_id, "seed": seed, "n_envs": n_envs, "timesteps": timesteps}, indent=2))


def recorded_command() -> str:
    """The command line as run, with the program as its name (``aerostat-gym``, not an
    absolute path) and paths inside the working directory made relative."""
    cwd = Path.cwd()
    args = []
    for a in sys.argv[1:]:
        p = Path(a)
        if p.is_absolute() and p.is_relative_to(cwd):
            a = str(p.relative_to(cwd))
        args.append(a)
    return " ".join(shlex.quote(a) for a in ["aerostat-gym", *args])
