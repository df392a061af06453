"""Running the command line in-process from tests, and the length of its error lines."""

import re

import click

from tqdyn import cli

#: Longest error line the command line may print (docs/reliability.md, "Error messages"), prefix included.
MAX_ERROR_LINE = 200
#: The prefix of the command line's error lines (tqdyn.cli._common.fail).
ERROR_PREFIX = "tqdyn: error: "


def run_cli(argv, capsys):
    """Run the CLI in-process with ``argv``; returns (exit status, stdout, stderr)."""
    try:
        status = cli.main(argv)
    except SystemExit as exc:
        status = exc.code
    out = capsys.readouterr()
    return status, out.out, out.err


def run_cli_interrupted(argv, capsys, monkeypatch, after_rows_calls=3):
    """Run the CLI in-process like :func:`run_cli`, with a Ctrl-C
    (KeyboardInterrupt) raised right after the ``after_rows_calls``-th chunk of
    output rows reached the writer; ``dynamics.propagate`` is restored
    afterwards.  Returns (exit status, stdout, stderr)."""
    from tqdyn import dynamics

    real = dynamics.propagate
    calls = {"n": 0}

    def interrupted(scen, sink=None, **kw):
        def sink_then_stop(rows):
            sink(rows)
            calls["n"] += 1
            if calls["n"] == after_rows_calls:
                raise KeyboardInterrupt
        return real(scen, sink=sink_then_stop, **kw)

    monkeypatch.setattr(dynamics, "propagate", interrupted)
    try:
        return run_cli(argv, capsys)
    finally:
        monkeypatch.setattr(dynamics, "propagate", real)


def error_line(status, err: str, *words: str, tmp_root=None) -> str:
    """The single error line of a refused command: exit status 2, ``err`` one line
    ``tqdyn: error: ...`` of at most :data:`MAX_ERROR_LINE` characters
    (:func:`counted_length`) holding every one of ``words``.  Returns the line."""
    lines = err.strip().splitlines()
    assert status == 2 and len(lines) == 1 and lines[0].startswith(ERROR_PREFIX), (status, err)
    assert counted_length(lines[0], tmp_root) <= MAX_ERROR_LINE, f"{len(lines[0])} characters: {lines[0]}"
    for w in words:
        assert w in lines[0], (w, lines[0])
    return lines[0]


#: What a path under a test's temporary directory counts as: a user's working directory.
USER_DIR = "/home/user"


def counted_length(line: str, tmp_root=None) -> int:
    """The length of an error line as a user would see it: a path under the
    tests' temporary directory ``tmp_root`` (``/tmp/pytest-of-<user>/pytest-<n>``)
    counts as the same file under :data:`USER_DIR` (the line prints the path
    the user gave, whole; the test's directory names are longer than a user's)."""
    if tmp_root is not None:
        line = re.sub(re.escape(str(tmp_root)) + r"/[^/'\s]+", USER_DIR, line)
    return len(line)


class ErrorLineWatch:
    """Every ``tqdyn: error:`` line the command line prints (``click.echo`` to
    stderr, as :func:`tqdyn.cli._common.fail` does) while installed, and those
    longer than :data:`MAX_ERROR_LINE` characters (:func:`counted_length`).
    Installed around every test by ``tests/conftest.py`` (the fixture fails
    the test at teardown on a long line), so every in-process command-line
    test checks the length."""

    def __init__(self, tmp_root=None):
        self.lines: list[str] = []
        self.tmp_root = tmp_root
        self._echo = click.echo

    def echo(self, message=None, file=None, nl=True, err=False, color=None):
        if err and isinstance(message, str):
            self.lines += [ln for ln in message.splitlines() if ln.startswith(ERROR_PREFIX)]
        return self._echo(message, file=file, nl=nl, err=err, color=color)

    @property
    def too_long(self) -> list[str]:
        return [ln for ln in self.lines if counted_length(ln, self.tmp_root) > MAX_ERROR_LINE]
