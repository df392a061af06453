"""The records behind the pages' numbers (docs/numbers.md): ``tqdyn bench --json`` (one entry per model,
merged), ``pytest --record-numbers`` (the ``record_number`` fixture, merged), ``tqdyn.workflows.numbers`` and
the renderer's formats and paths (``tools/render_docs.py``).  References: the records' documented layout and
Python's own formatting; each run here is short (a 1 h Kepler benchmark, one fast test)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from cli_support import run_cli
from docs_support import ROOT, rd
from tqdyn.workflows import numbers


def test_bench_json_merges_one_entry_per_model(tmp_path, capsys):
    path = tmp_path / "bench.json"
    status, out, err = run_cli(["bench", "--model", "kepler", "--duration", "1h", "--no-heyoka", "--json", str(path)],
                               capsys)
    assert status == 0, err
    first = json.loads(path.read_text())
    assert first["written_by"] == "tqdyn bench" and first["format_version"] == numbers.FORMAT_VERSION
    k = first["models"]["kepler"]
    assert k["command"] == f"tqdyn bench --model kepler --duration 1h --no-heyoka --json {path}"
    for key in ("date", "tqdyn_version", "machine", "libraries", "result"):
        assert key in k, key
    assert k["machine"]["cores"] >= 1 and k["machine"]["cpu"] and k["libraries"]["numba"]
    r = k["result"]
    assert r["duration_s"] == 3600.0 and r["n_steps"] == 72
    assert r["runs"]["tqdyn dd"]["wall_s"] > 0 and r["runs"]["tqdyn dd"]["err_vs_analytic_m"] < 1e-20
    status, out, err = run_cli(["bench", "--model", "lisa", "--duration", "6h", "--json", str(path)], capsys)
    assert status == 0, err
    merged = json.loads(path.read_text())
    assert set(merged["models"]) == {"kepler", "lisa"}
    assert merged["models"]["kepler"] == k                      # the other model's entry is kept as it was
    assert merged["models"]["lisa"]["result"]["n_steps"] == 1


@pytest.mark.parametrize("make, words", [
    (lambda p: p / "nodir" / "b.json", "does not exist"),
    (lambda p: p, "is a directory"),
    (lambda p: (p / "x.json").write_text("[1, 2]") and p / "x.json", "not a JSON object"),
    (lambda p: (p / "y.json").write_text('{"written_by": "someone else"}') and p / "y.json", "not written by tqdyn bench"),
])
def test_bench_json_bad_path_is_one_line(tmp_path, capsys, make, words):
    status, out, err = run_cli(["bench", "--model", "kepler", "--duration", "1h", "--json", str(make(tmp_path))],
                               capsys)
    assert status == 2 and out == "" and err.count("\n") == 1 and err.startswith("tqdyn: error: --json:"), err
    assert words in err


def test_merge_section_keeps_the_others(tmp_path):
    path = tmp_path / "r.json"
    numbers.merge_section(path, "numbers", {"a": {"value": 1}, "b": {"value": 2}}, {"written_by": "x"})
    out = numbers.merge_section(path, "numbers", {"b": {"value": 3}}, {"written_by": "y"})
    assert out["numbers"] == {"a": {"value": 1}, "b": {"value": 3}} and out["written_by"] == "y"
    assert json.loads(path.read_text()) == out
    assert not list(tmp_path.glob(".*tmp"))


def test_to_json_values():
    import numpy as np

    assert numbers.to_json({"a": np.float64(1.5), "b": np.arange(3), "c": (1, np.nan), "d": Path("/x")}) == \
        {"a": 1.5, "b": [0, 1, 2], "c": [1, None], "d": "/x"}


def test_record_numbers_option_writes_and_merges(tmp_path):
    """``pytest --record-numbers`` writes the numbers of the tests that ran and merges with an earlier record."""
    path = tmp_path / "tests.json"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}
    env.pop("TQDYN_RECORD_NUMBERS", None)

    def run(node):
        cmd = [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q", f"tests/{node}",
               "--record-numbers", str(path)]
        return subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)

    p = run("test_elements.py::test_round_trip_eccentric")
    assert p.returncode == 0, p.stdout[-2000:]
    rec = json.loads(path.read_text())
    assert rec["written_by"] == "pytest --record-numbers" and rec["command"].startswith("pytest ")
    e1 = rec["numbers"]["precision.elements_round_trip_e0.1"]
    assert e1["test"] == "tests/test_elements.py::test_round_trip_eccentric[0.1]" and 0 < e1["value"] < 2e-31
    assert e1["date"] and e1["tqdyn_version"]
    p = run("test_dp87_order_conditions.py::test_corrected_b_is_order_8")
    assert p.returncode == 0, p.stdout[-2000:]
    rec = json.loads(path.read_text())
    assert rec["numbers"]["precision.elements_round_trip_e0.1"] == e1       # kept
    assert 0 < rec["numbers"]["dp87.corrected_order_conditions"]["value"] < 3e-40
    assert "suite.default_wall_s" not in rec["numbers"]                        # only for the whole default suite


def test_record_number_does_nothing_without_the_option(record_number):
    assert record_number("not.recorded", 1.0) == 1.0


# ------------------------------------------------------------------------------------------------ the renderer


@pytest.mark.parametrize("value, fmt, text", [
    (5.9e-06, ".1e", "5.9e-6"), (1.54, ".2f", "1.54"), (155520, ",d", "155,520"), (1.0e-20, ".0e", "1e-20"),
    (4.1e3, ".3g", "4.1e3"), (1503.49, "~3", "1503"), (0.6949, "~2", "0.69"), (120.0, "/60:.0f", "2"),
    (0.9983, "-1:*100:.2f", "-0.17"), ([1.4651, 0.7012], ".2f", "1.47 / 0.70"), (9.9333, "hm", "09:56"),
    ("2026-05-03T10:00:00Z", "date", "2026-05-03"), (None, ".2f", "n/a"), ({"summary": "cpu, 2 cores"}, "machine",
                                                                          "cpu, 2 cores"),
])
def test_formats(value, fmt, text):
    assert rd.fmt_value(value, fmt) == text


RECORDS = {"bench": {"models": {"kepler": {"date": "2026-01-02T03:04:05Z", "result": {"runs": {"tqdyn dd": {
    "wall_s": 1.5}}, "ratio": [2.0, 4.0]}}}},
    "tianqin": {"values": {"deviation/dragfree-90d": {"max": [1.5, 0.7, 0.9]}, "a": 2.0, "b": 4.0}},
    "lisa": {}, "tests": {"numbers": {"x.1": {"value": [1.0, 5.0]}, "x.2": {"value": [3.0, 7.0]},
                                      "y": {"value": 2.5e-21, "date": "2026-01-01T00:00:00Z"}}}}


@pytest.mark.parametrize("src, path, want", [
    ("bench", "kepler/runs/tqdyn dd/wall_s", 1.5), ("bench", "kepler/date", "2026-01-02T03:04:05Z"),
    ("tianqin", "values/deviation/dragfree-90d/max/@max", 1.5), ("tianqin", "values/a // values/b", 0.5),
    ("tests", "y", 2.5e-21), ("tests", "y/date", "2026-01-01T00:00:00Z"), ("tests", "x.*/@max", 7.0),
    ("bench", "kepler/ratio/1", 4.0),
])
def test_lookup(src, path, want):
    assert rd.lookup(RECORDS, src, path) == want


def test_render_and_differences():
    page = ("Kepler <!--n:bench:kepler/runs/tqdyn dd/wall_s|.2f-->9.99<!--/n--> s, "
            "<!--n:tests:y|.1e-->2.5e-21<!--/n--> m\n```\n<!--n:tests:nothing-->example<!--/n-->\n```\n")
    out = rd.render(page, RECORDS, "p.md")
    assert "-->1.50<!--/n--> s" in out and "example" in out
    assert rd.differences(page, out) == [("<!--n:bench:kepler/runs/tqdyn dd/wall_s|.2f-->", "9.99", "1.50")]
    with pytest.raises(rd.RenderError, match=r"p.md: <!--n:tests:missing-->"):
        rd.render("<!--n:tests:missing-->1<!--/n-->", RECORDS, "p.md")
