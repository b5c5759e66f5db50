"""Session-wide fixtures.

``ray_session``: one local Ray instance with two CPUs for every test that needs Ray (start-up
costs a few seconds, so it is paid once). Tests that use it are skipped, with the reason, when
the optional ``ray`` extra is not installed.

``load_script``: a script of ``scripts/`` as a module, by name (the scripts are thin shims
over the library, and not a package).
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

SCRIPTS = Path(__file__).resolve().parents[1] / "scripts"


@pytest.fixture(scope="session")
def load_script():
    def load(name: str):
        spec = importlib.util.spec_from_file_location(name, SCRIPTS / f"{name}.py")
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        return mod
    return load


@pytest.fixture(scope="session")
def ray_session():
    """The ``ray`` module with a local two-CPU session running; shut down at the end."""
    ray = pytest.importorskip(
        "ray", reason="the optional 'ray' extra is not installed (pip install -e '.[ray]')")
    started = not ray.is_initialized()
    if started:
        ray.init(address="local", num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield ray
    if started:
        ray.shutdown()
