"""The version-0.1 import path of parameter sweeps, kept for users' scripts
(``from tqdyn.sweep import run_sweep``): the public names of
:mod:`tqdyn.workflows.sweep`, where the code lives."""

from __future__ import annotations

from .workflows.sweep import (
    MODES,
    Member,
    MemberOutcome,
    Parameter,
    SweepError,
    SweepPlan,
    SweepResult,
    SweepSpec,
    dask_client,
    default_workers,
    gather,
    load_sweep,
    loads_sweep,
    member_done,
    netcdf_engine,
    plan_sweep,
    run_sweep,
    write_netcdf,
)

__all__ = [
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
