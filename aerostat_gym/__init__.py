"""aerostat-gym: tethered-aerostat simulator, linear stability analysis and Gymnasium testbed."""

from .registration import ENV_ID, register

__version__ = "0.4.0"

register()

__all__ = ["ENV_ID", "__version__", "register"]
