"""Keplerian elements <-> Cartesian states in extended precision (mpmath).

All arithmetic is done with mpmath at ``max(50, mp.dps)`` significant digits
(far beyond double-double's ~32), so results converted with :func:`to_dd` are
correctly rounded double-doubles.  Inputs may be ``int``, ``str``,
``decimal.Decimal`` (converted through ``str``, hence exactly), ``float``
(its exact binary value) or ``mpf``; outputs are ``mpf``.

Conventions
-----------
* Units: SI -- a in m, positions in m, velocities in m/s, gm in m^3/s^2,
  times in s; angles in radians unless a function says otherwise.
* Frame: the frame of the elements; in tqdyn the GCRS (geocentric, ICRF
  axes), so i, raan are measured from the ICRF equator and x axis.
* Time: ``t`` is elapsed time (s) since the epoch of the elements; the time
  scale is whatever the caller uses (TT for tqdyn's geocentric runs).
* Two-body problem only, elliptic orbits ``0 <= e < 1``.
"""

from __future__ import annotations

from decimal import Decimal
from numbers import Integral

import mpmath
import numpy as np
from mpmath import mp, mpf

from ..numerics.dd import dd_from_mp as to_dd
from ..numerics.dd import mp_from_pair as from_dd

__all__ = [
    "deg",
    "elements_to_state",
    "state_to_elements",
    "kepler_state_at",
    "to_dd",
    "from_dd",
    "state_to_dd",
]

_MIN_DPS = 50


def _dps() -> int:
    return max(_MIN_DPS, mp.dps)


def _mp(x, name: str = "value") -> mpf:
    """Convert int/str/Decimal/float/mpf (or numpy scalar) to mpf at working precision."""
    if isinstance(x, mpf):
        return x  # kept exactly; arithmetic rounds at the working precision
    if isinstance(x, bool):
        raise TypeError(f"{name}: {x!r} is a bool; expected a number (int, str, Decimal, float or mpf)")
    if isinstance(x, Decimal):
        if not x.is_finite():
            raise ValueError(f"{name}: {x!r} is not finite")
        return mpf(str(x))
    if isinstance(x, (Integral, str, float, np.floating)):
        try:
            v = mpf(x) if not isinstance(x, np.floating) else mpf(float(x))
        except (ValueError, TypeError):
            raise ValueError(f"{name}: {x!r} is not a number") from None
        if not mpmath.isfinite(v):
            raise ValueError(f"{name}: {x!r} is not finite")
        return v
    raise TypeError(f"{name}: {x!r} of type {type(x).__name__}; expected int, str, Decimal, float or mpf")


def _vec(v, name: str) -> list[mpf]:
    try:
        items = list(v)
    except TypeError:
        raise TypeError(f"{name}: expected a sequence of 3 numbers, got {v!r}") from None
    if len(items) != 3:
        raise ValueError(f"{name}: expected 3 components, got {len(items)}")
    return [_mp(c, f"{name}[{k}]") for k, c in enumerate(items)]


def _check_orbit(a: mpf, e: mpf, gm: mpf) -> None:
    if not a > 0:
        raise ValueError(f"a: {a} m; allowed: a > 0 (elliptic orbit)")
    if not (0 <= e < 1):
        raise ValueError(f"e: {e}; allowed: 0 <= e < 1 (elliptic orbit)")
    if not gm > 0:
        raise ValueError(f"gm: {gm} m^3/s^2; allowed: gm > 0")


def deg(x) -> mpf:
    """Degrees -> radians at working precision (>= 50 digits).

    ``x`` may be a str, Decimal or int holding an exact decimal number of
    degrees (e.g. ``"211.6"``), a float or an mpf.  Returns ``x * pi / 180``
    as an mpf.
    """
    with mp.workdps(_dps()):
        return _mp(x, "angle_deg") * mp.pi / 180


def _rotation(i: mpf, raan: mpf, argp: mpf) -> list[list[mpf]]:
    """Columns P, Q, W of R3(-raan) R1(-i) R3(-argp): perifocal -> reference frame."""
    co, so = mp.cos(raan), mp.sin(raan)
    cw, sw = mp.cos(argp), mp.sin(argp)
    ci, si = mp.cos(i), mp.sin(i)
    p = [co * cw - so * sw * ci, so * cw + co * sw * ci, sw * si]
    q = [-co * sw - so * cw * ci, -so * sw + co * cw * ci, cw * si]
    return [p, q]


def _state(a, e, i, raan, argp, nu, gm):
    p = a * (1 - e * e)
    cn, sn = mp.cos(nu), mp.sin(nu)
    rad = p / (1 + e * cn)
    vs = mp.sqrt(gm / p)
    rp = (rad * cn, rad * sn)
    vp = (-vs * sn, vs * (e + cn))
    P, Q = _rotation(i, raan, argp)
    r = [P[k] * rp[0] + Q[k] * rp[1] for k in range(3)]
    v = [P[k] * vp[0] + Q[k] * vp[1] for k in range(3)]
    return r, v


def elements_to_state(a, e, i, raan, argp, nu, gm) -> tuple[list[mpf], list[mpf]]:
    """Keplerian elements -> Cartesian state in the frame of the elements (GCRS in tqdyn).

    Parameters
    ----------
    a : semi-major axis [m] (> 0)
    e : eccentricity [-] (0 <= e < 1)
    i, raan, argp, nu : inclination, right ascension of the ascending node,
        argument of pericenter, true anomaly [rad] (use :func:`deg` for degrees)
    gm : gravitational parameter [m^3/s^2] (> 0)

    Returns
    -------
    r, v : list of 3 mpf each; position [m] and velocity [m/s].
    """
    with mp.workdps(_dps()):
        a, e, i, raan, argp, nu, gm = (
            _mp(x, n) for x, n in zip((a, e, i, raan, argp, nu, gm), ("a", "e", "i", "raan", "argp", "nu", "gm"))
        )
        _check_orbit(a, e, gm)
        return _state(a, e, i, raan, argp, nu, gm)


def _cross(x, y):
    return [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]]


def _dot(x, y):
    return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]


def _wrap(angle: mpf) -> mpf:
    tau = 2 * mp.pi
    w = angle % tau
    return w if w < tau else w - tau


def state_to_elements(r, v, gm) -> dict[str, mpf]:
    """Cartesian state -> osculating Keplerian elements (elliptic orbits).

    Parameters
    ----------
    r : 3 numbers, position [m]; v : 3 numbers, velocity [m/s] (same frame,
        GCRS in tqdyn); gm : gravitational parameter [m^3/s^2].

    Returns
    -------
    dict of mpf with keys ``a`` [m], ``e`` [-], ``i``, ``raan``, ``argp``,
    ``nu``, ``u`` [rad].  Angles in [0, 2 pi) (``i`` in [0, pi]).  ``u =
    argp + nu`` (mod 2 pi) is the argument of latitude, well defined for
    circular orbits.  Degenerate cases: if ``e == 0`` exactly, ``argp = 0`` and
    ``nu = u``; if the orbit is exactly equatorial, ``raan = 0`` and angles
    are measured from the x axis.  Near-degenerate orbits give
    ill-conditioned ``argp``/``nu`` (or ``raan``) but ``u``, ``a``, ``e``,
    ``i`` remain accurate.  Raises ``ValueError`` for non-elliptic states.
    """
    with mp.workdps(_dps()):
        r = _vec(r, "r")
        v = _vec(v, "v")
        gm = _mp(gm, "gm")
        if not gm > 0:
            raise ValueError(f"gm: {gm} m^3/s^2; allowed: gm > 0")
        rn = mp.sqrt(_dot(r, r))
        v2 = _dot(v, v)
        if rn == 0:
            raise ValueError("r: zero position vector; allowed: |r| > 0")
        h = _cross(r, v)
        hn = mp.sqrt(_dot(h, h))
        if hn == 0:
            raise ValueError("r, v: parallel (rectilinear orbit); elements undefined")
        inv_a = 2 / rn - v2 / gm
        if not inv_a > 0:
            raise ValueError(f"r, v: specific energy {v2 / 2 - gm / rn} J/kg >= 0; state is not elliptic")
        a = 1 / inv_a
        rv = _dot(r, v)
        ev = [((v2 - gm / rn) * r[k] - rv * v[k]) / gm for k in range(3)]
        e = mp.sqrt(_dot(ev, ev))
        w = [hk / hn for hk in h]
        i = mp.atan2(mp.hypot(w[0], w[1]), w[2])
        nxy = mp.hypot(h[0], h[1])
        if nxy == 0:
            raan = mpf(0)
            nhat = [mpf(1), mpf(0), mpf(0)]
        else:
            raan = _wrap(mp.atan2(h[0], -h[1]))
            nhat = [-h[1] / nxy, h[0] / nxy, mpf(0)]
        mhat = _cross(w, nhat)
        u = _wrap(mp.atan2(_dot(r, mhat), _dot(r, nhat)))
        if e == 0:
            argp = mpf(0)
        else:
            argp = _wrap(mp.atan2(_dot(ev, mhat), _dot(ev, nhat)))
        nu = _wrap(u - argp)
        return {"a": a, "e": e, "i": i, "raan": raan, "argp": argp, "nu": nu, "u": u}


def _solve_kepler(m: mpf, e: mpf) -> mpf:
    """Eccentric anomaly E with E - e sin E = m, m in [0, 2 pi), by Newton to full precision."""
    if e == 0:
        return m
    big = e > mpf("0.8")
    ecc = mp.pi if big else m + e * mp.sin(m)
    tol = mpf(2) ** (-mp.prec + 4)
    for _ in range(200):
        f = ecc - e * mp.sin(ecc) - m
        d = f / (1 - e * mp.cos(ecc))
        ecc -= d
        if abs(d) <= tol * (1 + abs(ecc)):
            # one more step to reach full precision (Newton's quadratic convergence)
            ecc -= (ecc - e * mp.sin(ecc) - m) / (1 - e * mp.cos(ecc))
            return ecc
    raise ArithmeticError(f"Kepler's equation did not converge for M = {m}, e = {e}")


def kepler_state_at(a, e, i, raan, argp, nu0, gm, t) -> tuple[list[mpf], list[mpf]]:
    """Analytic two-body state at ``t`` seconds after the epoch of the elements.

    The mean anomaly advances by ``n t`` with ``n = sqrt(gm / a^3)``; Kepler's
    equation is solved by Newton iteration to full working precision.

    Parameters
    ----------
    a [m], e [-] (0 <= e < 1), i, raan, argp, nu0 [rad] (true anomaly at t = 0),
    gm [m^3/s^2], t [s] (elapsed time since the epoch; any sign).

    Returns
    -------
    r [m], v [m/s] : lists of 3 mpf in the frame of the elements (GCRS in tqdyn).
    """
    with mp.workdps(_dps()):
        a, e, i, raan, argp, nu0, gm, t = (
            _mp(x, n)
            for x, n in zip((a, e, i, raan, argp, nu0, gm, t), ("a", "e", "i", "raan", "argp", "nu0", "gm", "t"))
        )
        _check_orbit(a, e, gm)
        s = mp.sqrt((1 - e) / (1 + e))
        e0 = 2 * mp.atan2(s * mp.sin(nu0 / 2), mp.cos(nu0 / 2))
        m0 = e0 - e * mp.sin(e0)
        n = mp.sqrt(gm / a**3)
        m = _wrap(m0 + n * t)
        ecc = _solve_kepler(m, e)
        nu = 2 * mp.atan2(mp.sqrt(1 + e) * mp.sin(ecc / 2), mp.sqrt(1 - e) * mp.cos(ecc / 2))
        return _state(a, e, i, raan, argp, nu, gm)


def state_to_dd(r, v) -> np.ndarray:
    """Cartesian state (mpf) -> ``(6, 2)`` float64 array of double-doubles.

    Rows are x, y, z [m], vx, vy, vz [m/s] (frame of the input, GCRS in
    tqdyn); column 0 is ``hi``, column 1 is ``lo`` as produced by :func:`to_dd`.
    """
    with mp.workdps(_dps()):
        rr = _vec(r, "r")
        vv = _vec(v, "v")
    out = np.empty((6, 2), dtype=np.float64)
    for k, x in enumerate(rr + vv):
        out[k] = to_dd(x)
    return out
