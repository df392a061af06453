"""Fill the measured numbers of README.md, CHANGELOG.md and docs/*.md from their JSON records.

Usage:
    python tools/render_docs.py            # rewrite the pages whose numbers changed
    python tools/render_docs.py --check    # exit 1 and name every marker whose text differs

The records (docs/numbers.md): ``docs/data/bench.json`` (``tqdyn bench
--json``), ``docs/data/studies-tianqin.json`` and ``docs/data/studies-lisa.json``
(the ``summary.json`` of ``tqdyn report --studies [--mission lisa]``),
``docs/data/closed-loop.json`` (the ``summary.json`` of ``tqdyn report --closed-loop``),
``docs/data/od-study.json`` (``python tools/od_study.py``),
``docs/data/od-residuals.json`` (``python tools/od_residuals.py``),
``docs/data/closed-loop-hinf.json`` (``python tools/closed_loop_hinf.py``) and
``docs/data/tests.json`` (``pytest --record-numbers``).

Markers in the markdown (HTML comments: GitHub shows the value, not the marker):

* a value: ``<!--n:SOURCE:PATH|FORMAT-->1.54<!--/n-->``.  SOURCE is ``bench``,
  ``tianqin``, ``lisa``, ``closedloop``, ``odstudy``, ``odresiduals``, ``hinf`` or ``tests``; PATH is a ``/``-separated path into the
  record (``bench``: MODEL/... looked up in the model's ``result``, then in the
  entry itself: ``kepler/runs/tqdyn dd/wall_s``, ``kepler/date``; ``tests``:
  the key, its ``value``; the studies: from the record's top:
  ``values/pointing/global/per_beam``, ``runs/gravity-90d/file_mb``).  A path
  segment that is an integer indexes a list; ``@max``, ``@min``, ``@absmax``,
  ``@sum`` reduce a list; ``A // B`` is the ratio of two paths; a ``tests``
  key may hold ``*`` (the values of every matching key, in one list).  FORMAT
  (optional) is a Python format spec (``.2f``, ``.1e``, ``.3g``, ``,d``,
  ``,.0f``; ``~N``: N significant digits without an exponent) after optional
  scale steps (``*1e3:``, ``/60:``, ``-1:``), or one of ``date`` (the day of an ISO date),
  ``text`` (the string as is), ``machine`` (the one-line machine summary),
  ``hm`` (hours as HH:MM).
  Exponents are written short (``5.9e-6``).  A list is formatted element by
  element and joined with `` / ``.
* generated blocks (tables, transcripts): ``<!--gen:NAME-->`` ... ``<!--/gen-->``
  on lines of their own; NAME is a function of :data:`GENERATORS` (with an
  argument after a colon: ``<!--gen:transcript:default-run-->``).

Markers inside fenced code blocks are examples and are left alone (a
generated block may hold a fenced block: its markers sit outside it).

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
           "tests": "tests.json", "closedloop": "closed-loop.json", "odstudy": "od-study.json",
           "odresiduals": "od-residuals.json", "hinf": "closed-loop-hinf.json"}

INLINE = re.compile(r"<!--n:(?P<src>[a-z]+):(?P<path>[^|>]*?)(?:\|(?P<fmt>[^>]*?))?-->(?P<text>.*?)<!--/n-->",
                    re.S)
BLOCK = re.compile(r"(?P<open><!--gen:(?P<name>[^>]*?)-->\n)(?P<text>.*?)(?P<close><!--/gen-->)", re.S)


class RenderError(ValueError):
    """A marker that cannot be rendered (names the page and the marker)."""


class StaleRecordError(RenderError):
    """A marker reads a record measured on another tqdyn version than the package's."""


# =========================================================================== records


def package_version(root: Path = ROOT) -> str:
    """The version of the package in this tree (``src/tqdyn/_version.py``, read without importing it)."""
    text = (Path(root) / "src" / "tqdyn" / "_version.py").read_text(encoding="utf-8")
    return re.search(r'__version__\s*=\s*"([^"]+)"', text).group(1)


class Stale(dict):
    """A record, bench model or test number measured on another tqdyn version than the package's:
    any use of it raises :class:`StaleRecordError` naming what, both versions and the command to re-run."""

    def __init__(self, what: str, measured, package: str, command):
        super().__init__()
        self.message = (f"{what} was measured on tqdyn {measured or '(no version)'}, the package is {package}"
                        + (f"; re-run: {command}" if command else ""))

    def _fail(self, *args, **kwargs):
        raise StaleRecordError(self.message)

    __getitem__ = get = __contains__ = __iter__ = keys = items = values = _fail


def check_versions(records: dict, version: str) -> dict:
    """``records`` with every part measured on another version than ``version`` replaced by a
    :class:`Stale` (bench: each model; tests: each number; the other records as a whole)."""
    out = {}
    for name, rec in records.items():
        if not rec:
            out[name] = rec
        elif name == "bench":
            models = {m: e if e.get("tqdyn_version") == version else
                      Stale(f"bench model {m!r}", e.get("tqdyn_version"), version, e.get("command"))
                      for m, e in rec.get("models", {}).items()}
            out[name] = {**rec, "models": models}
        elif name == "tests":
            numbers = {k: e if e.get("tqdyn_version") == version else
                       Stale(f"test number {k!r} ({e.get('test')})", e.get("tqdyn_version"), version,
                             "pytest --record-numbers docs/data/tests.json " + str(e.get("test", "")).split("::")[0])
                       for k, e in rec.get("numbers", {}).items()}
            out[name] = {**rec, "numbers": numbers}
        elif rec.get("tqdyn_version") == version:
            out[name] = rec
        else:
            out[name] = Stale(f"docs/data/{SOURCES[name]}", rec.get("tqdyn_version"), version, rec.get("command"))
    return out


def load_records(data_dir: Path = DATA, version: str | None = None, check: bool = True) -> dict:
    """Every record by source name ({} for a missing file), the parts measured on another tqdyn version
    than ``version`` (default: the package's, :func:`package_version`) made :class:`Stale` unless
    ``check`` is False: a page that renders one of them fails (records match the code they describe,
    docs/numbers.md)."""
    out = {}
    for name, fname in SOURCES.items():
        p = Path(data_dir) / fname
        out[name] = json.loads(p.read_text(encoding="utf-8")) if p.exists() else {}
    return check_versions(out, package_version() if version is None else version) if check else out


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
    """The value at ``path`` of source ``src`` (KeyError naming what is missing); ``A // B``: the ratio of
    the values at paths A and B (element by element for lists)."""
    if " // " in path:
        a, b = (lookup(records, src, p.strip()) for p in path.split(" // ", 1))
        if isinstance(a, list) and isinstance(b, list):
            return [x / y for x, y in zip(a, b)]
        if isinstance(a, list):
            return [x / b for x in a]
        return a / b
    if src not in records:
        raise KeyError(f"unknown source {src!r}; allowed: {', '.join(SOURCES)}")
    segs = [s for s in path.split("/") if s != ""]
    rec = records[src]
    if src == "bench":
        node = rec.get("models", {})[segs[0]]
        rest = segs[1:]
        if rest and isinstance(node.get("result"), dict) and rest[0] in node["result"]:
            node = node["result"]
    elif src == "tests" and "*" in segs[0]:  # every key matching the pattern: their values, flattened once
        import fnmatch

        keys = sorted(k for k in rec.get("numbers", {}) if fnmatch.fnmatchcase(k, segs[0]))
        if not keys:
            raise KeyError(f"{src}:{path}: no key matches {segs[0]!r}")
        node, rest = [], segs[1:]
        for k in keys:
            v = rec["numbers"][k]["value"]
            node += v if isinstance(v, list) else [v]
    elif src == "tests":
        node = rec.get("numbers", {})[segs[0]]
        rest = segs[1:]
        if not rest or rest[0] not in node:
            node = node["value"]
    else:
        node, rest = rec, segs
    i = 0
    while i < len(rest):
        seg, used = rest[i], 1
        if isinstance(node, dict):  # keys may hold "/" themselves ("deviation/dragfree-global-90d"): longest first
            for j in range(len(rest), i, -1):
                if "/".join(rest[i:j]) in node:
                    seg, used = "/".join(rest[i:j]), j - i
                    break
        try:
            node = _step(node, seg)
        except StaleRecordError:
            raise
        except (KeyError, IndexError, ValueError, TypeError):
            raise KeyError(f"{src}:{path}: no {seg!r}") from None
        i += used
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
    if fmt == "hm":  # hours -> HH:MM
        m = int(round(float(value) * 60)) % (24 * 60)
        return f"{m // 60:02d}:{m % 60:02d}"
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
        elif sc.startswith("+"):
            x = x + float(sc[1:])
        elif sc.startswith("-"):
            x = x - float(sc[1:])
        else:
            raise ValueError(f"format {fmt!r}: {sc!r} is not a scale step (*X, /X, +X or -X)")
    if isinstance(x, float) and not math.isfinite(x):
        return "n/a"
    if spec == "":
        return _short_exp(repr(x)) if isinstance(x, float) else str(x)
    if spec.startswith("~"):  # N significant digits, never an exponent (1503, 682, 4.57, 0.00015)
        n = int(spec[1:])
        if x == 0:
            return "0"
        d = max(0, n - 1 - math.floor(math.log10(abs(x))))
        return f"{x:.{d}f}"
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
    rows.append(f"| Kepler, 3 satellites, DP87, {_span(k)} at {k['step_s']:g} s (`--model kepler`) | "
                f"{_f(kr['tqdyn dd']['wall_s'], '.2f')} s (error {_f(kr['tqdyn dd']['err_vs_analytic_m'], '.1e')} m) | "
                f"{_f(kr['tqdyn float64']['wall_s'], '.2f')} s ({_f(kr['tqdyn float64']['err_vs_analytic_m'], '.1e')} m) | "
                + (f"heyoka real128: {_f(hey['wall_s'], '.2f')} s ({_f(hey['err_vs_analytic_m'], '.1e')} m) |"
                   if hey else "- |"))
    red_hey = fr.get("reduced model, heyoka real128")
    rows.append(f"| full force model, pure gravity, DP87, {_span(fu)} (`--model full`) | "
                f"{_f(fr['full model, dd']['wall_s'], '.3g')} s | {_f(fr['full model, float64']['wall_s'], '.3g')} s | "
                f"reduced model (Earth 12x12 + Sun + Moon): tqdyn {_f(fr['reduced model, dd']['wall_s'], '.3g')} s"
                + (f", heyoka real128 {_f(red_hey['wall_s'], '.3g')} s |" if red_hey else " |"))
    cd, cf = cr["coupled, dd"], cr["coupled, float64"]
    rows.append(f"| coupled: full model + attitude + drag-free control, DP87, {_span(co)} (`--model coupled`) | "
                f"{_f(cd['wall_s'], '.3g')} s ({_f(cd['peak_rss_mb'], '.0f')} MB; "
                f"{_f(co['dd_over_kepler_float64'], '.0f')}x the Kepler float64 run of the same invocation; "
                f"CPU per simulated day {_f(cd['cpu_inputs_per_day_s'], '.2f')} s of time-only inputs + "
                f"{_f(cd['cpu_loop_per_day_s'], '.2f')} s of compiled loop) | {_f(cf['wall_s'], '.3g')} s | - |")
    md, mf = cr.get("coupled, dd, multistep"), cr.get("coupled, float64, multistep")
    if md and mf:  # records written before the multistep method have no such runs
        rows.append(f"| the same with the multistep method ({co['multistep']}; the default), {_span(co)} "
                    f"(`--model coupled`) | {_f(md['wall_s'], '.3g')} s ({_f(md['peak_rss_mb'], '.0f')} MB; "
                    f"{_f(co['multistep_dd_over_kepler_float64'], '.0f')}x the Kepler float64 run; DP87 takes "
                    f"{_f(co['dp87_over_multistep_dd'], '.1f')}x as long; CPU per simulated day "
                    f"{_f(md['cpu_inputs_per_day_s'], '.2g')} s of time-only inputs + "
                    f"{_f(md['cpu_loop_per_day_s'], '.2g')} s of compiled loop) | {_f(mf['wall_s'], '.3g')} s | - |")
    rows.append(f"| coupled TianQin, DP87, {_span(t5)} (`--model tianqin-5y`: `{t5['command']}`, "
                f"{_f(t5.get('n_steps'), ',d')} steps, {_f(t5['file_mb'], '.2g')} MB file) | "
                f"{_f(t5['wall_s'], '.0f')} s" + (f" ({_f(t5['wall_s'] / 60, '.0f')} min)" if t5["wall_s"] > 120 else "")
                + f", {_f(t5['peak_rss_mb'], '.0f')} MB "
                f"peak; resident set {_f(t5['rss_run_min_mb'], '.0f')}-{_f(t5['rss_run_max_mb'], '.0f')} MB after "
                f"the first 10 % of the run | - | - |")
    t5m = _bench(records, "tianqin-5y-multistep")["result"] if "tianqin-5y-multistep" in records["bench"]["models"] \
        else None
    if t5m is not None:
        rows.append(f"| coupled TianQin, multistep method, {_span(t5m)} (`--model tianqin-5y-multistep`: "
                    f"`{t5m['command']}`, {_f(t5m.get('n_steps'), ',d')} steps) | {_f(t5m['wall_s'], '.0f')} s"
                    + (f" ({_f(t5m['wall_s'] / 60, '.1f')} min)" if t5m["wall_s"] > 120 else "")
                    + f", {_f(t5m['peak_rss_mb'], '.0f')} MB peak | - | - |")
    ld, lf = li["runs"]["lisa, dd"], li["runs"]["lisa, float64"]
    rows.append(f"| LISA, heliocentric `lisa-esa` scenario (point masses), {_span(li)} at "
                f"{li['step_s'] / 3600:g} h, {_f(li['n_steps'], ',d')} steps (`--model lisa`) | "
                f"{_f(ld['wall_s'], '.2f')} s ({_f(ld['peak_rss_mb'], '.0f')} MB) | {_f(lf['wall_s'], '.2f')} s | - |")
    cd, cf = lc["runs"]["lisa, dd"], lc["runs"]["lisa, float64"]
    rows.append(f"| LISA coupled (`lisa`: 6 TMs, iterative pointing, drag-free), {_span(lc)} at "
                f"{lc['step_s'] / 3600:g} h, {_f(lc['n_steps'], ',d')} steps (`--model lisa-coupled`) | "
                f"{_f(cd['wall_s'], '.2f')} s ({_f(cd['peak_rss_mb'], '.0f')} MB) | {_f(cf['wall_s'], '.2f')} s | - |")
    rows.append(f"| LISA coupled, {_span(l10)} (`--model lisa-10y`: `{l10['command']}`, "
                f"{_f(l10.get('n_steps'), ',d')} steps of {l10['step_s'] / 3600:g} h, {_f(l10['file_mb'], '.2g')} MB "
                f"file) | {_f(l10.get('propagation_wall_s'), '.2g')} s ({_f(l10['wall_s'], '.2g')} s with start-up and "
                f"output; {_f(l10['peak_rss_mb'], '.0f')} MB peak) | - | - |")
    cl = records["bench"]["models"].get("closed-loop")
    if cl is not None:
        c = cl["result"]
        rows.append(f"| closed loop: {c['n_sat']} TianQin spacecraft, {_span(c)} at {c['fs']:g} Hz, "
                    f"{_f(c['n_samples'], ',d')} samples x {c['n_outputs']} outputs streamed to a "
                    f"{_f(c['file_mb'], '.0f')} MB file (`--model closed-loop`) | {_f(c['wall_s'], '.3g')} s "
                    f"({_f(c['samples_per_s'], ',.0f')} samples/s; {_f(c['peak_rss_mb'], '.0f')} MB peak) | - | - |")
    return "\n".join(rows)


def gen_bench_machines(records, arg=None) -> str:
    """Machine, date and versions of each benchmark entry (one line per model)."""
    lines = []
    for model in (arg.split(",") if arg else records["bench"]["models"]):
        e = _bench(records, model)
        lib = e["libraries"]
        load = e["machine"].get("load_average")
        lines.append(f"- `{e['command'].split(' --json')[0]}`: {e['machine']['summary']}"
                     + (f" (load average {load[0]:g} at the start)" if load else "") + f", {e['date'][:10]}, "
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


def gen_lisa_common_sg(records, arg=None) -> str:
    """docs/lisa-coupled.md, section c: the common self-gravity runs on LISA (``tqdyn report --studies --mission lisa``)."""
    v = records["lisa"]["values"]["common_sg"]
    deg = 180.0 / math.pi
    rows = ["| push (1e-9 m/s^2) | dL at 1 yr, arms 12 / 23 / 31 | max \\|dL\\| | max \\|dL/dt\\| | max \\|d alpha\\| | "
            "Hill estimate (max \\|dL\\|; run/estimate) |", "| --- | --- | --- | --- | --- | --- |"]
    for label in ("+x", "-x", "+y", "-y", "+z", "-z"):
        r = v[label]
        small = label[1] == "z"
        km = "~2" if small else "~3"
        if small:
            hill = "0 at first order"
        elif label[0] == "-":
            hill = "same, sign reversed"
        else:
            hill = (f"{_f([x / 1e3 for x in r['est_max_dL']], '~3')} km; "
                    f"{_f([a / b for a, b in zip(r['max_dL'], r['est_max_dL'])], '.3f')}")
        rows.append(f"| {label[0]}{label[1].upper()}_S | {_f([x / 1e3 for x in r['dL_end']], km)} km | "
                    f"{_f([x / 1e3 for x in r['max_dL']], km)} km | {_f([x * 1e3 for x in r['max_dLdot']], km)} mm/s | "
                    f"{_f([x * deg for x in r['max_dalpha']], '.2g')} deg | {hill} |")
    return "\n".join(rows)


def gen_lisa_pointing(records, arg=None) -> str:
    """docs/lisa-coupled.md, section d: the pointing laws on LISA."""
    p = records["lisa"]["values"]["pointing"]
    m, b = p["maxima"], p["bounds"]
    rows = ["| law | per beam | X_S | opening angle theta | MOSA angle theta/2 | first-order bound |",
            "| --- | --- | --- | --- | --- | --- |"]
    for law, name, bound in (("global", "global (instantaneous)", f"v/c = {_f(b['global'], '.3e')}"),
                             ("taylor1", "taylor1", f"v^2/(2c^2) = {_f(b['taylor'], '.3e')}"),
                             ("taylor2", "taylor2", "v^2/(2c^2)")):
        x = m[law]
        rows.append(f"| {name} | {_f(x['per_beam'], '.3e')} rad | {_f(x['x_s'], '.3e')} | {_f(x['theta'], '.3e')} | "
                    f"{_f(x['theta'] / 2, '.3e')} rad | {bound} |")
    rows.append(f"| tau = L/c vs the light time | {_f(p['tau_error'], '.3e')} s | | | | L v / c^2 = {_f(b['tau'], '.3e')} s |")
    return "\n".join(rows)


def gen_lisa_esa_ramp(records, arg=None) -> str:
    """docs/lisa-coupled.md, section e: coupled lisa - lisa-esa after one year and over ESA's span."""
    vals = records["lisa"]["values"]
    rows = ["| after | coupled `lisa` - `lisa-esa`: radial / along / cross (Sat1; Sat2; Sat3) | CW prediction | "
            "parts (along): incentre vs centroid; aberration; nominal G |", "| --- | --- | --- | --- |"]
    for key in ("ramp-1y", "ramp-span"):
        r = vals[f"esa/{key}"]
        days = r["t_end"] / 86400.0
        when = f"{days:g} d" + (f" ({days / 365.25:.3g} yr)" if days > 400 else "")
        meas = "; ".join(_f([r["radial_end"][s], r["along_end"][s], r["cross_end"][s]], "~3") for s in range(3))
        pred = "; ".join(_f(r["pred_end"][s], "~3") for s in range(3))
        parts = "; ".join(_f([r["parts_end"]["geometric"][s][1], r["parts_end"]["aberration"][s][1],
                              r["parts_end"]["nominal"][s][1]], "~3") for s in range(3))
        rows.append(f"| {when} | {meas} m | {pred} m | {parts} m |")
    return "\n".join(rows)


def gen_force_budget(records, arg) -> str:
    """A ``tqdyn forces`` budget recorded by a test (``force-budget:KEY``): max and RMS per term, largest first."""
    rows = records["tests"]["numbers"][arg]["value"]
    out = ["| term | max | RMS |", "| --- | ---: | ---: |"]
    for name, (mx, rms) in sorted(rows.items(), key=lambda kv: -kv[1][0]):
        out.append(f"| {name} | {mx:.2e} | {rms:.2e} |")
    return "\n".join(out)


def gen_helio_roundoff(records, arg=None) -> str:
    """docs/force-model.md: float64 round-off per heliocentric term (``tests/test_heliocentric.py``, three epochs)."""
    import fnmatch

    nums = records["tests"]["numbers"]
    tables = [nums[k]["value"] for k in sorted(nums) if fnmatch.fnmatchcase(k, "heliocentric.roundoff.*")]
    year2 = (365.25 * 86400.0) ** 2 / 2

    def span(name, key):
        return [t[name][key] for t in tables]

    rows = ["| term | float64 round-off [m/s^2] | err T^2/2 over one year |", "| --- | ---: | ---: |",
            f"| Sun monopole (float64) | {_f(min(span('sun_monopole', 'float64')), '.2g')} .. "
            f"{_f(max(span('sun_monopole', 'float64')), '.2g')} | {_f(min(span('sun_monopole', 'year_m')), '.2g')} .. "
            f"{_f(max(span('sun_monopole', 'year_m')), '.2g')} m |",
            f"| Sun monopole (dd) | <= {_f(max(span('sun_monopole', 'dd')), '.2g')} | "
            f"{_f(max(span('sun_monopole', 'dd')) * year2, '.1g')} m |"]
    named = ("earth", "jupiter", "venus")
    for body in named:
        rows.append(f"| {body.capitalize()} | <= {_f(max(span(body, 'float64')), '.2g')} | "
                    f"<= {_f(max(span(body, 'year_m')), '.2g')} m |")
    others = [n for n in tables[0] if n not in ("sun_monopole", *named)]
    rows.append(f"| every other term | <= {_f(max(max(span(n, 'float64')) for n in others), '.1g')} | "
                f"<= {_f(max(max(span(n, 'year_m')) for n in others), '.1g')} m |")
    return "\n".join(rows)


GENERATORS = {"readme-bench": gen_readme_bench, "bench-machines": gen_bench_machines,
              "precision-bench": gen_precision_bench, "transcript": gen_transcript,
              "studies-table": gen_studies_table, "kernels-table": gen_kernels_table,
              "force-budget": gen_force_budget, "helio-roundoff": gen_helio_roundoff, "lisa-common-sg": gen_lisa_common_sg, "lisa-pointing": gen_lisa_pointing, "lisa-esa-ramp": gen_lisa_esa_ramp}


# =========================================================================== rendering

FENCE = re.compile(r"^```", re.M)


def fenced(text: str) -> list[tuple[int, int]]:
    """(start, end) offsets of the fenced code blocks of ``text`` (markers there are examples, not markers)."""
    marks = [m.start() for m in FENCE.finditer(text)]
    return [(a, b) for a, b in zip(marks[::2], marks[1::2])]


def _outside(spans):
    return lambda pos: not any(a <= pos < b for a, b in spans)


def markers(rx, text):
    """The matches of ``rx`` in ``text`` outside fenced code blocks."""
    ok = _outside(fenced(text))
    return [m for m in rx.finditer(text) if ok(m.start())]


def render(text: str, records: dict, page: str = "page") -> str:
    """``text`` with every marker's content rendered from ``records``."""
    def block(m):
        name, _, arg = m.group("name").partition(":")
        if name not in GENERATORS:
            raise RenderError(f"{page}: <!--gen:{m.group('name')}-->: no generator {name!r}; allowed: "
                              f"{', '.join(GENERATORS)}")
        try:
            body = GENERATORS[name](records, arg or None)
        except StaleRecordError as exc:
            raise StaleRecordError(f"{page}: <!--gen:{m.group('name')}-->: {exc}") from None
        except (KeyError, IndexError, TypeError, ValueError) as exc:
            raise RenderError(f"{page}: <!--gen:{m.group('name')}-->: {exc!r}") from None
        return m.group("open") + body + "\n" + m.group("close")

    def inline(m):
        try:
            value = lookup(records, m.group("src"), m.group("path"))
            out = fmt_value(value, m.group("fmt"))
        except StaleRecordError as exc:
            raise StaleRecordError(f"{page}: {marker_of(m)}: {exc}") from None
        except (KeyError, IndexError, TypeError, ValueError) as exc:
            raise RenderError(f"{page}: {marker_of(m)}: {exc}") from None
        return m.group(0)[: m.start("text") - m.start(0)] + out + "<!--/n-->"

    ok = _outside(fenced(text))
    text = BLOCK.sub(lambda m: block(m) if ok(m.start()) else m.group(0), text)
    ok = _outside(fenced(text))
    return INLINE.sub(lambda m: inline(m) if ok(m.start()) else m.group(0), text)


def marker_of(m) -> str:
    """The opening comment of an inline match."""
    return m.group(0)[: m.start("text") - m.start(0)]


def differences(text: str, rendered: str) -> list[tuple[str, str, str]]:
    """(marker, text in the page, rendered text) of every marker that differs."""
    out = []
    pairs = [(BLOCK, lambda m: f"<!--gen:{m.group('name')}-->"), (INLINE, marker_of)]
    for rx, name in pairs:
        a, b = markers(rx, text), markers(rx, rendered)
        for ma, mb in zip(a, b):
            if ma.group("text") != mb.group("text"):
                out.append((name(ma), ma.group("text"), mb.group("text")))
    return out


def pages(root: Path = ROOT) -> list[Path]:
    """README.md, CHANGELOG.md (if present) and every docs/*.md."""
    top = [root / "README.md"] + [p for p in (root / "CHANGELOG.md",) if p.exists()]
    return top + sorted((root / "docs").glob("*.md"))


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
