"""The hyperparameter files of ``aerostat-gym train``: rl-baselines3-zoo YAML (a block per
registered task id, which the zoo reads unchanged, and a top-level ``aerostat_gym`` block for
the keys the zoo does not know; see :mod:`aerostat_gym.agents.train`), read and checked before
anything is built: the file, its blocks, every numeric hyperparameter against its range and
``normalize`` against VecNormalize's signature. A bad value is a :class:`TrainingError` naming
the key, the file or the algorithm.
"""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

from ..checks import is_finite_number, is_whole
from ..registration import TASKS
from ..resources import shipped_path, shipped_root

ALGOS = ("ppo", "sac", "td3", "rppo")
#: The class of each algorithm (Stable-Baselines3's, sb3-contrib's RecurrentPPO).
ALGO_CLASSES = {"ppo": "PPO", "sac": "SAC", "td3": "TD3", "rppo": "RecurrentPPO"}
#: Keys of a zoo block that configure the run rather than the algorithm's constructor.
RESERVED = {"n_timesteps", "n_envs", "policy", "normalize", "noise_type", "noise_std",
            "policy_kwargs"}
PROJECT_BLOCK = "aerostat_gym"
PROJECT_KEYS = {"eval_freq", "eval_suite", "env_kwargs", "frame_stack", "residual",
                "score_reward", "asymmetric_critic"}


class TrainingError(ValueError):
    """Bad training configuration (the message names the key or file)."""


def _hyperparams_file(algo: str, path: str | Path | None) -> Path:
    """The YAML file to read: ``path`` if it is a file, else a shipped file of that bare name
    (``ppo_realistic.yml``, as ``--config`` takes a shipped name), default ``ALGO.yml``."""
    if path is None:
        return shipped_path("hyperparams", f"{algo}.yml")
    given = Path(path)
    if given.is_file():
        return given
    shipped = sorted(f.name for f in (shipped_root() / "hyperparams").glob("*.yml"))
    if given.name == str(path) and given.name in shipped:
        return shipped_root() / "hyperparams" / given.name
    raise TrainingError(f"hyperparameter file not found: {path} (neither a file nor a shipped "
                        f"one: {', '.join(shipped)})")


def load_hyperparams(algo: str, path: str | Path | None = None) -> tuple[str, dict, dict]:
    """(task id, zoo block, project block) of a hyperparameter YAML file (a path, or a shipped
    file's name; default: the shipped ``hyperparams/ALGO.yml``). The zoo block is the one keyed
    by a registered task id."""
    import yaml

    if algo not in ALGOS:
        raise TrainingError(f"unknown algorithm {algo!r}; choose one of {ALGOS}")
    path = _hyperparams_file(algo, path)
    try:
        data = yaml.safe_load(path.read_bytes().decode("utf-8-sig")) or {}
    except UnicodeDecodeError as exc:
        raise TrainingError(f"{path}: not UTF-8 text: byte {exc.object[exc.start]:#04x} at "
                            f"offset {exc.start}") from None
    except yaml.YAMLError as exc:
        where = getattr(exc, "problem_mark", None)
        line = f" (line {where.line + 1})" if where is not None else ""
        raise TrainingError(f"{path}: not valid YAML{line}: "
                            f"{getattr(exc, 'problem', None) or exc}") from None
    if not isinstance(data, dict):
        raise TrainingError(f"{path} must hold a mapping of blocks, got {type(data).__name__}")
    tasks = [k for k in data if k in TASKS]
    if len(tasks) != 1:
        raise TrainingError(f"{path} needs exactly one block keyed by a task id of "
                            f"{sorted(TASKS)}, found {sorted(map(str, data))}")
    zoo, project = data[tasks[0]], data.get(PROJECT_BLOCK) or {}
    _check_block(path, tasks[0], zoo)
    _check_block(path, PROJECT_BLOCK, project)
    _check_block(path, f"{PROJECT_BLOCK}.env_kwargs", project.get("env_kwargs") or {})
    unknown = sorted(set(project) - PROJECT_KEYS)
    if unknown:
        raise TrainingError(f"{path}: unknown key(s) {unknown} in the {PROJECT_BLOCK!r} block; "
                            f"known: {sorted(PROJECT_KEYS)}")
    return tasks[0], dict(zoo), dict(project)


def _check_block(path: Path, name: str, block) -> None:
    if not isinstance(block, dict):
        raise TrainingError(f"{path}: the {name!r} block must be a mapping of keys to values, "
                            f"got {block!r}")


def normalize_kwargs(hp: dict) -> dict | None:
    """VecNormalize keyword arguments of a zoo block (None: no normalisation).

    ``normalize`` is a bool or the zoo's string ``"dict(norm_obs=True, norm_reward=False)"``
    (read here with ``ast``, never evaluated); the block's ``gamma`` is added, as the zoo does.
    """
    value = hp.get("normalize", False)
    if isinstance(value, str):
        try:
            call = ast.parse(value, mode="eval").body
            if not (isinstance(call, ast.Call) and getattr(call.func, "id", None) == "dict"
                    and not call.args):
                raise ValueError
            kw = {k.arg: ast.literal_eval(k.value) for k in call.keywords}
        except (SyntaxError, ValueError):
            raise TrainingError(f"normalize must be true, false or \"dict(key=value, ...)\", "
                                f"got {value!r}") from None
    elif isinstance(value, bool):
        kw = {} if value else None
    else:
        raise TrainingError(f"normalize must be true, false or \"dict(...)\", got {value!r}")
    if kw is not None and "gamma" in hp:
        kw["gamma"] = hp["gamma"]
    if kw:
        _check_normalize(kw)
    return kw


def _check_normalize(kw: dict) -> None:
    """VecNormalize's keyword arguments: names of its signature, values in their ranges."""
    from stable_baselines3.common.vec_env import VecNormalize

    known = sorted(set(inspect.signature(VecNormalize).parameters) - {"venv"})
    unknown = sorted(set(kw) - set(known))
    if unknown:
        raise TrainingError(f"normalize: unknown VecNormalize argument(s) {unknown}; it takes "
                            f"{known}")
    _check_ranges(kw, NORMALIZE_RANGES, "normalize's ")


def _unit_interval(v) -> bool:
    return is_finite_number(v) and 0 < v <= 1


def _positive(v) -> bool:
    return is_finite_number(v) and v > 0


def _non_negative(v) -> bool:
    return is_finite_number(v) and v >= 0


def _train_freq(v) -> bool:
    """An off-policy update period: a step count, or [count, "step" | "episode"]."""
    return is_whole(v) or (isinstance(v, (list, tuple)) and len(v) == 2 and is_whole(v[0])
                           and v[1] in ("step", "episode"))


def _sac_entropy(v) -> bool:
    """SAC's entropy weight: learned ("auto", or "auto_X" from X > 0) or fixed >= 0."""
    if isinstance(v, str) and v.startswith("auto"):
        _, _, start = v.partition("_")
        try:
            return _positive(float(start or 1.0))
        except ValueError:
            return False
    return _non_negative(v)


POSITIVE = (_positive, "a finite number > 0")
NON_NEGATIVE = (_non_negative, "a finite number >= 0")
OPTIONAL_POSITIVE = (lambda v: v is None or _positive(v), "null or a finite number > 0")
COUNT = (is_whole, "an integer >= 1")
#: What each numeric hyperparameter must be, checked before anything is built (SB3 takes a NaN,
#: a discount above 1 or a negative weight as given, and fails or diverges in its first update).
#: A key is checked where the algorithm takes it; any other is SB3's to refuse.
HYPERPARAMETER_RANGES = {
    "gamma": (_unit_interval, "a discount in (0, 1]"),
    "gae_lambda": (_unit_interval, "a number in (0, 1]"),
    "tau": (_unit_interval, "a soft-update rate in (0, 1]"),
    "learning_rate": POSITIVE,
    "clip_range": POSITIVE,
    "clip_range_vf": OPTIONAL_POSITIVE,
    "target_kl": OPTIONAL_POSITIVE,
    "max_grad_norm": POSITIVE,
    "ent_coef": NON_NEGATIVE,
    "vf_coef": NON_NEGATIVE,
    "target_policy_noise": NON_NEGATIVE,
    "target_noise_clip": NON_NEGATIVE,
    "n_steps": COUNT,
    "batch_size": COUNT,
    "n_epochs": COUNT,
    "buffer_size": COUNT,
    "policy_delay": COUNT,
    "target_update_interval": COUNT,
    "learning_starts": (lambda v: is_whole(v, 0), "an integer >= 0"),
    "gradient_steps": (lambda v: is_whole(v, -1),
                       "an integer >= -1 (-1: one update per environment step)"),
    "train_freq": (_train_freq, "an integer >= 1 or [n, step|episode]"),
}
#: Per algorithm, the rules that differ from (or add to) :data:`HYPERPARAMETER_RANGES`.
ALGO_RANGES = {
    "sac": {"ent_coef": (_sac_entropy, "'auto', 'auto_X' (X > 0) or a finite number >= 0")},
    "td3": {"noise_std": NON_NEGATIVE},
}
#: VecNormalize's arguments (``normalize``'s keys) that have a range.
NORMALIZE_RANGES = {
    "gamma": HYPERPARAMETER_RANGES["gamma"],
    "epsilon": POSITIVE,
    "clip_obs": POSITIVE,
    "clip_reward": POSITIVE,
    **{key: (lambda v: isinstance(v, bool), "true or false")
       for key in ("norm_obs", "norm_reward", "training")},
}


def _check_ranges(block: dict, rules: dict, prefix: str = "") -> None:
    """Each key of ``block`` that has a rule in ``rules`` (test, what it must be) passes it."""
    for key, (ok, must) in rules.items():
        if key in block and not ok(block[key]):
            raise TrainingError(f"{prefix}{key} must be {must}, got {block[key]!r}")


def refused(algo: str, why: str) -> TrainingError:
    return TrainingError(f"{algo.upper()} refuses the hyperparameters: {why}")


def check_hyperparams(algo: str, hp: dict) -> dict | None:
    """The zoo block's numeric hyperparameters checked against their ranges (the keys the
    algorithm takes) and its ``normalize`` against VecNormalize's signature, before anything
    is built; returns the VecNormalize keyword arguments (None: no normalisation)."""
    taken = set(inspect.signature(algorithm_class(algo).__init__).parameters)
    extra = ALGO_RANGES.get(algo, {})
    rules = {k: r for k, r in {**HYPERPARAMETER_RANGES, **extra}.items()
             if k in taken or k in extra}
    try:
        _check_ranges(hp, rules)
        return normalize_kwargs(hp)
    except TrainingError as exc:
        raise refused(algo, str(exc)) from None



def algorithm_class(algo: str):
    if algo == "rppo":
        from sb3_contrib import RecurrentPPO

        return RecurrentPPO
    from stable_baselines3 import PPO, SAC, TD3

    return {"ppo": PPO, "sac": SAC, "td3": TD3}[algo]
