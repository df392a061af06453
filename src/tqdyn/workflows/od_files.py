"""Orbit determination from files: the jobs behind ``tqdyn od simulate | fit | covariance``.

Each is the in-memory job of :mod:`tqdyn.workflows.od_memory` between a file read and a file written:

* :func:`simulate_to_tdm`: the scenario of a run file (its ``[accelerations]`` and initial states are
  the injected truth), a tracking plan, seeded measurements (``tqdyn.od``'s ``problem.simulate``) written
  as a CCSDS TDM (:mod:`tqdyn.formats.od_tdm`) whose header records the plan (and the run file's name
  and SHA-256);
* :func:`fit_to_file`: a scenario and a TDM, the batch least-squares fit
  (``tqdyn.od``'s ``problem.fit``) written as the estimate file (:mod:`tqdyn.formats.od_estimate`);
* :func:`covariance_of`: the predicted covariance of a tracking plan
  (``tqdyn.od``'s ``problem.covariance``), optionally written as JSON.

Every input is checked before any work and nothing is written on bad input (a ``ValueError`` /
``FileNotFoundError`` / :class:`tqdyn.formats.trajectory.OutputError` with one line); files are
written atomically.  ``progress`` callbacks receive the name of the stage that starts.  Nothing is
printed here; the CLI reports.
"""

from __future__ import annotations

import json
import os
import pathlib
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .._choices import unknown
from ..formats import trajectory as io
from ..formats.atomic import check_output, replacing, same_file
from ..formats.od_estimate import estimate_contents, write_estimate_file
from ..formats.od_tdm import read_measurements_tdm, write_measurements_tdm
from .closed_loop import file_sha256
from .od import _check_consider, _scenario, _sp3_inputs, covariance_record, parse_a_priori, parse_names
from .od_memory import ESTIMATOR_OPTIONS, covariance, fit, simulate

__all__ = ["SimulateSummary", "covariance_of", "fit_to_file", "simulate_to_tdm"]


@dataclass(frozen=True)
class SimulateSummary:
    """What :func:`simulate_to_tdm` wrote: path, measurement count per type, the tracking plan."""

    path: pathlib.Path
    counts: dict
    tracking: object
    notes: tuple



def simulate_to_tdm(run_file, tracking, arc, *, output, seed: int = 0, interval=None, stations=None, bias=None,
                    sp3=None, overrides=(), progress: Callable[[str], None] | None = None) -> SimulateSummary:
    """Simulate the measurements of ``tracking`` (kinds) over ``arc`` from the run file's scenario (its
    ``[accelerations]`` are the truth) with noise seed ``seed``, and write them as a TDM to ``output``:
    :func:`tqdyn.workflows.od_memory.simulate` between the file checks and the file.
    stations: ground-station names (None: the plan's defaults); bias: constant measurement biases
    (:func:`parse_biases`; None: none), recorded in the TDM's header; sp3: SP3 files of the GNSS
    transmitters (a path or a sequence; None: the nominal constellations), their names and SHA-256
    recorded in the header."""
    
    say = progress or (lambda stage: None)
    box = {}

    def ready():
        if not io.is_trajectory_file(run_file):
            raise (FileNotFoundError(f"RUN.h5: trajectory file {str(run_file)!r} does not exist or is not a file")
                   if not os.path.isfile(os.fspath(run_file)) else
                   ValueError(f"RUN.h5: {str(run_file)!r} is not a trajectory file; allowed: a file written by "
                              "tqdyn run"))
        box["out"] = check_output(output, "--output", {"RUN.h5": run_file, **_sp3_inputs(sp3)})

    s = simulate(run_file, tracking, arc, seed=seed, interval=interval, stations=stations, bias=bias, sp3=sp3,
                 overrides=overrides, progress=say, ready=ready, cli=True)
    info = {}
    for key, value in s.info.items():
        info[key] = value
        if key == "scenario":
            info["run_file"] = pathlib.Path(run_file).name
            info["run_sha256"] = file_sha256(run_file)
    say("writing")
    scen = s.scenario
    path = write_measurements_tdm(box["out"], s.meas, epoch=scen.epoch, time_scale=scen.reference.time_scale,
                                  satellite_names=[x.name for x in scen.satellites], info=info)
    counts: dict = {}
    for typ in np.asarray(s.meas.type).tolist():
        counts[typ] = counts.get(typ, 0) + 1
    return SimulateSummary(path, counts, s.tracking, s.notes)



def fit_to_file(scenario, tdm, *, output=None, estimate=None, consider=None, a_priori=None, edit_sigma=None,
                sp3=None, overrides=(), figure=None, progress: Callable[[str], None] | None = None, **options):
    """Fit the scenario's parameters (``estimate``, ``consider``: names of parameter groups, default
    the plan's) to the measurements of the TDM ``tdm``; write the estimate file ``output`` (None: no
    file) and the residuals' figure ``figure`` (None: none; PNG or PDF by its suffix,
    :func:`tqdyn.analysis.figures_od.plot_od_residuals`, checked before the fit).  a_priori: a
    priori sigmas per group (:func:`parse_a_priori`), needed for each considered group.  sp3: the
    SP3 files the TDM was simulated with (its header names them; refused when they differ, by
    SHA-256; None: none, the nominal constellations).  Returns
    (:class:`tqdyn.od.estimator.Estimate`, the scenario, notes).  ``options`` go to
    :func:`tqdyn.od.estimator.estimate` with ``edit_sigma`` (checked: those of
    :data:`tqdyn.workflows.od_memory.ESTIMATOR_OPTIONS`).  The fit is
    :func:`tqdyn.workflows.od_memory.fit` between the TDM and the files."""
    
    say = progress or (lambda stage: None)
    for key in options:
        if key not in ESTIMATOR_OPTIONS:
            raise TypeError(unknown("fit_to_file()", key, ["edit_sigma", *ESTIMATOR_OPTIONS],
                                    problem="is not an estimator option", noun="options"))
    est_names, con_names = parse_names(estimate, "--estimate"), parse_names(consider, "--consider")
    sig = parse_a_priori(a_priori)
    _check_consider(con_names, sig)
    if edit_sigma is not None and not (isinstance(edit_sigma, (int, float)) and edit_sigma > 0):
        raise ValueError(f"--edit-sigma: {edit_sigma!r} is not allowed; allowed: a number > 0")
    if not os.path.isfile(os.fspath(tdm)):
        raise FileNotFoundError(f"MEAS.tdm: measurement file {str(tdm)!r} does not exist or is not a file")
    inputs = {"MEAS.tdm": tdm, "SCENARIO": scenario if scenario and os.path.isfile(str(scenario)) else None,
              **_sp3_inputs(sp3)}
    out = check_output(output, "--output", inputs) if output is not None else None
    if figure is not None:
        from ..analysis.figures_od import check_residual_figure_path

        try:
            check_residual_figure_path(figure)
        except ImportError as exc:
            raise ValueError(f"--figure: {str(figure)!r} cannot be drawn ({exc}); allowed: no --figure, or install "
                             "matplotlib") from None
        if out is not None and same_file(out, figure):
            raise ValueError(f"--figure: {str(figure)!r} is the output EST.h5; allowed: another file")
        check_output(figure, "--figure", inputs)
    scen, notes, label = _scenario(scenario, overrides)
    say("reading")
    fields, info = read_measurements_tdm(tdm, epoch=scen.epoch, time_scale=scen.reference.time_scale,
                                         with_lines=True, grid_s=float(scen.integrator.step_s))
    f = fit(label, fields, info, estimate=est_names, consider=con_names, a_priori=sig, edit_sigma=edit_sigma,
            sp3=sp3, options=options, name=str(tdm), progress=say, cli=True, scen=scen)
    attrs = {}
    for key, value in f.attrs.items():
        if key == "edit_sigma":
            attrs.update(tdm_file=pathlib.Path(tdm).name, tdm_sha256=file_sha256(tdm))
        attrs[key] = value
    fit_, meas, rows, units = f.estimate, f.meas, f.residual_rows, f.units
    if out is not None:
        say("writing")
        write_estimate_file(out, fit_, meas, attrs=attrs, units=units, residual_rows=rows)
    if figure is not None:
        from ..analysis.figures_od import plot_od_residuals

        say("plotting")
        try:
            plot_od_residuals(estimate_contents(fit_, meas, attrs=attrs, units=units, residual_rows=rows), figure)
        except io.OutputIOError as exc:  # a full disk: status 3, the estimate file stays
            err = io.OutputIOError(f"--figure: {exc}")
            err.tqdyn_note = ("the figure was not written" + (f", the estimate file {str(out)!r} was"
                                                              if out is not None else ""))
            raise err from None
        except (OSError, RuntimeError) as exc:  # a directory removed since the check, a missing LaTeX
            raise ValueError(f"--figure: {str(figure)!r} could not be written ({exc}); nothing was written there"
                             + (f", the estimate file {str(out)!r} was" if out is not None else "")
                             + "; allowed: a writable file with space for the figure") from None
    return fit_, scen, tuple(notes)


def covariance_of(scenario, tracking, arc, *, interval=None, estimate=None, consider=None, a_priori=None,
                  stations=None, sp3=None, overrides=(), json_out=None, progress: Callable[[str], None] | None = None):
    """The predicted covariance (:class:`tqdyn.od.estimator.Covariance`) of the tracking plan on the
    scenario (a_priori, sp3: as :func:`simulate_to_tdm`'s), and (optionally) its JSON file ``json_out``:
    :func:`tqdyn.workflows.od_memory.covariance` and the file.  Returns (covariance, scenario, notes)."""
    
    say = progress or (lambda stage: None)
    box = {}

    def ready():
        paths = [sp3] if isinstance(sp3, (str, os.PathLike)) else list(sp3 or ())
        inputs = {"SCENARIO": scenario if scenario and os.path.isfile(str(scenario)) else None, **_sp3_inputs(paths)}
        box["out"] = check_output(json_out, "--json", inputs) if json_out is not None else None

    cov, scen, plan, sp3_paths, notes = covariance(scenario, tracking, arc, interval=interval, estimate=estimate,
                                                   consider=consider, a_priori=a_priori, stations=stations, sp3=sp3,
                                                   overrides=overrides, ready=ready, progress=say, cli=True)
    if box["out"] is not None:
        say("writing")
        rec = covariance_record(cov, scen, plan, sp3_paths)
        with replacing(box["out"], "the covariance JSON") as tmp:
            tmp.write_text(json.dumps(rec, indent=1) + "\n", encoding="utf-8")
    return cov, scen, tuple(notes)
