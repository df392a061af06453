"""Running the command line in-process from tests."""

from tqdyn import cli


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
