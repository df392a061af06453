"""Command line: ``tqdyn bench [--duration D] [--step S] [--model kepler|full|coupled|lisa|all] [--no-heyoka]``.

Registered in :mod:`tqdyn.cli` with ``cli.add_command(bench)``.  It only
composes :mod:`tqdyn.workflows.bench` and prints its tables; bad input exits
with status 2 and one line on stderr.
"""

from __future__ import annotations

import click

from ._common import fail as _fail

__all__ = ["bench"]


@click.command("bench")
@click.option("--duration", default=None,
              help="Propagated span [default: 90d; lisa: 3652.5d = 10 years; lisa-coupled: 365d; rounded up to "
                   "whole 6 h steps].")
@click.option("--step", default="50", show_default=True, help="Step / output grid [s].")
@click.option("--no-heyoka", is_flag=True, help="Skip the heyoka real128 peer even if installed.")
@click.option("--model", "which", type=click.Choice(["kepler", "full", "coupled", "lisa", "lisa-coupled", "all"]), default="all",
              show_default=True,
              help="kepler: monopole only; full: the full force model, pure gravity (and the reduced model vs "
                   "heyoka); coupled: the full coupled run (attitude + drag-free control); lisa: the heliocentric "
                   "lisa-esa scenario (ESA's orbits and force model, point masses); lisa-coupled: the coupled "
                   "lisa scenario (LISA architecture and drag-free scheme, one year).")
def bench(duration, step, no_heyoka, which):
    """Benchmarks: Kepler (3 TianQin satellites, Earth monopole: tqdyn dd vs
    float64 vs heyoka real128 on the same grid), the force model (full
    model dd / float64, reduced model dd vs heyoka real128), the coupled
    constellation (dd / float64), LISA (heliocentric point masses, 10
    years, dd / float64) and the coupled LISA constellation (one year)."""
    from ..workflows import bench as _bench
    from ..scenario import ScenarioError

    lisa_duration = duration or _bench.LISA_DURATION
    lisa_coupled_duration = duration or _bench.LISA_COUPLED_DURATION
    duration = duration or "90d"
    try:
        if which in ("kepler", "all"):
            click.echo(_bench.format_report(_bench.kepler_benchmark(duration=duration, step=step,
                                                                    heyoka=not no_heyoka)))
        if which in ("full", "all"):
            click.echo(_bench.format_force_report(_bench.force_model_benchmark(duration=duration,
                                                                               heyoka=not no_heyoka)))
        if which in ("coupled", "all"):
            click.echo(_bench.format_coupled_report(_bench.coupled_benchmark(duration=duration)))
        if which in ("lisa", "all"):
            click.echo(_bench.format_lisa_report(_bench.lisa_benchmark(duration=lisa_duration)))
        if which in ("lisa-coupled", "all"):
            click.echo(_bench.format_lisa_report(_bench.lisa_benchmark(duration=lisa_coupled_duration,
                                                                       scenario="lisa")))
    except (ScenarioError, ValueError) as exc:
        _fail(str(exc))
