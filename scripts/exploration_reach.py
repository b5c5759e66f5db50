"""How much of a residual PPO policy's exploration reaches the winch on its training task
(:mod:`aerostat_gym.agents.exploration`): episodes flown with the policy's mean action, the
command path re-run on them with sampled actions at the policy's own action spread and at the
spreads given.

Usage: python scripts/exploration_reach.py [--policy shipped] [--sigma 0.37 --sigma 1.0]
       [--seeds 20] [--json]
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from aerostat_gym.cli.common import run_script, script_description

#: Episode seeds: the task-returns table's held-out seeds.
FIRST_SEED = 1000


def record(policy, env, seed: int):
    """(base commands, policy means) of one deterministic episode of ``policy`` (an SB3Policy
    with a residual) on ``env``: the policy's own step (:meth:`SB3Policy.command_parts`), its
    two parts kept before they pass its command path."""
    from aerostat_gym.agents.sb3io import policy_obs

    shaper = policy.residual[1]
    obs, _ = env.reset(seed=seed)
    state, start = None, np.array([True])
    bases, means = [], []
    while True:
        b, mu, state, start = policy.command_parts(
            policy_obs(policy, np.asarray(obs, np.float32)[None, :]), state, start)
        bases.append(float(np.reshape(b, -1)[0]))
        means.append(float(mu[0]))
        a, state["filter"] = shaper(b, mu, state.get("filter"), start)
        start = np.array([False])
        obs, _, terminated, truncated, _ = env.step(a[0])
        if terminated or truncated:
            return np.array(bases), np.array(means)


def main(argv=None) -> int:
    import gymnasium as gym

    import aerostat_gym  # noqa: F401  (registers the tasks)
    from aerostat_gym.agents.exploration import exploration_reach, lowpass_noise_gain
    from aerostat_gym.agents.policies import load_policy

    ap = argparse.ArgumentParser(description=script_description(__doc__),
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--policy", default="shipped", help="a residual PPO policy: 'shipped' or .zip")
    ap.add_argument("--task", default="TetheredAerostatRealistic-v0")
    ap.add_argument("--sigma", type=float, action="append", default=[],
                    help="action spreads to try besides the policy's own")
    ap.add_argument("--seeds", type=int, default=20, help=f"episodes, seeds from {FIRST_SEED}")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    policy = load_policy(args.policy)
    if getattr(policy, "residual", None) is None:
        raise SystemExit(f"{args.policy!r} is not a residual policy")
    shaper = policy.residual[1]
    own = float(np.exp(policy.model.policy.log_std.detach().numpy()).reshape(-1)[0])
    env = gym.make(args.task)
    episodes = [record(policy, env, FIRST_SEED + i) for i in range(args.seeds)]
    rows = []
    for sigma in [own, *args.sigma]:
        rng = np.random.default_rng(0)
        per = [exploration_reach(shaper, b, m, sigma, rng) for b, m in episodes]
        rows.append({"sigma": sigma, "own": sigma == own,
                     "closed_form_rms": shaper.scale * sigma * lowpass_noise_gain(shaper.alpha),
                     **{k: float(np.mean([p[k] for p in per])) for k in per[0]}})
    info = {"policy": args.policy, "task": args.task, "episodes": args.seeds,
            "scale": shaper.scale, "lowpass_alpha": shaper.alpha, "deadband": shaper.deadband,
            "rows": rows}
    if args.json:
        print(json.dumps(info, indent=1))
        return 0
    print(f"{args.policy} on {args.task}, {args.seeds} episodes; scale {shaper.scale:g}, "
          f"low-pass alpha {shaper.alpha:.4f}, deadband {shaper.deadband:g} (top speeds)")
    print("| sigma | steps whose set-point the sampling changes | RMS change [top speeds] | "
          "closed form, no deadband | RMS set-point flown |")
    print("|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['sigma']:.3f}{' (its own)' if r['own'] else ''} | {r['changed']:.3f} | "
              f"{r['rms']:.4f} | {r['closed_form_rms']:.4f} | {r['rms_mean_command']:.4f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(run_script(main))
