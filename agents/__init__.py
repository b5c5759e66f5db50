"""Shipped agents data: hyperparameter YAML, policies with their normalisation statistics,
training curves and evaluation reports. Installed as the package ``aerostat_gym.shipped`` (see
``aerostat_gym.resources``); there is no code here."""
