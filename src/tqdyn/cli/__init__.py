"""Command line: ``tqdyn run | info | forces | bench | export | sweep | report``.

The CLI only composes library calls: it resolves the scenario, checks the
output path, runs the propagator with a progress bar, streams the rows into
the HDF5 writer and prints a short summary.  Bad input exits with status 2
and one line on stderr (no traceback, no partial output file).
"""

from __future__ import annotations

import sys

import click

from .. import __version__
from ._common import EXIT_INTERRUPTED as _EXIT_INTERRUPTED, fail as _fail

__all__ = ["main"]


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
@click.option("--checkpoint-every", type=click.IntRange(min=0), default=20000, show_default=True,
              help="Write a resumable checkpoint every N steps (fixed mode; 0 = never).")
@click.option("--resume", is_flag=True, help="Continue an interrupted run from its checkpoint (same arguments).")
def run(scenario, duration, step, output, precision, sets, quiet, checkpoint_every, resume):
    """Propagate SCENARIO (a built-in name or a TOML file; default: tianqin)
    and write the trajectory file.  Interrupted runs (Ctrl-C, a crash) keep
    their last checkpoint; `--resume` continues them to a bit-identical file."""
    from tqdm import tqdm

    from ..formats import trajectory as io
    from .. import dynamics
    from ..workflows import run as runner
    from ..scenario import ScenarioError, load_scenario

    try:
        scen = load_scenario(scenario, _overrides(sets, duration, step, output, precision))
        io.check_writable(scen.run.output)
        model = dynamics.check_inputs(scen)
    except (ScenarioError, io.OutputError, ValueError, FileNotFoundError) as exc:
        _fail(str(exc))
    integ = scen.integrator
    fixed = integ.mode == "fixed"
    n_total = scen.n_steps
    c = scen.constellation
    click.echo(f"tqdyn {__version__}: scenario {scen.name!r}, {len(scen.satellites)} satellite(s), "
               f"{scen.run.precision} precision, DP87 {integ.mode} "
               + (f"{integ.step_s} s x {n_total} steps" if fixed else f"rtol {integ.rtol}, output every {integ.step_s} s")
               + f", {scen.run.duration_s} s from {scen.epoch_utc} UTC"
               + (f"; pointing {c.pointing}, control {c.control}" + (", free TMs" if c.free_tms else "")
                  if c.coupled else ""), err=True)
    state = {"bar": None}

    def progress(n):
        if state["bar"] is None:
            state["bar"] = tqdm(total=n_total if fixed else float(scen.run.duration_s),
                                disable=True if quiet else None, unit="step" if fixed else "s",
                                unit_scale=not fixed, file=sys.stderr, dynamic_ncols=True, desc="propagating")
        state["bar"].update(n)

    try:
        summary = runner.run_to_file(scen, model=model, progress=progress,
                                     checkpoint_every=checkpoint_every if fixed else 0, resume=resume)
    except (ValueError, io.OutputError) as exc:
        if state["bar"] is not None:
            state["bar"].close()
        if hasattr(exc, "tqdyn_checkpoint") and not isinstance(exc, io.OutputError):
            raise  # a failure inside the propagation, not bad input
        _fail(str(exc))
    except KeyboardInterrupt as exc:
        if state["bar"] is not None:
            state["bar"].close()
        ckpt = getattr(exc, "tqdyn_checkpoint", None)
        _fail(f"interrupted; continue with the same command and --resume (checkpoint {ckpt})"
              if ckpt else "interrupted; no output file written", _EXIT_INTERRUPTED)
    if state["bar"] is not None:
        state["bar"].close()
    result = summary.result
    lines = [
        f"steps: {result.n_steps} accepted" + (f", {result.n_rejected} rejected" if not fixed else "")
        + f", {result.n_rhs} right-hand-side evaluations",
        f"wall time: {result.wall_s:.2f} s propagation (+ {summary.compile_s:.2f} s JIT compilation)",
        f"final states (GCRS, t = {result.t_final[0] + result.t_final[1]:.3f} s TDB after the epoch):",
        *_format_state_table(scen, result.y_final),
    ]
    if result.energy_rel_drift is not None:
        lines.append("two-body energy drift (relative): "
                     + ", ".join(f"{s.name} {d:.2e}" for s, d in zip(scen.satellites, result.energy_rel_drift)))
    for key, text in result.extra.items():
        lines.append(f"{key}: {text}")
    lines.append(f"output: {summary.path} ({summary.rows} rows, {summary.size_mb:.1f} MB)")
    click.echo("\n".join(lines))


@cli.command()
@click.argument("scenario", required=False)
@click.option("--duration", help="Span of the orbit sampled (default: the scenario's).")
@click.option("--every", default="600", show_default=True, help="Sampling interval [s] (a multiple of the step).")
@click.option("--plot", "plot_path", help="Also plot |a| of every term against time (PNG or PDF).")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE", help="Override a scenario value (repeatable).")
def forces(scenario, duration, every, plot_path, sets):
    """Force budget along the orbit of SCENARIO (default: tianqin): max and
    RMS of |a| of each force term [m/s^2]."""
    from decimal import Decimal, InvalidOperation

    from .. import dynamics
    from ..analysis.budget import force_budget
    from ..forces import atmospheric_tides
    from ..scenario import ScenarioError, load_scenario
    from ..astro.timescales import Epoch

    try:
        scen = load_scenario(scenario, _overrides(sets, duration, None, None, None))
        try:
            ratio = Decimal(every) / scen.integrator.step_s
        except InvalidOperation:
            raise ValueError(f"--every: {every!r} is not a number of seconds") from None
        if ratio <= 0 or ratio != ratio.to_integral_value():
            raise ValueError(f"--every: {every} s is not a positive multiple of the step {scen.integrator.step_s} s")
        scen = load_scenario(scenario, _overrides(sets, duration, None, None, None) + [f"run.output_every={int(ratio)}"])
        model = dynamics.check_inputs(scen)
    except (ScenarioError, ValueError, FileNotFoundError) as exc:
        _fail(str(exc))
    blocks = []
    click.echo(f"propagating {scen.name!r} for {scen.run.duration_s} s and sampling every {every} s ...", err=True)
    dynamics.propagate(scen, sink=blocks.append, model=model)
    rows = dynamics.Rows.concatenate(blocks)
    t_hi, t_lo = rows.t
    r = rows.sat_r[0] + rows.sat_r[1]
    v = rows.sat_v[0] + rows.sat_v[1]
    budget = force_budget(model, Epoch.from_utc(scen.epoch_utc), t_hi, t_lo, r, v)
    lines = [f"force budget along {scen.name!r} ({len(scen.satellites)} satellites, {t_hi.size} samples over "
             f"{float(scen.run.duration_s) / 86400:g} days), |a| in m/s^2:",
             f"  {'term':<22} {'max':>10} {'rms':>10}  source"]
    for b in sorted(budget, key=lambda b: -b.max):
        lines.append(f"  {b.name:<22} {b.max:>10.2e} {b.rms:>10.2e}  {b.source}")
    lines.append(f"  {atmospheric_tides.NAME:<22} {'~' + format(atmospheric_tides.estimate_accel(1.0e8), '.0e'):>10} "
                 f"{'':>10}  NOT modelled: {atmospheric_tides.SOURCE}")
    click.echo("\n".join(lines))
    if plot_path:
        from ..analysis.figures import plot_force_budget

        try:
            plot_force_budget(budget, t_hi + t_lo, plot_path, title=f"force budget, {scen.name}")
        except (ImportError, OSError) as exc:
            _fail(str(exc))
        click.echo(f"plot: {plot_path}")


@cli.command()
def info():
    """Versions, built-in scenarios, integrator tableaux, force models and
    their sources."""
    import platform
    from importlib import resources

    from ..forces import atmospheric_tides
    from ..forces.model import describe_terms
    from ..numerics import _dp87_tableau
    from ..scenario import builtin_scenarios

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
        lines.append(f"  {name:<20} {description} [{source}]")
    lines.append(f"  {atmospheric_tides.NAME:<20} {atmospheric_tides.DESCRIPTION}: ~"
                 f"{atmospheric_tides.estimate_accel(1.0e8):.0e} m/s^2 at 1e5 km [{atmospheric_tides.SOURCE}]")
    data = resources.files("tqdyn") / "data"
    lines.append(f"shipped data ({data}; provenance in SOURCES.md):")
    for entry in sorted(p.name for p in data.iterdir() if p.name != "SOURCES.md"):
        lines.append(f"  {entry}")
    lines.append("ephemeris: DE421 from the skyfield-data package (any JPL DE file by path: forces.ephemeris)")
    lines += [
        "constellation (coupled dynamics, [constellation] / [spacecraft] in a scenario):",
        "  pointing laws: global (instantaneous plane) | taylor1, taylor2 (light-time Taylor expansion) |"
        " iterative (light-time equation solved exactly); none = independent point masses",
        "  control: on (drag-free G_i in the orbits, suspension A_c,l from eq. E1/E2, G from the three"
        " conditions: tan/cot of theta/2) | off (pure-gravity orbits); free_tms: TMs as free bodies (verification)",
        "  spacecraft: TMs +/-d_tm/2 along tm_axis of S (default y), pivots d_p; DC self-gravity per TM in"
        " OA_l (Table IV of the paper by default) + a common part fixed in S",
    ]
    click.echo("\n".join(lines))


@cli.command()
@click.option("--duration", default="90d", show_default=True, help="Propagated span.")
@click.option("--step", default="50", show_default=True, help="Step / output grid [s].")
@click.option("--no-heyoka", is_flag=True, help="Skip the heyoka real128 peer even if installed.")
@click.option("--model", "which", type=click.Choice(["kepler", "full", "coupled", "all"]), default="all",
              show_default=True,
              help="kepler: monopole only; full: the full force model, pure gravity (and the reduced model vs "
                   "heyoka); coupled: the full coupled run (attitude + drag-free control).")
def bench(duration, step, no_heyoka, which):
    """Benchmarks: Kepler (3 TianQin satellites, Earth monopole: tqdyn dd vs
    float64 vs heyoka real128 on the same grid), the force model (full
    model dd / float64, reduced model dd vs heyoka real128) and the coupled
    constellation (dd / float64)."""
    from ..workflows import bench as _bench
    from ..scenario import ScenarioError

    try:
        if which in ("kepler", "all"):
            click.echo(_bench.format_report(_bench.kepler_benchmark(duration=duration, step=step,
                                                                    heyoka=not no_heyoka)))
        if which in ("full", "all"):
            click.echo(_bench.format_force_report(_bench.force_model_benchmark(duration=duration,
                                                                               heyoka=not no_heyoka)))
        if which in ("coupled", "all"):
            click.echo(_bench.format_coupled_report(_bench.coupled_benchmark(duration=duration)))
    except (ScenarioError, ValueError) as exc:
        _fail(str(exc))


from .export import export as _export_command  # noqa: E402  (commands in their own modules)
from .report import report as _report_command  # noqa: E402
from .sweep import sweep as _sweep_command  # noqa: E402

cli.add_command(_export_command)
cli.add_command(_sweep_command)
cli.add_command(_report_command)


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
