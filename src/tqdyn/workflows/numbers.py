"""Records of measured numbers: the JSON files that ``tqdyn bench --json``,
``tqdyn report --studies`` (``summary.json``) and the recording test run
(``pytest --record-numbers``) write, and from which ``tools/render_docs.py``
fills the numbers of README.md and docs/*.md (docs/numbers.md).

Every record carries its provenance (:func:`provenance`): what wrote it
(``written_by``), the command line, the date (UTC), the tqdyn version, the
machine (CPU model, cores, memory, load average when it started) and the
versions of the libraries that set the speed and the results.  Files are
written atomically (a temporary file renamed into place), and
:func:`merge_section` updates the entries of one section (one bench model,
one test number) and keeps the others with their own provenance.

Values are converted to JSON by :func:`to_json` (numpy scalars and arrays to
numbers and lists, tuples to lists, non-finite floats to null).
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import platform
import sys
from importlib import metadata
from pathlib import Path

from ..formats.atomic import replacing

__all__ = ["FORMAT_VERSION", "LIBRARIES", "commit", "machine", "libraries", "provenance", "to_json", "read_record",
           "write_record", "merge_section"]

#: Layout version of the records (a top-level ``format_version``).
FORMAT_VERSION = 1

#: Distributions whose versions a record lists (those installed).
LIBRARIES = ("numpy", "numba", "llvmlite", "scipy", "mpmath", "pyerfa", "h5py", "astropy-iers-data",
             "skyfield-data", "jplephem", "heyoka", "dask", "matplotlib")


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _memory_bytes() -> int | None:
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return None


def machine() -> dict:
    """The machine: ``cpu`` (model name), ``cores`` (usable by this
    process), ``memory_gb`` (physical), ``os``, ``load_average`` (1, 5,
    15 min, at the call) and ``summary`` (one line for the pages)."""
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        cores = os.cpu_count() or 1
    mem = _memory_bytes()
    mem_gb = None if mem is None else round(mem / 1e9, 1)
    try:
        load = [round(x, 2) for x in os.getloadavg()]
    except OSError:  # pragma: no cover
        load = None
    cpu = _cpu_model()
    summary = f"{cpu}, {cores} core{'s' if cores != 1 else ''}" + ("" if mem_gb is None else f", {mem_gb:g} GB")
    return {"cpu": cpu, "cores": cores, "memory_gb": mem_gb, "os": platform.platform(), "load_average": load,
            "summary": summary}


def libraries() -> dict:
    """Versions of Python and of the installed :data:`LIBRARIES` (by distribution name)."""
    out = {"python": platform.python_version()}
    for name in LIBRARIES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            pass
    return out


def commit() -> str | None:
    """The git commit of the source tree tqdyn is imported from (40 hex digits, with ``+dirty`` when
    files tracked by git differ from it), or None when the package is not a git checkout (an installed
    wheel) or git is not available."""
    import subprocess

    where = Path(__file__).resolve().parent
    try:
        head = subprocess.run(["git", "-C", str(where), "rev-parse", "HEAD"], capture_output=True, text=True,
                              timeout=10)
        if head.returncode != 0:
            return None
        dirty = subprocess.run(["git", "-C", str(where), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.SubprocessError):
        return None
    return head.stdout.strip() + ("+dirty" if dirty.returncode == 0 and dirty.stdout.strip() else "")


def provenance(written_by: str, command: str | None = None) -> dict:
    """Who, where and when: ``written_by``, ``command`` (default: this
    process's command line), ``date`` (UTC, ISO 8601, seconds),
    ``tqdyn_version``, ``tqdyn_commit`` (:func:`commit`), ``machine``
    (:func:`machine`), ``libraries``."""
    from .._version import __version__

    if command is None:
        command = " ".join([Path(sys.argv[0]).name] + sys.argv[1:]) if sys.argv and sys.argv[0] else "python"
    now = _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0)
    return {"written_by": written_by, "command": command, "date": now.isoformat().replace("+00:00", "Z"),
            "tqdyn_version": __version__, "tqdyn_commit": commit(), "machine": machine(), "libraries": libraries()}


def to_json(value):
    """``value`` with numpy scalars / arrays, tuples, Paths and mappings
    turned into plain JSON types; non-finite floats become None."""
    if isinstance(value, dict):
        return {str(k): to_json(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_json(v) for v in value]
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, int):
        return value
    if hasattr(value, "tolist"):  # numpy scalar or array
        return to_json(value.tolist())
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    try:
        f = float(value)
    except (TypeError, ValueError):
        return str(value)
    return f if math.isfinite(f) else None


def read_record(path) -> dict:
    """The record at ``path`` ({} if there is none).  ValueError (one line)
    if the file is not a JSON object."""
    p = Path(path)
    if not p.exists():
        return {}
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise ValueError(f"{str(p)!r} is not a readable JSON record ({exc}); allowed: a file written by tqdyn, "
                         "or a new path") from None
    if not isinstance(data, dict):
        raise ValueError(f"{str(p)!r} is not a JSON object; allowed: a file written by tqdyn, or a new path")
    return data


def write_record(path, data: dict) -> Path:
    """Write ``data`` (made JSON-ready by :func:`to_json`) to ``path``
    atomically, indented, keys in insertion order; returns the path."""
    p = Path(path)
    text = json.dumps(to_json(data), indent=1, ensure_ascii=False, allow_nan=False) + "\n"
    p.parent.mkdir(parents=True, exist_ok=True)
    with replacing(p, "the JSON record") as tmp:
        tmp.write_text(text, encoding="utf-8")
    return p


def merge_section(path, section: str, entries: dict, header: dict) -> dict:
    """Update the record at ``path``: the entries of ``entries`` replace
    those of the same name in ``record[section]``, the others stay; the
    top-level keys of ``header`` (``written_by``, a description, ...) are
    set, with ``format_version``.  Returns the record written."""
    data = read_record(path)
    out = {"format_version": FORMAT_VERSION, **header}
    for k, v in data.items():
        if k not in out and k != section:
            out[k] = v
    merged = dict(data.get(section) or {})
    merged.update(entries)
    out[section] = dict(sorted(merged.items()))
    write_record(path, out)
    return out
