"""Numerics: double-double arithmetic (:mod:`.dd`), 3-vector helpers for the
compiled kernels (:mod:`.vec3`), the kernel cache (:mod:`.jit`), the DP87
integrator (:mod:`.dp87`, tableau in :mod:`._dp87_tableau`), Hermite dense
output (:mod:`.hermite`) and the one test of "a finite number" for values read
from files (:mod:`.finite`)."""
