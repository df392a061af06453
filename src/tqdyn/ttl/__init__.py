"""Tilt-to-length (physics, no I/O): the coupling of the six links' optical path lengths to the MOSAs'
angle jitter, in LISA Instrument's convention (docs/tilt-to-length.md, docs/lisa-ttl.md).

Modules: :mod:`~tqdyn.ttl.coupling` (the coefficients, constant or time-varying, and the local plus
delayed distant term of each link), :mod:`~tqdyn.ttl.budget` (the links' TTL ASDs from the closed
loop's angle outputs, :mod:`tqdyn.closedloop`), :mod:`~tqdyn.ttl.injection` (the TTL as LISA
Instrument's science-readout injections), :mod:`~tqdyn.ttl.estimation` (one link's coefficients from
its readout) and :mod:`~tqdyn.ttl.estimation_tdi` (the 24 coefficients of the six links, joint and
through TDI).  The package sits above :mod:`tqdyn.closedloop` (docs/design.md, "Layers"): the budget
reads the closed loops, the estimation their ASD models.

The public names of :mod:`~tqdyn.ttl.coupling` (numpy only) are re-exported here; the other modules
are imported by name (the budget imports python-control, which is slow to import).
"""

from .coupling import MOSAS, TTLCoefficients, TimeVaryingTTLCoefficients, link_ttl, mosa_angles, ttl_terms

__all__ = ["MOSAS", "TTLCoefficients", "TimeVaryingTTLCoefficients", "link_ttl", "mosa_angles", "ttl_terms"]
