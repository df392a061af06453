"""The package-wide compiled-kernel cache: tqdyn's kernels are cached under
one folder per package version (hash of every tqdyn source file), so a change
anywhere in the package can never reuse stale machine code."""

from __future__ import annotations

import pathlib

from numba.core import caching

from tqdyn.dynamics.loops import _chunk as _fixed_chunk
from tqdyn.numerics import jit as _jit


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


def test_dynamic_constants_share_one_compiled_callee():
    """numba compiles a jitted callee once per distinct constant argument (literal types); passed through
    ``numerics.jit.dynamic`` the constants are run-time values and the callee compiles once (numba's own
    ``signatures`` of the callee are the reference).  Without it, the same calls give three versions."""
    from numba import njit

    def callee(a, k, flag):
        return a + k if flag else a - k

    plain, wrapped = njit(callee), njit(callee)

    @njit
    def with_constants(a):
        return plain(a, 1, True) + plain(a, 2, True) + plain(a, 3, False)

    @njit
    def with_dynamic(a):
        d = _jit.dynamic
        return wrapped(a, d(1), d(True)) + wrapped(a, d(2), d(True)) + wrapped(a, d(3), d(False))

    assert with_constants(1.0) == with_dynamic(1.0) == 2.0 + 3.0 - 2.0
    assert len(plain.signatures) == 3
    assert len(wrapped.signatures) == 1 and str(wrapped.signatures[0]) == "(float64, int64, bool)"


def test_compile_clock_counts_compilations_not_calls():
    """The start-up benchmark's clock (workflows.bench_mission.compile_clock): one compiled function (with its
    callee compiled inside it) counts once, with positive time; calling it again, compiled, adds nothing."""
    from numba import njit

    from tqdyn.workflows.bench_mission import compile_clock

    @njit
    def inner(x):
        return 2.0 * x

    @njit
    def outer(x):
        return inner(x) + 1.0

    with compile_clock() as jit:
        assert outer(1.0) == 3.0
        first = dict(jit)
        assert outer(2.0) == 5.0
    assert first["n"] == 1 and 0.0 < first["cpu_s"] and 0.0 < first["wall_s"] < 60.0
    assert jit == first


def _has_cpython_wrapper(dispatcher, sig) -> bool:
    cres = dispatcher.overloads[sig]
    return cres.library.get_pointer_to_function(cres.fndesc.llvm_cpython_wrapper_name) != 0


def test_inner_kernels_have_no_wrappers_and_serve_python_through_a_twin():
    """An ``inner_kernel`` compiled for a compiled caller has no CPython wrapper (numba's own ``njit``
    version of the same function has one: the reference); calling it from Python afterwards with the
    same argument types (its compiled version cannot be entered from Python) runs the twin compiled
    with the wrapper, and both give what the plain ``njit`` function gives."""
    import numpy as np
    from numba import njit

    def f(x, a):
        return x * a[0] + a[1]

    inner, plain = _jit.inner_kernel(cache=False)(f), njit(f)

    @njit
    def caller(x, a):
        return inner(x, a) - 1.0

    a = np.array([3.0, 0.5])
    assert caller(2.0, a) == plain(2.0, a) - 1.0 == 5.5
    sig = inner.signatures[0]
    assert not _has_cpython_wrapper(inner, sig) and _has_cpython_wrapper(plain, sig)
    assert inner(2.0, a) == plain(2.0, a) == 6.5
    entry = inner.python_entry()
    assert entry.signatures == [sig] and _has_cpython_wrapper(entry, sig)
    assert inner.signatures == [sig]  # the Python call compiled nothing more into the inner kernel


def test_entry_kernels_keep_the_python_wrapper():
    """``kernel`` (numba's njit without the C wrapper) is called from Python and from compiled code."""
    from numba import njit

    def g(x):
        return 3.0 * x

    k = _jit.kernel(cache=False)(g)

    @njit
    def caller(x):
        return k(x) + 1.0

    assert caller(2.0) == 7.0 and k(2.0) == 6.0 and len(k.signatures) == 1
    assert _has_cpython_wrapper(k, k.signatures[0])
