"""Deprecated: the version-0.1 import path of the trajectory files.

Kept so that scripts written for tqdyn 0.1 (``from tqdyn.io import
read_trajectory``) keep working; importing it warns (DeprecationWarning).
Use :func:`tqdyn.open_trajectory`, or :mod:`tqdyn.formats.trajectory` where
the format lives: this module re-exports its public names (the same objects,
so ``tqdyn.io.OutputError is tqdyn.formats.trajectory.OutputError``).
"""

import warnings

from .formats import trajectory as _trajectory
from .formats.trajectory import *  # noqa: F401,F403  (the same objects)

__all__ = list(_trajectory.__all__)

warnings.warn("tqdyn.io is deprecated (the import path of tqdyn 0.1): use tqdyn.open_trajectory or "
              "tqdyn.formats.trajectory", DeprecationWarning, stacklevel=2)
