"""On-disk cache of tqdyn's compiled (numba) kernels.

numba's own cache checks only the source file of the cached function, so a
kernel that inlines functions from other modules could be reused after those
modules changed.  tqdyn's kernels are therefore cached by a locator whose
freshness stamp is a hash of *every* tqdyn source file (plus the numba
version): any change to the package invalidates all of them.  The cache
lives in ``$TQDYN_CACHE_DIR`` (default ``~/.cache/tqdyn``); if it cannot be
created, numba falls back to its usual locations.  Compilation happens once
per machine and package version instead of once per process.

Every source version gets its own folder ``<cache>/numba/<stamp>``, so
folders of versions that are no longer installed pile up (tens of MB each).
:func:`prune_stale_caches` removes the folders of other versions that have
not been used for :data:`STALE_AFTER_DAYS` days (each process touches its own
folder's ``last-used`` file once); it runs at most once a day per machine
(the ``last-prune`` file), when the locator is installed.

The locator plugs into numba's caching internals; if those change in a
future numba, tqdyn keeps working and numba's default locators are used.
"""

from __future__ import annotations

import functools
import hashlib
import os
import pathlib
import shutil
import time

import numba
from numba.core import types as _types
from numba.extending import intrinsic

__all__ = ["STALE_AFTER_DAYS", "cache_dir", "dynamic", "install_cache_locator", "prune_stale_caches"]

_PACKAGE = pathlib.Path(__file__).resolve().parent.parent  # the tqdyn package folder

#: A version's kernel folder unused for this many days is removed by
#: :func:`prune_stale_caches` (long enough that two installs used side by side,
#: e.g. a release and a development checkout, never delete each other's kernels).
STALE_AFTER_DAYS = 30.0
#: Seconds between two prunes on one machine (one directory listing per day).
_PRUNE_EVERY_S = 86400.0
_STAMP_CHARS = 16


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
            self._py_file = py_file  # numba's warning of an uncachable function names it
            # one folder per package version (stamp) and source folder: every
            # install of the same sources shares it, old versions' folders are
            # simply never read again
            sub = pathlib.Path(py_file).resolve().parent.relative_to(_PACKAGE)
            self._cache_path = str(cache_dir() / _package_stamp()[:_STAMP_CHARS] / sub)

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
    try:
        prune_stale_caches()
    except OSError:
        pass  # a read-only or vanished cache folder: nothing to clean
    return True


@intrinsic
def dynamic(typingctx, x):
    """``x`` itself, typed as a run-time value (compiled code only).

    numba compiles a jitted function once more for every distinct constant
    passed to it from other compiled code (a literal argument type); a
    constant wrapped in ``dynamic`` is passed as a plain int / float / bool,
    so all such calls share one compiled version.  Costs nothing at run time.
    """
    def codegen(context, builder, signature, args):
        return context.cast(builder, args[0], signature.args[0], signature.return_type)

    return _types.unliteral(x)(x), codegen


def _touch(path: pathlib.Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.touch()


def prune_stale_caches(now: float | None = None, stale_after_days: float = STALE_AFTER_DAYS,
                       force: bool = False) -> list[pathlib.Path]:
    """Remove the kernel folders of other package versions unused for
    ``stale_after_days`` days; returns the removed folders.

    The current version's folder is marked as used (its ``last-used`` file
    is touched) and never removed; a folder without a ``last-used`` file
    counts by its own modification time.  Unless ``force``, nothing is done
    if the last prune on this machine was less than a day ago (``now``: a
    POSIX time [s], default the current time).  A folder that another process
    removes at the same time is skipped.
    """
    root = cache_dir()
    now = time.time() if now is None else now
    current = root / _package_stamp()[:_STAMP_CHARS]
    _touch(current / "last-used")
    marker = root / "last-prune"
    if not force and marker.exists() and now - marker.stat().st_mtime < _PRUNE_EVERY_S:
        return []
    _touch(marker)
    removed = []
    for folder in root.iterdir():
        if folder == current or not folder.is_dir() or len(folder.name) != _STAMP_CHARS:
            continue
        used = folder / "last-used"
        try:
            last = (used if used.exists() else folder).stat().st_mtime
        except OSError:
            continue
        if now - last > stale_after_days * 86400.0:
            shutil.rmtree(folder, ignore_errors=True)
            removed.append(folder)
    return removed


install_cache_locator()
