"""Joining or starting a Ray cluster, timed (the start-up overhead is a reported figure)."""

from __future__ import annotations

import os
import time
from dataclasses import dataclass

from ..extras import require


@dataclass
class RayStart:
    """How Ray was brought up.

    Attributes
    ----------
    ray : the imported ``ray`` module.
    started_here : True if this call ran ``ray.init`` (and :func:`stop_ray` should shut it down).
    import_s : seconds to import ray.
    init_s : seconds in ``ray.init`` (0 when a session was already running).
    cpus : CPUs the cluster offers.
    """

    ray: object
    started_here: bool
    import_s: float
    init_s: float
    cpus: float


def start_ray(purpose: str, address: str | None = None, num_cpus: int | None = None,
              hint: str = "") -> RayStart:
    """Join the cluster at ``address``, or start a local one with ``num_cpus`` CPUs.

    Parameters
    ----------
    purpose : what needs Ray (named in the error when Ray is missing).
    address : ``ray://host:10001``, ``host:6379`` or ``auto`` for an existing cluster; None
        starts a fresh local instance (never silently joins a cluster found on the machine).
    num_cpus : CPUs of the local instance (default: the machine's cores); ignored with an
        address.
    hint : appended to the missing-extra message.

    Returns
    -------
    :class:`RayStart`; an already initialised session (a test fixture) is reused as is.
    """
    t0 = time.perf_counter()
    ray = require("ray", purpose, "ray", hint=hint)
    import_s = time.perf_counter() - t0
    if ray.is_initialized():
        return RayStart(ray, False, import_s, 0.0, ray.cluster_resources().get("CPU", 0.0))
    if num_cpus is not None and num_cpus < 1:
        raise ValueError(f"--workers must be >= 1, got {num_cpus}")
    t1 = time.perf_counter()
    if address:
        try:
            ray.init(address=address, log_to_driver=False)
        except ConnectionError as exc:
            raise RuntimeError(f"could not join the Ray cluster at --address {address}: {exc} "
                               "(on the head node, --address auto finds it)") from None
    else:
        ray.init(address="local", num_cpus=num_cpus or os.cpu_count(),
                 include_dashboard=False, log_to_driver=False)
    init_s = time.perf_counter() - t1
    return RayStart(ray, True, import_s, init_s, ray.cluster_resources().get("CPU", 0.0))


def stop_ray(start: RayStart) -> None:
    """Shut Ray down if :func:`start_ray` started or joined it.

    Parameters
    ----------
    start : what :func:`start_ray` returned.
    """
    if start.started_here:
        start.ray.shutdown()
