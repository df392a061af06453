"""Shared test set-up: no test may change mpmath's global working precision; the README's default run; the
recording of measured numbers (``record_number``) that docs/*.md and README.md quote (docs/numbers.md)."""

import os

import mpmath
import pytest

#: Environment variable naming the JSON record of ``--record-numbers`` (the option wins).
RECORD_ENV = "TQDYN_RECORD_NUMBERS"


def pytest_addoption(parser):
    parser.addoption("--record-numbers", metavar="PATH", default=None,
                     help="write the numbers the tests measure with the record_number fixture into this JSON record "
                          f"(entries of the tests that ran are replaced, the others kept; also ${RECORD_ENV}); "
                          "docs/numbers.md")
    parser.addoption("--numbers-only", action="store_true",
                     help="run only the tests that record numbers (those using the record_number fixture)")


def pytest_collection_modifyitems(config, items):
    """``--numbers-only``: keep only the tests that record numbers (those using ``record_number``)."""
    if not config.getoption("--numbers-only"):
        return
    keep = [it for it in items if "record_number" in getattr(it, "fixturenames", ())]
    drop = [it for it in items if "record_number" not in getattr(it, "fixturenames", ())]
    if drop:
        config.hook.pytest_deselected(items=drop)
    items[:] = keep


def _record_path(config):
    return config.getoption("--record-numbers") or os.environ.get(RECORD_ENV) or None


def pytest_configure(config):
    config._tqdyn_numbers = {}


def pytest_sessionstart(session):
    import time

    session.config._tqdyn_t0 = time.perf_counter()
    session.config._tqdyn_files = {}


def pytest_runtest_logreport(report):
    """Per test file: wall time of its tests (setup, call, teardown) and their number, for the records."""
    files = _FILES.setdefault("files", {})
    name = report.nodeid.split("::")[0]
    wall, tests = files.get(name, (0.0, set()))
    tests.add(report.nodeid)
    files[name] = (wall + report.duration, tests)


_FILES: dict = {}


@pytest.fixture
def record_number(request):
    """``record_number(key, value, unit="")``: the test measured ``value``
    (a number, a list of numbers, or a short text) in ``unit``; written to the
    JSON record of ``pytest --record-numbers PATH`` (or ``$TQDYN_RECORD_NUMBERS``)
    under ``key`` with the test's node id, and ignored otherwise.  The pages
    render it through ``tools/render_docs.py`` as ``tests:<key>``.  A key
    recorded by two tests of one session is an error."""
    store = request.config._tqdyn_numbers
    recording = _record_path(request.config) is not None

    def record(key: str, value, unit: str = ""):
        if not recording:
            return value
        from tqdyn.workflows.numbers import to_json

        if "/" in key or not key:
            raise ValueError(f"record_number: {key!r}: a key is a non-empty name without '/'")
        old = store.get(key)
        if old is not None and old["test"] != request.node.nodeid:
            raise ValueError(f"record_number: {key!r} is recorded by {old['test']} and {request.node.nodeid}")
        store[key] = {"value": to_json(value), "unit": unit, "test": request.node.nodeid}
        return value

    return record


def _is_default_suite(config) -> bool:
    """True when the run is the default suite: no paths, -k or -m of its own, not --numbers-only."""
    paths = [a.rstrip("/") for a in config.args]
    return (paths == list(config.getini("testpaths")) and not config.getoption("keyword") and config.getoption("markexpr") == "not slow"
            and not config.getoption("--numbers-only"))


def pytest_sessionfinish(session, exitstatus):
    import time

    path = _record_path(session.config)
    store = getattr(session.config, "_tqdyn_numbers", {})
    if path is None:
        return
    from tqdyn.workflows.numbers import machine, merge_section, provenance

    prov = provenance("pytest --record-numbers", "pytest " + " ".join(session.config.invocation_params.args))
    if exitstatus in (0, 1) and _is_default_suite(session.config) and not session.config.getoption("maxfail"):
        # the whole default suite ran (failures included: a failing test records no number of its own)
        where = machine()["summary"]
        store["suite.default_wall_s"] = {"value": time.perf_counter() - session.config._tqdyn_t0, "unit": "s",
                                         "test": "the default suite (pytest)", "tests": session.testscollected,
                                         "failed": session.testsfailed, "machine": where}
        for name, (wall, tests) in _FILES.get("files", {}).items():
            key = "suite.file." + name.rsplit("/", 1)[-1].removesuffix(".py")
            store[key] = {"value": {"wall_s": wall, "tests": len(tests)}, "unit": "s, tests",
                          "test": f"{name} in the default suite", "machine": where}
    if not store:
        return
    entries = {k: {**v, "date": prov["date"], "tqdyn_version": prov["tqdyn_version"]} for k, v in store.items()}
    merge_section(path, "numbers", entries, {**prov, "description": "numbers measured by the tests (record_number "
                                                                   "in tests/), one entry per key with its test"})


@pytest.fixture(autouse=True)
def _mpmath_precision_unchanged():
    """Tests use ``mpmath.workdps`` (a context manager or decorator); a test
    that sets ``mpmath.mp.dps`` and leaves it changed fails here."""
    dps = mpmath.mp.dps
    yield
    assert mpmath.mp.dps == dps, f"the test left mpmath.mp.dps = {mpmath.mp.dps} (was {dps}): use mpmath.workdps"


@pytest.fixture(autouse=True)
def _cli_error_lines_short(monkeypatch, tmp_path_factory):
    """Every ``tqdyn: error:`` line printed in-process during a test is at most
    ``cli_support.MAX_ERROR_LINE`` characters (docs/reliability.md, "Error messages";
    a path under the temporary directory counts as one under ``/home/user``):
    ``click.echo`` is watched, and a longer line fails the test at teardown."""
    import click
    from cli_support import MAX_ERROR_LINE, ErrorLineWatch

    watch = ErrorLineWatch(tmp_path_factory.getbasetemp())
    monkeypatch.setattr(click, "echo", watch.echo)
    yield watch
    assert not watch.too_long, (f"error line(s) over {MAX_ERROR_LINE} characters: "
                                + " | ".join(f"{len(ln)}: {ln}" for ln in watch.too_long))


@pytest.fixture(scope="session")
def default_run(tmp_path_factory):
    """``tqdyn run -q`` with no scenario argument -- the README's main job: the built-in ``tianqin`` scenario (full
    force model, global pointing, Table IV self-gravity, drag-free control), 10 days at 50 s -- run once per
    session in a fresh working directory (~8 s).  Returns (exit status, stdout, stderr, path of tqdyn-run.h5).
    Used by tests/test_cli.py (the command and its file), tests/test_coupled.py (the printed control maxima) and
    tests/test_pointing.py (the 10-day pointing-law errors of the README)."""
    import contextlib
    import io
    import os

    from tqdyn import cli

    work = tmp_path_factory.mktemp("default-run")
    out, err = io.StringIO(), io.StringIO()
    cwd = os.getcwd()
    os.chdir(work)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                status = cli.main(["run", "-q"])
            except SystemExit as exc:
                status = exc.code
    finally:
        os.chdir(cwd)
    return status, out.getvalue(), err.getvalue(), work / "tqdyn-run.h5"
