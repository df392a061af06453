"""Parameter sweeps: many scenarios run in parallel on Dask (``tqdyn sweep``).

A sweep file (TOML, documented in ``docs/sweeps.md``) names a base scenario,
overrides common to every member and one or more varied parameters::

    [sweep]
    name = "self-gravity-directions"   # default: the sweep file's stem
    scenario = "tianqin"                # built-in name or path (relative: to the sweep file)
    output_dir = "sweep-out"            # default: "<sweep file stem>-out" next to the sweep file
    set = ["run.duration=1d"]           # overrides common to all members
    mode = "product"                    # "product" (grid) | "zip" (parallel lists)

    [[sweep.parameter]]
    key = "spacecraft.self_gravity_common"   # any scenario override key
    values = [[1e-9, 0, 0], [-1e-9, 0, 0]]
    labels = ["+x", "-x"]                # needed for non-scalar values
    name = "direction"                   # coordinate name (default: "self_gravity_common")

Each member is the base scenario + ``set`` + its parameter values (applied
as ``--set`` overrides would be).  Its trajectory file is
``<output_dir>/member-<hash>.h5``, the hash being a short SHA-256 of the
member's resolved scenario TOML (with ``run.output`` normalised): a re-run
skips every member whose file exists, ends at ``run.duration`` and stores
that same resolved scenario; anything else is run again.

Members run as Dask tasks (one task = one :func:`tqdyn.workflows.run.run_to_file`,
quiet, no checkpoint) on a new ``distributed.LocalCluster`` (processes,
1 thread each) or on an existing cluster given by its scheduler address.  A
member that raises does not stop the others; it is reported with its
parameters and a one-line error.

Gathering: one ``xarray.Dataset`` holding every member's
:meth:`tqdyn.formats.trajectory.Trajectory.to_xarray` variables with the varied parameters as
leading dimensions (``product``: one dimension per parameter; ``zip``: one
``member`` dimension with every parameter as a coordinate on it).  Failed
members are **NaN-filled** (never dropped: the grid stays rectangular) and
flagged by the boolean variable ``ok``; ``error`` holds their one-line error.
It is written to ``<output_dir>/<name>.nc`` (netCDF-4/HDF5 through xarray's
``h5netcdf`` engine, or ``netcdf4`` if only that is installed).

Units and conventions are those of the trajectory files: SI, GCRS, time
``time`` in TT seconds since each member's ``epoch_utc``; all members must
share one time grid (checked before anything runs).

Errors in the sweep file raise :class:`SweepError` (a ``ValueError``, one
line) before anything is submitted.

Modules: :mod:`.spec` (the sweep file: :class:`SweepSpec`, :func:`load_sweep`),
:mod:`.plan` (members, :func:`member_done`, :func:`plan_sweep`),
:mod:`.outcome` (:class:`MemberOutcome`), :mod:`.execute` (members on Dask,
:func:`run_sweep`), :mod:`.gathering` (:func:`gather`); the netCDF file is
written by :mod:`.integrity` (Fletcher-32 checksums; :func:`read_sweep_netcdf`
verifies them).
"""

from __future__ import annotations

from ...formats.netcdf import netcdf_engine, write_netcdf
from .execute import (DEFAULT_CONNECT_TIMEOUT, DEFAULT_DASHBOARD, SweepResult, check_dashboard, check_output_dir, connect,
                      dask_client,
                      default_workers, make_security, run_sweep)
from .gathering import gather
from .integrity import SweepFileError, checksum_encoding, read_sweep_netcdf, write_sweep_netcdf
from .outcome import MemberOutcome
from .plan import Member, SweepPlan, member_done, plan_sweep
from .spec import MODES, Parameter, SweepError, SweepSpec, load_sweep, loads_sweep

__all__ = [
    "DEFAULT_CONNECT_TIMEOUT",
    "DEFAULT_DASHBOARD",
    "SweepFileError",
    "check_dashboard",
    "check_output_dir",
    "checksum_encoding",
    "connect",
    "make_security",
    "read_sweep_netcdf",
    "write_sweep_netcdf",
    "MODES",
    "Member",
    "MemberOutcome",
    "Parameter",
    "SweepError",
    "SweepPlan",
    "SweepResult",
    "SweepSpec",
    "default_workers",
    "dask_client",
    "gather",
    "load_sweep",
    "loads_sweep",
    "member_done",
    "netcdf_engine",
    "plan_sweep",
    "run_sweep",
    "write_netcdf",
]
