"""Trajectory files: the public HDF5 output format of tqdyn (I/O only).

This package writes and reads the ``tqdyn-trajectory`` HDF5 format, version
:data:`FORMAT_VERSION`.  It is pure I/O: it imports no physics module and no
physics module imports it.  The format is documented field by field in
``docs/trajectory-format.md``; :data:`FIELDS` is its machine-readable form.

Conventions (for every field, see :data:`FIELDS` for each one's unit/frame)
--------------------------------------------------------------------------
* Units: SI (m, m/s, m/s^2, rad, rad/s, rad/s^2, s).
* Time scale: the root attribute ``time_scale`` (TT for the geocentric
  system).  Times ``t`` are seconds since the root attribute ``epoch_utc``
  (the epoch is *labelled* in UTC, ISO 8601).  Format version 1 files say
  ``"TDB"``: their t is TT-elapsed seconds labelled TDB (the ephemerides of
  tqdyn 0.1 were read at TDB(epoch) + t).
* Frame: GCRS for inertial vectors; body frame S for the angular velocity;
  the optical-assembly frame OA_l for test-mass quantities.
* Shapes: ``[time, satellite, tm, component]``; the satellite axis has length
  ``n_sat`` (3 for coupled runs; point-mass runs any number >= 1), the
  test-mass (= MOSA) axis length 2, components x, y, z.
* Double-double ("dd") fields are HDF5 groups holding two float64 datasets
  ``hi`` and ``lo`` of equal shape; the value is the unevaluated sum
  ``hi + lo``.  "f8" fields are a single float64 dataset.

Writing is atomic: :class:`TrajectoryWriter` writes to a hidden temporary file
in the destination directory and renames it into place on :meth:`close`; on any
failure (including ``KeyboardInterrupt``) the temporary file is removed and the
destination is left untouched.

Modules: :mod:`~tqdyn.formats.trajectory.schema` (format identity, field
catalogue, root attributes, errors), :mod:`~tqdyn.formats.trajectory.writer`
(:func:`check_writable`, :class:`TrajectoryWriter`) and
:mod:`~tqdyn.formats.trajectory.reader` (:func:`read_trajectory`,
:class:`Trajectory`).  Their public names are re-exported here.
"""

from . import reader, schema, writer
from .reader import *  # noqa: F401,F403
from .schema import *  # noqa: F401,F403
from .writer import *  # noqa: F401,F403

__all__ = schema.__all__ + writer.__all__ + reader.__all__
