"""Command line: ``tqdyn forces [SCENARIO] [--every S] [--plot FILE]``: the force budget along an orbit.

Registered in :mod:`tqdyn.cli` with ``cli.add_command(forces)``.  It only
composes library calls (:func:`tqdyn.analysis.budget.force_budget`,
:func:`tqdyn.analysis.figures.plot_force_budget`); bad input exits with
status 2 and one line on stderr.
"""

from __future__ import annotations

from decimal import Decimal, InvalidOperation

import click

from ._common import _overrides, fail as _fail, fail_io

__all__ = ["forces"]


#: Default sampling interval [s]: 600 s, or the smallest multiple of the step above it.
DEFAULT_EVERY_S = 600
#: Most samples one ``tqdyn forces`` keeps in memory (all states are held to evaluate the terms).
MAX_SAMPLES = 10_000_000


def _fmt(x: Decimal) -> str:
    """A Decimal as the user would write it (``600``, ``0.5``, ``1E+400``)."""
    return format(x.normalize(), "f") if abs(x.adjusted()) < 20 else str(x.normalize())


def sampling_ratio(every, step_s: Decimal, duration_s: Decimal) -> tuple[int, Decimal]:
    """Steps per sample and the interval [s] for ``--every`` (a string or None for
    the default) with step ``step_s`` over ``duration_s``; ValueError
    ``"--every: <value> <problem>; allowed: ..."`` for anything that is not a
    positive, finite multiple of the step at most the duration, or that would
    give more than :data:`MAX_SAMPLES` samples."""
    step, duration = Decimal(step_s), Decimal(duration_s)
    allowed = (f"allowed: a positive, finite number of seconds that is a multiple of the step {_fmt(step)} s "
               f"and at most the duration {_fmt(duration)} s")
    if every is None:
        ratio = max(1, -(-Decimal(DEFAULT_EVERY_S) // step))
        value = ratio * step
        samples = duration // value + 1
        if samples > MAX_SAMPLES:
            raise ValueError(f"--duration: {_fmt(duration)} s gives {samples} samples at the default --every "
                             f"{_fmt(value)} s; allowed: at most {MAX_SAMPLES} samples (a shorter --duration "
                             "or a larger --every)")
        return int(ratio), value
    try:
        value = Decimal(str(every).strip())
    except InvalidOperation:
        raise ValueError(f"--every: {every!r} is not a number; {allowed}") from None
    if value.is_nan() or value.is_infinite():
        raise ValueError(f"--every: {every!r} is not finite; {allowed}")
    if value <= 0:
        raise ValueError(f"--every: {every} is not positive; {allowed}")
    if value > duration:
        raise ValueError(f"--every: {every} s is longer than the duration {_fmt(duration)} s; {allowed}")
    ratio = value / step
    if ratio != ratio.to_integral_value():
        raise ValueError(f"--every: {every} s is not a multiple of the step {_fmt(step)} s; {allowed}")
    samples = duration // value + 1
    if samples > MAX_SAMPLES:
        raise ValueError(f"--every: {every} s gives {samples} samples over {_fmt(duration)} s; allowed: at most "
                         f"{MAX_SAMPLES} samples (a larger --every or a shorter --duration)")
    return int(ratio), value


@click.command("forces")
@click.argument("scenario", required=False)
@click.option("--duration", help="Span of the orbit sampled (default: the scenario's).")
@click.option("--every", default=None,
              help=f"Sampling interval [s], a multiple of the step  [default: {DEFAULT_EVERY_S}, "
                   "or the smallest multiple of the step above it]")
@click.option("--plot", "plot_path",
              help="Also plot |a| of every term against time (any format matplotlib writes: .png, .pdf, .svg, ...).")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE", help="Override a scenario value (repeatable).")
def forces(scenario, duration, every, plot_path, sets):
    """Force budget along the orbit of SCENARIO (default: tianqin): max and
    RMS of |a| of each force term [m/s^2].

    Every option is checked before any computation: bad input exits with
    status 2 and one line on stderr, and no file is written."""
    from .. import dynamics
    from ..analysis.budget import force_budget
    from ..formats.trajectory import OutputError
    from ..scenario import ScenarioError, load_scenario

    try:
        over = _overrides(sets, duration, None, None, None)
        scen = load_scenario(scenario, over)
        ratio, every_s = sampling_ratio(every, scen.integrator.step_s, scen.run.duration_s)
        scen = load_scenario(scenario, over + [f"run.output_every={ratio}"])
        if plot_path is not None:
            from ..analysis.figures import check_figure_path

            check_figure_path(plot_path)
            from ..formats.atomic import check_output
            from ..workflows.run import scenario_inputs

            check_output(plot_path, "--plot", scenario_inputs(scenario, scen))
        model = dynamics.check_inputs(scen)
    except (ScenarioError, ValueError, FileNotFoundError, OutputError) as exc:
        _fail(str(exc))
    except ImportError as exc:
        _fail(f"--plot: {plot_path!r} cannot be drawn ({exc}); allowed: no --plot, or install matplotlib")
    blocks = []
    click.echo(f"propagating {scen.name!r} for {scen.run.duration_s} s and sampling every {_fmt(every_s)} s ...",
               err=True)
    from ..workflows.run import eop_warning

    if note := eop_warning(scen, model):
        click.echo(f"tqdyn: warning: {note}", err=True)
    dynamics.propagate(scen, sink=blocks.append, model=model)
    rows = dynamics.Rows.concatenate(blocks)
    t_hi, t_lo = rows.t
    r = rows.sat_r[0] + rows.sat_r[1]
    v = rows.sat_v[0] + rows.sat_v[1]
    budget = force_budget(model, scen.epoch, t_hi, t_lo, r, v)
    lines = [f"force budget along {scen.name!r} ({len(scen.satellites)} satellites, {t_hi.size} samples over "
             f"{float(scen.run.duration_s) / 86400:g} days), |a| in m/s^2:",
             f"  {'term':<22} {'max':>10} {'rms':>10}  source"]
    for b in sorted(budget, key=lambda b: -b.max):
        lines.append(f"  {b.name:<22} {b.max:>10.2e} {b.rms:>10.2e}  {b.source}")
    click.echo("\n".join(lines))
    if plot_path is not None:
        from ..analysis.figures import plot_force_budget

        from ..formats.trajectory import OutputIOError

        try:
            plot_force_budget(budget, t_hi + t_lo, plot_path, title=f"force budget, {scen.name}")
        except ValueError as exc:  # the path changed since it was checked
            _fail(str(exc))
        except OutputIOError as exc:  # a full disk: status 3
            fail_io(f"--plot: {exc}; nothing was written there")
        except (OSError, RuntimeError) as exc:  # a missing LaTeX for .pgf, ...
            _fail(f"--plot: {plot_path!r} could not be written ({exc}); nothing was written there; "
                  "allowed: a writable file with space for the figure")
        click.echo(f"plot: {plot_path}")
