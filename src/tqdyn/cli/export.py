"""Command line: ``tqdyn export RUN.h5 --format lisa OUT.h5`` and ``--format oem OUT.oem``.

A click command registered by :mod:`tqdyn.cli` (``cli.add_command(export)``).
It only composes library calls (:func:`tqdyn.workflows.export.export_lisa`).  As
everywhere in the CLI, bad input exits with status 2 and one line
``tqdyn: error: ...`` on stderr, and no output file is left behind.

Formats are registered in :data:`_EXPORTERS` (name -> function(run_file,
out_file, options) returning the lines to print); a new format adds one
function and one entry there, and its own options to the command (options
that do not apply to the chosen format are rejected by its function).
"""

from __future__ import annotations


import click

from ._common import EXIT_INTERRUPTED as _EXIT_INTERRUPTED, fail as _fail

__all__ = ["FORMATS", "export"]


def _export_lisa(run_file, out_file, opts) -> list[str]:
    """``--format lisa``: :func:`tqdyn.workflows.export.export_lisa`; returns the report lines."""
    from ..workflows.export import export_lisa

    summary = export_lisa(run_file, out_file, shapiro=opts["shapiro"], frame=opts["frame"],
                          axes=opts["axes"] or "icrf", time_origin=opts["time_origin"] or "epoch")
    if summary.frame == "bcrs":
        where = f"TCB, {opts['time_origin'] or 'epoch'} origin, BCRS" + (
            ", ecliptic axes" if opts["axes"] == "ecliptic" else "")
    else:
        where = "TT since the epoch, GCRS"
    shap = f"; Shapiro delay of {summary.shapiro_bodies} included"
    head = (f"LISA orbit file {summary.path}: {summary.size} samples from t0 = {summary.t0:g} s every "
            f"{summary.dt:g} s ({where})")
    return [
        head,
        f"light travel times: {summary.note}; {summary.ltt_range[0]:.9f} .. {summary.ltt_range[1]:.9f} s"
        + (shap if summary.shapiro else ""),
        f"dropped {summary.dropped_rows} leading row(s) whose emission time precedes the trajectory",
    ]


def _export_oem(run_file, out_file, opts) -> list[str]:
    """``--format oem``: :func:`tqdyn.workflows.export_oem.export_oem`; returns the report lines."""
    given = [f"--{k.replace('_', '-')}" for k, v in opts.items() if v is not None]
    if given:
        raise ValueError(f"{given[0]}: applies to --format lisa only; allowed with --format oem: no options")
    from ..workflows.export_oem import export_oem

    paths = export_oem(run_file, out_file)
    return [f"CCSDS OEM 2.0: {len(paths)} file(s), one per satellite: " + ", ".join(str(p) for p in paths)]


def _export_lisa_injection(cl_file, out_file, opts) -> list[str]:
    """``--format lisa-injection``: :func:`tqdyn.workflows.export_injection.export_lisa_injection` of the
    closed-loop file ``cl_file`` (the command's first argument) and its run ``--run``."""
    given = [f"--{k.replace('_', '-')}" for k, v in opts.items() if v is not None and k not in _INJECTION_OPTIONS]
    if given:
        raise ValueError(f"{given[0]}: applies to --format lisa only; allowed with --format lisa-injection: "
                         "--run, --ttl-coefficients, --tm-acceleration")
    if opts.get("run") is None:
        raise ValueError("--run RUN.h5 is required with --format lisa-injection (the run the closed-loop file "
                         "was made from: its light travel times)")
    from ..workflows.export_injection import export_lisa_injection

    r = export_lisa_injection(cl_file, opts["run"], out_file, opts.get("ttl_coefficients") or "worst-case",
                              tm=bool(opts.get("tm_acceleration")))
    return [f"LISA Instrument injection file {r.path}: {r.size} samples from t0 = {r.t0:g} s every {r.dt:g} s; "
            f"TTL coefficients {r.coefficients}; readout_isi_carrier/usb of the six links, RMS up to "
            f"{r.rms_hz:.3g} Hz ({r.rms_m:.3g} m of path length)"]


_INJECTION_OPTIONS = ("run", "ttl_coefficients", "tm_acceleration")
_EXPORTERS = {"lisa": _export_lisa, "oem": _export_oem, "lisa-injection": _export_lisa_injection}
FORMATS = tuple(_EXPORTERS)
"""Export formats: ``lisa`` = LISA orbit file (lisaorbits layout 2.x); ``oem`` = CCSDS OEM 2.0 files;
``lisa-injection`` = LISA Instrument glitch file of a closed-loop file's tilt-to-length."""


@click.command("export")
@click.argument("run_file", metavar="RUN.h5")
@click.argument("out_file", metavar="OUT")
@click.option("--format", "fmt", metavar="FORMAT", help="Output format (required); allowed: lisa, oem, lisa-injection.")
@click.option("--shapiro/--no-shapiro", default=None,
              help="lisa: include the Shapiro delay in the light travel times (GCRS: the Earth's; BCRS: the Sun's, "
                   "and the Earth's for a geocentric run).  Default: on for heliocentric runs, off for geocentric.")
@click.option("--frame", type=click.Choice(["gcrs", "bcrs"]), default=None,
              help="lisa: gcrs = the run's geocentric GCRS and TT (default for geocentric runs); bcrs = barycentric "
                   "BCRS with TCB as coordinate time (default, and the only choice, for heliocentric runs).")
@click.option("--axes", type=click.Choice(["icrf", "ecliptic"]), default=None,
              help="lisa, bcrs only: the axes of the vectors, icrf (default) or the J2000 mean ecliptic of "
                   "lisaorbits' files.")
@click.option("--time-origin", "time_origin", type=click.Choice(["epoch", "j2000", "unix"]), default=None,
              help="lisa, bcrs only: t = TCB seconds since the run's epoch (default), since J2000.0 TCB, or t0 = the "
                   "Unix time of the first sample (as lisaorbits' OEM orbits).")
@click.option("--run", "run", metavar="RUN.h5", default=None,
              help="lisa-injection: the run the closed-loop file was made from (its light travel times; checked "
                   "by SHA-256).")
@click.option("--ttl-coefficients", "ttl_coefficients", metavar="SPEC", default=None,
              help="lisa-injection: worst-case (default: LISA Instrument's random-draw bounds), random:SEED, "
                   "constant:LP,LE,DP,DE (m/rad) or a JSON file of TTL coefficients.")
@click.option("--tm-acceleration", "tm_acceleration", is_flag=True, default=None,
              help="lisa-injection: also inject the TMs' residual velocity (the integral of the closed loop's "
                   "TM acceleration) at LISA Instrument's test-mass point.")
def export(run_file, out_file, fmt, shapiro, frame, axes, time_origin, run, ttl_coefficients, tm_acceleration):
    """Export the trajectory RUN.h5 to OUT in another tool's format.

    --format lisa writes a LISA orbit file OUT.h5 (lisaorbits layout 2.x,
    read by lisainstrument and pytdi): satellite states, light travel times
    between the test masses (satellite centres for runs without test
    masses), proper times and proper pseudoranges, in the run's GCRS and TT
    (geocentric default) or the BCRS with TCB (--frame bcrs; heliocentric
    runs); the file's attributes say how each quantity is defined.

    --format oem writes CCSDS OEM 2.0 files for mission-analysis tools
    (GMAT, Orekit, STK), one per satellite (OUT-<name>.oem beside OUT.oem),
    in the run's own system (SUN/ICRF/TDB or EARTH/GCRF/TT).

    --format lisa-injection takes a closed-loop file CL.h5 (tqdyn
    closed-loop) in place of RUN.h5 and its run as --run RUN.h5, and writes
    a LISA Instrument glitch file OUT.h5: the closed loop's tilt-to-length
    of the six links injected at the science readouts
    (docs/lisa-ttl.md).
    """
    if fmt is None:
        _fail(f"--format is required; allowed: {', '.join(FORMATS)}")
    if fmt not in FORMATS:
        _fail(f"--format: {fmt!r} is not allowed; allowed: {', '.join(FORMATS)}")
    from ..formats import trajectory as io

    opts = {"shapiro": shapiro, "frame": frame, "axes": axes, "time_origin": time_origin}
    if fmt == "lisa-injection":
        opts.update(run=run, ttl_coefficients=ttl_coefficients, tm_acceleration=tm_acceleration)
    else:
        for name, v in (("--run", run), ("--ttl-coefficients", ttl_coefficients), ("--tm-acceleration", tm_acceleration)):
            if v is not None:
                _fail(f"{name}: applies to --format lisa-injection only")
    try:
        lines = _EXPORTERS[fmt](run_file, out_file, opts)
    except (FileNotFoundError, ValueError, io.OutputError) as exc:
        _fail(str(exc))
    except KeyboardInterrupt:
        _fail("interrupted; no output file written", _EXIT_INTERRUPTED)
    click.echo("\n".join(lines))
