"""aerostat-gym: tethered-aerostat simulator, linear stability analysis and Gymnasium testbed."""

from . import jit_cache

jit_cache.refresh()  # before any compiled function loads its cache: see jit_cache

from .registration import ENV_ID, register  # noqa: E402

__version__ = "0.7.22"
#: Oldest version whose registered tasks (dynamics, wind, reward, winch logic) and residual
#: command path this version reproduces: a policy trained by it or later runs here as it was
#: trained (0.5 added a baseline and stricter loading, 0.6 training options and an optional
#: per-episode turbulence draw, 0.7 training options, 0.7.3 re-integrates a terminating step
#: that used to end as a numerical failure and stops an over-hauled drum at the end of the
#: line instead of ending the episode there, 0.7.4 fades the baselines' gains below their
#: lowest design speed, 2 m/s, under every registered task's winds; every 0.4 report row
#: reproduced). 0.7.12 changes one thing a task draws, not how it runs: a randomised episode
#: (``randomize``, as in ``TetheredAerostatRealistic-v0``) draws again the moments of inertia
#: no body has, about 11 % of the starts. A start seeded by reset(seed=...) whose first draw
#: is a body is bit-identical; in a stream of unseeded resets (training) the redraws shift the
#: generator, so every episode after the first redraw differs. 0.7.17 changes the wind of the
#: turbulent tasks: the aerostat, flying between the turbulence field's height rows, feels the
#: class's full sigma (3 / 5 / 8 % more in u / v / w than before, which the interpolation between
#: rows lost); calm-air episodes are bit-identical, turbulent ones differ, and a policy trained
#: before runs in the turbulence its class states, a few per cent stronger than the one it was
#: trained in. So the oldest compatible version is 0.7.17 (0.4.0 until 0.7.17, when the shipped
#: policy was 0.4.0's; the one shipped since 0.7.18 was trained by 0.7.17).
TASKS_COMPATIBLE_SINCE = "0.7.17"

register()

__all__ = ["ENV_ID", "TASKS_COMPATIBLE_SINCE", "__version__", "register"]
