"""Trajectory files under their version-0.1 import path ``tqdyn.io``.

Kept so that users' scripts written for tqdyn 0.1 (``from tqdyn.io import
read_trajectory``) keep working.  The format lives in
:mod:`tqdyn.formats.trajectory`; this module only re-exports its public
names (the same objects, so ``tqdyn.io.OutputError is
tqdyn.formats.trajectory.OutputError``).
"""

from .formats import trajectory as _trajectory
from .formats.trajectory import *  # noqa: F401,F403  (the same objects)

__all__ = list(_trajectory.__all__)
