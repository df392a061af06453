"""Index conventions of the constellation: satellites, MOSAs and links.

Satellites are numbered i = 1, 2, 3 as in Table I of the reference paper.
For satellite i, ``(i, j, k)`` is the *even* permutation of (1, 2, 3):
(1, 2, 3), (2, 3, 1), (3, 1, 2).  With the unit vectors n_ij, n_ik from i
towards j and k, the satellite frame has Z_S = n_ij x n_ik / sin(alpha_i)
(the same normal for all three satellites), X_S on the bisector of n_ij and
n_ik.  MOSA 1 (optical assembly OA_1) is X_S rotated by +theta/2 about Z_S,
which brings it onto n_ik: it faces satellite k; MOSA 2 is X_S rotated by
-theta/2 and faces satellite j (theta = angle between the two beams).
``tests/test_pointing.py`` checks this rotation sense numerically.

The tables at the end of this module are the single source of these
conventions for array code: numpy modules index with them and the compiled
kernels read them as constants (numba freezes global arrays at compile time),
so a sign or an order is written once.

Links are the six one-way laser links in the LISA order 12, 23, 31, 13, 32,
21; link ``ab`` is received on satellite a (receiver) and emitted by
satellite b (emitter).  Array layouts used by :mod:`tqdyn.constellation`:

* per satellite: axis of length 3 in the order Sat 1, 2, 3 (``Sat.index``);
* per MOSA: axes (3, 2) = (satellite, MOSA 1/2) (``Mosa.index``);
* per link: axis of length 6 in the LISA order (``Link.index``).
"""

from __future__ import annotations

from enum import IntEnum

import numpy as np

__all__ = [
    "EMITTER_OF_MOSA",
    "LINKS",
    "LINK_EMITTER",
    "LINK_EMITTER_MOSA",
    "LINK_IJ",
    "LINK_IK",
    "LINK_OF_MOSA",
    "LINK_RECEIVER",
    "LINK_RECEIVER_MOSA",
    "MOSAS",
    "MOSA_OF_LINK",
    "MOSA_SIGN",
    "PARTNERS",
    "SATS",
    "Link",
    "Mosa",
    "Sat",
]


class Sat(IntEnum):
    """Satellite index i = 1, 2, 3 (Table I of the paper)."""

    S1 = 1
    S2 = 2
    S3 = 3

    @property
    def index(self) -> int:
        """0-based position along a satellite axis (i - 1)."""
        return int(self) - 1

    @property
    def j(self) -> Sat:
        """Second element of the even permutation (i, j, k): i + 1 (cyclic)."""
        return Sat(int(self) % 3 + 1)

    @property
    def k(self) -> Sat:
        """Third element of the even permutation (i, j, k): i + 2 (cyclic)."""
        return Sat((int(self) + 1) % 3 + 1)

    @property
    def partners(self) -> tuple[Sat, Sat]:
        """(j, k): the two remote satellites in even-permutation order."""
        return self.j, self.k

    def mosa_facing(self, remote: Sat) -> Mosa:
        """The MOSA of this satellite that faces ``remote`` (k -> MOSA 1, j -> MOSA 2)."""
        remote = Sat(remote)
        if remote == self.k:
            return Mosa.OA1
        if remote == self.j:
            return Mosa.OA2
        raise ValueError(f"satellite {int(remote)} is not remote from satellite {int(self)}")

    def link_from(self, emitter: Sat) -> Link:
        """The link received on this satellite and emitted by ``emitter``."""
        return Link(10 * int(self) + int(Sat(emitter)))


class Mosa(IntEnum):
    """MOSA (optical assembly, test mass) l = 1, 2 of a satellite.

    OA_1 = X_S rotated by +theta/2 about Z_S: faces satellite k;
    OA_2 = X_S rotated by -theta/2 about Z_S: faces satellite j.
    """

    OA1 = 1
    OA2 = 2

    @property
    def index(self) -> int:
        """0-based position along a MOSA axis (l - 1)."""
        return int(self) - 1

    @property
    def sign(self) -> int:
        """Rotation sense of X_OA from X_S about Z_S: +1 for OA_1, -1 for OA_2
        (the MOSA angle is sign * theta / 2)."""
        return 1 if self is Mosa.OA1 else -1

    def remote(self, sat: Sat) -> Sat:
        """The remote satellite this MOSA of satellite ``sat`` faces."""
        sat = Sat(sat)
        return sat.k if self is Mosa.OA1 else sat.j

    def link(self, sat: Sat) -> Link:
        """The link received by this MOSA of satellite ``sat``."""
        return Sat(sat).link_from(self.remote(sat))

    @property
    def other(self) -> Mosa:
        """The other MOSA of the same satellite."""
        return Mosa.OA2 if self is Mosa.OA1 else Mosa.OA1


_LINK_ORDER = (12, 23, 31, 13, 32, 21)


class Link(IntEnum):
    """One-way link ab: received on satellite a, emitted by satellite b.

    Iteration order (and ``.index``) is the LISA order 12, 23, 31, 13, 32, 21.
    """

    L12 = 12
    L23 = 23
    L31 = 31
    L13 = 13
    L32 = 32
    L21 = 21

    @property
    def index(self) -> int:
        """0-based position along a link axis (LISA order)."""
        return _LINK_ORDER.index(int(self))

    @property
    def receiver(self) -> Sat:
        """Receiving (local) satellite a."""
        return Sat(int(self) // 10)

    @property
    def emitter(self) -> Sat:
        """Emitting (distant) satellite b."""
        return Sat(int(self) % 10)

    @property
    def local(self) -> Sat:
        """Alias of :attr:`receiver`."""
        return self.receiver

    @property
    def distant(self) -> Sat:
        """Alias of :attr:`emitter`."""
        return self.emitter

    @property
    def reverse(self) -> Link:
        """The link in the opposite direction (ab -> ba)."""
        return Link(10 * int(self.emitter) + int(self.receiver))

    @property
    def mosa(self) -> Mosa:
        """The MOSA of the receiver that faces the emitter."""
        return self.receiver.mosa_facing(self.emitter)


SATS: tuple[Sat, ...] = tuple(Sat)
MOSAS: tuple[Mosa, ...] = tuple(Mosa)
LINKS: tuple[Link, ...] = tuple(Link)

#: (3, 2) int array: LINK_OF_MOSA[i-1, l-1] = link index received by MOSA l of satellite i.
LINK_OF_MOSA = np.array([[m.link(s).index for m in MOSAS] for s in SATS], dtype=np.intp)
#: (6, 2) int array: MOSA_OF_LINK[link.index] = (satellite index, MOSA index) receiving it.
MOSA_OF_LINK = np.array([[ln.receiver.index, ln.mosa.index] for ln in LINKS], dtype=np.intp)

#: (2,) float64: rotation sense of X_OA_l from X_S about Z_S, MOSA_SIGN[l-1] =
#: ``Mosa.sign``: the MOSA angle of OA_l is MOSA_SIGN[l-1] * theta / 2, its rates
#: MOSA_SIGN[l-1] * theta_dot / 2 and MOSA_SIGN[l-1] * theta_ddot / 2.
MOSA_SIGN = np.array([float(m.sign) for m in MOSAS])
#: (3, 2) int array: PARTNERS[i-1] = 0-based indices of (j, k), the even permutation of satellite i.
PARTNERS = np.array([[s.j.index, s.k.index] for s in SATS], dtype=np.intp)
#: (3, 2) int array: EMITTER_OF_MOSA[i-1, l-1] = 0-based index of the satellite MOSA l of satellite i faces.
EMITTER_OF_MOSA = np.array([[m.remote(s).index for m in MOSAS] for s in SATS], dtype=np.intp)
#: (6,) int arrays over the links (LISA order): 0-based receiver / emitter satellite indices.
LINK_RECEIVER = np.array([ln.receiver.index for ln in LINKS], dtype=np.intp)
LINK_EMITTER = np.array([ln.emitter.index for ln in LINKS], dtype=np.intp)
#: (6,) int arrays over the links: 0-based MOSA of the receiver that faces the emitter, and of the
#: emitter that faces the receiver (the TMs at the two ends of the link).
LINK_RECEIVER_MOSA = np.array([ln.receiver.mosa_facing(ln.emitter).index for ln in LINKS], dtype=np.intp)
LINK_EMITTER_MOSA = np.array([ln.emitter.mosa_facing(ln.receiver).index for ln in LINKS], dtype=np.intp)
#: (3,) int arrays: link index of i -> j and i -> k for each satellite i (links 12, 23, 31 and 13, 21, 32).
LINK_IJ = np.array([Link(10 * int(s) + int(s.j)).index for s in SATS], dtype=np.intp)
LINK_IK = np.array([Link(10 * int(s) + int(s.k)).index for s in SATS], dtype=np.intp)

for _table in (LINK_OF_MOSA, MOSA_OF_LINK, MOSA_SIGN, PARTNERS, EMITTER_OF_MOSA, LINK_RECEIVER, LINK_EMITTER,
               LINK_RECEIVER_MOSA, LINK_EMITTER_MOSA, LINK_IJ, LINK_IK):
    _table.setflags(write=False)
del _table
