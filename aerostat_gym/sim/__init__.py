"""The simulator: owns time, the integrator choice, the winch's supervisory logic and the wind
state, and calls the compiled core (:mod:`aerostat_gym.physics`).

- :class:`Model` (:mod:`.model`): a parameter set bound to the compiled right-hand side, with
  the one compiled interval advance that every front end uses.
- :func:`simulate` (:mod:`.simulate`): trajectories with named fields and events.
- :class:`WinchController` (:mod:`.winch`): set-point validation, the brake rule, load cell and
  winch events, once per control step.
- :mod:`.events`: episode outcome codes and the compiled outcome check.
"""

from .events import OUTCOMES
from .model import BRAKED, INTEGRATORS, Model, SimulationError
from .simulate import Trajectory, simulate
from .winch import WinchController, WinchInputError

__all__ = ["BRAKED", "INTEGRATORS", "Model", "OUTCOMES", "SimulationError", "Trajectory",
           "WinchController", "WinchInputError", "simulate"]
