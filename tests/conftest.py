"""Shared test set-up: no test may change mpmath's global working precision; the README's default run."""

import mpmath
import pytest


@pytest.fixture(autouse=True)
def _mpmath_precision_unchanged():
    """Tests use ``mpmath.workdps`` (a context manager or decorator); a test
    that sets ``mpmath.mp.dps`` and leaves it changed fails here."""
    dps = mpmath.mp.dps
    yield
    assert mpmath.mp.dps == dps, f"the test left mpmath.mp.dps = {mpmath.mp.dps} (was {dps}): use mpmath.workdps"


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
