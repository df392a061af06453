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
    """``--numbers-only``: keep only the tests that record numbers (those using ``record_number``).  In a
    pytest-xdist worker: the longest units of work first (see :func:`pytest_xdist_make_scheduler`)."""
    if _is_worker(config):
        weight = _recorded_file_walls()
        order = {}
        for it in items:
            scope = _scope(it.nodeid)
            order[scope] = order.get(scope, 0.0) + weight.get(it.nodeid.split("::", 1)[0].rsplit("/", 1)[-1], 0.0)
        items.sort(key=lambda it: -order[_scope(it.nodeid)])  # stable: a file's tests keep their order
    if not config.getoption("--numbers-only"):
        return
    keep = [it for it in items if "record_number" in getattr(it, "fixturenames", ())]
    drop = [it for it in items if "record_number" not in getattr(it, "fixturenames", ())]
    if drop:
        config.hook.pytest_deselected(items=drop)
    items[:] = keep


def _record_path(config):
    return config.getoption("--record-numbers") or os.environ.get(RECORD_ENV) or None


def _is_worker(config) -> bool:
    """True in a pytest-xdist worker process (``-n``); the controller gathers what the workers measured."""
    return hasattr(config, "workerinput")


class _WorkerNumbers:
    """Under pytest-xdist: each worker hands the numbers its tests recorded to the controller
    (``workeroutput``), which merges them (a key recorded by two tests is an error, as in one process) and
    writes the one record in its ``pytest_sessionfinish``."""

    def __init__(self, config):
        self.config = config

    @pytest.hookimpl(optionalhook=True)
    def pytest_testnodedown(self, node, error):
        store = self.config._tqdyn_numbers
        self.config._tqdyn_workers += 1
        for key, entry in getattr(node, "workeroutput", {}).get("tqdyn_numbers", {}).items():
            old = store.get(key)
            if old is not None and old["test"] != entry["test"]:
                self.config._tqdyn_clashes.append(f"record_number: {key!r} is recorded by {old['test']} and "
                                                  f"{entry['test']}")
            store[key] = entry


#: Under pytest-xdist (the default suite runs with ``-n 2 --dist loadfile``, pyproject.toml) each process
#: computes the session fixtures its tests use.  The test files that share an expensive one run in one process,
#: so that it is computed once: fixture -> the files that use it.
SHARED_SESSION_FIXTURES = {
    "default_run": ("test_cli.py", "test_coupled.py", "test_pointing.py", "test_jerks.py",
                    "test_differential_gravity.py"),
}
_FILE_GROUP = {f: name for name, files in SHARED_SESSION_FIXTURES.items() for f in files}


def _scope(nodeid: str) -> str:
    """The unit of work of a test under ``--dist loadfile``: its file, or its group of
    :data:`SHARED_SESSION_FIXTURES`."""
    path = nodeid.split("::", 1)[0]
    group = _FILE_GROUP.get(path.rsplit("/", 1)[-1])
    return path if group is None else f"session fixture {group}"


def _recorded_file_walls() -> dict:
    """{test file name: its wall time [s] in the last recorded default suite} (docs/data/tests.json,
    ``suite.file.*``); empty if there is no record."""
    import json
    import pathlib

    try:
        numbers = json.loads((pathlib.Path(__file__).parents[1] / "docs" / "data" / "tests.json").read_text())["numbers"]
        return {k.removeprefix("suite.file.") + ".py": float(v["value"]["wall_s"]) for k, v in numbers.items()
                if k.startswith("suite.file.")}
    except (OSError, ValueError, KeyError, TypeError):
        return {}


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadfile`` with the files of :data:`SHARED_SESSION_FIXTURES` as one unit of work, handed out in
    the workers' collection order: the longest units first (by the per-file times of the last recorded
    default suite, :func:`pytest_collection_modifyitems`), so that the processes finish together."""
    if config.getvalue("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    class SharedFixtureScheduling(LoadFileScheduling):
        def _split_scope(self, nodeid):
            return _scope(nodeid)

    config.option.loadscopereorder = False
    return SharedFixtureScheduling(config, log)


def pytest_configure(config):
    config._tqdyn_numbers = {}
    config._tqdyn_clashes = []
    config._tqdyn_workers = 0
    if not _is_worker(config) and config.pluginmanager.hasplugin("xdist"):
        config.pluginmanager.register(_WorkerNumbers(config), "tqdyn-worker-numbers")


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
    if _is_worker(session.config):  # the controller writes the record
        session.config.workeroutput["tqdyn_numbers"] = store
        return
    if session.config._tqdyn_clashes:  # as a clash inside one process fails its test: no record, a failure
        reporter = session.config.pluginmanager.get_plugin("terminalreporter")
        for line in session.config._tqdyn_clashes:
            reporter.write_line(f"ERROR {line}", red=True)
        session.exitstatus = pytest.ExitCode.TESTS_FAILED
        return
    from tqdyn.workflows.numbers import machine, merge_section, provenance

    prov = provenance("pytest --record-numbers", "pytest " + " ".join(session.config.invocation_params.args))
    if exitstatus in (0, 1) and _is_default_suite(session.config) and not session.config.getoption("maxfail"):
        # the whole default suite ran (failures included: a failing test records no number of its own)
        where = machine()["summary"]
        store["suite.default_wall_s"] = {"value": time.perf_counter() - session.config._tqdyn_t0, "unit": "s",
                                         "test": "the default suite (pytest)", "tests": session.testscollected,
                                         "failed": session.testsfailed, "machine": where,
                                         "processes": max(1, session.config._tqdyn_workers)}
        for name, (wall, tests) in _FILES.get("files", {}).items():
            key = "suite.file." + name.rsplit("/", 1)[-1].removesuffix(".py")
            store[key] = {"value": {"wall_s": wall, "tests": len(tests)}, "unit": "s, tests",
                          "test": f"{name} in the default suite", "machine": where}
    if not store:
        return
    entries = {k: {**v, "date": prov["date"], "tqdyn_version": prov["tqdyn_version"],
                   "tqdyn_commit": prov["tqdyn_commit"]} for k, v in store.items()}
    merge_section(path, "numbers", entries, {**prov, "description": "numbers measured by the tests (record_number "
                                                                   "in tests/), one entry per key with its test"})


@pytest.fixture(autouse=True)
def _mpmath_precision_unchanged():
    """Tests use ``mpmath.workdps`` (a context manager or decorator); a test
    that sets ``mpmath.mp.dps`` and leaves it changed fails here."""
    dps = mpmath.mp.dps
    yield
    assert mpmath.mp.dps == dps, f"the test left mpmath.mp.dps = {mpmath.mp.dps} (was {dps}): use mpmath.workdps"


#: The scenario and RunResult of the propagation of ``default_run`` (its fixture fills it).
_DEFAULT_RUN: dict = {}


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
    Used by tests/test_cli.py (the command and its file), tests/test_coupled.py (the printed control maxima),
    tests/test_pointing.py (the 10-day pointing-law errors of the README), tests/test_jerks.py and, through
    ``default_run_result``, tests/test_differential_gravity.py."""
    import contextlib
    import io
    import os

    from tqdyn import cli, dynamics

    work = tmp_path_factory.mktemp("default-run")
    out, err = io.StringIO(), io.StringIO()
    cwd = os.getcwd()
    propagate = dynamics.propagate

    def keep(scen, **kw):
        result = propagate(scen, **kw)
        _DEFAULT_RUN.update(scenario=scen, result=result)
        return result

    os.chdir(work)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), pytest.MonkeyPatch.context() as mp:
            mp.setattr(dynamics, "propagate", keep)
            try:
                status = cli.main(["run", "-q"])
            except SystemExit as exc:
                status = exc.code
    finally:
        os.chdir(cwd)
    return status, out.getvalue(), err.getvalue(), work / "tqdyn-run.h5"


@pytest.fixture(scope="session")
def default_run_result(default_run):
    """(Scenario, RunResult) of the propagation inside ``default_run``: its final states (``y_final``) serve the
    tests that need the 10-day default run in memory (tests/test_differential_gravity.py)."""
    assert default_run[0] == 0, default_run[2]
    return _DEFAULT_RUN["scenario"], _DEFAULT_RUN["result"]
