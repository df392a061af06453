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
