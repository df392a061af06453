"""The package's layers (docs/design.md, "Layers"): dependencies point down, no cycles, small modules.

Reference: the source itself.  Every ``import`` statement of every module
(including the ones inside functions) is parsed with :mod:`ast` and resolved
to a tqdyn module; each module belongs to the layer of its first package
component, and a module may import only modules of its own layer or of a
lower one.  Physics and file-format layers must not import the command line,
plotting or the distributed engine.
"""

from __future__ import annotations

import ast
import pathlib

import pytest

import tqdyn

PACKAGE = pathlib.Path(tqdyn.__file__).resolve().parent

#: Layers from the bottom up (docs/design.md).  ``readers`` may also import
#: ``astro.constants``, the one dependency-free module of ``astro``.  ``_version``
#: is the version string alone (so that no layer imports the package root,
#: whose lazy attributes import the front door); ``_choices`` words every
#: layer's message about a name that is not allowed (the closest names, where
#: the list is documented).  ``peers`` (other libraries'
#: formulations of tqdyn's models) sit just above ``numerics``, so that they
#: cannot borrow tqdyn's physics; only the workflows use them
#: (:func:`test_only_workflows_use_the_peers`).
LAYERS = ("_version", "_choices", "numerics", "peers", "readers", "astro", "forces", "constellation", "lightpath", "dynamics", "scenario",
          "closedloop", "ttl", "od",
          "formats", "analysis", "workflows", "cli", "<front>")
#: Top-level modules outside the layer packages: the front door and the
#: version-0.1 import paths kept for users' scripts (they re-export).
FRONT = ("__init__", "api", "io", "sweep")
#: Third-party packages a layer must not import (I/O, plotting, CLI, distributed engine).
FORBIDDEN = {
    "_choices": ("h5py", "matplotlib", "click", "dask", "distributed", "xarray", "tqdm"),
    "numerics": ("h5py", "matplotlib", "click", "dask", "distributed", "xarray", "tqdm"),
    "peers": ("h5py", "matplotlib", "click", "dask", "distributed", "xarray", "tqdm"),
    "readers": ("h5py", "matplotlib", "click", "dask", "distributed", "xarray", "tqdm"),
    "astro": ("h5py", "matplotlib", "click", "dask", "distributed", "xarray", "tqdm"),
    "forces": ("h5py", "matplotlib", "click", "dask", "distributed", "xarray", "tqdm"),
    "constellation": ("h5py", "matplotlib", "click", "dask", "distributed", "xarray", "tqdm"),
    "lightpath": ("h5py", "matplotlib", "click", "dask", "distributed", "xarray", "tqdm"),
    "dynamics": ("h5py", "matplotlib", "click", "dask", "distributed", "xarray", "tqdm"),
    "scenario": ("h5py", "matplotlib", "click", "dask", "distributed", "xarray", "tqdm"),
    "closedloop": ("h5py", "matplotlib", "click", "dask", "distributed", "xarray", "tqdm"),
    "ttl": ("h5py", "matplotlib", "click", "dask", "distributed", "xarray", "tqdm"),
    "od": ("h5py", "matplotlib", "click", "dask", "distributed", "xarray", "tqdm"),
    "formats": ("matplotlib", "click", "dask", "distributed", "tqdm"),
    "analysis": ("click", "dask", "distributed", "tqdm"),
}
#: Longest module allowed, and the modules allowed to be longer (with the one job that needs it).
MAX_LINES = 600
LONG_MODULES: dict[str, str] = {}


def _modules():
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).with_suffix("")
        parts = list(rel.parts)
        is_pkg = parts[-1] == "__init__"
        if is_pkg:
            parts = parts[:-1]
        name = ".".join(["tqdyn"] + parts)
        out[name] = (path, is_pkg)
    return out


MODULES = _modules()


def _layer(module: str) -> str:
    parts = module.split(".")
    if len(parts) == 1 or (len(parts) == 2 and parts[1] in FRONT):
        return "<front>"
    return parts[1]


def _imports(name: str) -> set[tuple[str, int]]:
    """(imported tqdyn module, line) of module ``name``: ``from X import y``
    counts as X.y when that is a module, else X."""
    path, is_pkg = MODULES[name]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    base = name if is_pkg else name.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name == "tqdyn" or a.name.startswith("tqdyn."):
                    found.add((a.name, node.lineno))
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = base.split(".")
                parts = parts[: len(parts) - (node.level - 1)]
                target = ".".join(parts + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if not (target == "tqdyn" or target.startswith("tqdyn.")):
                continue
            for a in node.names:
                sub = f"{target}.{a.name}"
                found.add((sub if sub in MODULES else target, node.lineno))
    return found


def _third_party(name: str) -> set[str]:
    tree = ast.parse(MODULES[name][0].read_text(encoding="utf-8"))
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
            out.add(node.module.split(".")[0])
    return out


def test_the_layers_are_the_documented_ones():
    layers = {_layer(m) for m in MODULES}
    assert layers == set(LAYERS), f"undocumented layer(s): {sorted(layers - set(LAYERS))}"


@pytest.mark.parametrize("name", sorted(MODULES))
def test_dependencies_point_down(name):
    own = LAYERS.index(_layer(name))
    bad = []
    for target, line in _imports(name):
        layer = _layer(target)
        if layer == "astro" and target == "tqdyn.astro.constants" and _layer(name) == "readers":
            continue
        if LAYERS.index(layer) > own:
            bad.append(f"line {line}: {target} ({layer})")
    assert not bad, f"{name} ({_layer(name)}) imports upward: " + "; ".join(bad)


@pytest.mark.parametrize("name", sorted(m for m in MODULES if _layer(m) in FORBIDDEN))
def test_physics_and_formats_import_no_io_plotting_or_cli(name):
    bad = _third_party(name) & set(FORBIDDEN[_layer(name)])
    assert not bad, f"{name} imports {sorted(bad)}"


def test_only_workflows_use_the_peers():
    users = {m for m in MODULES for t, _ in _imports(m) if _layer(t) == "peers" and _layer(m) != "peers"}
    assert users and {_layer(m) for m in users} == {"workflows"}, f"peers imported by {sorted(users)}"


def test_no_import_cycles():
    graph = {m: {t for t, _ in _imports(m) if t in MODULES and t != m} for m in MODULES}
    # a package's __init__ importing its own submodules is how re-exports work: not a cycle
    for m in graph:
        graph[m] = {t for t in graph[m] if not t.startswith(m + ".")}
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m):
        state[m] = 1
        stack.append(m)
        for t in sorted(graph[m]):
            if state.get(t) == 1:
                cycle = stack[stack.index(t):] + [t]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if t not in state:
                visit(t)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m)


def test_modules_are_small():
    long = {m: sum(1 for _ in MODULES[m][0].open(encoding="utf-8")) for m in MODULES}
    too_long = {m: n for m, n in long.items() if n > MAX_LINES and m not in LONG_MODULES}
    assert not too_long, f"modules over {MAX_LINES} lines: {too_long}"


def _private_imports(name: str) -> list[str]:
    """Private names (``_x``, not dunders) that module ``name`` takes from a
    module of another layer: ``from tqdyn.a.b import _x``, ``from tqdyn.a
    import _module``, or ``m._x`` on a module ``m`` imported from another layer."""
    path, is_pkg = MODULES[name]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    base = name if is_pkg else name.rsplit(".", 1)[0]
    own = _layer(name)
    foreign_modules = {}   # local name -> imported module of another layer
    bad = []

    def private(n: str) -> bool:
        return n.startswith("_") and not (n.startswith("__") and n.endswith("__"))

    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                parts = base.split(".")
                parts = parts[: len(parts) - (node.level - 1)]
                target = ".".join(parts + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if not target.startswith("tqdyn") or _layer(target) == own:
                continue
            for a in node.names:
                sub = f"{target}.{a.name}"
                if private(a.name):
                    bad.append(f"line {node.lineno}: {sub}")
                elif sub in MODULES:
                    foreign_modules[a.asname or a.name] = sub
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("tqdyn.") and _layer(a.name) != own:
                    if any(private(p) for p in a.name.split(".")):
                        bad.append(f"line {node.lineno}: {a.name}")
                    if a.asname:
                        foreign_modules[a.asname] = a.name
    for node in ast.walk(tree):
        if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                and node.value.id in foreign_modules and private(node.attr)):
            bad.append(f"line {node.lineno}: {foreign_modules[node.value.id]}.{node.attr}")
    return sorted(set(bad))


@pytest.mark.parametrize("name", sorted(MODULES))
def test_no_private_names_across_layers(name):
    """What one layer uses of another is public (listed in ``__all__`` or at
    least not ``_``-prefixed); private names stay inside their layer."""
    bad = _private_imports(name)
    assert not bad, f"{name} uses private names of other layers: " + "; ".join(bad)


def test_no_layer_imports_the_package_root():
    """``from tqdyn import x`` inside a layer would run the front door's lazy
    imports (an import loop the cycle test cannot see): the version comes from
    ``tqdyn._version``."""
    bad = [f"{m} line {line}" for m in MODULES if _layer(m) != "<front>"
           for target, line in _imports(m) if target == "tqdyn"]
    assert not bad, "; ".join(bad)


def test_every_dotted_tqdyn_name_in_the_source_exists():
    """Docstrings, comments and messages name modules and objects as
    ``tqdyn.a.b.c``; every such name resolves (a module, then attributes), so
    that no text points at a module that moved (e.g. version 0.1's flat
    ``tqdyn.frames``)."""
    import importlib
    import inspect
    import re

    bad = []
    pattern = re.compile(r"\btqdyn(?:\.[A-Za-z_][A-Za-z0-9_]*)+")
    for name, (path, _) in MODULES.items():
        for lineno, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
            for dotted in pattern.findall(line):
                parts = dotted.split(".")
                k = max(i for i in range(1, len(parts) + 1) if ".".join(parts[:i]) in MODULES or i == 1)
                obj = importlib.import_module(".".join(parts[:k]))
                for attr in parts[k:]:
                    if isinstance(obj, type) and f"self.{attr} =" in inspect.getsource(obj):
                        break  # an instance attribute set by the class
                    if not hasattr(obj, attr):
                        bad.append(f"{path.relative_to(PACKAGE)}:{lineno}: {dotted}")
                        break
                    obj = getattr(obj, attr)
    assert not bad, "names that do not exist: " + "; ".join(bad)
