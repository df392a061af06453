"""The constellation: indices, geometry, pointing laws, attitude, spacecraft and control.

The numpy modules (``geometry``, ``pointing``, ``attitude``, ``spacecraft``,
``control``) are vectorised over time for analysis and are the references
of the tests; ``_kinematics_jit`` and ``_control_jit`` are their compiled
counterparts used inside the integrator by :mod:`tqdyn.dynamics`.
"""
