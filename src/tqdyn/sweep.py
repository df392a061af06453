"""Deprecated: the version-0.1 import path of parameter sweeps.

Kept so that scripts written for tqdyn 0.1 (``from tqdyn.sweep import
run_sweep``) keep working; importing it warns (DeprecationWarning).  Use
:mod:`tqdyn.workflows.sweep`, where the code lives: this module re-exports
its public names (the same objects).
"""

import warnings

from .workflows import sweep as _sweep
from .workflows.sweep import *  # noqa: F401,F403  (the same objects)

__all__ = list(_sweep.__all__)

warnings.warn("tqdyn.sweep is deprecated (the import path of tqdyn 0.1): use tqdyn.workflows.sweep",
              DeprecationWarning, stacklevel=2)
