"""A stateful policy's state dropped between steps is named, not run silently.

The LQR's length integral, the Kalman filter of the LQG baselines, the command low-pass and the
residual's base all live in the state that ``predict`` returns. SB3's feed-forward policies
ignore ``state``, so a hand-written loop often drops it (``action, _ = policy.predict(obs)``):
every call is then an episode start, the filter restarts from its prior at each step, and the
controller scores far below its own (measured on a 7 m hull at 10 m/s: the LQG's return
-28 717 against -8 238 with its state passed back). One call with ``state=None`` is an episode
start; two in a row on batches of the same size without ``episode_start`` set is that
mistake, and warns once per policy.
"""

from __future__ import annotations

import warnings

import numpy as np


class DroppedStateWarning(UserWarning):
    """A stateful policy was called twice in a row without its state."""


def check_state_passed(policy, state, episode_start, n: int, holds: str) -> None:
    """Call first in a stateful ``predict`` of ``n`` observations: warn (once per ``policy``)
    where ``state`` is None on two calls in a row of the same ``n`` and ``episode_start`` does
    not mark every observation as a start (a batch of another size is another stream).
    ``holds`` says what the state carries (for the message)."""
    start = episode_start is not None and bool(np.all(np.asarray(episode_start, bool)))
    dropped = n if state is None and not start else None
    if dropped is not None and getattr(policy, "_state_dropped", None) == dropped \
            and not getattr(policy, "_state_warned", False):
        policy._state_warned = True
        warnings.warn(
            f"{type(policy).__name__}.predict got state=None on two calls in a row: its state "
            f"({holds}) restarts at every call, as at an episode start. Pass back the state it "
            "returns (action, state = policy.predict(obs, state=state, episode_start=starts)), "
            "with episode_start=True where an episode begins", DroppedStateWarning, stacklevel=3)
    policy._state_dropped = dropped
