"""Command line: ``tqdyn od simulate | fit | covariance`` -- orbit determination from files.

Registered in :mod:`tqdyn.cli`.  It only composes :mod:`tqdyn.workflows.od_files` (the jobs) and :mod:`tqdyn.workflows.od`: bad input (an unknown
tracking type, an arc outside the run, a malformed TDM, a station below the horizon for the whole
arc, an output path that is an input, an unobservable fit, a ``--figure`` that is not a writable
``.png`` or ``.pdf``, a ``--bias`` or ``--a-priori`` that is not TYPE=VALUE / GROUP=SIGMA, a
considered group without an a priori sigma, an ``--sp3`` file that is missing, malformed, too short
for the arc or other than the one a TDM was simulated with) exits with status 2 and one line,
nothing written;
a failed write (disk full) exits with 3, Ctrl-C with 130, SIGTERM with 143, and none leaves a file
(the files are written atomically).  The stages show as a
progress bar on stderr (``--quiet``: none).
"""

from __future__ import annotations

import sys

import click

from ._common import guarded

__all__ = ["od"]

_SET_HELP = ("Override a scenario value, e.g. --set run.duration=30d or --set accelerations.s_frame=[...] "
             "(repeatable; docs/scenarios.md).")


class _Stages:
    """A progress bar over the named stages of a job (one step per stage)."""

    def __init__(self, stages: tuple, quiet: bool, desc: str):
        from tqdm import tqdm

        self.stages = list(stages)
        self.bar = tqdm(total=len(stages), disable=True if quiet else None, unit="stage", file=sys.stderr,
                        dynamic_ncols=True, desc=desc)
        self.seen = 0

    def __call__(self, stage: str) -> None:
        if self.seen:
            self.bar.update(1)
        self.seen += 1
        self.bar.set_postfix_str(stage)

    def close(self) -> None:
        if self.seen:
            self.bar.update(1)
        self.bar.close()


def _run(job, stages: _Stages):
    """Run ``job()`` in :func:`._common.guarded`: bad input -> status 2, a failed write -> 3, Ctrl-C ->
    130, SIGTERM -> 143 (no file is left: writes are atomic)."""
    from ..formats import trajectory as io
    from ..scenario import ScenarioError

    with guarded(bad_input=(ValueError, FileNotFoundError, ScenarioError, io.OutputError), cleanup=stages.bar.close):
        out = job()
    stages.close()
    return out


def _ttc_option(f):
    """``--ttc-stations FILE``: the TT&C stations file of the command (docs/od-measurements.md)."""
    return click.option("--ttc-stations", "ttc_stations", metavar="FILE",
                        help="TT&C ground stations from this TOML file instead of the shipped one "
                             "(docs/od-measurements.md; also $TQDYN_TTC_STATIONS).")(f)


def _with_ttc(path, job):
    """``job`` run with the TT&C stations file ``path`` (None: the default), checked first (one line)
    and handed on to Dask workers started later through ``$TQDYN_TTC_STATIONS``."""
    if path is None:
        return job

    def run():
        import os

        from ..od.measurements_ttc import use_ttc_stations

        before = os.environ.get("TQDYN_TTC_STATIONS")
        try:
            use_ttc_stations(path)
            os.environ["TQDYN_TTC_STATIONS"] = os.fspath(path)
            return job()
        finally:  # the command's choice ends with it (commands may run in one process, as in the tests)
            if before is None:
                os.environ.pop("TQDYN_TTC_STATIONS", None)
            else:
                os.environ["TQDYN_TTC_STATIONS"] = before
            use_ttc_stations(None)

    return run


def _notes(notes) -> None:
    for note in notes:
        if note:
            click.echo(f"tqdyn: warning: {note}", err=True)


def summary_lines(names, values, sigma, units, consider_sigma=None) -> list[str]:
    """One line per parameter: ``name = value +- sigma unit`` (values None: ``name: sigma = s unit``),
    and the consider sigma when it differs."""
    width = max([len(n) for n in names] + [4])
    out = []
    for i, n in enumerate(names):
        line = (f"  {n:<{width}} = {values[i]: .9e} +- {sigma[i]:.3e} {units[i]}" if values is not None else
                f"  {n:<{width}}   sigma = {sigma[i]:.3e} {units[i]}").rstrip()
        if consider_sigma is not None and consider_sigma[i] != sigma[i]:
            line += f"  (consider: +- {consider_sigma[i]:.3e})"
        out.append(line)
    return out


@click.group("od")
def od():
    """Orbit determination: simulate tracking (CCSDS TDM), fit a scenario's initial states and
    acceleration parameters (the DC self-gravity among them) to it, or predict the covariance of a
    tracking plan (docs/orbit-determination.md)."""


@od.command("simulate")
@click.argument("run_file", metavar="RUN.h5")
@click.option("--tracking", required=True,
              help="Tracking kinds, comma-separated, e.g. gnss,slr,isr (every kind: "
                   "docs/od-measurements.md#measurement-types).")
@click.option("--arc", required=True, help="Arc from the epoch: seconds, or with a unit: 7d, 12h, 30min.")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the measurement noise.")
@click.option("--interval", help="Measurement interval: seconds or with a unit [default: 600 s].")
@click.option("--stations", help="Ground stations (SLR, deep-space), comma-separated [default: the plan's].")
@click.option("--bias", "biases", multiple=True, metavar="TYPE[/PEER]=VALUE",
              help="A constant measurement bias (the type's unit: m, m/s for range rates) added to every station "
                   "or link of a type with biases (TYPE=VALUE) or to one (slr_range/Graz, isr_range/Sat2->Sat1); "
                   "repeatable.")
@click.option("--sp3", "sp3", multiple=True, metavar="FILE",
              help="GNSS transmitter orbits from this SP3-c/d file instead of the nominal GPS and BeiDou "
                   "constellations (repeatable: files of other satellites, or consecutive days of the same ones, "
                   "which are joined in time).")
@click.option("--output", "-o", required=True, help="Output measurement file (CCSDS TDM, KVN).")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE", help=_SET_HELP)
@click.option("--quiet", "-q", is_flag=True, help="No progress bar.")
@_ttc_option
def simulate(run_file, tracking, arc, seed, interval, stations, biases, sp3, output, sets, quiet, ttc_stations):
    """Simulate the measurements of a tracking plan on the run RUN.h5: its recorded scenario, with its
    [accelerations] and initial states as the truth, seeded white noise; written as a CCSDS TDM."""
    from ..workflows import od_files as wf

    stages = _Stages(("scheduling", "simulating", "writing"), quiet, "od simulate")
    s = _run(_with_ttc(ttc_stations, lambda: wf.simulate_to_tdm(
        run_file, tracking, arc, output=output, seed=seed, interval=interval, stations=stations, bias=biases,
        sp3=sp3, overrides=sets, progress=stages)), stages)
    _notes(s.notes)
    counts = ", ".join(f"{n} {t}" for t, n in s.counts.items())
    click.echo(f"measurements: {sum(s.counts.values())} ({counts}) over {s.tracking.arc_s:g} s, seed {seed}")
    click.echo(f"output: {s.path}")


@od.command("fit")
@click.argument("scenario", metavar="SCENARIO")
@click.argument("tdm", metavar="MEAS.tdm")
@click.option("--output", "-o", required=True, help="Output estimate file (HDF5, docs/orbit-determination.md).")
@click.option("--estimate", help="Parameter groups to estimate, comma-separated [default: state,s_frame; "
              "coupled runs: state,self_gravity_common].")
@click.option("--consider", help="Parameter groups to consider (not estimated, their uncertainty kept).")
@click.option("--a-priori", "a_priori", multiple=True, metavar="GROUP=SIGMA",
              help="A priori 1-sigma of a parameter group (state=SIGMA_R,SIGMA_V in m, m/s; bias=SIGMA or "
                   "bias/TYPE=SIGMA in m or m/s; the acceleration groups in m/s^2); needed for --consider; "
                   "repeatable.")
@click.option("--edit-sigma", type=float, help="Leave out measurements beyond K normalised sigmas (off by default).")
@click.option("--sp3", "sp3", multiple=True, metavar="FILE",
              help="GNSS transmitter orbits from this SP3-c/d file, one MEAS.tdm was simulated with (its header "
                   "names them); repeatable.")
@click.option("--figure", help="Also draw the normalised post-fit residuals and their histogram (.png or .pdf).")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE", help=_SET_HELP)
@click.option("--quiet", "-q", is_flag=True, help="No progress bar.")
@_ttc_option
def fit(scenario, tdm, output, estimate, consider, a_priori, edit_sigma, sp3, figure, sets, quiet, ttc_stations):
    """Fit SCENARIO (a built-in name, a TOML file or a run file) to the measurements MEAS.tdm by batch
    least squares; print each estimated parameter with its 1-sigma, and chi^2/dof."""
    from ..workflows import od as od_inputs, od_files as wf

    stages = _Stages(("reading", "fitting", "writing") + (("plotting",) if figure else ()), quiet, "od fit")
    est, _, notes = _run(_with_ttc(ttc_stations, lambda: wf.fit_to_file(
        scenario, tdm, output=output, estimate=estimate, consider=consider, a_priori=a_priori,
        edit_sigma=edit_sigma, sp3=sp3, overrides=sets, figure=figure, progress=stages)), stages)
    _notes(notes)
    units = [od_inputs.parameter_unit(n) for n in est.names]
    click.echo("\n".join(summary_lines(est.names, est.values, est.sigma, units,
                                       est.consider_sigma if est.consider_names else None)))
    m = int(len(est.edited))
    click.echo(f"chi2/dof = {est.chi2:.6g}/{est.chi2_dof} = {est.chi2 / max(est.chi2_dof, 1):.4g} "
               f"(p = {est.chi2_pvalue:.3g}); {m - int(sum(est.edited))} of {m} measurements kept, "
               f"{est.iterations} iterations, condition number {est.condition_number:.3g}")
    click.echo(f"output: {output}")
    if figure:
        click.echo(f"figure: {figure}")


@od.command("covariance")
@click.argument("scenario", metavar="SCENARIO")
@click.option("--tracking", required=True,
              help="Tracking kinds, comma-separated, e.g. gnss,slr,isr (every kind: "
                   "docs/od-measurements.md#measurement-types).")
@click.option("--arc", required=True, help="Arc from the epoch: seconds, or with a unit: 7d, 12h, 30min.")
@click.option("--interval", help="Measurement interval: seconds or with a unit [default: 600 s].")
@click.option("--estimate", help="Parameter groups to estimate, comma-separated [default: state,s_frame; "
              "coupled runs: state,self_gravity_common].")
@click.option("--consider", help="Parameter groups to consider (not estimated, their uncertainty kept).")
@click.option("--a-priori", "a_priori", multiple=True, metavar="GROUP=SIGMA",
              help="A priori 1-sigma of a parameter group (state=SIGMA_R,SIGMA_V in m, m/s; bias=SIGMA or "
                   "bias/TYPE=SIGMA in m or m/s; the acceleration groups in m/s^2); needed for --consider; "
                   "repeatable.")
@click.option("--stations", help="Ground stations (SLR, deep-space), comma-separated [default: the plan's].")
@click.option("--sp3", "sp3", multiple=True, metavar="FILE",
              help="GNSS transmitter orbits from this SP3-c/d file instead of the nominal GPS and BeiDou "
                   "constellations (repeatable: files of other satellites, or consecutive days of the same ones, "
                   "which are joined in time).")
@click.option("--json", "json_out", help="Also write the covariance as JSON to this file.")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE", help=_SET_HELP)
@click.option("--quiet", "-q", is_flag=True, help="No progress bar.")
@_ttc_option
def covariance(scenario, tracking, arc, interval, estimate, consider, a_priori, stations, sp3, json_out, sets,
               quiet, ttc_stations):
    """Predict, without measurements, how well a tracking plan determines SCENARIO's parameters: the
    1-sigma of each (and with --consider the consider sigma)."""
    from ..workflows import od as od_inputs, od_files as wf

    stages = _Stages(("covariance", "writing") if json_out else ("covariance",), quiet, "od covariance")
    cov, _, notes = _run(_with_ttc(ttc_stations, lambda: wf.covariance_of(
        scenario, tracking, arc, interval=interval, estimate=estimate, consider=consider, a_priori=a_priori,
        stations=stations, sp3=sp3, overrides=sets, json_out=json_out, progress=stages)), stages)
    _notes(notes)
    units = [od_inputs.parameter_unit(n) for n in cov.names]
    click.echo("\n".join(summary_lines(cov.names, None, cov.sigma, units,
                                       cov.consider_sigma if cov.consider_names else None)))
    click.echo(f"condition number {cov.condition_number:.3g}")
    if json_out:
        click.echo(f"output: {json_out}")


def _register_campaign() -> None:
    from .od_campaign import campaign

    od.add_command(campaign)


_register_campaign()
