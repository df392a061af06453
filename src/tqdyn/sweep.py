"""The version-0.1 import path of parameter sweeps, kept for users' scripts
(``from tqdyn.sweep import run_sweep``): the public names of
:mod:`tqdyn.workflows.sweep`, where the code lives."""

from .workflows import sweep as _sweep
from .workflows.sweep import *  # noqa: F401,F403  (the same objects)

__all__ = list(_sweep.__all__)
