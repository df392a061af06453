"""The package-wide compiled-kernel cache: tqdyn's kernels are cached under
one folder per package version (hash of every tqdyn source file), so a change
anywhere in the package can never reuse stale machine code."""

from __future__ import annotations

import pathlib

from numba.core import caching

from tqdyn.numerics import jit as _jit
from tqdyn.dynamics.fixed import _fixed_chunk


def test_locator_registered_first_and_used_for_tqdyn_kernels():
    assert _jit.install_cache_locator()
    impl = getattr(caching, "CacheImpl", None) or caching._CacheImpl
    first = impl._locator_classes[0]
    assert getattr(first, "_tqdyn", False)
    py_file = _fixed_chunk.py_func.__code__.co_filename
    loc = first.from_function(_fixed_chunk.py_func, py_file)
    assert loc is not None
    path = pathlib.Path(loc.get_cache_path())
    assert path.is_relative_to(_jit.cache_dir())
    assert _jit._package_stamp()[:16] in path.parts
    assert loc.get_source_stamp() == _jit._package_stamp()


def test_foreign_functions_are_left_to_numba():
    def f(x):
        return x

    first = (getattr(caching, "CacheImpl", None) or caching._CacheImpl)._locator_classes[0]
    assert first.from_function(f, __file__) is None


def test_cache_dir_env(monkeypatch, tmp_path):
    monkeypatch.setenv("TQDYN_CACHE_DIR", str(tmp_path))
    assert _jit.cache_dir() == tmp_path / "numba"


def test_stale_version_folders_are_pruned(monkeypatch, tmp_path):
    """Folders of other source versions unused for longer than STALE_AFTER_DAYS
    are removed; recent ones, the current one and foreign files are kept; the
    prune runs at most once a day unless forced."""
    import os
    import time

    monkeypatch.setenv("TQDYN_CACHE_DIR", str(tmp_path))
    root = tmp_path / "numba"
    now = time.time()
    old, recent, used = root / ("a" * 16), root / ("b" * 16), root / ("c" * 16)
    for folder, age_days in ((old, 45.0), (recent, 3.0), (used, 45.0)):
        (folder / "dynamics").mkdir(parents=True)
        os.utime(folder, (now - age_days * 86400, now - age_days * 86400))
    (used / "last-used").touch()                      # used just now, although the folder is old
    (root / "notes").mkdir()                          # not a version folder
    removed = _jit.prune_stale_caches(now=now, force=True)
    assert removed == [old]
    assert not old.exists() and recent.exists() and used.exists() and (root / "notes").exists()
    current = root / _jit._package_stamp()[:16]
    assert (current / "last-used").exists()
    os.utime(recent, (now - 40 * 86400, now - 40 * 86400))
    assert _jit.prune_stale_caches(now=now) == []     # pruned less than a day ago
    assert _jit.prune_stale_caches(now=now + 2 * 86400) == [recent]
