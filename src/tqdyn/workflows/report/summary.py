"""What a report produces: :class:`Report`, the rows of ``summary.md``
(:class:`SummaryRow`, :func:`format_summary`), ``summary.json``
(:func:`write_summary_json`), the output directory and the formatting of
the measured values."""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..._choices import unknown
from ...analysis.metrics import times_s
from ...formats import trajectory as io
from ..studies import STUDIES_DOC

__all__ = ["Report", "RunFiles", "evaluate_studies", "SummaryRow", "check_out_dir", "format_summary",
           "write_summary_json"]


@dataclass(frozen=True)
class SummaryRow:
    """One line of the summary: ``quantity``, ``paper`` (the paper's value,
    "-" if the paper has none), ``tqdyn`` (measured), ``notes`` (agreement
    and explanation)."""

    quantity: str
    paper: str
    tqdyn: str
    notes: str


@dataclass
class Report:
    """What a report wrote: ``out_dir``; ``figures`` (every PNG / PDF file);
    ``rows`` (:class:`SummaryRow`); ``summary_path`` (``summary.md``);
    ``notes`` (things skipped and why); ``values`` (the measured numbers by
    key, SI units, for tests and scripts)."""

    out_dir: Path
    figures: list = field(default_factory=list)
    rows: list = field(default_factory=list)
    summary_path: Path | None = None
    notes: list = field(default_factory=list)
    values: dict = field(default_factory=dict)


def format_summary(rows: Sequence[SummaryRow], title: str = "tqdyn report", notes: Sequence[str] = ()) -> str:
    """The summary as a markdown document (a table of ``rows`` and a list of notes)."""
    def cell(s):
        return str(s).replace("|", "\\|").replace("\n", " ")

    out = [f"# {title}", "", "| quantity | paper | tqdyn | agreement / notes |", "|---|---|---|---|"]
    out += [f"| {cell(r.quantity)} | {cell(r.paper)} | {cell(r.tqdyn)} | {cell(r.notes)} |" for r in rows]
    if notes:
        out += ["", "Notes:", ""] + [f"- {n}" for n in notes]
    return "\n".join(out) + "\n"


def write_summary_json(rep: Report, command: str, **extra) -> Path:
    """Write ``summary.json`` next to ``summary.md``: the provenance of the
    numbers (:func:`tqdyn.workflows.numbers.provenance`: ``command``, date,
    machine, library versions), the keyword arguments ``extra`` (e.g. the
    study runs and their timing), the table rows, the notes and every
    measured value (``rep.values``, SI units; arrays as lists).  Returns the
    path.  Read by ``tools/render_docs.py`` (docs/numbers.md)."""
    from ..numbers import provenance, write_record

    data = {"format_version": 1, **provenance("tqdyn report", command), **extra,
            "rows": [{"quantity": r.quantity, "paper": r.paper, "tqdyn": r.tqdyn, "notes": r.notes} for r in rep.rows],
            "notes": list(rep.notes), "values": rep.values}
    return write_record(rep.out_dir / "summary.json", data)


def check_out_dir(out_dir) -> Path:
    """Create the output directory ``out_dir`` if needed; ValueError (one
    line) if it cannot be created or written.  Returns its absolute path."""
    out = Path(os.path.abspath(os.path.expanduser(os.fspath(out_dir))))
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"--out: {str(out)!r} cannot be created ({exc}); allowed: a writable directory") from None
    if not os.access(out, os.W_OK):
        raise ValueError(f"--out: {str(out)!r} is not writable; allowed: a writable directory")
    return out


def _finish(rep: Report, title: str, runs: Sequence[str]) -> None:
    notes = list(rep.notes) + [f"run {r}" for r in runs]
    rep.summary_path = rep.out_dir / "summary.md"
    rep.summary_path.write_text(format_summary(rep.rows, title, notes), encoding="utf-8")


# =========================================================================== formatting helpers


def _e(x, unit="", digits=2) -> str:
    if x is None or not np.isfinite(x):
        return "n/a"
    return f"{x:.{digits}e}" + (f" {unit}" if unit else "")


def _per_sat(values, unit, fmt="{:.2f}") -> str:
    """One value per satellite: "v1 / v2 / v3 unit (Sat1/2/3)" (as many as there are satellites)."""
    values = list(values)
    return " / ".join(fmt.format(v) for v in values) + f" {unit} (Sat" + "/".join(
        str(k) for k in range(1, len(values) + 1)) + ")"


def _order_ok(value, paper, factor=10 ** 0.5 * 3) -> bool:
    """Same order of magnitude as a paper's "~x" value (within ~1 decade)."""
    return bool(np.isfinite(value) and paper / factor <= value <= paper * factor)


def _asd_verdict(res) -> str:
    """Agreement text for "ASD under the requirement in band"."""
    if not np.isfinite(res.max_ratio):
        return "n/a: run too short for the band"
    if res.max_ratio < 1:
        return "agrees: under the requirement in the whole band"
    return (f"agrees above {res.f_above:.3g} Hz only: below it the orbits' own gravity signal (the Earth's "
            "static field, the same in pure-gravity orbits, docs/report.md) reaches the requirement")


def _span_days(traj) -> float:
    t = times_s(traj)
    return float(t[-1] - t[0]) / 86400.0


def _label_of(path: Path, used: set) -> str:
    base = path.stem
    label, k = base, 2
    while label in used:
        label, k = f"{base}-{k}", k + 1
    used.add(label)
    return label


class RunFiles:
    """Trajectories of the study runs (run name -> file, None if missing),
    read lazily and cached: :meth:`get` (KeyError if missing), :meth:`has`,
    :meth:`drop` (free a cached trajectory)."""

    def __init__(self, paths):
        self.paths = dict(paths)
        self._cache: dict = {}

    def get(self, name):
        p = self.paths.get(name)
        if p is None:
            raise KeyError(name)
        if name not in self._cache:
            self._cache[name] = io.read_trajectory(p)
        return self._cache[name]

    def has(self, *names) -> bool:
        return all(self.paths.get(n) is not None for n in names)

    def drop(self, name):
        self._cache.pop(name, None)


def evaluate_studies(catalogue, funcs, run_paths, out_dir, studies=None, progress=None, label=None):
    """Evaluate the studies ``studies`` (names in ``catalogue``, default all)
    from their runs: checks the names (ValueError naming the study and the
    allowed ones), the output directory, reads the run files lazily
    (:class:`RunFiles`), skips a study whose runs are missing with a note,
    and calls ``funcs[name](report, runs)`` for the others.  ``label(name,
    study)``: its name in progress messages and notes.  Returns (report,
    runs, the names of the runs used)."""
    say = progress or (lambda msg: None)
    label = label or (lambda name, st: name)
    names = tuple(catalogue) if studies is None else tuple(studies)
    for s in names:
        if s not in catalogue:
            raise ValueError(unknown("study", s, catalogue, STUDIES_DOC, problem="is not a study"))
    rep = Report(out_dir=check_out_dir(out_dir))
    runs = RunFiles({k: (Path(v) if v is not None else None) for k, v in run_paths.items()})
    for s in names:
        st = catalogue[s]
        missing = [r for r in st.runs if not runs.has(r)]
        if missing:
            rep.notes.append(f"study {label(s, st)} skipped: run(s) {', '.join(missing)} not available")
            continue
        say(f"study {label(s, st)}: {st.title}")
        funcs[s](rep, runs)
    used = sorted({r for s in names for r in catalogue[s].runs if runs.has(r)})
    return rep, runs, used
