"""Scaling beyond one process with Ray: multi-seed hyperparameter search (``tune``) and Monte
Carlo stability studies over the estimated parameters (``montecarlo``).

Ray and Optuna are an optional extra (``pip install -e ".[ray]"``). Nothing in this package
imports them at module level: the serial Monte Carlo path and the rest of aerostat-gym work
without them, and a command that needs them stops with one line naming the extra
(:class:`~aerostat_gym.extras.MissingExtraError`).
"""
