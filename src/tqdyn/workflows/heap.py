"""The process heap of a long run: freed large blocks go back to the system.

glibc's ``malloc`` raises its mmap threshold each time a mapped block is
freed (up to 32 MB on 64-bit), after which the large, short-lived arrays of
a run (the time-only inputs of each block, the rows of each chunk, their
temporaries) come from the heap, where fragmentation keeps them: the
resident set of a coupled TianQin run then sits higher and creeps with the
run (``tqdyn bench --model tianqin-5y`` records the resident set over a
five-year run).  :func:`bound_heap_retention` fixes the threshold at
:data:`MMAP_THRESHOLD_BYTES` (which also stops the adjustment), so that
every block of that size or more is mapped on allocation and unmapped on
free, while the smaller temporaries, the same sizes block after block,
reuse the heap.  Results do not depend on it.  Elsewhere than glibc
(macOS, musl) it does nothing.
"""

from __future__ import annotations

import ctypes
import sys

__all__ = ["MMAP_THRESHOLD_BYTES", "bound_heap_retention"]

#: Blocks of this many bytes or more are mapped: the inputs array of a block
#: (~10 MB for the coupled TianQin model: n_tdat x 13 x 512 x 8 bytes).  Lower
#: thresholds cost CPU in page faults (at 256 KiB the (6656, 3, 3)-sized
#: temporaries of a block are mapped and zeroed anew each time); at 4 MiB the
#: time-only inputs cost the same CPU as with glibc's default.
MMAP_THRESHOLD_BYTES = 4 * 1024 * 1024
_M_MMAP_THRESHOLD = -3  # glibc <malloc.h>
_state = {"done": False}


def bound_heap_retention() -> bool:
    """Fix glibc's mmap threshold at :data:`MMAP_THRESHOLD_BYTES` for this
    process (once; later calls return at once).  Returns True if it took
    effect, False where the C library has no such setting."""
    if _state["done"]:
        return True
    if not sys.platform.startswith("linux"):
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    mallopt.restype = ctypes.c_int
    _state["done"] = mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES) == 1
    return _state["done"]
