"""Command line: ``tqdyn export RUN.h5 --format lisa OUT.h5``, ``--format oem OUT.oem``,
``tqdyn export CL.h5 --format ttl OUT.h5`` and ``tqdyn export CL.h5 --format lisa-injection OUT.h5
--run RUN.h5`` (the positional file is then a closed-loop file).

A click command registered by :mod:`tqdyn.cli` (``cli.add_command(export)``).
It only composes library calls (:func:`tqdyn.workflows.export.export_lisa`,
:func:`tqdyn.workflows.export_oem.export_oem`, :func:`tqdyn.workflows.export_ttl.export_ttl`,
:func:`tqdyn.workflows.export_injection.export_lisa_injection`).  As
everywhere in the CLI, bad input (an output that is one of the inputs among it) exits with status 2
and one line ``tqdyn: error: ...`` on stderr, a failed write with 3, Ctrl-C / SIGTERM with 130 / 143
(:func:`._common.guarded`), and no output file is left behind.

Formats are registered in :data:`_EXPORTERS` (name -> function(run_file,
out_file, options) returning the lines to print); a new format adds one
function and one entry there, and its own options to the command (options
that do not apply to the chosen format are rejected by its function).
"""

from __future__ import annotations


import click

from .._choices import unknown
from ._common import Choice, fail as _fail, guarded

__all__ = ["FORMATS", "export"]

_LISA_OPTIONS = ("shapiro", "frame", "axes", "time_origin")
_TTL_OPTIONS = ("coefficients", "seed", "drift", "step")
_INJECTION_OPTIONS = ("run", "tm_acceleration")
#: LISA Pathfinder's measured drift of its TTL coefficients, 1 um/rad in 100 days, in m/rad per day
#: (:data:`tqdyn.ttl.coupling.LPF_DRIFT_M_PER_RAD_PER_S`).
_LPF_DRIFT_PER_DAY = 1e-8


def _refuse(opts, names, fmt, allowed) -> None:
    """ValueError for the first option of ``names`` given (not None) with ``--format fmt``."""
    given = [f"--{k.replace('_', '-')}" for k in names if opts.get(k) is not None]
    if given:
        raise ValueError(f"{given[0]}: does not apply to --format {fmt}; allowed with --format {fmt}: "
                         + (", ".join(allowed) if allowed else "no options"))


def _export_lisa(run_file, out_file, opts) -> list[str]:
    """``--format lisa``: :func:`tqdyn.workflows.export.export_lisa`; returns the report lines."""
    _refuse(opts, _TTL_OPTIONS + _INJECTION_OPTIONS, "lisa", ["--shapiro/--no-shapiro", "--frame", "--axes", "--time-origin"])
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
    _refuse(opts, _LISA_OPTIONS + _TTL_OPTIONS + _INJECTION_OPTIONS, "oem", [])
    from ..workflows.export_oem import export_oem

    paths = export_oem(run_file, out_file)
    return [f"CCSDS OEM 2.0: {len(paths)} file(s), one per satellite: " + ", ".join(str(p) for p in paths)]


def _drift_per_second(text) -> float | None:
    """``--drift`` (m/rad per day, or ``lpf``) as m/rad/s; None when not given."""
    if text is None:
        return None
    if str(text).strip().lower() == "lpf":
        per_day = _LPF_DRIFT_PER_DAY
    else:
        try:
            per_day = float(text)
        except ValueError:
            per_day = float("nan")
        if per_day != per_day or per_day in (float("inf"), float("-inf")):
            raise ValueError(f"--drift = {text!r}: must be a finite number (m/rad per day) or lpf")
    return per_day / 86400.0


def _export_ttl(cl_file, out_file, opts) -> list[str]:
    """``--format ttl``: :func:`tqdyn.workflows.export_ttl.export_ttl`; returns the report lines."""
    _refuse(opts, _LISA_OPTIONS + _INJECTION_OPTIONS, "ttl", ["--coefficients", "--seed", "--drift", "--step"])
    from ..workflows.export_ttl import export_ttl

    summary = export_ttl(cl_file, out_file, coefficients=opts["coefficients"] or "worst-case", seed=opts["seed"],
                         drift=_drift_per_second(opts["drift"]), step=opts["step"])
    m = summary.model
    how = m["kind"] + (f" (seed {m['seed']})" if "seed" in m else "") + (f" ({m['file']})" if "file" in m else "")
    drift = (f", drifting {m['drift_m_per_rad_per_s'] * 86400:g} m/rad per day from t = {m['t_ref_s']:g} s"
             if "drift_m_per_rad_per_s" in m else ", constant")
    grid = "the closed-loop file's grid" if summary.step is None else f"every {summary.step:g} s"
    return [f"LISA Instrument TTL coefficient file {summary.path}: {summary.size} samples from t = "
            f"{summary.t_start:g} s to {summary.t_stop:g} s ({grid}; the run's time axis since its epoch)",
            f"coefficients: {how}{drift}"]


def _export_lisa_injection(cl_file, out_file, opts) -> list[str]:
    """``--format lisa-injection``: :func:`tqdyn.workflows.export_injection.export_lisa_injection` of the
    closed-loop file ``cl_file`` (the command's first argument) and its run ``--run``."""
    _refuse(opts, _LISA_OPTIONS + ("step",), "lisa-injection",
            ["--run", "--coefficients", "--seed", "--drift", "--tm-acceleration"])
    if opts.get("run") is None:
        raise ValueError("--run RUN.h5 is required with --format lisa-injection (the run the closed-loop file "
                         "was made from: its light travel times)")
    from ..workflows.export_injection import export_lisa_injection

    r = export_lisa_injection(cl_file, opts["run"], out_file, opts["coefficients"] or "worst-case", seed=opts["seed"],
                              drift=_drift_per_second(opts["drift"]), tm=bool(opts.get("tm_acceleration")))
    return [f"LISA Instrument injection file {r.path}: {r.size} samples from t0 = {r.t0:g} s every {r.dt:g} s; "
            f"TTL coefficients {r.coefficients}; readout_isi_carrier/usb of the six links, RMS up to "
            f"{r.rms_hz:.3g} Hz ({r.rms_m:.3g} m of path length)"]


_EXPORTERS = {"lisa": _export_lisa, "oem": _export_oem, "ttl": _export_ttl, "lisa-injection": _export_lisa_injection}
FORMATS = tuple(_EXPORTERS)
"""Export formats: ``lisa`` = LISA orbit file (lisaorbits layout 2.x); ``oem`` = CCSDS OEM 2.0 files;
``ttl`` = LISA Instrument's TTL coefficient file and ``lisa-injection`` = LISA Instrument glitch file of the
closed loop's tilt-to-length (both from a closed-loop file)."""


@click.command("export")
@click.argument("run_file", metavar="RUN.h5")
@click.argument("out_file", metavar="OUT")
@click.option("--format", "fmt", metavar="FORMAT", help="Output format (required); allowed: lisa, oem, ttl, lisa-injection.")
@click.option("--shapiro/--no-shapiro", default=None,
              help="lisa: include the Shapiro delay in the light travel times (GCRS: the Earth's; BCRS: the Sun's, "
                   "and the Earth's for a geocentric run).  Default: on for heliocentric runs, off for geocentric.")
@click.option("--frame", type=Choice(["gcrs", "bcrs"]), default=None,
              help="lisa: gcrs = the run's geocentric GCRS and TT (default for geocentric runs); bcrs = barycentric "
                   "BCRS with TCB as coordinate time (default, and the only choice, for heliocentric runs).")
@click.option("--axes", type=Choice(["icrf", "ecliptic"]), default=None,
              help="lisa, bcrs only: the axes of the vectors, icrf (default) or the J2000 mean ecliptic of "
                   "lisaorbits' files.")
@click.option("--time-origin", "time_origin", type=Choice(["epoch", "j2000", "unix"]), default=None,
              help="lisa, bcrs only: t = TCB seconds since the run's epoch (default), since J2000.0 TCB, or t0 = the "
                   "Unix time of the first sample (as lisaorbits' OEM orbits).")
@click.option("--coefficients", default=None, metavar="worst-case|random|FILE",
              help="ttl, lisa-injection: the TTL coefficients: worst-case (default; every MOSA at the half-widths of LISA "
                   "Instrument's random draw, 2.2 mm/rad local, 2.4 mm/rad distant), random (uniform in those "
                   "ranges, with --seed) or a .toml/.json file with tables local_phi, local_eta, distant_phi, "
                   "distant_eta keyed by MOSA (12, 23, 31, 13, 32, 21) in m/rad.")
@click.option("--seed", type=int, default=None, help="ttl, lisa-injection, --coefficients random only: the seed of the draw.")
@click.option("--drift", default=None, metavar="RATE",
              help="ttl, lisa-injection: every linear coefficient drifts by RATE m/rad per day from the first sample on; lpf = "
                   "LISA Pathfinder's measured 1 um/rad per 100 days.  Default: constant.")
@click.option("--step", type=float, default=None, metavar="SECONDS",
              help="ttl: sample step (s) over the closed-loop file's span.  Default: its own time grid.")
@click.option("--run", "run", metavar="RUN.h5", default=None,
              help="lisa-injection: the run the closed-loop file was made from (its light travel times; checked "
                   "by SHA-256).")
@click.option("--tm-acceleration", "tm_acceleration", is_flag=True, default=None,
              help="lisa-injection: also inject the TMs' residual velocity (the integral of the closed loop's "
                   "TM acceleration) at LISA Instrument's test-mass point.")
def export(run_file, out_file, fmt, shapiro, frame, axes, time_origin, coefficients, seed, drift, step, run,
           tm_acceleration):
    """Export the trajectory RUN.h5 to OUT in another tool's format.

    With --format ttl the positional file is a closed-loop file CL.h5
    (tqdyn closed-loop RUN.h5 -o CL.h5).

    --format lisa writes a LISA orbit file OUT.h5 (lisaorbits layout 2.x,
    read by lisainstrument and pytdi): satellite states, light travel times
    between the test masses (satellite centres for runs without test
    masses), proper times and proper pseudoranges, in the run's GCRS and TT
    (geocentric default) or the BCRS with TCB (--frame bcrs; heliocentric
    runs); the file's attributes say how each quantity is defined.

    --format oem writes CCSDS OEM 2.0 files for mission-analysis tools
    (GMAT, Orekit, STK), one per satellite (OUT-<name>.oem beside OUT.oem),
    in the run's own system (SUN/ICRF/TDB or EARTH/GCRF/TT).

    --format ttl writes LISA Instrument's TTL coefficient file OUT.h5 (read
    by Instrument(ttl_coeffs=("file", "OUT.h5"))): per-MOSA linear
    coefficients sampled on the closed-loop file's time grid t (the run's
    time axis since its epoch, the t of the GCRS LISA orbit file).

    --format lisa-injection takes a closed-loop file CL.h5 (tqdyn
    closed-loop) in place of RUN.h5 and its run as --run RUN.h5, and writes
    a LISA Instrument glitch file OUT.h5: the closed loop's tilt-to-length
    of the six links injected at the science readouts
    (docs/lisa-ttl.md).
    """
    if fmt is None:
        _fail(f"--format is required; allowed: {', '.join(FORMATS)}")
    if fmt not in FORMATS:
        _fail(unknown("--format", fmt, FORMATS))
    from ..formats import trajectory as io

    opts = {"shapiro": shapiro, "frame": frame, "axes": axes, "time_origin": time_origin,
            "coefficients": coefficients, "seed": seed, "drift": drift, "step": step, "run": run,
            "tm_acceleration": tm_acceleration}
    with guarded(bad_input=(FileNotFoundError, ValueError, io.OutputError)):
        lines = _EXPORTERS[fmt](run_file, out_file, opts)
    click.echo("\n".join(lines))
