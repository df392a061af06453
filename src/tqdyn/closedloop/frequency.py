"""Many closed loops at once: the loops of a run (every spacecraft and segment) built, checked and evaluated
in the frequency domain as stacked arrays (docs/closed-loop.md).

A closed loop (:func:`tqdyn.closedloop.loop.build_closed_loop`) joins the linearised plant (second order in its
20 coordinates q: q'' = Kq q + Gq q' + Bq u; outputs y = Cq q + Cv q' + Dp u), static sensors
e = Sy y + Sw w, one SISO controller per channel c = K(s) e, static actuators u = Ac c + Ad d + Aw w and
static observables z = Oy y + Ou u (w the noise inputs, d the loop breaks, z the outputs of
:data:`tqdyn.closedloop.loop.OUTPUTS`).  The sensors read coordinates only (Sy Dp = 0: no algebraic loop).

* :func:`stack_loops` collects these blocks for many working points (``LoopStack``, a first axis over the
  loops) and :func:`closed_loop_matrices` joins them into the closed loops' state-space matrices (the plant's
  40 states, then the controllers'; inputs w then d; outputs z, then c, then
  the in-loop coordinates e), the same matrices as
  python-control's ``interconnect`` of the named blocks, without its per-loop numerical linearisation.
* :func:`noise_asd` and :func:`loop_gains` evaluate the closed loops at s = i 2 pi f without their
  74 states: eliminating u, y, e and c leaves one 20 x 20 complex system per loop and frequency,

      [s^2 I - s Gq - Kq - Bq Ac K(s) Sy (Cq + s Cv)] q = Bq (Ac K(s) Sw + Aw) w + Bq Ad d,

  solved by LAPACK (``numpy.linalg.solve``, partial pivoting) batched over loops and frequencies, in the
  plant's own coordinates.  The plant outputs that are second derivatives of a coordinate (the TMs'
  relative accelerations x_l'', rows of the plant's C, D equal to rows of its A, B) are taken as s^2 q:
  no cancellation of large terms at low frequencies.  The controllers' terms P diag(K(s)) S are one matrix
  product over all frequencies, in blocks small enough that BLAS keeps them on one thread.  The outputs are
  z = W(s) q + (direct terms), W (46 x 20) built per loop and frequency: one stacked matrix product, a few
  dozen frequencies of one loop at a time (arrays of a few MB).

Units SI; frequencies in Hz, s in rad/s; ASDs one-sided in (output unit)/Hz^1/2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..scenario.closed_loop import ATTITUDE_Z_SENSORS, check_controller
from ..scenario.closed_loop import SCHEME_LOOPS
from .loop import SOURCES, ClosedLoop, channel_names, controller_realisations, loop_blocks, output_names, \
    source_inputs

__all__ = ["LoopStack", "NOISE_INPUTS", "STACKED_SCHEMES", "closed_loop_matrices", "closed_loops",
           "controller_response", "loop_gains", "noise_asd", "rows_product", "stack_loops", "unstable_loops"]

#: The noise inputs w of a closed loop, in order (sources of :data:`SOURCES`, their components).
NOISE_INPUTS = tuple(s for src in SOURCES for s in source_inputs(src))
#: Control schemes whose sensors read only plant outputs and noise (e = Sy y + Sw w), the form this module
#: stacks.  "single_tm" is not one: its drag-free error is the suspension controller's output (TianQin-1's
#: accelerometer mode), so its loops are built one at a time (build_closed_loop) and its budget takes the
#: per-loop path (tqdyn.closedloop.budget.noise_budget).
STACKED_SCHEMES = ("constellation", "collinear")
#: Complex numbers held at once per evaluation chunk (bounds the memory: 16 bytes each).
_CHUNK_ELEMENTS = 1_500_000
#: Complex numbers of one loop's transfer functions evaluated at once by :func:`noise_asd` (a few MB, so that its
#: arrays stay in the processor's caches).
_BLOCK_ELEMENTS = 250_000
#: Complex multiply-adds of one matrix product that OpenBLAS runs on one thread (measured: its zgemm threads at
#: 5e4 multiply-adds, not at 2e4).
_BLAS_SINGLE = 20_000


@dataclass(frozen=True)
class LoopStack:
    """The blocks of n closed loops (module docstring), real arrays stacked along a first axis of length n.

    plant : (A (n, 40, 40), B (n, 40, 32), C (n, 32, 40), D (n, 32, 32)), states [q, q'].
    Sy (n, 17, 32), Sw (n, 17, 58); Ac, Ad (n, 32, 17), Aw (n, 32, 58); Oy, Ou (n, 46, 32).
    derivative : ((plant output j, coordinate k), ...): y_j = q_k''.
    controllers : per channel the realisation (A, B, C, D); zpk : per channel (zeros, poles, gain) [rad/s].
    dc_force : per loop the ``dc_force`` of :class:`~tqdyn.closedloop.loop.ClosedLoop`.
    plant_names : (inputs, outputs, states) of the plant; channels : :func:`~tqdyn.closedloop.loop.channel_names`.
    """

    plant: tuple
    Sy: np.ndarray
    Sw: np.ndarray
    Ac: np.ndarray
    Ad: np.ndarray
    Aw: np.ndarray
    Oy: np.ndarray
    Ou: np.ndarray
    derivative: tuple
    controllers: tuple
    zpk: tuple
    dc_force: list
    plant_names: tuple
    channels: tuple

    def __len__(self) -> int:
        return self.Sy.shape[0]


def _columns(D, names, wanted) -> np.ndarray:
    """The columns of ``D`` (rows x len(names)) for the signal names ``wanted`` (zero for names not there)."""
    idx = {s: k for k, s in enumerate(names)}
    out = np.zeros((D.shape[0], len(wanted)))
    for j, s in enumerate(wanted):
        if s in idx:
            out[:, j] = D[:, idx[s]]
    return out


def _rows(D, names, wanted) -> np.ndarray:
    idx = {s: k for k, s in enumerate(names)}
    return D[[idx[s] for s in wanted]]


def stack_loops(parts, controllers: dict, attitude_z_sensor: str = ATTITUDE_Z_SENSORS[0],
                scheme: str = "constellation") -> LoopStack:
    """The :class:`LoopStack` of the closed loops of ``parts`` (a sequence of (PlantParameters, WorkingPoint))
    with the ``controllers`` ({loop: Controller}), the attitude-z sensor and the control ``scheme``
    (``loop_blocks``; one of :data:`STACKED_SCHEMES`).  ValueError (one line) otherwise."""
    if scheme not in STACKED_SCHEMES:
        raise ValueError(f"closed_loop.scheme: {scheme!r} has sensors reading controller outputs; allowed here: "
                         f"{', '.join(STACKED_SCHEMES)} (build its loops one at a time: build_closed_loop)")
    loops = SCHEME_LOOPS[scheme]
    chans = channel_names(scheme)
    E, Cn, Dn = [f"e_{c}" for c in chans], [f"c_{c}" for c in chans], [f"d_{c}" for c in chans]
    outs = output_names()
    keys = ("A", "B", "C", "D", "Sy", "Sw", "Ac", "Ad", "Aw", "Oy", "Ou")
    acc = {k: [] for k in keys}
    dc, names = [], None
    for p, wp in parts:
        b = loop_blocks(p, wp, attitude_z_sensor, scheme)
        A, B, C, D, pin, pout, pst = b["plant"]
        names = (tuple(pin), tuple(pout), tuple(pst))
        sD, sin, sout = b["sensors"]
        sD = _rows(sD, sout, E)
        if np.any(_columns(sD, sin, [s for s in sin if s not in pout and s not in NOISE_INPUTS])):
            raise ValueError("closed loop: a sensor reads a signal that is neither a plant output nor a noise input")
        aD, ain, aout = b["actuators"]
        aD = _rows(aD, aout, pin)
        oD, oin, oout = b["observables"]
        oD = _rows(oD, oout, outs)
        for k, v in zip(keys, (A, B, C, D, _columns(sD, sin, pout), _columns(sD, sin, NOISE_INPUTS),
                               _columns(aD, ain, Cn), _columns(aD, ain, Dn), _columns(aD, ain, NOISE_INPUTS),
                               _columns(oD, oin, pout), _columns(oD, oin, pin))):
            acc[k].append(v)
        dc.append(b["dc_force"])
    st = {k: np.array(v) for k, v in acc.items()}
    n = st["A"].shape[1] // 2
    A, B, C, D = st["A"][0], st["B"][0], st["C"][0], st["D"][0]
    deriv = tuple((j, k) for j in range(C.shape[0]) for k in range(n)
                  if np.any(C[j]) and np.array_equal(C[j], A[n + k]) and np.array_equal(D[j], B[n + k])
                  and all(np.array_equal(st["C"][i, j], st["A"][i, n + k]) for i in range(len(st["A"]))))
    if np.any(np.einsum("sij,sjk->sik", st["Sy"], st["D"])):
        raise ValueError("closed loop: a sensor reads a plant output with direct feed-through (an algebraic loop)")
    zpk = []
    realisations = tuple(controller_realisations(controllers, loops))
    for loop, (channels, *_r) in loops.items():
        c = controllers[loop]
        zpk += [check_controller(c.name, list(c.zeros), list(c.poles), c.gain)] * len(channels)
    return LoopStack(plant=(st["A"], st["B"], st["C"], st["D"]), Sy=st["Sy"], Sw=st["Sw"], Ac=st["Ac"], Ad=st["Ad"],
                     Aw=st["Aw"], Oy=st["Oy"], Ou=st["Ou"], derivative=deriv,
                     controllers=realisations, zpk=tuple(zpk), dc_force=dc,
                     plant_names=names, channels=tuple(chans))


def _block_diag(mats) -> np.ndarray:
    r = sum(m.shape[0] for m in mats)
    c = sum(m.shape[1] for m in mats)
    out = np.zeros((r, c))
    i = j = 0
    for m in mats:
        out[i:i + m.shape[0], j:j + m.shape[1]] = m
        i, j = i + m.shape[0], j + m.shape[1]
    return out


def closed_loop_matrices(st: LoopStack) -> tuple:
    """The closed loops' state-space matrices A (n, nx, nx), B (n, nx, 58 + nc), C (n, 46 + 2 nc, nx),
    D (n, 46 + 2 nc, 58 + nc), nc the channels (17 for "constellation") (module docstring; the plant's states,
    then each channel's controller states; outputs z, c, e)."""
    AP, BP, CP, DP = st.plant
    Ak, Bk, Ck, Dk = (_block_diag([c[i] for c in st.controllers]) for i in range(4))
    mm = np.matmul
    SC = mm(st.Sy, CP)                                            # e = SC xP + Sw w
    Uxp = mm(st.Ac, mm(Dk, SC))                                   # u = Uxp xP + Uxc xc + Uw w + Ad d
    Uxc = mm(st.Ac, Ck)
    Uw = mm(st.Ac, mm(Dk, st.Sw)) + st.Aw
    Zu = mm(st.Oy, DP) + st.Ou                                    # z = Oy CP xP + Zu u
    n, nk, nw, nd = len(st), Ak.shape[0], st.Sw.shape[2], st.Ad.shape[2]
    A = np.concatenate([np.concatenate([AP + mm(BP, Uxp), mm(BP, Uxc)], axis=2),
                        np.concatenate([mm(Bk, SC), np.broadcast_to(Ak, (n, nk, nk))], axis=2)], axis=1)
    B = np.concatenate([np.concatenate([mm(BP, Uw), mm(BP, st.Ad)], axis=2),
                        np.concatenate([mm(Bk, st.Sw), np.zeros((n, nk, nd))], axis=2)], axis=1)
    ne = SC.shape[1]
    C = np.concatenate([np.concatenate([mm(st.Oy, CP) + mm(Zu, Uxp), mm(Zu, Uxc)], axis=2),
                        np.concatenate([mm(Dk, SC), np.broadcast_to(Ck, (n,) + Ck.shape)], axis=2),
                        np.concatenate([SC, np.zeros((n, ne, nk))], axis=2)], axis=1)
    D = np.concatenate([np.concatenate([mm(Zu, Uw), mm(Zu, st.Ad)], axis=2),
                        np.concatenate([mm(Dk, st.Sw), np.zeros((n, Dk.shape[0], nd))], axis=2),
                        np.concatenate([st.Sw, np.zeros((n, ne, nd))], axis=2)], axis=1)
    return A, B, C, D


def closed_loops(st: LoopStack, matrices=None) -> list[ClosedLoop]:
    """One named :class:`~tqdyn.closedloop.loop.ClosedLoop` per loop of ``st`` (the signal and state names of
    :func:`~tqdyn.closedloop.loop.build_closed_loop`); ``matrices``: :func:`closed_loop_matrices` if computed."""
    import control

    A, B, C, D = closed_loop_matrices(st) if matrices is None else matrices
    chans = list(st.channels)
    inputs = list(NOISE_INPUTS) + [f"d_{c}" for c in chans]
    outputs = output_names() + [f"c_{c}" for c in chans] + [f"e_{c}" for c in chans]
    states = [f"plant_{s}" for s in st.plant_names[2]]
    for c, (a, *_r) in zip(chans, st.controllers):
        states += [f"C_{c.replace('[', '_').rstrip(']')}_x[{i}]" for i in range(a.shape[0])]
    return [ClosedLoop(system=control.ss(A[i], B[i], C[i], D[i], inputs=inputs, outputs=outputs, states=states,
                                         name="closed_loop"), channel_names=tuple(chans), dc_force=st.dc_force[i])
            for i in range(len(st))]


def unstable_loops(A, states, tol: float = 1e-9) -> np.ndarray:
    """Indices of the closed loops (A (n, nx, nx)) with a pole of Re > ``tol`` x max(1, |poles|), leaving out
    the spacecraft's displacement from its orbit (the states ``plant_u[.]``, ``plant_du[.]`` of ``states``:
    free and Hill modes no loop controls), as :func:`tqdyn.closedloop.budget.check_stable`."""
    keep = [k for k, s in enumerate(states) if not (s.startswith("plant_u[") or s.startswith("plant_du["))]
    ev = np.linalg.eigvals(np.asarray(A)[:, keep][:, :, keep])
    scale = np.maximum(1.0, np.max(np.abs(ev), axis=1))
    return np.nonzero(np.max(ev.real, axis=1) > tol * scale)[0]


def controller_response(st: LoopStack, s) -> np.ndarray:
    """K(s) (n_channel, n_s) of every channel's controller at the complex frequencies ``s`` [rad/s]."""
    s = np.asarray(s)
    out = []
    for z, p, k in st.zpk:
        num = np.prod(s[:, None] - np.asarray(z, dtype=complex)[None, :], axis=1) if len(z) else np.ones(len(s))
        den = np.prod(s[:, None] - np.asarray(p, dtype=complex)[None, :], axis=1) if len(p) else np.ones(len(s))
        out.append(k * num / den)
    return np.array(out)


def _parts(st: LoopStack, idx):
    """The second-order pieces of the loops ``idx`` (module docstring): Kq, Gq, Bq, Cq, Cv, C2 (the
    derivative outputs' selector), Dp (derivative rows zeroed)."""
    A, B, C, D = (m[idx] for m in st.plant)
    n = A.shape[1] // 2
    Cq, Cv, Dp = C[:, :, :n].copy(), C[:, :, n:].copy(), D.copy()
    C2 = np.zeros_like(Cq)
    for j, k in st.derivative:
        Cq[:, j], Cv[:, j], Dp[:, j] = 0.0, 0.0, 0.0
        C2[:, j, k] = 1.0
    return A[:, n:, :n], A[:, n:, n:], B[:, n:], Cq, Cv, C2, Dp


def _chunks(n_loops: int, per_loop: int):
    size = max(1, _CHUNK_ELEMENTS // max(1, per_loop))
    for a in range(0, n_loops, size):
        yield range(a, min(n_loops, a + size))


def _columns_product(A, B) -> np.ndarray:
    """A B for A (k, r, c) and B (c, n), in blocks of B's columns small enough (<= :data:`_BLAS_SINGLE` multiply-adds)
    that BLAS runs each on one thread: on a machine shared with other jobs a threaded product of these sizes waits
    for its threads far longer than it computes."""
    k, r, c = A.shape
    n = max(1, _BLAS_SINGLE // max(1, r * c))
    out = np.empty((k, r, B.shape[1]), dtype=np.result_type(A, B))
    for a in range(0, B.shape[1], n):
        out[:, :, a:a + n] = np.matmul(A, B[:, a:a + n])
    return out


def rows_product(A, B) -> np.ndarray:
    """A B for stacked A (..., r, c) and B (..., c, n) (numpy's broadcasting), in blocks of A's rows small enough
    (<= :data:`_BLAS_SINGLE` multiply-adds) that BLAS runs each on one thread (:func:`_columns_product`)."""
    r, c = A.shape[-2:]
    m = max(1, _BLAS_SINGLE // max(1, c * B.shape[-1]))
    out = np.empty(np.broadcast_shapes(A.shape[:-2], B.shape[:-2]) + (r, B.shape[-1]), dtype=np.result_type(A, B))
    for a in range(0, r, m):
        np.matmul(A[..., a:a + m, :], B, out=out[..., a:a + m, :])
    return out


def _kmul(P, S, Ks, out) -> np.ndarray:
    """``out`` (k, F, a, b) complex plus P diag(K(s)) S for real P (k, a, 17), S (k, 17, b) and K(s) ``Ks``
    (17, F), in place and returned: the real products P_ic S_cj (one matrix per loop), then over their nonzero
    entries shared by the k loops one matrix product with K(s) over all frequencies (:func:`_columns_product`)."""
    k, a, nc = P.shape
    b = S.shape[2]
    PS = (P[:, :, None, :] * np.moveaxis(S, 1, 2)[:, None, :, :]).reshape(k, a * b, nc)
    rows = np.flatnonzero(np.any(PS != 0, axis=(0, 2)))
    if len(rows):
        y = _columns_product(PS[:, rows].astype(complex), np.asarray(Ks, dtype=complex))
        flat = out.reshape(k, Ks.shape[1], a * b)
        flat[:, :, rows] += np.moveaxis(y, 2, 1)
    return out


def _powers(terms, s, shape) -> np.ndarray:
    """sum_p s^p L_p (k, F, a, b) complex over the (L_p, p) of ``terms`` (real L_p (k, a, b), zero ones left out)
    at ``s`` (F,)."""
    out = np.zeros(shape, dtype=complex)
    for L, power in terms:
        if np.any(L):
            out += L[:, None] if power == 0 else L[:, None] * (s ** power)[None, :, None, None]
    return out


def _solve(st: LoopStack, idx, s, Ks, breaks: bool):
    """q (k, F, 20, m) of the loops ``idx`` at ``s`` (F,) [rad/s] with K(s) ``Ks`` (17, F) for the noise inputs
    (m = 58) or, with ``breaks``, the loop breaks (m = 17); and the pieces: the sensors' terms
    [(Sy Cq, 0), (Sy Cv, 1), (Sy C2, 2)] and :func:`_parts`."""
    pieces = _parts(st, idx)
    Kq, Gq, Bq, Cq, Cv, C2, _Dp = pieces
    nq = Kq.shape[1]
    Sy = st.Sy[idx]
    sens = [(np.matmul(Sy, Cq), 0), (np.matmul(Sy, Cv), 1), (np.matmul(Sy, C2), 2)]
    sF = s[None, :, None, None]
    Pbar = np.matmul(Bq, st.Ac[idx])
    M = sF ** 2 * np.eye(nq) - sF * Gq[:, None] - Kq[:, None]
    for L, power in sens:
        if np.any(L):
            _kmul(-Pbar, L, Ks * s[None, :] ** power, M)
    shape = M.shape[:2] + (nq, st.Ad.shape[2] if breaks else st.Sw.shape[2])
    if breaks:
        rhs = np.broadcast_to(np.matmul(Bq, st.Ad[idx])[:, None], shape).astype(complex)
    else:
        rhs = _kmul(Pbar, st.Sw[idx], Ks, np.broadcast_to(np.matmul(Bq, st.Aw[idx])[:, None], shape).astype(complex))
    return np.linalg.solve(M, rhs), sens, pieces


def _response(st: LoopStack, idx, f, Ks=None) -> np.ndarray:
    """:func:`noise_response` with the frequency second: (k, F, 46, 58).  Eliminating c and u, the outputs are
    z = W(s) q + Zu (Ac K(s) Sw + Aw) w with Zu = Oy Dp + Ou and W(s) = Oy (Cq + s Cv + s^2 C2)
    + Zu Ac K(s) Sy (Cq + s Cv + s^2 C2): W is built per loop and frequency (46 x 20) and multiplied with the
    solves q (20 x 58) in one stacked matrix product; the direct terms are added on their nonzero pattern.
    ``Ks``: :func:`controller_response` at ``f`` if computed."""
    idx = np.atleast_1d(np.asarray(idx))
    s = 2j * math.pi * np.asarray(f, dtype=np.float64)
    Ks = controller_response(st, s) if Ks is None else Ks
    q, sens, (_Kq, _Gq, _Bq, Cq, Cv, C2, Dp) = _solve(st, idx, s, Ks, False)
    Oy = st.Oy[idx]
    Zu = np.matmul(Oy, Dp) + st.Ou[idx]
    ZuAc = np.matmul(Zu, st.Ac[idx])
    k, F, nq, m = q.shape
    W = _powers([(np.matmul(Oy, Cq), 0), (np.matmul(Oy, Cv), 1), (np.matmul(Oy, C2), 2)], s, (k, F, Oy.shape[1], nq))
    for L, power in sens:
        if np.any(L):
            _kmul(ZuAc, L, Ks * s[None, :] ** power, W)
    z = _kmul(ZuAc, st.Sw[idx], Ks, rows_product(W, q))
    ZuAw = np.matmul(Zu, st.Aw[idx])
    r, c = np.nonzero(np.any(ZuAw != 0, axis=0))
    z[:, :, r, c] += ZuAw[:, None, r, c]
    return z


def noise_response(st: LoopStack, idx, f) -> np.ndarray:
    """The closed-loop transfer functions G (k, 46, 58, F) from the noise inputs (:data:`NOISE_INPUTS`) to the
    outputs (:func:`~tqdyn.closedloop.loop.output_names`) of the loops ``idx`` at ``f`` (F,) [Hz]."""
    return np.moveaxis(_response(st, idx, f), 1, 3)


def noise_asd(st: LoopStack, idx, noise: dict, f) -> tuple[np.ndarray, list]:
    """ASD (k, 46, n_source, F) of every output from every source of ``noise`` ({source: AsdModel}) for the
    loops ``idx`` at ``f`` [Hz] (the components of a source summed in power), and the source names."""
    f = np.asarray(f, dtype=np.float64)
    sources = [s for s in SOURCES if s in noise]
    idx = np.atleast_1d(np.asarray(idx))
    starts = np.cumsum([0] + [SOURCES[src][0] for src in SOURCES])[:-1]
    pick = [list(SOURCES).index(src) for src in sources]
    asd = np.array([noise[src].asd(f) for src in sources]).reshape(len(sources), len(f))
    out = np.empty((len(idx), len(output_names()), len(sources), len(f)))
    nf = max(1, _BLOCK_ELEMENTS // (len(output_names()) * len(NOISE_INPUTS)))
    Ks = controller_response(st, 2j * math.pi * f)                                 # the same for every loop
    for j in range(len(idx)):
        for a in range(0, len(f), nf):
            z = _response(st, idx[j:j + 1], f[a:a + nf], Ks[:, a:a + nf])[0].view(np.float64)  # (F, 46, 116): re, im
            z *= z
            ps = np.add.reduceat(z, 2 * starts, axis=2)[..., pick]                  # (F, 46, n_source)
            out[j, :, :, a:a + nf] = np.sqrt(np.moveaxis(ps, 0, 2)) * asd[:, a:a + nf]
    return out, sources


def loop_gains(st: LoopStack, idx, f) -> np.ndarray:
    """Loop-at-a-time gains L (k, 17, F) of every channel of the loops ``idx`` at ``f`` [Hz]: L = -T/(1 + T),
    T the closed-loop transfer from the loop break d_k to the controller output c_k
    (:mod:`tqdyn.closedloop.budget`)."""
    idx = np.atleast_1d(np.asarray(idx))
    s = 2j * math.pi * np.asarray(f, dtype=np.float64)
    Ks = controller_response(st, s)
    out = np.empty((len(idx), len(st.channels), len(s)), dtype=complex)
    for part in _chunks(len(idx), len(s) * 17 * 40):
        sel = idx[list(part)]
        q, sens, _pieces = _solve(st, sel, s, Ks, True)
        T = np.zeros(q.shape[:2] + (q.shape[3],), dtype=complex)                      # (k, F, 17)
        for L, power in sens:
            if np.any(L):
                T += np.einsum("kcj,kfjc->kfc", L, q) * (s ** power)[None, :, None]
        T *= Ks.T[None]
        out[part.start:part.stop] = np.moveaxis(-T / (1.0 + T), 1, 2)
    return out
