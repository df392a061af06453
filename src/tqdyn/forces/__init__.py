"""The force model: one module per term of the paper's Table II, composed in :mod:`.model`.

Every term has the same interface (``name``, ``description``, ``source``,
``params()``, ``n_tdat``, ``precompute(epoch, t_hi, t_lo)`` and a compiled
kernel ``(r, v, tdat, params) -> a``); :func:`tqdyn.forces.model.build_force_model`
builds the scenario's model and :func:`tqdyn.forces.model.gravity` sums it in
the compiled loop.  Coefficient files are read by :mod:`tqdyn.readers`.
"""
