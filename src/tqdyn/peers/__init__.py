"""Peers: tqdyn's models formulated independently with other libraries, as references for the benchmarks
(``tqdyn bench``) and the tests -- :mod:`.heyoka` (heyoka's Taylor integrator in real128: Kepler problems and
the reduced force model).  A peer imports nothing of tqdyn's physics (only :mod:`tqdyn.numerics`, if anything),
so that comparing with it checks tqdyn against another implementation, and nothing below the workflows uses
it."""
