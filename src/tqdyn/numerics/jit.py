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
import types

import numba
from numba.core import types as _types
from numba.core.caching import NullCache
from numba.core.compiler import CompilerBase, DefaultPassBuilder
from numba.core.compiler_machinery import LoweringPass, register_pass
from numba.core.registry import CPUDispatcher
from numba.core.typed_passes import NativeLowering
from numba.extending import intrinsic

__all__ = ["STALE_AFTER_DAYS", "cache_dir", "dynamic", "INLINED_OVERLOAD_OPTIONS", "OVERLOAD_OPTIONS", "inner_kernel",
           "install_cache_locator", "kernel", "prune_stale_caches"]

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


#: ``jit_options`` of tqdyn's numba overloads (called by compiled code only): no C wrapper (numba gives
#: overloads no CPython wrapper already), which every caller would link in and optimise again.
OVERLOAD_OPTIONS = {"no_cfunc_wrapper": True}

#: Suffix of the qualified name of an inner kernel's Python entry (:class:`_InnerDispatcher`): its own
#: cache files, apart from the inner kernel's (numba keys a cached kernel by name and argument types only).
_PYTHON_ENTRY = "__python_entry"


@register_pass(mutates_CFG=False, analysis_only=False)
class _DropWrappers(LoweringPass):
    """Compiler pass before the lowering: no CPython and no C wrapper for
    this function (set here, after typing, so that the functions it calls
    are typed and compiled with the same flags as under ``njit`` and their
    compiled versions are shared)."""
    _name = "tqdyn_drop_wrappers"
    keep_python = False

    def __init__(self):
        LoweringPass.__init__(self)

    def run_pass(self, state):
        state.flags = state.flags.copy()
        state.flags.no_cfunc_wrapper = True
        if not self.keep_python:
            state.flags.no_cpython_wrapper = True
        return True


@register_pass(mutates_CFG=False, analysis_only=False)
class _DropCWrapper(_DropWrappers):
    """:class:`_DropWrappers` that keeps the CPython wrapper (the C wrapper
    serves only numba's first-class function objects, which tqdyn does not use)."""
    _name = "tqdyn_drop_c_wrapper"
    keep_python = True


def _light_final_module(library) -> None:
    """Let ``library`` (a numba code library) skip the full optimisation of
    its final module, the module with its callees linked in: only numba's
    "cheap" module passes run on it (each callee was fully optimised in its
    own library already).  Left unchanged if numba's codegen internals are
    not as expected (numba 0.68)."""
    codegen = getattr(library, "_codegen", None)
    if not hasattr(codegen, "_module_pass_manager") or not hasattr(library, "_optimize_final_module"):
        return

    full = library._optimize_final_module

    def optimize_final_module():
        try:
            mpm, mpb = codegen._module_pass_manager(loop_vectorize=codegen._loopvect, slp_vectorize=False,
                                                    opt=codegen._opt_level, cost="cheap")
            timings = library._recorded_timings
        except (AttributeError, TypeError):  # another numba's internals: its own full optimisation
            return full()
        with timings.record("Module passes (cheap optimization for refprune)", mpb):
            mpm.run(library._final_module, mpb)

    library._optimize_final_module = optimize_final_module


@register_pass(mutates_CFG=False, analysis_only=False)
class _LinkOnly(LoweringPass):
    """Compiler pass before the lowering: the function's code library
    optimises its own code fully but its linked callees only lightly
    (:func:`_light_final_module`)."""
    _name = "tqdyn_link_only"

    def __init__(self):
        LoweringPass.__init__(self)

    def run_pass(self, state):
        if state.library is None:  # as numba's NativeLowering creates it
            state.library = state.targetctx.codegen().create_library(state.func_id.func_qualname)
            state.library.enable_object_caching()
        _light_final_module(state.library)
        return True


class _InnerCompiler(CompilerBase):
    """numba's nopython pipeline with :class:`_DropWrappers` before the lowering."""
    drop = _DropWrappers

    def define_pipelines(self):
        pm = DefaultPassBuilder.define_nopython_pipeline(self.state)
        at = next(i for i, (p, _) in enumerate(pm.passes) if p is NativeLowering)
        pm.passes.insert(at, (self.drop, self.drop.__doc__.split("\n")[0]))
        pm.finalize()
        return [pm]


class _EntryCompiler(_InnerCompiler):
    """numba's nopython pipeline with :class:`_DropCWrapper` before the lowering."""
    drop = _DropCWrapper


class _LoopCompiler(_EntryCompiler):
    """:class:`_EntryCompiler` with :class:`_LinkOnly` before the lowering."""

    def define_pipelines(self):
        pm = DefaultPassBuilder.define_nopython_pipeline(self.state)
        at = next(i for i, (p, _) in enumerate(pm.passes) if p is NativeLowering)
        pm.passes.insert(at, (self.drop, self.drop.__doc__.split("\n")[0]))
        pm.passes.insert(at, (_LinkOnly, _LinkOnly.__doc__.split("\n")[0]))
        pm.finalize()
        return [pm]


#: ``jit_options`` of an overload inlined into its callers (``inline="always"``): numba compiles it once to
#: type it and never runs that code, so its callees are linked into it without being optimised again.
INLINED_OVERLOAD_OPTIONS = {**OVERLOAD_OPTIONS, "pipeline_class": _LoopCompiler}


class _InnerDispatcher(CPUDispatcher):
    """A numba dispatcher whose compiled versions have no CPython and no C
    wrapper: the versions compiled for other compiled functions, which call
    the native function directly.  Every compiled function otherwise gets
    both wrappers, and each caller links them in and optimises them again
    with its own code (a fifth of the first run's compile time).  Called
    from Python, it runs a twin compiled with the wrappers (same source and
    options; its own cache files), so Python callers see an ordinary kernel."""

    def __init__(self, py_func, locals=None, targetoptions=None, pipeline_class=_InnerCompiler):
        super().__init__(py_func, locals=locals, targetoptions=targetoptions, pipeline_class=pipeline_class)
        self._python_entry = None

    def python_entry(self) -> CPUDispatcher:
        """The twin with the wrappers, which calls from Python run (compiled and cached on first use)."""
        if self._python_entry is None:
            f = self.py_func
            twin = types.FunctionType(f.__code__, f.__globals__, f.__name__, f.__defaults__, f.__closure__)
            twin.__qualname__ = f.__qualname__ + _PYTHON_ENTRY
            twin.__doc__ = f.__doc__
            entry = CPUDispatcher(twin, locals=self.locals, targetoptions=self.targetoptions)
            if not isinstance(self._cache, NullCache):
                entry.enable_caching()
            self._python_entry = entry
        return self._python_entry

    def __call__(self, *args, **kwargs):
        return self.python_entry()(*args, **kwargs)


def inner_kernel(func=None, *, cache: bool = True, **options):
    """``numba.njit(cache=cache, **options)`` for a function called mostly
    from other compiled functions: its compiled versions carry neither the
    CPython nor the C wrapper (:class:`_InnerDispatcher`), which saves their
    compilation in every caller; the compiled code is the same.  Calls from
    Python work as for any kernel (through a twin compiled with the
    wrappers).  Entry points that Python and compiled code both call stay
    ``njit``, so that one compiled version serves both.  Usage:
    ``@inner_kernel`` or ``@inner_kernel(...)``."""
    def decorate(f):
        dispatcher = _InnerDispatcher(f, targetoptions={"nopython": True, **options})
        if cache:
            dispatcher.enable_caching()
        return dispatcher

    return decorate if func is None else decorate(func)


def kernel(func=None, *, cache: bool = True, link_only: bool = False, **options):
    """``numba.njit(cache=cache, **options)`` without numba's C wrapper (a
    second entry besides the CPython one, which every caller compiled
    later links in): for the kernels that Python calls and compiled code
    calls too (e.g. the right-hand sides, called by the propagation loops
    and by :func:`tqdyn.dynamics.rhs.evaluate_rhs`).  Usage: ``@kernel`` or
    ``@kernel(...)``.  ``link_only``: the kernel's callees, fully optimised
    in their own compilation, are not optimised again with the kernel's
    code (for a kernel whose own code is a loop of calls, such as the
    propagation loops: the callees' code is most of it, and optimising it
    once more takes seconds; the arithmetic is the same, numba never
    reorders floating-point operations without ``fastmath``)."""
    def decorate(f):
        pipeline = _LoopCompiler if link_only else _EntryCompiler
        return numba.njit(cache=cache, pipeline_class=pipeline, **options)(f)

    return decorate if func is None else decorate(func)


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
