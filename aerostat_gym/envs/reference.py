"""The braked winch's return of episodes already started in a batch: the reference against which
the evaluator scores every episode (return over the passive return, so passive scores -1), made
available to training.

:class:`BrakedReference` keeps a second :class:`~aerostat_gym.envs.batch.EnvBatch` of the same
task (it shares the trim table and the turbulence bank through their caches), copies a slot's
episode start into it (:meth:`EnvBatch.get_slot` / :meth:`EnvBatch.set_slot`: the same state,
randomised parameters, wind field and offset, gust) and runs it to its end with the action 0 of
the passive policy, which sets the brake. The copy draws nothing from the environment's random
generators, so the training episodes are those the environment gives without it.
"""

from __future__ import annotations

import numpy as np

from ..checks import is_whole
from ..sim.events import RUNNING
from .batch import EnvBatch


class BrakedReference:
    """Braked-winch returns of the episodes started in ``batch``'s slots, over at most
    ``max_steps`` control steps (the episode's time limit)."""

    def __init__(self, batch: EnvBatch, max_steps: int):
        if batch.task.reward_fn is not None:
            raise ValueError("the braked-winch reference is the default score's return; this "
                             "environment has a custom reward_fn")
        if not is_whole(max_steps):
            raise ValueError(f"max_steps must be an integer >= 1, got {max_steps!r}")
        self.batch = batch
        self.max_steps = int(max_steps)
        self.shadow = EnvBatch(batch.task, batch.num_envs, batch.threads)
        self._zeros = np.zeros(batch.num_envs)

    def returns(self, slots) -> np.ndarray:
        """The braked winch's episode return from the current start of each slot in ``slots``
        (the slots are left untouched)."""
        slots = np.asarray(slots, dtype=np.int64).reshape(-1)
        sh = self.shadow
        active = np.zeros(sh.num_envs, dtype=np.bool_)
        for i in slots:
            sh.set_slot(int(i), self.batch.get_slot(int(i)))
            active[i] = True
        total = np.zeros(sh.num_envs)
        sh.set_actions(self._zeros)
        for _ in range(self.max_steps):
            if not active.any():
                break
            sh.step(active)
            total[active] += sh.terms[active].sum(axis=1)
            active &= sh.code == RUNNING  # terminated, or the wind field ran out
        return total[slots]
