"""Seeded episode returns of policies on the registered tasks, with confidence intervals: the
baseline figures an RL researcher compares a new policy with (``scripts/task_returns.py``).

Seeds 1000 and up are disjoint from the training seeds (0, 1, ...) and from the evaluation
suites' seeds (0, 100-109). Each episode runs the task's full registered length (600 steps of
0.2 s) or to its termination; the return is the sum of the environment's default reward.
"""

from __future__ import annotations

import numpy as np

from ..envs.vector import TetheredAerostatVectorEnv
from ..registration import MAX_EPISODE_STEPS, TASKS
from .evaluate import rollout
from .policies import load_policy
from .protocol_stats import bootstrap_mean_ci, paired_difference_ci

#: Held-out seeds of the returns table.
RETURN_SEEDS = tuple(range(1000, 1020))


def task_returns(policy_name, task_id: str, seeds=RETURN_SEEDS, params=None,
                 env_kwargs=None) -> np.ndarray:
    """Episode return of ``policy_name`` (a baseline name, "shipped", a .zip path, or a policy
    object with SB3's ``predict``, used as it is) on each seed of the task ``task_id``, one
    batched environment per seed; ``env_kwargs`` over the task's registered arguments, as a
    training configuration's ``env_kwargs`` block sets them."""
    if task_id not in TASKS:
        raise ValueError(f"unknown task {task_id!r}; registered: {sorted(TASKS)}")
    seeds = [int(s) for s in seeds]
    kwargs = {**TASKS[task_id][0], **(env_kwargs or {})}
    if params is not None:
        kwargs["params"] = params
    # a filtering baseline (the LQG) is designed for the task's sensor noise
    policy = (policy_name if hasattr(policy_name, "predict") else
              load_policy(policy_name, params=params, obs_noise=kwargs.get("obs_noise", 0.0)))
    env = TetheredAerostatVectorEnv(num_envs=len(seeds), observation="full", **kwargs)
    obs, _ = env.reset(seed=seeds)
    total, _ = rollout(policy, env, obs, MAX_EPISODE_STEPS)
    env.close()
    return total


def returns_table(policies, tasks=tuple(TASKS), seeds=RETURN_SEEDS, reference="passive") -> list:
    """One row per (task, policy): mean return with its 95 % bootstrap CI over the seeds, and
    the paired difference from ``reference`` on the same seeds with its CI."""
    rows = []
    for task_id in tasks:
        ref = task_returns(reference, task_id, seeds)
        for name in policies:
            r = ref if name == reference else task_returns(name, task_id, seeds)
            mean = bootstrap_mean_ci(r)
            diff = paired_difference_ci(r, ref)
            rows.append({"task": task_id, "policy": name, "n_seeds": len(r),
                         **mean.as_dict("return"), **diff.as_dict(f"minus_{reference}")})
    return rows


def format_returns(rows: list, reference: str = "passive") -> str:
    """Markdown table of :func:`returns_table`'s rows."""
    key = f"minus_{reference}"
    lines = [f"| task | policy | return, mean [95 % CI] | minus {reference}, mean [95 % CI] |",
             "|---|---|---|---|"]
    for r in rows:
        lo, hi = r["return_ci"]
        dlo, dhi = r[key + "_ci"]
        diff = "(reference)" if r["policy"] == reference else \
            f"{r[key]:+.1f} [{dlo:+.1f}, {dhi:+.1f}]"
        lines.append(f"| `{r['task']}` | {r['policy']} | {r['return']:.1f} [{lo:.1f}, {hi:.1f}] "
                     f"| {diff} |")
    return "\n".join(lines)
