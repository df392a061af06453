"""Command line: ``tqdyn run | info | bench``.

The CLI only composes library calls: it resolves the scenario, checks the
output path, runs the propagator with a progress bar, streams the rows into
the HDF5 writer and prints a short summary.  Bad input exits with status 2
and one line on stderr (no traceback, no partial output file).
"""

from __future__ import annotations

import sys
import time

import click

from . import __version__

__all__ = ["main"]

_EXIT_BAD_INPUT = 2
_EXIT_INTERRUPTED = 130


def _fail(message: str, status: int = _EXIT_BAD_INPUT):
    click.echo(f"tqdyn: error: {message}", err=True)
    sys.exit(status)


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="tqdyn")
def cli():
    """tqdyn -- coupled dynamics of drag-free gravitational-wave constellations
    (TianQin by default) in double-double precision."""


def _overrides(sets, duration, step, output, precision) -> list[str]:
    over = list(sets)
    for key, value in (("run.duration", duration), ("integrator.step", step),
                       ("run.output", output), ("run.precision", precision)):
        if value is not None:
            over.append(f"{key}={value}")
    return over


def _format_state_table(scenario, y_dd) -> list[str]:
    import numpy as np

    lines = []
    for sat, row in zip(scenario.satellites, y_dd):
        r = row[0:3, 0] + row[0:3, 1]
        v = row[3:6, 0] + row[3:6, 1]
        lines.append(f"  {sat.name:<6} r = [{r[0]: .9e}, {r[1]: .9e}, {r[2]: .9e}] m"
                     f"  |r| = {np.linalg.norm(r):.6f} m  |v| = {np.linalg.norm(v):.9f} m/s")
    return lines


@cli.command()
@click.argument("scenario", required=False)
@click.option("--duration", help="Propagation span: seconds, or with a unit: 90d, 12h, 30min, 3600s.")
@click.option("--step", help="Integrator step [s] (fixed mode) or output interval (adaptive mode).")
@click.option("--output", "-o", help="Output HDF5 trajectory file.")
@click.option("--precision", type=click.Choice(["dd", "float64"]), help="Arithmetic of the propagation.")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE",
              help="Override a scenario value, e.g. --set integrator.mode=adaptive or "
                   "--set satellites.2.nu_deg=151 (repeatable).")
@click.option("--quiet", "-q", is_flag=True, help="No progress bar.")
def run(scenario, duration, step, output, precision, sets, quiet):
    """Propagate SCENARIO (a built-in name or a TOML file; default: tianqin)
    and write the trajectory file."""
    from tqdm import tqdm

    from . import io, propagator
    from .scenario import ScenarioError, load_scenario

    try:
        scen = load_scenario(scenario, _overrides(sets, duration, step, output, precision))
        out_path = io.check_writable(scen.run.output)
    except (ScenarioError, io.OutputError, ValueError) as exc:
        _fail(str(exc))
    integ = scen.integrator
    fixed = integ.mode == "fixed"
    n_total = scen.n_steps
    attrs = {
        "scenario": scen.to_toml(),
        "epoch_utc": scen.epoch_utc,
        "precision": scen.run.precision,
        "step_s": float(integ.step_s),
        "integrator": f"dp87-{integ.mode}-{integ.tableau}",
        "pointing": "none",
        "control": "off",
    }
    fields = ("t", "sat/r", "sat/v", "sat/a_gravity")
    click.echo(f"tqdyn {__version__}: scenario {scen.name!r}, {len(scen.satellites)} satellite(s), "
               f"{scen.run.precision} precision, DP87 {integ.mode} "
               + (f"{integ.step_s} s x {n_total} steps" if fixed else f"rtol {integ.rtol}, output every {integ.step_s} s")
               + f", {scen.run.duration_s} s from {scen.epoch_utc} UTC", err=True)
    t_compile = time.perf_counter()
    propagator.warm_up(scen.run.precision)
    t_compile = time.perf_counter() - t_compile
    bar = tqdm(total=n_total if fixed else float(scen.run.duration_s), disable=True if quiet else None,
               unit="step" if fixed else "s", unit_scale=not fixed, file=sys.stderr, dynamic_ncols=True,
               desc="propagating")
    try:
        with io.TrajectoryWriter(out_path, attrs, fields, n_sat=len(scen.satellites),
                                 expected_rows=n_total // scen.run.output_every + 1) as writer:
            result = propagator.propagate(scen, sink=writer.append, progress=bar.update)
            rows = writer.rows_written
    except KeyboardInterrupt:
        bar.close()
        _fail("interrupted; no output file written", _EXIT_INTERRUPTED)
    except io.OutputError as exc:
        bar.close()
        _fail(str(exc))
    bar.close()
    size_mb = out_path.stat().st_size / 1e6
    lines = [
        f"steps: {result.n_steps} accepted" + (f", {result.n_rejected} rejected" if not fixed else "")
        + f", {result.n_rhs} right-hand-side evaluations",
        f"wall time: {result.wall_s:.2f} s propagation (+ {t_compile:.2f} s JIT compilation)",
        f"final states (GCRS, t = {result.t_final[0] + result.t_final[1]:.3f} s TDB after the epoch):",
        *_format_state_table(scen, result.y_final),
    ]
    if result.energy_rel_drift is not None:
        lines.append("two-body energy drift (relative): "
                     + ", ".join(f"{s.name} {d:.2e}" for s, d in zip(scen.satellites, result.energy_rel_drift)))
    lines.append(f"output: {out_path} ({rows} rows, {size_mb:.1f} MB)")
    click.echo("\n".join(lines))


@cli.command()
def info():
    """Versions, built-in scenarios, integrator tableaux, force models and
    their sources."""
    import platform

    from .forces.model import describe_terms
    from .integrators import _dp87_tableau
    from .scenario import builtin_scenarios

    def version(mod):
        try:
            return __import__(mod).__version__
        except ImportError:
            return "not installed"

    lines = [f"tqdyn {__version__} (Python {platform.python_version()}, {platform.machine()})",
             "libraries: " + ", ".join(f"{m} {version(m)}" for m in
                                       ("numpy", "numba", "mpmath", "erfa", "h5py", "xarray", "heyoka")),
             "built-in scenarios: " + ", ".join(builtin_scenarios()),
             "precision: dd (compiled double-double, ~32 digits, FMA two-product) | float64",
             "integrator: Prince-Dormand RK8(7)13M, fixed step or adaptive (embedded 7th order), "
             "Hermite dense output",
             f"  tableaux: corrected (default; {_dp87_tableau.__doc__.splitlines()[0].strip()}) | published "
             "(GSL rk8pd.c / GMAT rationals, order conditions hold to ~6.5e-18)",
             "force models:"]
    for name, description, source in describe_terms():
        lines.append(f"  {name:<16} {description} [{source}]")
    click.echo("\n".join(lines))


@cli.command()
@click.option("--duration", default="90d", show_default=True, help="Propagated span.")
@click.option("--step", default="50", show_default=True, help="Step / output grid [s].")
@click.option("--no-heyoka", is_flag=True, help="Skip the heyoka real128 peer even if installed.")
def bench(duration, step, no_heyoka):
    """Kepler benchmark: 3 TianQin satellites, Earth monopole: tqdyn dd vs
    float64 vs heyoka real128 (optional) on the same output grid."""
    from . import bench as _bench
    from .scenario import ScenarioError

    try:
        report = _bench.kepler_benchmark(duration=duration, step=step, heyoka=not no_heyoka)
    except (ScenarioError, ValueError) as exc:
        _fail(str(exc))
    click.echo(_bench.format_report(report))


def main(argv=None):
    """Entry point: click in non-standalone mode so usage errors are one line."""
    try:
        cli.main(args=argv, prog_name="tqdyn", standalone_mode=False)
    except click.exceptions.Abort:
        _fail("interrupted", _EXIT_INTERRUPTED)
    except click.exceptions.ClickException as exc:
        _fail(exc.format_message())
    except KeyboardInterrupt:
        _fail("interrupted", _EXIT_INTERRUPTED)
    return 0


if __name__ == "__main__":  # pragma: no cover
    main()
