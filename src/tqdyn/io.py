"""Trajectory files under their version-0.1 import path ``tqdyn.io``.

Kept so that users' scripts written for tqdyn 0.1 (``from tqdyn.io import
read_trajectory``) keep working.  The format lives in
:mod:`tqdyn.formats.trajectory`; this module only re-exports its public
names (the same objects, so ``tqdyn.io.OutputError is
tqdyn.formats.trajectory.OutputError``).
"""

from .formats.trajectory import (
    FIELDS,
    FORMAT,
    FORMAT_VERSION,
    ROOT_ATTRS,
    FieldSpec,
    OutputError,
    Trajectory,
    TrajectoryFormatError,
    TrajectoryWriter,
    check_writable,
    read_trajectory,
)

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "FieldSpec",
    "FIELDS",
    "ROOT_ATTRS",
    "OutputError",
    "TrajectoryFormatError",
    "check_writable",
    "TrajectoryWriter",
    "Trajectory",
    "read_trajectory",
]
