"""The learning curve on the training task itself: a run's checkpoints flown on fresh seeds of
the task they were trained on, each against where the learning started.

A training run's own curve (``evaluations.json``) scores the calm ``damping`` suite without
noise, which the realistic task's policies barely move (the shipped one stays within 0.3 %).
What the learning did to the objective it was given is read here: the return on the run's
training task, deterministic, on :data:`TASK_CURVE_SEEDS`, as a paired difference from the
run's starting point with its 95 % studentized interval. A residual run starts at a zero
residual, so its starting point is its base controller through its command path
(:func:`zero_residual`: for the shipped configuration, ``modal_lqg_shaped`` to the bit); any
other run is compared with a named baseline (the braked winch by default). The return is the
task's default reward, the one every policy is compared on, also for a run trained on the
evaluator's score (``score_reward``).
"""

from __future__ import annotations

import json
import re
import zipfile
from pathlib import Path

import numpy as np

from ..params import as_params
from .hyperparams import load_hyperparams
from .policies import load_policy
from .protocol_stats import paired_difference_ci
from .residual import ShapedPolicy
from .returns import task_returns

#: Episode seeds of the task curve: disjoint from training (0-35 over seeds 0-4), the suites'
#: (0, 100-109, 5000-5019, 7000-7009), the task-returns table's (1000-1019) and the selection
#: gate's (3000-3199), so a curve read here chooses nothing the gate then judges. 200, as the
#: gate, because the task's returns are heavy-tailed.
TASK_CURVE_SEEDS = tuple(range(4000, 4200))

_CHECKPOINT = re.compile(r"^(?P<algo>[a-z]+)_(?P<steps>\d+)_steps\.zip$")


def run_models(run_dir) -> list[tuple[int, Path]]:
    """(timesteps, model path) of a training run: every checkpoint under ``checkpoints/`` and
    the final model, in order of timesteps."""
    run = Path(run_dir)
    summary = run / "training_summary.json"
    if not summary.is_file():
        raise ValueError(f"{run} is not a finished training run (no training_summary.json)")
    info = json.loads(summary.read_text())
    models = [(int(m["steps"]), p) for p in sorted((run / "checkpoints").glob("*.zip"))
              if (m := _CHECKPOINT.match(p.name))]
    final = run / f"{info['algo']}_final.zip"
    if final.is_file():  # its own count: the last rollout runs past the requested timesteps
        models.append((saved_timesteps(final), final))
    if not models:
        raise ValueError(f"{run} holds no checkpoint and no final model")
    return sorted(models, key=lambda m: m[0])


def saved_timesteps(model_path) -> int:
    """The environment steps a saved SB3 model had trained for (its archive's ``data``)."""
    with zipfile.ZipFile(model_path) as archive:
        return int(json.loads(archive.read("data"))["num_timesteps"])


def run_task(run_dir) -> tuple[str, dict]:
    """The task a run was trained on (its training summary's) and the environment arguments
    its configuration set over the task's (its ``hyperparams.yml``'s ``env_kwargs``). A run on
    another aerostat than the baseline (its ``params.toml``) is refused: its starting point
    would need the base designed for that aerostat, which this curve does not build."""
    run = Path(run_dir)
    algo = json.loads((run / "training_summary.json").read_text())["algo"]
    if as_params(run / "params.toml") != as_params(None):
        raise ValueError(f"{run} was trained on another aerostat than the baseline "
                         "(its params.toml); the task curve flies the baseline only")
    task, _, project = load_hyperparams(algo, run / "hyperparams.yml")
    return task, dict(project.get("env_kwargs") or {})


def zero_residual(model_path):
    """A residual model's starting point: its base controller (rebuilt as at evaluation, for
    the sensor noise it was trained with) through its command path with the residual at zero;
    None for a model that is not a residual."""
    policy = load_policy(str(model_path))
    residual = getattr(policy, "residual", None)
    if residual is None:
        return None
    base, shaper = residual
    return ShapedPolicy(base, deadband=shaper.deadband, lowpass=shaper.lowpass, dt=shaper.dt)


def task_curve(run_dir, seeds=TASK_CURVE_SEEDS, reference: str = "passive") -> dict:
    """Each model of the run (:func:`run_models`) on its training task, against its starting
    point: the zero residual for a residual run, else the baseline ``reference``.

    Returns {"run", "task", "env_kwargs", "seeds", "reference", "reference_mean",
    "reference_returns", "points": [{"timesteps", "mean", "minus_reference": [mean, low,
    high], "median_minus_reference", "returns"}]} (returns per seed, in the seeds' order)."""
    models = run_models(run_dir)
    task, env_kwargs = run_task(run_dir)
    start = zero_residual(models[-1][1])
    label = "zero residual" if start is not None else reference
    ref = task_returns(start if start is not None else reference, task, seeds,
                       env_kwargs=env_kwargs)
    points = []
    for steps, path in models:
        mine = task_returns(str(path), task, seeds, env_kwargs=env_kwargs)
        iv = paired_difference_ci(mine, ref)
        points.append({"timesteps": steps, "mean": float(mine.mean()),
                       "minus_reference": [iv.estimate, iv.low, iv.high],
                       "median_minus_reference": float(np.median(mine - ref)),
                       "returns": _rounded(mine)})
    return {"run": str(run_dir), "task": task, "env_kwargs": env_kwargs,
            "seeds": [int(s) for s in seeds], "reference": label,
            "reference_mean": float(ref.mean()), "reference_returns": _rounded(ref),
            "points": points}


def _rounded(returns: np.ndarray) -> list[float]:
    """Episode returns kept to 1e-3 (a return's last digits are the platform's rounding)."""
    return [round(float(r), 3) for r in returns]


def curve_markdown(curves: dict) -> str:
    """One table per run: label -> :func:`task_curve` result."""
    lines = []
    for name, c in curves.items():
        lines += [f"**{name}** (`{c['run']}`) on {c['task']}, {len(c['seeds'])} seeds; "
                  f"{c['reference']}: {c['reference_mean']:.1f}", "",
                  f"| timesteps | mean return | minus {c['reference']} [95 % CI] | median of "
                  "the paired differences |", "|---|---|---|---|"]
        for p in c["points"]:
            est, lo, hi = p["minus_reference"]
            lines.append(f"| {p['timesteps']:,} | {p['mean']:.1f} | {est:+.1f} [{lo:+.1f}, "
                         f"{hi:+.1f}] | {p['median_minus_reference']:+.1f} |")
        lines.append("")
    return "\n".join(lines)


def plot_curves(curves: dict, path) -> None:
    """Against timesteps, each run's paired difference from its starting point: the mean with
    its interval as a band (left), and the median (right: what a typical episode sees, where
    the mean is decided by a few); zero is where the learning started."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(10.5, 4.2))
    for name, c in curves.items():
        steps = [p["timesteps"] / 1e6 for p in c["points"]]
        est, lo, hi = (np.array([p["minus_reference"][k] for p in c["points"]]) for k in range(3))
        (line,) = left.plot(steps, est, marker="o", ms=3, label=name)
        left.fill_between(steps, lo, hi, color=line.get_color(), alpha=0.10)
        right.plot(steps, [p["median_minus_reference"] for p in c["points"]], marker="o", ms=3,
                   color=line.get_color(), label=name)
    first = next(iter(curves.values()))
    for ax, what in ((left, "mean [95 % CI]"), (right, "median")):
        ax.axhline(0.0, color="k", lw=0.8)
        ax.set_xlabel("training timesteps [millions]")
        ax.set_ylabel(f"return minus {first['reference']}: {what}")
    left.legend(fontsize=8)
    fig.suptitle(f"{first['task']}: {len(first['seeds'])} fresh seeds, paired differences per "
                 "episode", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
