"""Figures and a summary table of tqdyn runs: ``tqdyn report``.

Two entry points, both writing PNG + PDF figures and ``summary.md`` into an
output directory and returning a :class:`Report`:

* :func:`report_runs` -- whatever the given trajectory files contain, for
  TianQin, LISA and Taiji alike: per run the reference system and (coupled
  runs) the spacecraft architecture and drag-free scheme the file records,
  the electrostatic / drag-free control and the actuation per TM and axis,
  the arm lengths and their rates, the breathing angles against the
  constellation's design and constraints, the range ASD of the six light
  paths (uniform grids reaching the band) and the pointing-law comparison
  (runs on the integrator grid); across runs that share an epoch, the orbit
  deviation from a reference run (the first pure-gravity run, else the
  first run).
* :func:`report_studies` -- the paper's section V from the study runs of
  :mod:`tqdyn.workflows.studies` (Figs. 5-11, the drag-free and common self-gravity
  deviations) with a table "quantity | paper | tqdyn | agreement / notes".

Conventions: SI units (m, s, m/s^2, rad; angles in the figures and table in
deg where marked), the file's inertial frame for inertial vectors (GCRS
geocentric, the Sun-centred BCRS heliocentric), S / OA_l frames for control
quantities as stored in the trajectory (:data:`tqdyn.formats.trajectory.FIELDS`), time in
seconds (days in the figures) since the scenario epoch in the file's time
scale (TT geocentric, TDB heliocentric).  Ranges are
formed and differenced in double-double before any float64 rounding
(:mod:`tqdyn.lightpath`, :mod:`tqdyn.analysis.spectra`); the ASDs use the
default Kaiser-window Welch estimate of the second dd difference
(:func:`tqdyn.analysis.spectra.range_asd`) and are compared with the
requirement 0.3 pm/Hz^1/2 sqrt(1 + (7 mHz/f)^4) from max(0.1 mHz, 26 Welch
bins) to the Nyquist frequency (the lowest ~26 bins are biased, see the
spectra module).

The metrics are in :mod:`tqdyn.analysis.metrics` (orbit deviations and the
secular along-track drift that explains the drag-free orbit's deviation from
the gravity orbit), the figures in :mod:`tqdyn.analysis.figures`.  Modules:
:mod:`.summary` (:class:`Report`, :class:`SummaryRow`, ``summary.md``),
:mod:`.generic` (:func:`report_runs`), :mod:`.paper` (:func:`report_studies`:
the paper's values and their comparison).
"""

from __future__ import annotations

from .generic import report_runs
from .paper import report_studies
from .summary import Report, SummaryRow, check_out_dir, format_summary, write_summary_json

__all__ = ["Report", "SummaryRow", "check_out_dir", "format_summary", "report_runs", "report_studies",
           "write_summary_json"]
