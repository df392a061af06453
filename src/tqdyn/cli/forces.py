"""Command line: ``tqdyn forces [SCENARIO] [--every S] [--plot FILE]``: the force budget along an orbit.

Registered in :mod:`tqdyn.cli` with ``cli.add_command(forces)``.  It only
composes library calls (:func:`tqdyn.analysis.budget.force_budget`,
:func:`tqdyn.analysis.figures.plot_force_budget`); bad input exits with
status 2 and one line on stderr.
"""

from __future__ import annotations

import click

from ._common import _overrides, fail as _fail

__all__ = ["forces"]


@click.command("forces")
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
    from ..scenario import ScenarioError, load_scenario

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
    if plot_path:
        from ..analysis.figures import plot_force_budget

        try:
            plot_force_budget(budget, t_hi + t_lo, plot_path, title=f"force budget, {scen.name}")
        except (ImportError, OSError) as exc:
            _fail(str(exc))
        click.echo(f"plot: {plot_path}")
