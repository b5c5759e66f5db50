"""Numba's on-disk cache kept consistent with the package's sources.

Numba keys a cached function on its own source file only (numba issue #6845): a compiled
function that calls into another module keeps the machine code it was built with when only the
callee's file changes. The environment's step (``envs/kernel.py``) would go on running the old
winch model after an edit of ``physics/core.py``, a silent wrong answer in a git checkout after
a pull or an edit. (A pip install rewrites every file, so every cache entry is invalidated.)

:func:`refresh` hashes the sources of every module that holds compiled code and compares the
hash with the one stored beside the caches; when they differ it removes the package's cache
files, so each compiled function is rebuilt from the current sources on first call (a one-off
compilation of about a minute). It runs once, when the package is imported, and quietly does
nothing where the package's folders are read-only (numba then caches elsewhere, per file).
"""

from __future__ import annotations

import hashlib
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent
#: Where the hash of the compiled sources is kept.
STAMP = PACKAGE / "__pycache__" / "numba-sources.sha256"
#: Numba's cache files: the index and the compiled code of each function.
CACHE_PATTERNS = ("*.nbi", "*.nbc")


def compiled_sources_hash(package: Path = PACKAGE) -> str:
    """SHA-256 over the path and text of every module of ``package`` that uses numba."""
    digest = hashlib.sha256()
    for path in sorted(package.rglob("*.py")):
        text = path.read_bytes()
        if b"numba" in text:
            digest.update(path.relative_to(package).as_posix().encode())
            digest.update(text)
    return digest.hexdigest()


def refresh(package: Path = PACKAGE, stamp: Path = STAMP) -> bool:
    """Remove the package's numba cache files if the compiled sources changed since they were
    stamped; returns True when it removed them."""
    current = compiled_sources_hash(package)
    try:
        if stamp.is_file() and stamp.read_text().strip() == current:
            return False
        for pattern in CACHE_PATTERNS:
            for path in package.rglob(pattern):
                path.unlink(missing_ok=True)
        stamp.parent.mkdir(exist_ok=True)
        stamp.write_text(current + "\n")
    except OSError:  # a read-only install: numba caches per file in its user-wide folder
        return False
    return True
