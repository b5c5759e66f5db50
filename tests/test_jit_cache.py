"""The numba cache is dropped when a compiled module's source changes (aerostat_gym.jit_cache):
numba itself keys each cached function on its own file only, so a caller whose callee changed in
another file would run stale machine code."""

import os

import pytest

from aerostat_gym import jit_cache


def _package(root):
    """A package with a compiled module, a plain module and a cache file of each kind."""
    (root / "physics").mkdir()
    (root / "physics" / "core.py").write_text("from numba import njit\n")
    (root / "cli.py").write_text("print('no compiled code here')\n")
    caches = [root / "physics" / "__pycache__" / "core.f-1.py311.nbi",
              root / "__pycache__" / "kernel.g-2.py311.1.nbc"]
    for path in caches:
        path.parent.mkdir(exist_ok=True)
        path.write_bytes(b"compiled")
    return caches


def test_caches_survive_unchanged_sources_and_go_when_a_compiled_module_changes(tmp_path):
    caches = _package(tmp_path)
    stamp = tmp_path / "__pycache__" / "numba-sources.sha256"
    assert jit_cache.refresh(tmp_path, stamp)  # no stamp yet: the caches' sources are unknown
    assert not any(path.exists() for path in caches)
    for path in caches:
        path.write_bytes(b"compiled")
    assert not jit_cache.refresh(tmp_path, stamp)  # same sources: kept
    (tmp_path / "cli.py").write_text("print('edited, still no compiled code')\n")
    assert not jit_cache.refresh(tmp_path, stamp)
    assert all(path.exists() for path in caches)
    (tmp_path / "physics" / "core.py").write_text("from numba import njit  # edited\n")
    assert jit_cache.refresh(tmp_path, stamp)
    assert not any(path.exists() for path in caches)
    assert stamp.read_text().strip() == jit_cache.compiled_sources_hash(tmp_path)


@pytest.mark.skipif(not os.access(jit_cache.PACKAGE, os.W_OK),
                    reason="a read-only install: numba caches per file elsewhere, no stamp")
def test_the_package_is_stamped_with_its_own_sources():
    """Importing the package ran refresh: the stamp beside its caches is the hash of its
    current compiled sources."""
    assert jit_cache.STAMP.read_text().strip() == jit_cache.compiled_sources_hash()
