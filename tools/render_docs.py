"""Fill the measured numbers of README.md and docs/*.md from their JSON records.

Usage:
    python tools/render_docs.py            # rewrite the pages whose numbers changed
    python tools/render_docs.py --check    # exit 1 and name every marker whose text differs

The records (docs/numbers.md): ``docs/data/bench.json`` (``tqdyn bench
--json``), ``docs/data/studies-tianqin.json`` and ``docs/data/studies-lisa.json``
(the ``summary.json`` of ``tqdyn report --studies [--mission lisa]``) and
``docs/data/tests.json`` (``pytest --record-numbers``).

Markers in the markdown (HTML comments: GitHub shows the value, not the marker):

* a value: ``<!--n:SOURCE:PATH|FORMAT-->1.54<!--/n-->``.  SOURCE is ``bench``,
  ``tianqin``, ``lisa`` or ``tests``; PATH is a ``/``-separated path into the
  record (``bench``: MODEL/... looked up in the model's ``result``, then in the
  entry itself: ``kepler/runs/tqdyn dd/wall_s``, ``kepler/date``; ``tests``:
  the key, its ``value``; the studies: from the record's top:
  ``values/pointing/global/per_beam``, ``runs/gravity-90d/file_mb``).  A path
  segment that is an integer indexes a list; ``@max``, ``@min``, ``@absmax``,
  ``@sum`` reduce a list.  FORMAT (optional) is a Python format spec
  (``.2f``, ``.1e``, ``.3g``, ``,d``, ``,.0f``) after optional scale steps
  (``*1e3:``, ``/60:``), or one of ``date`` (the day of an ISO date),
  ``text`` (the string as is), ``machine`` (the one-line machine summary).
  Exponents are written short (``5.9e-6``).  A list is formatted element by
  element and joined with `` / ``.
* generated blocks (tables, transcripts): ``<!--gen:NAME-->`` ... ``<!--/gen-->``
  on lines of their own; NAME is a function of :data:`GENERATORS` (with an
  argument after a colon: ``<!--gen:transcript:default-run-->``).

A value missing from its record, or a marker that cannot be parsed, is an
error naming the page and the marker.  ``tests/test_docs_numbers.py`` renders
every page in memory and fails when a page and its records disagree.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "docs" / "data"
SOURCES = {"bench": "bench.json", "tianqin": "studies-tianqin.json", "lisa": "studies-lisa.json",
           "tests": "tests.json"}

INLINE = re.compile(r"<!--n:(?P<src>[a-z]+):(?P<path>[^|>]*?)(?:\|(?P<fmt>[^>]*?))?-->(?P<text>.*?)<!--/n-->",
                    re.S)
BLOCK = re.compile(r"(?P<open><!--gen:(?P<name>[^>]*?)-->\n)(?P<text>.*?)(?P<close><!--/gen-->)", re.S)


class RenderError(ValueError):
    """A marker that cannot be rendered (names the page and the marker)."""


# =========================================================================== records


def load_records(data_dir: Path = DATA) -> dict:
    """Every record by source name ({} for a missing file)."""
    out = {}
    for name, fname in SOURCES.items():
        p = Path(data_dir) / fname
        out[name] = json.loads(p.read_text(encoding="utf-8")) if p.exists() else {}
    return out


def _step(node, seg: str):
    if seg.startswith("@"):
        vals = [v for v in node if v is not None]
        op = seg[1:]
        if op == "max":
            return max(vals)
        if op == "min":
            return min(vals)
        if op == "absmax":
            return max(abs(v) for v in vals)
        if op == "sum":
            return sum(vals)
        raise KeyError(seg)
    if isinstance(node, list):
        return node[int(seg)]
    return node[seg]


def lookup(records: dict, src: str, path: str):
    """The value at ``path`` of source ``src`` (KeyError naming what is missing)."""
    if src not in records:
        raise KeyError(f"unknown source {src!r}; allowed: {', '.join(SOURCES)}")
    segs = [s for s in path.split("/") if s != ""]
    rec = records[src]
    if src == "bench":
        node = rec.get("models", {})[segs[0]]
        rest = segs[1:]
        if rest and isinstance(node.get("result"), dict) and rest[0] in node["result"]:
            node = node["result"]
    elif src == "tests":
        node = rec.get("numbers", {})[segs[0]]
        rest = segs[1:]
        if not rest or rest[0] not in node:
            node = node["value"]
    else:
        node, rest = rec, segs
    for seg in rest:
        try:
            node = _step(node, seg)
        except (KeyError, IndexError, ValueError, TypeError):
            raise KeyError(f"{src}:{path}: no {seg!r}") from None
    return node


# =========================================================================== formatting


def _short_exp(s: str) -> str:
    return re.sub(r"e([+-])0*(\d)", lambda m: "e" + ("-" if m.group(1) == "-" else "") + m.group(2), s)


def fmt_value(value, fmt: str | None) -> str:
    """``value`` formatted by ``fmt`` (see the module docstring)."""
    if isinstance(value, list):
        return " / ".join(fmt_value(v, fmt) for v in value)
    fmt = (fmt or "").strip()
    if fmt == "text":
        return str(value)
    if fmt == "date":
        return str(value)[:10]
    if fmt == "machine":
        return str(value["summary"] if isinstance(value, dict) else value)
    if value is None:
        return "n/a"
    if isinstance(value, str):
        return value
    *scales, spec = fmt.split(":") if fmt else [""]
    x = value
    for sc in scales:
        if sc.startswith("*"):
            x = x * float(sc[1:])
        elif sc.startswith("/"):
            x = x / float(sc[1:])
        else:
            raise ValueError(f"format {fmt!r}: {sc!r} is not a scale step (*X or /X)")
    if isinstance(x, float) and not math.isfinite(x):
        return "n/a"
    if spec == "":
        return _short_exp(repr(x)) if isinstance(x, float) else str(x)
    if spec.endswith("d") and isinstance(x, float):
        x = int(round(x))
    return _short_exp(format(x, spec))


# =========================================================================== generated blocks


def _bench(records, model):
    return records["bench"]["models"][model]


def _res(records, model):
    return _bench(records, model)["result"]


def _f(x, spec):
    return fmt_value(x, spec)


def _span(res) -> str:
    days = res["duration_s"] / 86400
    return f"{days:g} d"


def gen_readme_bench(records, arg=None) -> str:
    """The README's benchmark table."""
    k, fu, co = _res(records, "kepler"), _res(records, "full"), _res(records, "coupled")
    li, lc = _res(records, "lisa"), _res(records, "lisa-coupled")
    t5, l10 = _res(records, "tianqin-5y"), _res(records, "lisa-10y")
    kr = k["runs"]
    fr = fu["runs"]
    cr = co["runs"]
    rows = ["| run | tqdyn dd | tqdyn float64 | peer |", "| --- | ---: | ---: | ---: |"]
    hey = kr.get("heyoka real128")
    rows.append(f"| Kepler, 3 satellites, {_span(k)} at {k['step_s']:g} s (`--model kepler`) | "
                f"{_f(kr['tqdyn dd']['wall_s'], '.2f')} s (error {_f(kr['tqdyn dd']['err_vs_analytic_m'], '.1e')} m) | "
                f"{_f(kr['tqdyn float64']['wall_s'], '.2f')} s ({_f(kr['tqdyn float64']['err_vs_analytic_m'], '.1e')} m) | "
                + (f"heyoka real128: {_f(hey['wall_s'], '.2f')} s ({_f(hey['err_vs_analytic_m'], '.1e')} m) |"
                   if hey else "- |"))
    red_hey = fr.get("reduced model, heyoka real128")
    rows.append(f"| full force model, pure gravity, {_span(fu)} (`--model full`) | "
                f"{_f(fr['full model, dd']['wall_s'], '.3g')} s | {_f(fr['full model, float64']['wall_s'], '.3g')} s | "
                f"reduced model (Earth 12x12 + Sun + Moon): tqdyn {_f(fr['reduced model, dd']['wall_s'], '.3g')} s"
                + (f", heyoka real128 {_f(red_hey['wall_s'], '.3g')} s |" if red_hey else " |"))
    cd, cf = cr["coupled, dd"], cr["coupled, float64"]
    rows.append(f"| coupled: full model + attitude + drag-free control, {_span(co)} (`--model coupled`) | "
                f"{_f(cd['wall_s'], '.3g')} s ({_f(cd['peak_rss_mb'], '.0f')} MB; "
                f"{_f(co['dd_over_kepler_float64'], '.0f')}x the Kepler float64 run of the same invocation; "
                f"CPU per simulated day {_f(cd['cpu_inputs_per_day_s'], '.2f')} s of time-only inputs + "
                f"{_f(cd['cpu_loop_per_day_s'], '.2f')} s of compiled loop) | {_f(cf['wall_s'], '.3g')} s | - |")
    rows.append(f"| coupled TianQin, {_span(t5)} (`--model tianqin-5y`: `{t5['command']}`, "
                f"{_f(t5.get('n_steps'), ',d')} steps, {_f(t5['file_mb'], '.0f')} MB file) | "
                f"{_f(t5['wall_s'], '.0f')} s ({_f(t5['wall_s'] / 60, '.0f')} min), {_f(t5['peak_rss_mb'], '.0f')} MB "
                f"peak; resident set {_f(t5['rss_run_min_mb'], '.0f')}-{_f(t5['rss_run_max_mb'], '.0f')} MB after "
                f"the first 10 % of the run | - | - |")
    ld, lf = li["runs"]["lisa, dd"], li["runs"]["lisa, float64"]
    rows.append(f"| LISA, heliocentric `lisa-esa` scenario (point masses), {_span(li)} at "
                f"{li['step_s'] / 3600:g} h, {_f(li['n_steps'], ',d')} steps (`--model lisa`) | "
                f"{_f(ld['wall_s'], '.2f')} s ({_f(ld['peak_rss_mb'], '.0f')} MB) | {_f(lf['wall_s'], '.2f')} s | - |")
    cd, cf = lc["runs"]["lisa, dd"], lc["runs"]["lisa, float64"]
    rows.append(f"| LISA coupled (`lisa`: 6 TMs, iterative pointing, drag-free), {_span(lc)} at "
                f"{lc['step_s'] / 3600:g} h, {_f(lc['n_steps'], ',d')} steps (`--model lisa-coupled`) | "
                f"{_f(cd['wall_s'], '.2f')} s ({_f(cd['peak_rss_mb'], '.0f')} MB) | {_f(cf['wall_s'], '.2f')} s | - |")
    rows.append(f"| LISA coupled, {_span(l10)} (`--model lisa-10y`: `{l10['command']}`, "
                f"{_f(l10.get('n_steps'), ',d')} steps of {l10['step_s'] / 3600:g} h, {_f(l10['file_mb'], '.0f')} MB "
                f"file) | {_f(l10.get('propagation_wall_s'), '.2g')} s ({_f(l10['wall_s'], '.2g')} s with start-up and "
                f"output; {_f(l10['peak_rss_mb'], '.0f')} MB peak) | - | - |")
    return "\n".join(rows)


def gen_bench_machines(records, arg=None) -> str:
    """Machine, date and versions of each benchmark entry (one line per model)."""
    lines = []
    for model in (arg.split(",") if arg else records["bench"]["models"]):
        e = _bench(records, model)
        lib = e["libraries"]
        lines.append(f"- `{e['command'].split(' --json')[0]}`: {e['machine']['summary']}, {e['date'][:10]}, "
                     f"tqdyn {e['tqdyn_version']}, numba {lib.get('numba', '?')}, numpy {lib.get('numpy', '?')}"
                     + (f", heyoka {lib['heyoka']}" if "heyoka" in lib and model in ("kepler", "full") else ""))
    return "\n".join(lines)


def gen_precision_bench(records, arg=None) -> str:
    """docs/precision.md: the Kepler benchmark table."""
    k = _res(records, "kepler")
    lib = _bench(records, "kepler")["libraries"]
    rows = ["| run | wall [s] | us/step | final error vs analytic [m] |", "| --- | ---: | ---: | ---: |"]
    names = {"tqdyn dd": "tqdyn dd", "tqdyn float64": "tqdyn float64",
             "tqdyn dd h/2": f"tqdyn dd, {k['step_s'] / 2:g} s step",
             "heyoka real128": f"heyoka {lib.get('heyoka', '')} real128, `propagate_grid`"}
    for key, r in k["runs"].items():
        rows.append(f"| {names.get(key, key)} | {_f(r['wall_s'], '.2f')} | {_f(r['us_per_step'], '.1f')} | "
                    f"{_f(r['err_vs_analytic_m'], '.1e')} |")
    return "\n".join(rows)


def gen_transcript(records, arg) -> str:
    """A ``tqdyn run`` transcript of a bench model (``transcript:MODEL``; ``transcript:MODEL:short`` keeps
    the first satellite's line only)."""
    model, _, how = arg.partition(":")
    lines = _res(records, model)["transcript"].splitlines()
    if how == "short":
        out, seen = [], False
        for ln in lines:
            if ln.startswith("  ") and " r = [" in ln:
                if seen:
                    if out[-1] != "  ...":
                        out.append("  ...")
                    continue
                seen = True
            out.append(ln)
        lines = out
    return "```\n" + "\n".join(lines) + "\n```"


def _studies_rows(records, src):
    rec = records[src]
    head = "| quantity | paper | tqdyn | agreement / notes |" if src == "tianqin" else \
        "| quantity | reference | tqdyn | notes |"

    def cell(s):
        return str(s).replace("|", "\\|").replace("\n", " ")

    rows = [head, "|---|---|---|---|"]
    rows += [f"| {cell(r['quantity'])} | {cell(r['paper'])} | {cell(r['tqdyn'])} | {cell(r['notes'])} |"
             for r in rec["rows"]]
    return "\n".join(rows)


def gen_studies_table(records, arg) -> str:
    """The summary table of ``tqdyn report --studies`` (``studies-table:tianqin`` / ``:lisa``)."""
    return _studies_rows(records, arg)


def gen_kernels_table(records, arg=None) -> str:
    """The kernels micro-benchmark (``tqdyn bench --model kernels``)."""
    k = _res(records, "kernels")
    rows = ["| time-only input (one chunk) | ms | us per instant |", "| --- | ---: | ---: |"]
    for name, ms in k["chunk_ms"].items():
        rows.append(f"| {name} | {_f(ms, '.1f')} | {_f(k['chunk_us_per_instant'][name], '.2f')} |")
    return "\n".join(rows)


GENERATORS = {"readme-bench": gen_readme_bench, "bench-machines": gen_bench_machines,
              "precision-bench": gen_precision_bench, "transcript": gen_transcript,
              "studies-table": gen_studies_table, "kernels-table": gen_kernels_table}


# =========================================================================== rendering


def render(text: str, records: dict, page: str = "page") -> str:
    """``text`` with every marker's content rendered from ``records``."""
    def block(m):
        name, _, arg = m.group("name").partition(":")
        if name not in GENERATORS:
            raise RenderError(f"{page}: <!--gen:{m.group('name')}-->: no generator {name!r}; allowed: "
                              f"{', '.join(GENERATORS)}")
        try:
            body = GENERATORS[name](records, arg or None)
        except (KeyError, IndexError, TypeError, ValueError) as exc:
            raise RenderError(f"{page}: <!--gen:{m.group('name')}-->: {exc!r}") from None
        return m.group("open") + body + "\n" + m.group("close")

    def inline(m):
        try:
            value = lookup(records, m.group("src"), m.group("path"))
            out = fmt_value(value, m.group("fmt"))
        except (KeyError, IndexError, TypeError, ValueError) as exc:
            raise RenderError(f"{page}: {marker_of(m)}: {exc}") from None
        return m.group(0)[: m.start("text") - m.start(0)] + out + "<!--/n-->"

    return INLINE.sub(inline, BLOCK.sub(block, text))


def marker_of(m) -> str:
    """The opening comment of an inline match."""
    return m.group(0)[: m.start("text") - m.start(0)]


def differences(text: str, rendered: str) -> list[tuple[str, str, str]]:
    """(marker, text in the page, rendered text) of every marker that differs."""
    out = []
    pairs = [(BLOCK, lambda m: f"<!--gen:{m.group('name')}-->"), (INLINE, marker_of)]
    for rx, name in pairs:
        a, b = list(rx.finditer(text)), list(rx.finditer(rendered))
        for ma, mb in zip(a, b):
            if ma.group("text") != mb.group("text"):
                out.append((name(ma), ma.group("text"), mb.group("text")))
    return out


def pages(root: Path = ROOT) -> list[Path]:
    """README.md and every docs/*.md."""
    return [root / "README.md"] + sorted((root / "docs").glob("*.md"))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="do not write; exit 1 if a page differs from its records")
    args = ap.parse_args(argv)
    records = load_records()
    status = 0
    for page in pages():
        text = page.read_text(encoding="utf-8")
        rel = page.relative_to(ROOT)
        try:
            new = render(text, records, str(rel))
        except RenderError as exc:
            print(f"render_docs: error: {exc}", file=sys.stderr)
            status = 2
            continue
        if new == text:
            continue
        if args.check:
            for marker, old, want in differences(text, new):
                print(f"{rel}: {marker}: page has {old!r}, records give {want!r}")
            status = max(status, 1)
        else:
            page.write_text(new, encoding="utf-8")
            print(f"rendered {rel}")
    return status


if __name__ == "__main__":
    sys.exit(main())
