"""aerostat-gym: tethered-aerostat simulator, linear stability analysis and Gymnasium testbed."""

from .registration import ENV_ID, register

__version__ = "0.7.3"
#: Oldest version whose registered tasks (dynamics, wind, reward, winch logic) and residual
#: command path this version reproduces: a policy trained by it or later runs here as it was
#: trained (0.5 added a baseline and stricter loading, 0.6 training options and an optional
#: per-episode turbulence draw, 0.7 training options, 0.7.3 re-integrates a terminating step
#: that used to end as a numerical failure; every 0.4 report row reproduced).
TASKS_COMPATIBLE_SINCE = "0.4.0"

register()

__all__ = ["ENV_ID", "TASKS_COMPATIBLE_SINCE", "__version__", "register"]
