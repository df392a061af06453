"""The measured numbers of README.md, CHANGELOG.md and docs/*.md against their JSON records (docs/numbers.md).

Every page is rendered in memory by ``tools/render_docs.py`` from ``docs/data/*.json`` (the records that
``tqdyn bench --json``, ``tqdyn report --studies`` and ``pytest --record-numbers`` write); a page whose
marker text differs from what its record gives fails, naming the page, the marker and both texts (the fix:
``python tools/render_docs.py``, or a new run of the command that writes the record).  A second test keeps
new typed speed, memory and file-size numbers out of the pages: outside markers and code blocks, a size in
MB/GB, a time per evaluation or step, or a phrase such as "takes 8 s" fails, except the few constants listed
in ``TYPED_ALLOWED`` (each with its reason).
"""

from __future__ import annotations

import re

import pytest

from docs_support import ROOT, rd

PAGES = [p.relative_to(ROOT).as_posix() for p in rd.pages(ROOT)]


@pytest.fixture(scope="module")
def records():
    return rd.load_records()


@pytest.mark.parametrize("page", PAGES)
def test_page_numbers_match_their_records(page, records):
    text = (ROOT / page).read_text(encoding="utf-8")
    try:
        rendered = rd.render(text, records, page)
    except rd.RenderError as exc:
        pytest.fail(str(exc))
    diffs = rd.differences(text, rendered)
    assert not diffs, "\n".join(f"{page}: {marker}: page has {old!r}, records give {new!r} "
                                f"(python tools/render_docs.py)" for marker, old, new in diffs)
    assert rendered == text, f"{page}: differs from its rendering (python tools/render_docs.py)"


def test_records_have_provenance():
    """Each record says what wrote it, and each speed number carries the machine and the date."""
    records = rd.load_records(check=False)
    for name in ("bench", "tianqin", "lisa", "tests"):
        assert records[name], f"docs/data/{rd.SOURCES[name]} is missing (tools/refresh_numbers.sh)"
        assert records[name].get("written_by"), name
    for model, entry in records["bench"]["models"].items():
        for key in ("command", "date", "tqdyn_version", "machine", "libraries", "result"):
            assert key in entry, (model, key)
        assert entry["machine"]["cpu"] and entry["machine"]["cores"] and entry["machine"]["memory_gb"], model
    for name in ("tianqin", "lisa"):
        for key in ("command", "date", "machine", "libraries", "rows", "values", "timing", "runs"):
            assert key in records[name], (name, key)
    for key, entry in records["tests"]["numbers"].items():
        assert entry.get("test") and entry.get("date") and "value" in entry, key


#: Typed numbers with a speed / memory / size unit that are not measurements: (page, text, why).
TYPED_ALLOWED = [
    ("docs/design.md", "4 MiB", "the mmap threshold tqdyn sets (workflows.heap.MMAP_THRESHOLD_BYTES)"),
    ("docs/design.md", "1 MB per\ndataset", "HDF5's default chunk cache, a library setting"),
    ("docs/design.md", "1 MB per dataset", "HDF5's default chunk cache, a library setting"),
    ("docs/design.md", "~10 MB each", "n_tdat x 13 stages x 512 steps x 8 bytes: arithmetic"),
    ("docs/closed-loop-file.md", "2 MiB", "the chunk-size bound of the closed-loop writer, a setting"),
    ("docs/reliability.md", "2.6 MB tmpfs", "the size of the test's file system, a test setting"),
    ("docs/reliability.md", "1 MiB", "the headroom constant of the writer"),
    ("docs/reliability.md", "1 kB", "the file-size limit of the fault-table test, a test setting"),
    ("docs/reliability.md", "64 kB", "the size of the fault-table test's file system, a test setting"),
    ("docs/reliability.md", "100 B, 5 kB\n  and 5 MB", "the sizes the test cuts the ephemeris file to"),
    ("docs/reliability.md", "100 B, 5 kB and 5 MB", "the sizes the test cuts the ephemeris file to"),
    ("docs/lisa-toolchain.md", "takes about 30 s", "tools/lisa_toolchain_x2.py: not recorded yet (the page is being "
                                                    "rewritten with the OEM reader)"),
]

SIZE = re.compile(r"\d[\d.,]*\s?(?:MB|GB|MiB|GiB|kB)\b")
PER_EVAL = re.compile(r"\d[\d.,]*\s?(?:ms|us|s)\s+(?:per|/)\s*(?:evaluation|call|step|instant|chunk|simulated day)")
RUNTIME = re.compile(r"(?<!at )(?<![\d.,-])\d[\d.,-]*\s?(?:s|min)\s+(?:in double-double|in float64|of propagation|of compiled loop|"
                     r"of time-only inputs|of CPU|with start-up|after (?:the )?(?:JIT )?compilation)")
TAKES = re.compile(r"\b(?:takes?|took|taking|runs? in|ran in|in about|compiles? for|compiled in|start in under|"
                   r"finishes in|wall time of)\s+(?:about\s+|~\s?)?\d[\d.,]*\s?(?:s|min|minutes|seconds|h|hours)\b")


def _typed_speed_numbers(page: str, text: str) -> list[str]:
    """Speed / memory / size numbers of ``text`` outside markers and fenced code blocks."""
    spans = rd.fenced(text)
    for rx in (rd.BLOCK, rd.INLINE):
        spans += [m.span() for m in rx.finditer(text)]
    chars = list(text)
    for a, b in spans:
        chars[a:b] = " " * (b - a)
    bare = "".join(chars)
    for p, allowed, _ in TYPED_ALLOWED:
        if p == page:
            bare = bare.replace(allowed, " " * len(allowed))
    found = []
    for rx in (SIZE, PER_EVAL, RUNTIME, TAKES):
        for m in rx.finditer(bare):
            line = text.count("\n", 0, m.start()) + 1
            found.append(f"{page}:{line}: {m.group(0)!r}")
    return found


@pytest.mark.parametrize("page", PAGES)
def test_no_typed_speed_or_size_numbers(page):
    text = (ROOT / page).read_text(encoding="utf-8")
    found = _typed_speed_numbers(page, text)
    assert not found, ("typed speed, memory or size numbers outside markers (render them from a record, "
                       "docs/numbers.md):\n" + "\n".join(found))


def test_the_guard_sees_typed_numbers():
    """The guard itself: it flags typed numbers and ignores marked ones and code blocks."""
    text = ("a run takes 8 s and 300 MB; <!--n:bench:x/y|.1f-->5.0<!--/n--> MB\n"
            "```\nwall time: 7.30 s, 38.8 MB\n```\n0.4 us per evaluation; 40-53 s in double-double\n")
    found = _typed_speed_numbers("x.md", text)
    assert [f.split(": ", 1)[1] for f in found] == ["'300 MB'", "'0.4 us per evaluation'",
                                                     "'40-53 s in double-double'", "'takes 8 s'"]


def test_a_record_of_another_version_fails_the_check():
    """docs/numbers.md: a page renders only records measured on the package's own version.  The same
    record files render with the package's version and fail, naming the record and both versions, when the
    package is another version (a bench model, a test number and a whole record each)."""
    version = rd.package_version()
    records = {"bench": {"models": {"m": {"tqdyn_version": version, "command": "tqdyn bench --model m",
                                          "result": {"wall_s": 1.5}}}},
               "tests": {"numbers": {"k": {"tqdyn_version": version, "test": "tests/test_x.py::t", "value": 2.0}}},
               "closedloop": {"tqdyn_version": version, "command": "tqdyn report --closed-loop", "x": 3.0}}
    text = "<!--n:bench:m/wall_s-->?<!--/n--> <!--n:tests:k-->?<!--/n--> <!--n:closedloop:x-->?<!--/n-->"
    assert rd.render(text, rd.check_versions(records, version)) == text.replace("?", "1.5", 1).replace(
        "?", "2.0", 1).replace("?", "3.0", 1)
    for marker in text.split(" "):
        with pytest.raises(rd.StaleRecordError, match=r"measured on tqdyn .*, the package is 9\.9"):
            rd.render(marker, rd.check_versions(records, "9.9"), "x.md")
    with pytest.raises(rd.StaleRecordError, match="README.md"):
        readme = (ROOT / "README.md").read_text(encoding="utf-8")
        rd.render(readme, rd.load_records(version="0.0.0"), "README.md")
