"""Deprecated: the version-0.2 import path of the first-order estimates of the LISA studies.

Kept so that scripts written for tqdyn 0.2 (``from tqdyn.analysis.lisa_estimates import cw_response``)
keep working; importing it warns (DeprecationWarning).  Use :mod:`tqdyn.constellation.estimates`, where
the models live (the analysis measures runs; it computes no dynamical model): this module re-exports
its public names (the same objects).
"""

import warnings

from ..constellation import estimates as _estimates
from ..constellation.estimates import *  # noqa: F401,F403  (the same objects)

__all__ = list(_estimates.__all__)

warnings.warn("tqdyn.analysis.lisa_estimates is deprecated (the import path of tqdyn 0.2): use "
              "tqdyn.constellation.estimates", DeprecationWarning, stacklevel=2)
