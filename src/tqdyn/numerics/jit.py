"""On-disk cache of tqdyn's compiled (numba) kernels.

numba's own cache checks only the source file of the cached function, so a
kernel that inlines functions from other modules could be reused after those
modules changed.  tqdyn's kernels are therefore cached by a locator whose
freshness stamp is a hash of *every* tqdyn source file (plus the numba
version): any change to the package invalidates all of them.  The cache
lives in ``$TQDYN_CACHE_DIR`` (default ``~/.cache/tqdyn``); if it cannot be
created, numba falls back to its usual locations.  Compilation happens once
per machine and package version instead of once per process.

The locator plugs into numba's caching internals; if those change in a
future numba, tqdyn keeps working and numba's default locators are used.
"""

from __future__ import annotations

import functools
import hashlib
import os
import pathlib

import numba

__all__ = ["cache_dir", "install_cache_locator"]

_PACKAGE = pathlib.Path(__file__).resolve().parent.parent  # the tqdyn package folder


def cache_dir() -> pathlib.Path:
    """Directory of tqdyn's compiled-kernel cache."""
    root = os.environ.get("TQDYN_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"), "tqdyn")
    return pathlib.Path(root) / "numba"


@functools.lru_cache(maxsize=1)
def _package_stamp() -> str:
    """sha256 over the package's Python sources and the numba version."""
    h = hashlib.sha256(numba.__version__.encode())
    for path in sorted(_PACKAGE.rglob("*.py")):
        h.update(str(path.relative_to(_PACKAGE)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def install_cache_locator() -> bool:
    """Register the package-wide cache locator with numba (idempotent).
    Returns False if numba's caching internals are not as expected."""
    try:
        from numba.core import caching
        base = caching._CacheLocator
        impl = getattr(caching, "CacheImpl", None) or caching._CacheImpl  # renamed in numba 0.61
        classes = impl._locator_classes
    except (ImportError, AttributeError):
        return False
    if any(getattr(c, "_tqdyn", False) for c in classes):
        return True

    class TqdynCacheLocator(base):
        _tqdyn = True

        def __init__(self, py_func, py_file):
            self._lineno = py_func.__code__.co_firstlineno
            # one folder per package version (stamp) and source folder: every
            # install of the same sources shares it, old versions' folders are
            # simply never read again
            sub = pathlib.Path(py_file).resolve().parent.relative_to(_PACKAGE)
            self._cache_path = str(cache_dir() / _package_stamp()[:16] / sub)

        def get_cache_path(self):
            return self._cache_path

        def get_source_stamp(self):
            return _package_stamp()

        def get_disambiguator(self):
            return str(self._lineno)

        @classmethod
        def from_function(cls, py_func, py_file):
            try:
                pathlib.Path(py_file).resolve().relative_to(_PACKAGE)
            except ValueError:
                return None  # not a tqdyn function: numba's own locators
            self = cls(py_func, py_file)
            try:
                self.ensure_cache_path()
            except OSError:
                return None
            return self

    classes.insert(0, TqdynCacheLocator)
    return True


install_cache_locator()
