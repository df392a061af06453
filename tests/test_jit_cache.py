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
