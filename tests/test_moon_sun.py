"""The Moon's field (tqdyn.forces.moon) with libration
(tqdyn.astro.lunar_orientation) and the Sun's J2 with its IAU orientation
(tqdyn.forces.sun), against independent references.

Where each reference comes from:

* NAIF text-kernel values: read back from pck00010.tpc as printed in the
  file (BODY10_POLE_RA = 286.13 ...).
* Lunar PA orientation: NAIF's own example in the comments of
  ``moon_080317.tf`` (N. Bachman, NAIF/JPL, 2008): the geometric position of
  the Earth relative to the Moon at 2008 MAR 17 20:10:00 UTC with DE421, in
  MOON_PA = (379908.634, 33385.003, -12516.8859) km and in MOON_ME =
  (379892.825, 33510.118, -12661.5278) km (printed to 1 m / 0.1 m).  The same
  kernel states the PA-ME rotation angle (~0.0288473 deg) and, for
  2000-2020, the ME(DE421) - IAU_MOON difference: amplitude ~0.0051 deg,
  mean ~0.00249 deg.
* Rotation-matrix construction: pyerfa's ``rz``/``rx`` and ``s2c``.
* Field accelerations: the gradient (mpmath.diff, 40 digits) of the
  potential written in the test from the definition (exact Legendre
  polynomials, no recursion), and for degree 2 a closed-form Cartesian
  formula in numpy; the Sun's J2 also against ``sh_accel`` with
  C20 = -J2/sqrt(5) in the IAU solar frame.
"""

from __future__ import annotations

import importlib.resources
import math
from fractions import Fraction

import erfa
import mpmath
import numpy as np
import pytest

from tqdyn.astro import lunar_orientation
from tqdyn.astro.ephemeris import default_ephemeris
from tqdyn.forces import moon
from tqdyn.forces import sun
from tqdyn.readers import pck
from tqdyn.readers.naif import parse_text_kernel, read_text_kernel
from tqdyn.forces.spherical_harmonics import sh_accel
from tqdyn.astro.timescales import Epoch, tdb_jd

EPOCH = Epoch.from_utc("2004-06-06T00:00:00")
AS = math.pi / 648000.0  # one arcsecond [rad]
GM_EARTH = 3.986004415e14  # m^3/s^2 (EGM2008), for the test orbit's mean motion


def _read_gl0660b():
    """Independent reader of the shipped GL0660B table: (GM [m^3/s^2],
    R [m], {(n, m): (C, S)}) straight from the PDS SHADR text."""
    text = (importlib.resources.files("tqdyn") / "data" / "jggrx_0660b_sha_deg20.tab").read_text()
    lines = text.splitlines()
    head = [f.strip() for f in lines[0].split(",")]
    radius, gm = float(head[0]) * 1e3, float(head[1]) * 1e9
    cs = {}
    for line in lines[1:]:
        f = [v.strip() for v in line.split(",")]
        if len(f) >= 4:
            cs[int(f[0]), int(f[1])] = (float(f[2]), float(f[3]))
    return gm, radius, cs


def _angle(a, b):
    """Rotation angle [rad] between rotation matrices a, b (..., 3, 3)."""
    d = np.einsum("...ij,...kj->...ik", a, b)
    return np.arccos(np.clip((np.trace(d, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0))


def _tianqin_orbit(t):
    """Geocentric GCRS positions [m] of the three satellites, (..., 3, 3):
    circular r = 1e8 m, i = 74.5 deg, node 211.6 deg, argument of latitude
    30/150/270 deg at t = 0 (Table I of the TianQin paper), t [s]."""
    a, inc, node = 1e8, math.radians(74.5), math.radians(211.6)
    n = math.sqrt(GM_EARTH / a**3)
    u = np.radians([30.0, 150.0, 270.0]) + n * np.asarray(t)[..., None]
    xo, yo = a * np.cos(u), a * np.sin(u)
    cn, sn, ci, si = math.cos(node), math.sin(node), math.cos(inc), math.sin(inc)
    return np.stack([cn * xo - sn * ci * yo, sn * xo + cn * ci * yo, si * yo], axis=-1)


# --------------------------------------------------------------------------
# NAIF text kernels


def test_text_kernel_grammar():
    text = """KPL/PCK
    comment before the first data block: X = ( 9 )
    \\begindata
    A = ( 1.5  -2.5D-3, 4 )
    B = 'it''s'
    C = ( 1
          2 )
    C += 3
    \\begintext
    D = ( 7 )
    \\begindata
    E = @2000-JAN-01
    """
    k = parse_text_kernel(text)
    assert k == {"A": [1.5, -2.5e-3, 4.0], "B": ["it's"], "C": [1.0, 2.0, 3.0], "E": ["@2000-JAN-01"]}
    with pytest.raises(ValueError, match="'F'"):
        parse_text_kernel("\\begindata\nF = ( 1 2\n")
    with pytest.raises(FileNotFoundError, match="nope.tpc"):
        read_text_kernel("/nonexistent/nope.tpc")


def test_pck00010_values():
    """Values as printed in pck00010.tpc (IAU WGCCRE 2009)."""
    k = read_text_kernel(importlib.resources.files("tqdyn") / "data" / "pck00010.tpc")
    assert k["BODY10_POLE_RA"] == [286.13, 0.0, 0.0]
    assert k["BODY10_POLE_DEC"] == [63.87, 0.0, 0.0]
    assert k["BODY10_PM"] == [84.176, 14.1844, 0.0]
    assert k["BODY301_PM"] == [38.3213, 13.17635815, -1.4e-12]
    assert len(k["BODY3_NUT_PREC_ANGLES"]) == 26 and k["BODY3_NUT_PREC_ANGLES"][-2:] == [25.053, 473327.79642]
    el = pck.read_iau_moon_elements()
    assert el.angles.shape == (13, 2) and el.nut_pm[0] == 3.5610 and el.nut_dec[12] == -0.0009


# --------------------------------------------------------------------------
# orientation


def test_rotations_orthonormal():
    jd1, jd2 = tdb_jd(EPOCH, np.linspace(0.0, 90 * 86400.0, 501))
    mats = {
        "pa_de421": lunar_orientation.lunar_pa_rotation(jd1, jd2, "de421"),
        "pa_iau": lunar_orientation.lunar_pa_rotation(jd1, jd2, "iau"),
        "me_iau": lunar_orientation.lunar_iau_rotation(jd1, jd2),
        "sun_iau": sun.solar_iau_rotation(jd1, jd2),
    }
    for name, m in mats.items():
        assert m.shape == (501, 3, 3), name
        err = np.abs(m @ np.swapaxes(m, -1, -2) - np.eye(3)).max()
        assert err < 1e-15, (name, err)
        assert np.allclose(np.linalg.det(m), 1.0, atol=1e-15), name
    assert np.abs(lunar_orientation.T_PA_ME_DE421 @ lunar_orientation.T_PA_ME_DE421.T - np.eye(3)).max() < 1e-15


def test_euler_composition_matches_erfa():
    """T_PA_ICRF = R3(psi) R1(theta) R3(phi) built with pyerfa's rotations
    from angles that match jplephem's own Chebyshev evaluation of the
    kernel; the IAU matrices = R3(W) R1(90-dec) R3(90+ra) likewise."""
    jd1, jd2 = tdb_jd(EPOCH, np.array([0.0, 3.3e6, 7.7e6]))
    ang = lunar_orientation.lunar_pa_euler_angles(jd1, jd2)
    mats = lunar_orientation.lunar_pa_rotation(jd1, jd2)
    # the compiled Chebyshev evaluation = jplephem's own (psi ~ 3e3 rad: ulp 5e-13)
    from jplephem.pck import PCK

    seg = PCK.open(str(importlib.resources.files("tqdyn") / "data" / "moon_pa_de421_1900-2050.bpc")).segments[0]
    jd_all = np.arange(2415020.5, 2470172.5, 7.3)
    ref = seg.compute(jd_all, 0.0, derivative=False).T
    assert np.abs(lunar_orientation.lunar_pa_euler_angles(jd_all, 0.0) - ref).max() < 5e-12
    assert np.abs(lunar_orientation.lunar_pa_euler_angles(jd1, jd2) - seg.compute(jd1, jd2, derivative=False).T).max() < 5e-12
    for k in range(3):
        phi, theta, psi = ang[k]
        ref = erfa.rz(psi, erfa.rx(theta, erfa.rz(phi, np.eye(3))))
        assert np.abs(mats[k] - ref).max() < 2e-16
    # Sun at J2000 + 1000.25 d: W = 84.176 + 14.1844 * d
    d = 1000.25
    ref = erfa.rz(math.radians((84.176 + 14.1844 * d) % 360.0),
                  erfa.rx(math.radians(90 - 63.87), erfa.rz(math.radians(90 + 286.13), np.eye(3))))
    assert np.abs(sun.solar_iau_rotation(2451545.0, d) - ref).max() < 1e-13


def test_pa_rotation_naif_example():
    """NAIF moon_080317.tf example: Earth relative to Moon at 2008 MAR 17
    20:10:00 UTC (DE421, geometric) in MOON_PA and MOON_ME, km."""
    tdb = Epoch.from_utc("2008-03-17T20:10:00").tdb
    earth_from_moon = -default_ephemeris().geocentric("moon", tdb[0], tdb[1])[0]  # m, ICRF
    pa = lunar_orientation.lunar_pa_rotation(tdb[0], tdb[1]) @ earth_from_moon
    me = lunar_orientation.T_PA_ME_DE421.T @ pa
    pa_naif = np.array([379908.634, 33385.003, -12516.8859]) * 1e3
    me_naif = np.array([379892.825, 33510.118, -12661.5278]) * 1e3
    # printed to 1 m (x, y) and 0.1 m (z): 1 m at 3.8e8 m is 2.6e-9 rad
    assert np.abs(pa - pa_naif).max() < 1.0, pa - pa_naif
    assert np.abs(me - me_naif).max() < 1.0, me - me_naif
    # the other composition order of the TK angles misses by ~4 m
    a1, a2, a3 = 67.92 * AS, 78.56 * AS, 0.30 * AS
    wrong = erfa.rz(-a1, erfa.ry(-a2, erfa.rx(-a3, np.eye(3))))
    assert np.abs(wrong @ pa - me_naif).max() > 3.0
    # and the stated size of the PA-ME rotation (0.0288473 deg)
    angle = math.degrees(math.acos((np.trace(lunar_orientation.T_PA_ME_DE421) - 1) / 2))
    assert abs(angle - 0.0288473) < 5e-7


def test_pa_de421_vs_iau():
    """The IAU 2009 ME model mapped into PA with the constant DE421 offset
    agrees with the DE421 PA frame to < 1e-4 rad (20.6") over 1900-2050:
    what is left is the truncation of the IAU libration series, which NAIF
    measured for 2000-2020 as ~0.0051 deg amplitude about ~0.00249 deg
    (moon_080317.tf).  Without the ~104" PA-ME offset they differ by
    89"..118" (> 4e-4 rad), so the check sees the offset and its sign."""
    jd = np.arange(2415021.0, 2470172.0, 0.5)  # 1900-01-01 .. 2050-12-31, TDB
    de = lunar_orientation.lunar_pa_rotation(jd, 0.0, "de421")
    iau = lunar_orientation.lunar_pa_rotation(jd, 0.0, "iau")
    ang = _angle(de, iau)
    assert ang.max() < 1e-4, ang.max() / AS
    recent = (jd > 2451545.0) & (jd < 2458850.0)  # 2000-2020
    assert abs(ang[recent].max() - 0.0051 * 3600 * AS) < 0.1 * 0.0051 * 3600 * AS
    assert abs(ang[recent].mean() - 0.00249 * 3600 * AS) < 0.1 * 0.00249 * 3600 * AS
    bare = _angle(de, lunar_orientation.lunar_iau_rotation(jd, 0.0))
    assert bare.min() > 4e-4
    assert np.abs(iau - lunar_orientation.T_PA_ME_DE421 @ lunar_orientation.lunar_iau_rotation(jd, 0.0)).max() < 1e-15


def test_orientation_bad_input():
    with pytest.raises(ValueError, match="outside the kernel span"):
        lunar_orientation.lunar_pa_rotation(2415000.5, 0.0)
    with pytest.raises(ValueError, match="2470172"):
        lunar_orientation.lunar_pa_rotation(2470172.5, 1.0)
    with pytest.raises(ValueError, match="libration: 'spice' is not allowed"):
        lunar_orientation.lunar_pa_rotation(2451545.0, 0.0, "spice")
    with pytest.raises(FileNotFoundError):
        pck.load_lunar_pa_kernel("/nonexistent/moon.bpc")
    with pytest.raises(FileNotFoundError):
        pck.read_iau_sun_elements("/nonexistent/pck.tpc")
    with pytest.raises(ValueError, match="degree 1"):
        moon.MoonField(degree=1)
    with pytest.raises(ValueError, match="libration"):
        moon.MoonField(libration="DE430")
    with pytest.raises(ValueError, match="degree 21"):
        moon.MoonField(degree=21)


def test_sun_pole():
    """Pole unit vector = pyerfa's spherical-to-Cartesian of (286.13, 63.87) deg,
    = the third row of the solar IAU matrix."""
    p = sun.sun_pole()
    assert np.abs(p - erfa.s2c(math.radians(286.13), math.radians(63.87))).max() < 1e-16
    assert np.abs(sun.solar_iau_rotation(2453162.5, 0.3)[2] - p).max() < 1e-15


# --------------------------------------------------------------------------
# independent field references


def _mp_legendre_dm(n: int, m: int):
    """Exact coefficients (Fractions, by power of t) of d^m/dt^m P_n(t),
    from P_n(t) = 2^-n sum_k (-1)^k C(n,k) C(2n-2k,n) t^(n-2k)."""
    coef = [Fraction(0)] * (n + 1)
    for k in range(n // 2 + 1):
        coef[n - 2 * k] = Fraction((-1) ** k * math.comb(n, k) * math.comb(2 * n - 2 * k, n), 2**n)
    for _ in range(m):
        coef = [coef[p + 1] * (p + 1) for p in range(len(coef) - 1)] or [Fraction(0)]
    return coef


def _mp_potential(cs, gm, radius, nmax):
    """V(x, y, z) [m^2/s^2] of degrees 2..nmax (mpmath), the definition:
    V = GM sum_n R^n / r^(n+1) sum_m N_nm P_n^(m)(z/r) Re/Im[(x+iy)^m] / r^m
    (C, S), with N_nm = sqrt((2-d_m0)(2n+1)(n-m)!/(n+m)!), no Condon-Shortley
    phase.  (1-t^2)^(m/2) cos(m lambda) = Re((x+iy)^m)/r^m avoids all trig."""
    terms = []
    for n in range(2, nmax + 1):
        for m in range(n + 1):
            c, s = cs.get((n, m), (0.0, 0.0))
            if c == 0.0 and s == 0.0:
                continue
            nn = mpmath.sqrt(mpmath.mpf((2 if m else 1) * (2 * n + 1) * math.factorial(n - m)) / math.factorial(n + m))
            terms.append((n, m, nn * mpmath.mpf(c), nn * mpmath.mpf(s), [mpmath.mpf(f.numerator) / f.denominator for f in _mp_legendre_dm(n, m)]))

    def v(x, y, z):
        r = mpmath.sqrt(x * x + y * y + z * z)
        t = z / r
        w = mpmath.mpc(x, y)
        tot = mpmath.mpf(0)
        for n, m, c, s, poly in terms:
            p = mpmath.mpf(0)
            for a in reversed(poly):  # Horner, ascending coefficients
                p = p * t + a
            wm = w**m
            tot += mpmath.mpf(radius) ** n / r ** (n + 1 + m) * p * (c * wm.real + s * wm.imag)
        return mpmath.mpf(gm) * tot

    return v


def _mp_grad(v, pos):
    x, y, z = (mpmath.mpf(float(c)) for c in pos)
    return [mpmath.diff(v, (x, y, z), order) for order in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]


def _degree2_numpy(p, gm, radius, cs):
    """Degree-2 field acceleration [m/s^2] (numpy, closed form): V2 = GM R^2
    Q(p)/r^5 with Q = C20 (3z^2 - r^2)/2 + 3z (C21 x + S21 y) + 3 C22 (x^2 -
    y^2) + 6 S22 x y (unnormalised C2m), grad = GM R^2 (grad Q / r^5 -
    5 Q p / r^7).  p: (..., 3) body-fixed [m]."""
    c20 = cs[2, 0][0] * math.sqrt(5.0)
    c21, s21 = (v * math.sqrt(5.0 / 3.0) for v in cs[2, 1])
    c22, s22 = (v * math.sqrt(5.0 / 12.0) for v in cs[2, 2])
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    r2 = x * x + y * y + z * z
    q = 0.5 * c20 * (3 * z * z - r2) + 3 * z * (c21 * x + s21 * y) + 3 * c22 * (x * x - y * y) + 6 * s22 * x * y
    gq = np.stack([-c20 * x + 3 * c21 * z + 6 * c22 * x + 6 * s22 * y,
                   -c20 * y + 3 * s21 * z - 6 * c22 * y + 6 * s22 * x,
                   2 * c20 * z + 3 * (c21 * x + s21 * y)], axis=-1)
    r5 = r2 * r2 * np.sqrt(r2)
    return gm * radius**2 * (gq / r5[..., None] - 5.0 * (q / (r5 * r2))[..., None] * p)


def _kernel_many(kernel, r, tdat, params):
    """Evaluate a force kernel at positions r (n, 3) with tdat (n, k)."""
    return np.array([kernel(*r[i], 0.0, 0.0, 0.0, tdat[i], params) for i in range(len(r))])


def test_moon_coefficients_and_params():
    gm, radius, cs = _read_gl0660b()
    term = moon.MoonField(degree=7)
    p = term.params()
    assert p.shape == (3 + 2 * 64,)
    assert (p[0], p[1], p[2]) == (gm, radius, 7.0)
    c, s = p[3:67].reshape(8, 8), p[67:].reshape(8, 8)
    assert c[2, 0] == -9.088083466222001e-05 and c[2, 2] == 3.467379822995e-05
    assert c[7, 7] == -1.820296126625e-06 and s[7, 7] == -1.600026884716e-06  # SOURCES.md parse check
    for (n, m), (cv, sv) in cs.items():
        if 2 <= n <= 7:
            assert (c[n, m], s[n, m]) == (cv, sv), (n, m)
    assert not c[:2].any() and not s[:2].any()
    assert term.n_tdat == 15


def test_moon_field_degree2_closed_form():
    """MoonField(degree=2) at 200 instants of 10 days on the TianQin orbit =
    the closed-form numpy degree-2 field, satellite minus Earth, rotated with
    the same T_PA_GCRS.  Tolerance 1e-26 m/s^2 (the field is ~1e-13)."""
    gm, radius, cs = _read_gl0660b()
    term = moon.MoonField(degree=2)
    t = np.linspace(0.0, 10 * 86400.0, 200)
    tdat = term.precompute(EPOCH, t, 0.0)
    assert tdat.shape == (200, 15)
    r = _tianqin_orbit(t)[:, 0]
    s, rot = tdat[:, :3], tdat[:, 3:12].reshape(-1, 3, 3)
    sat = np.einsum("nij,nj->ni", rot, r - s)
    earth = np.einsum("nij,nj->ni", rot, -s)
    ref = np.einsum("nji,nj->ni", rot, _degree2_numpy(sat, gm, radius, cs) - _degree2_numpy(earth, gm, radius, cs))
    got = _kernel_many(moon.moon_field_accel, r, tdat, term.params())
    assert np.abs(got - ref).max() < 1e-26, np.abs(got - ref).max()
    assert 1e-14 < np.linalg.norm(ref, axis=1).max() < 1e-11


def test_moon_field_degree7_mpmath():
    """MoonField(degree=7) = T^T [grad V(T (r - s)) - grad V(-T s)] with V
    the degree 2..7 potential of the definition (mpmath, 40 digits, numerical
    gradient), at 3 instants / positions.  Tolerance 1e-25 m/s^2."""
    gm, radius, cs = _read_gl0660b()
    term = moon.MoonField(degree=7)
    t = np.array([0.0, 3.1e5, 8.2e5])
    tdat = term.precompute(EPOCH, t, 0.0)
    r = _tianqin_orbit(t)[np.arange(3), np.arange(3)]
    got = _kernel_many(moon.moon_field_accel, r, tdat, term.params())
    with mpmath.workdps(40):
        v = _mp_potential(cs, gm, radius, 7)
        for i in range(3):
            rot = mpmath.matrix(tdat[i, 3:12].reshape(3, 3).tolist())
            s = mpmath.matrix(tdat[i, :3].tolist())
            rr = mpmath.matrix(r[i].tolist())
            g_sat = mpmath.matrix(_mp_grad(v, rot * (rr - s)))
            g_earth = mpmath.matrix(_mp_grad(v, rot * (-s)))
            ref = rot.T * (g_sat - g_earth)
            err = max(abs(float(ref[k]) - got[i, k]) for k in range(3))
            assert err < 1e-25, (i, err, [float(x) for x in ref])


def test_kernels_on_slices():
    """The kernels read only their own slices: the same result when tdat and
    params are tails of longer arrays, as the compiled dispatcher passes them
    (tdat[c:], params[o:])."""
    for term, kern in ((moon.MoonField(degree=7), moon.moon_field_accel), (sun.SunJ2(), sun.sun_j2_accel)):
        tdat = term.precompute(EPOCH, np.array([5e4]), 0.0)[0]
        prm = term.params()
        r = _tianqin_orbit(5e4)[2]
        ref = kern(*r, 1.0, 2.0, 3.0, tdat, prm)
        big_t = np.concatenate([np.full(7, np.nan), tdat, np.full(5, np.nan)])
        big_p = np.concatenate([np.full(4, np.nan), prm, np.full(3, np.nan)])
        assert kern(*r, 0.0, 0.0, 0.0, big_t[7:], big_p[4:]) == ref


def test_indirect_term_vanishes_at_geocenter():
    for term, kern in ((moon.MoonField(degree=7), moon.moon_field_accel), (sun.SunJ2(), sun.sun_j2_accel)):
        tdat = term.precompute(EPOCH, np.array([1234.5]), 0.0)[0]
        assert kern(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, tdat, term.params()) == (0.0, 0.0, 0.0)


def test_sun_j2_mpmath():
    """Sun J2 kernel = grad of V = -GM J2 R^2 P2(z/r)/r^3 (z along the IAU
    pole), satellite minus Earth, in mpmath (40 digits).  The difference is
    ~1e-16 m/s^2 of two ~3e-14 m/s^2 terms; tolerance 1e-28 m/s^2: the
    float64 kernel forms r - s at 1 au with ~3e-5 m rounding (2e-16
    relative), which moves each term by ~4 * 2e-16 * 3e-14 = 3e-29 m/s^2."""
    term = sun.SunJ2()
    prm = term.params()
    gm, j2, radius = prm[0], term.j2, term.radius
    t = np.array([0.0, 4.4e5])
    tdat = term.precompute(EPOCH, t, 0.0)
    r = _tianqin_orbit(t)[:, 1]
    got = _kernel_many(sun.sun_j2_accel, r, tdat, prm)
    with mpmath.workdps(40):
        pole = [mpmath.mpf(float(c)) for c in sun.sun_pole()]

        def v(x, y, z):
            r2 = x * x + y * y + z * z
            zz = (x * pole[0] + y * pole[1] + z * pole[2]) ** 2 / r2
            return -mpmath.mpf(gm) * mpmath.mpf(j2) * mpmath.mpf(radius) ** 2 * (3 * zz - 1) / 2 / r2 ** mpmath.mpf(1.5)

        for i in range(2):
            s = tdat[i]
            gs = _mp_grad(v, [mpmath.mpf(float(r[i, k])) - mpmath.mpf(float(s[k])) for k in range(3)])
            ge = _mp_grad(v, [-mpmath.mpf(float(s[k])) for k in range(3)])
            for k in range(3):
                assert abs(float(gs[k] - ge[k]) - got[i, k]) < 1e-28, (i, k, float(gs[k] - ge[k]), got[i, k])


def test_sun_j2_vs_sh_accel():
    """The zonal formula = sh_accel with C20 = -J2/sqrt(5) (fully normalised)
    in the IAU solar frame, rotated back (direct term at 1 au)."""
    term = sun.SunJ2()
    gm = term.params()[0]
    c = np.zeros((3, 3))
    c[2, 0] = -term.j2 / math.sqrt(5.0)
    s = np.zeros((3, 3))
    rot = sun.solar_iau_rotation(2453162.5, 0.7)
    pole = sun.sun_pole()
    for d in ([1.2e11, -7.0e10, 3.3e10], [-2.0e10, 9.0e10, 1.1e11], [1e9, 2e9, -8e8]):
        d = np.array(d)
        ref = rot.T @ np.array(sh_accel(*(rot @ d), gm, term.radius, c, s, 2, 2))
        got = np.array(sun.zonal_j2_accel(*d, gm, term.j2 * term.radius**2, *pole))
        assert np.abs(got - ref).max() < 1e-13 * np.abs(ref).max(), (got, ref)


# --------------------------------------------------------------------------
# magnitudes along the TianQin orbit and cost


def _magnitudes(days=10.0, n=2001):
    """Accelerations [m/s^2] of the terms at n instants over ``days`` for the
    three satellites, (n, 3, 3); plus the direct (satellite) and indirect
    (Earth) parts of the Moon's field and of the Sun's J2 alone."""
    t = np.linspace(0.0, days * 86400.0, n)
    r = _tianqin_orbit(t)  # (n, 3 sats, 3)
    out = {}
    for key, term, kern in (("moon7", moon.MoonField(degree=7), moon.moon_field_accel),
                            ("moon2", moon.MoonField(degree=2), moon.moon_field_accel),
                            ("moon7_iau", moon.MoonField(degree=7, libration="iau"), moon.moon_field_accel),
                            ("sunj2", sun.SunJ2(), sun.sun_j2_accel)):
        tdat = term.precompute(EPOCH, t, 0.0)
        prm = term.params()
        out[key] = np.array([[kern(*r[i, j], 0.0, 0.0, 0.0, tdat[i], prm) for j in range(3)] for i in range(n)])
        if key == "moon7":
            n1 = 8
            c, s_ = prm[3:3 + n1 * n1].reshape(n1, n1), prm[3 + n1 * n1:].reshape(n1, n1)
            rot, pos = tdat[:, 3:12].reshape(-1, 3, 3), tdat[:, :3]
            out["moon7_direct"] = np.array([rot[i].T @ np.array(sh_accel(*(rot[i] @ (r[i, 0] - pos[i])), prm[0], prm[1], c, s_, 7, 2))
                                            for i in range(n)])
            out["moon7_earth"] = np.array([rot[i].T @ np.array(sh_accel(*(rot[i] @ -pos[i]), prm[0], prm[1], c, s_, 7, 2))
                                           for i in range(n)])
        if key == "sunj2":
            p = sun.sun_pole()
            out["sunj2_earth"] = np.array([sun.zonal_j2_accel(*(-tdat[i]), prm[0], prm[1], *p) for i in range(n)])
    return out


def test_magnitudes_tianqin_orbit(capsys):
    """Along three TianQin-like satellites (r = 1e8 m) over 10 days from
    2004-06-06: Moon degree 2..7 ~1e-13..1e-12 m/s^2 (of which degrees 3..7
    ~1e-15), Sun J2 ~1e-16 m/s^2 (a tidal remainder of two ~4e-14 m/s^2
    terms).  Orders asserted with a decade of margin; the numbers are
    printed."""
    m = _magnitudes()
    norm = {k: np.linalg.norm(v, axis=-1) for k, v in m.items()}
    with capsys.disabled():
        for k, v in norm.items():
            print(f"\n  {k:12s} max {v.max():.3e}  rms {np.sqrt((v**2).mean()):.3e}  min {v.min():.3e} m/s^2", end="")
        d = np.linalg.norm(m["moon7"] - m["moon7_iau"], axis=-1)
        print(f"\n  de421 - iau  max {d.max():.3e} m/s^2", end="")
        d = np.linalg.norm(m["moon7"] - m["moon2"], axis=-1)
        print(f"\n  deg 3..7     max {d.max():.3e} m/s^2")
    assert 1e-13 < norm["moon7"].max() < 1e-11
    assert 1e-18 < norm["sunj2"].max() < 1e-15
    assert 1e-14 < norm["sunj2_earth"].min() and norm["sunj2_earth"].max() < 1e-13
    # degree 2 dominates; degrees 3..7 add a few percent at most
    assert np.linalg.norm(m["moon7"] - m["moon2"], axis=-1).max() < 0.2 * norm["moon2"].max()
    # the DE421 and IAU orientations differ by <= 20" -> ~1e-4 of the field
    assert np.linalg.norm(m["moon7"] - m["moon7_iau"], axis=-1).max() < 1e-3 * norm["moon7"].max()
