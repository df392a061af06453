"""Instantaneous ranges of the six links (no light travel time), in double-double.

Both ends at the same coordinate time t (TT), for comparison with the
light-path ranges c tau of :func:`tqdyn.lightpath.light_time.light_travel_times`;
bodies per link as in :func:`tqdyn.lightpath.light_time.link_bodies`.
"""

from __future__ import annotations

import numpy as np

from ..numerics.dd import np_dd_add, np_dd_sqr, np_dd_sqrt
from .light_time import _dd_input, _layout_of, link_bodies

__all__ = ["instantaneous_ranges"]


def instantaneous_ranges(r) -> tuple[np.ndarray, np.ndarray]:
    """Instantaneous ranges |r_emitter(t) - r_receiver(t)| of the six links, in dd.

    r: dd positions [m], GCRS, of the test masses (N, 3, 2, 3) or of the
    satellite centres (N, 3, 3) (``(hi, lo)`` tuple, trailing axis 2, or
    float64).  Bodies per link as in
    :func:`~tqdyn.lightpath.light_time.link_bodies` (TM facing TM, or centre
    to centre); links ab and ba give the same value.  No light travel time:
    both ends at the same coordinate time t (TT), for comparison with the
    light-path ranges c tau.  Returns (hi, lo), each (N, 6) [m], LISA
    link order.
    """
    rh, rl = _dd_input(r, "r")
    layout = _layout_of(rh.shape, "r")
    rec_h, emit_h = link_bodies(rh, layout)
    rec_l, emit_l = link_bodies(rl, layout)
    dh, dl = np_dd_add(emit_h, emit_l, -rec_h, -rec_l)
    s2h, s2l = np_dd_sqr(dh[..., 0], dl[..., 0])
    for q in (1, 2):
        qh, ql = np_dd_sqr(dh[..., q], dl[..., q])
        s2h, s2l = np_dd_add(s2h, s2l, qh, ql)
    return np_dd_sqrt(s2h, s2l)
