"""Ruff (configured in pyproject.toml) over the package, scripts, agents and tests."""

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_ruff_clean():
    ruff = shutil.which("ruff")
    if ruff is None:
        pytest.skip("ruff not installed (it is in the test extra)")
    targets = [str(ROOT / d) for d in ("aerostat_gym", "scripts", "agents", "tests") if (ROOT / d).exists()]
    res = subprocess.run([ruff, "check", *targets], capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stdout + res.stderr
