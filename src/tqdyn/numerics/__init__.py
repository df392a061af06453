"""Numerics: double-double arithmetic (:mod:`.dd`), 3-vector helpers for the
compiled kernels (:mod:`.vec3`), the kernel cache (:mod:`.jit`), the DP87
integrator (:mod:`.dp87`, tableau in :mod:`._dp87_tableau`) and Hermite dense
output (:mod:`.hermite`)."""
