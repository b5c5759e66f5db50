"""Winch-control agents and the studies that run the environment: the baselines by name
(``policies``), the LQR, modal and LQG designs and their gain scheduling over the wind speed
(``lqr``, ``modal``, ``lqg``, ``scheduling``), learned Stable-Baselines3 policies (``sb3io``,
``residual``, ``train`` with ``hyperparams``), and the evaluation protocol, its metrics and
reports (``evaluate``, ``protocol*``, ``metrics*``, ``report``). README "Layout" lists every
module."""
