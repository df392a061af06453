"""Gravity-field readers (tqdyn.forces.gravity_models) and the Earth field
term (tqdyn.forces.earth).

References:
* reader parse checks: the values printed in src/tqdyn/data/SOURCES.md
  (copied from the files' rows), NGA's EGM2008 zero-tide C20
  (-0.484169317366974e-3) and IERS TN36 eq. 6.13 for the permanent tide;
* the kernel: the same field evaluated directly in the ITRS by the verified
  spherical-harmonic kernels (tests/test_spherical_harmonics.py) and by the
  40+-digit mpmath evaluation of the defining series, with the
  GCRS -> ITRS rotation from pyerfa's own composite routine ``c2t06a``
  (IAU 2006/2000A, CIO based);
* tidal corrections: the summed square arrays built independently in numpy.
"""

from __future__ import annotations

import math

import erfa
import numpy as np
import pytest
from numba import njit

from test_spherical_harmonics import _mp_accel, _tianqin_circle  # noqa: E402  (tests/ is on sys.path)
from tqdyn.forces.earth import (
    EarthField,
    earth_field_accel,
    earth_field_accel_batch,
    earth_field_static_accel,
    earth_tides_accel,
)
from tqdyn.readers.gravity_fields import (
    EGM2008_C20_ZERO_TIDE,
    GravityModel,
    egm2008,
    gl0660b,
    read_icgem_gfc,
    read_shadr,
)
from tqdyn.forces.spherical_harmonics import sh_accel, sh_accel_corrections, sh_accel_delta
from tqdyn.astro.timescales import Epoch, tdb_jd

EPOCH = Epoch.from_utc("2004-06-06T00:00:00")


# --------------------------------------------------------------------------
# readers


def test_egm2008_parse_checks():
    """SOURCES.md: C20, C22, S22, C(12,12); header GM and radius; tide-free;
    4184 gfc rows = C00 + degrees 2..90 (no degree 1)."""
    m = egm2008(90)
    assert m.name == "EGM2008" and m.nmax == 90 and m.tide_system == "tide_free"
    assert m.gm == 3.986004415e14 and m.radius == 6378136.3
    assert m.C[2, 0] == -4.84165143790815e-04
    assert m.C[2, 2] == 2.43938357328313e-06 and m.S[2, 2] == -1.40027370385934e-06
    assert m.C[12, 12] == -2.42377235648074e-09
    assert m.C[0, 0] == 1.0 and not m.C[1].any() and not m.S[1].any()
    assert np.count_nonzero(np.tril(m.C)) == 4184  # every row's C is non-zero here
    assert not np.triu(m.C, 1).any() and not m.S[:, 0].any()
    m12 = egm2008(12)
    assert m12.nmax == 12 and m12.C.shape == (13, 13)
    assert np.array_equal(m12.C, m.C[:13, :13]) and np.array_equal(m12.S, m.S[:13, :13])
    assert egm2008(12) is m12  # cached
    with pytest.raises(ValueError):
        m12.C[2, 0] = 0.0  # read-only


def test_gl0660b_parse_checks():
    """SOURCES.md: C20 (J2 = 2.0321572e-4), C22, C77, S77; header
    R_ref = 1738 km, GM = 4902.8003055554 km^3/s^2 -> SI; file degree 20
    although the header says 660."""
    m = gl0660b(20)
    assert m.nmax == 20 and m.tide_system == "tide_free" and "660" in m.source
    assert m.gm == pytest.approx(4.9028003055554e12, rel=1e-15) and m.radius == 1.738e6
    assert m.C[2, 0] == -9.088083466222001e-05
    assert -math.sqrt(5.0) * m.C[2, 0] == pytest.approx(2.0321572e-4, abs=1e-11)
    assert m.C[2, 2] == 3.467379822995e-05
    assert m.C[7, 7] == -1.820296126625e-06 and m.S[7, 7] == -1.600026884716e-06
    assert m.C[0, 0] == 1.0 and not m.C[1].any()
    assert gl0660b().nmax == 7


def test_degree_limits():
    with pytest.raises(ValueError, match="degree 91 requested.*up to 90"):
        egm2008(91)
    with pytest.raises(ValueError, match="degree 21 requested.*up to 20"):
        gl0660b(21)
    with pytest.raises(ValueError, match="negative"):
        egm2008(-1)
    with pytest.raises(ValueError, match="tide_system"):
        egm2008(12, tide_system="mean_tide")


def test_zero_tide_c20():
    """NGA's zero-tide C20 replaces the tide-free one, nothing else changes;
    the difference -4.1736e-9 is EGM2008's permanent-tide conversion, within
    0.7% of TN36 eq. 6.13, A0 H0 k20 = 4.4228e-8 x (-0.31460) x 0.30190."""
    tf, zt = egm2008(12), egm2008(12, tide_system="zero_tide")
    assert zt.tide_system == "zero_tide"
    assert zt.C[2, 0] == EGM2008_C20_ZERO_TIDE == -0.484169317366974e-03
    d = zt.C[2, 0] - tf.C[2, 0]
    assert abs(d - (-4.173576159e-9)) < 1e-18
    assert abs(d - 4.4228e-8 * -0.31460 * 0.30190) < 3e-11
    C = zt.C.copy()
    C[2, 0] = tf.C[2, 0]
    assert np.array_equal(C, tf.C) and np.array_equal(zt.S, tf.S)


def test_icgem_reader_synthetic(tmp_path):
    """Fortran D exponents, an unnormalised model (converted: C20 = -J2 ->
    -J2/sqrt5), header degree above the rows, and the errors."""
    p = tmp_path / "toy.gfc"
    p.write_text("modelname toy\nearth_gravity_constant 3.986004418D+14\nradius 6378137.0\n"
                 "max_degree 10\nnorm unnormalized\ntide_system zero_tide\nend_of_head ===\n"
                 "gfc 0 0 1.0 0.0 0 0\ngfc 2 0 -1.0826D-03 0.0 0 0\ngfc 2 2 1.5D-06 -0.9D-06 0 0\n")
    m = read_icgem_gfc(p)
    assert m.name == "toy" and m.nmax == 2 and m.tide_system == "zero_tide"
    assert m.gm == 3.986004418e14 and m.radius == 6378137.0
    assert m.C[2, 0] == pytest.approx(-1.0826e-3 / math.sqrt(5.0), rel=1e-15)
    # N22 = sqrt(2 * 5 * 0! / 4!) = sqrt(5/12)
    assert m.C[2, 2] == pytest.approx(1.5e-6 / math.sqrt(5 / 12), rel=1e-15)
    with pytest.raises(ValueError, match="degree 3 requested.*up to 2"):
        read_icgem_gfc(p, nmax=3)
    with pytest.raises(FileNotFoundError, match="nope.gfc"):
        read_icgem_gfc(tmp_path / "nope.gfc")
    bad = tmp_path / "bad.gfc"
    bad.write_text("earth_gravity_constant 1\nradius 1\n")
    with pytest.raises(ValueError, match="end_of_head"):
        read_icgem_gfc(bad)
    bad.write_text("earth_gravity_constant 1\nradius 1\nend_of_head\ngfct 2 0 1 0 0 0 20000101\n")
    with pytest.raises(ValueError, match="time-variable"):
        read_icgem_gfc(bad)


def test_shadr_reader_synthetic(tmp_path):
    p = tmp_path / "toy.tab"
    p.write_text(" 0.1738E+04, 0.4902E+04, 0.0, 50, 50, 0, 0.0, 0.0\n"
                 "    2,    0,-0.2032E-03, 0.0, 0.0, 0.0\n    3,    1, 0.1E-04, 0.2E-04, 0.0, 0.0\n")
    m = read_shadr(p, name="toy", tide_system="zero_tide")
    assert m.nmax == 3 and m.gm == pytest.approx(4.902e12, rel=1e-15) and m.radius == pytest.approx(1.738e6)
    assert m.C[2, 0] == pytest.approx(-0.2032e-3 / math.sqrt(5.0), rel=1e-15)
    with pytest.raises(ValueError, match="degree 4 requested.*up to 3"):
        read_shadr(p, nmax=4)


def test_gravity_model_validation():
    with pytest.raises(ValueError, match="shape"):
        GravityModel("x", 1.0, 1.0, np.zeros((3, 3)), np.zeros((3, 3)), nmax=3)
    with pytest.raises(ValueError, match="tide_system"):
        GravityModel("x", 1.0, 1.0, np.zeros((3, 3)), np.zeros((3, 3)), nmax=2, tide_system="free")


# --------------------------------------------------------------------------
# rotation providers for the tests


def _erfa_rotation(epoch, t_hi, t_lo):
    """T_ITRS_GCRS from pyerfa's composite c2t06a (IAU 2006/2000A), with
    UT1 = UTC + (-0.4704721 s) (the EOP value of 2004-06-06, SOURCES.md) and
    the polar motion of that day; TT from TDB via erfa.dtdb."""
    jd1, jd2 = tdb_jd(epoch, t_hi, t_lo)
    dtr = erfa.dtdb(jd1, jd2, 0.0, 0.0, 0.0, 0.0)
    tt1, tt2 = jd1, jd2 - dtr / 86400.0
    ut2 = tt2 - (32.184 + 32.0 + 0.4704721) / 86400.0  # TAI-UTC = 32 s in 2004
    as2r = math.pi / 648000.0
    return erfa.c2t06a(tt1, tt2, jd1, ut2, -0.074487 * as2r, 0.475665 * as2r)


def _spin_rotation(epoch, t_hi, t_lo):
    """Cheap vectorised rotation (Earth spin about a slightly tilted axis)."""
    t = np.asarray(t_hi, dtype=np.float64) + np.asarray(t_lo, dtype=np.float64)
    th = 7.2921150e-5 * t + 1.2
    c, s = np.cos(th), np.sin(th)
    T = np.zeros(t.shape + (3, 3))
    T[..., 0, 0], T[..., 0, 1], T[..., 1, 0], T[..., 1, 1], T[..., 2, 2] = c, s, -s, c, 1.0
    e = 1e-3
    tilt = np.array([[1.0, 0.0, -e], [0.0, 1.0, 0.0], [e, 0.0, 1.0]])
    tilt /= np.linalg.norm(tilt, axis=1)[:, None]
    return T @ tilt


class _Tide:
    """A synthetic tide provider of degree k (time-dependent coefficients)."""

    def __init__(self, k, scale, seed, permanent_tide=None):
        self.nmax = k
        rng = np.random.default_rng(seed)
        self.a = np.tril(rng.normal(size=(k + 1, k + 1))) * scale
        self.b = np.tril(rng.normal(size=(k + 1, k + 1))) * scale
        self.b[:, 0] = 0.0
        if permanent_tide is not None:
            self.permanent_tide = permanent_tide

    def __call__(self, epoch, t_hi, t_lo):
        w = np.cos(1e-4 * (np.asarray(t_hi) + np.asarray(t_lo)))[..., None, None]
        return w * self.a, w * self.b


# --------------------------------------------------------------------------
# the Earth field term


def test_params_and_tdat_layout():
    f = EarthField(rotation=_spin_rotation)
    m = egm2008(12)
    p = f.params()
    assert p.dtype == np.float64 and p.shape == (5 + 2 * 169 + 1,)  # + the extended-degree-2 flag
    assert p[-1] == 0.0
    assert list(p[:5]) == [m.gm, m.radius, 12.0, 12.0, -1.0]
    assert np.array_equal(p[5:174], m.C.ravel()) and np.array_equal(p[174:343], m.S.ravel())
    assert f.n_tdat == 9 and f.model.tide_system == "tide_free" and "tide_free" in f.source
    t = np.arange(12.0).reshape(3, 4) * 100.0
    td = f.precompute(EPOCH, t, 0.25)
    assert td.shape == (3, 4, 9)
    assert np.array_equal(td[1, 2].reshape(3, 3), _spin_rotation(EPOCH, t[1, 2], 0.25))
    g = EarthField(4, order=2, rotation=_spin_rotation, tides=(_Tide(4, 1e-9, 1), _Tide(10, 1e-11, 2)))
    assert g.tide_degree == 10 and g.n_tdat == 9 + 11 * 12
    assert list(g.params()[:5]) == [m.gm, m.radius, 4.0, 2.0, 10.0]


def test_kernel_vs_itrs_evaluation_erfa_rotation():
    """a_GCRS = T^T a_ITRS(T r) with T from erfa.c2t06a: the kernel against
    (1) sh_accel in the ITRS with numpy rotations (1e-15 |a|) and (2) the
    mpmath series at the rotated point (1e-14 |a| [m/s^2])."""
    f = EarthField(12, rotation=_erfa_rotation)
    m = f.model
    t = np.array([0.0, 3.3e5, 7.776e6])  # 0, ~4 d, 90 d
    td = f.precompute(EPOCH, t, 0.0)
    for k, r in enumerate(_tianqin_circle(5)[:3]):
        T = _erfa_rotation(EPOCH, t[k], 0.0)
        assert np.allclose(T @ T.T, np.eye(3), atol=1e-15)
        a = np.array(earth_field_accel(*r, 0.0, 0.0, 0.0, td[k], f.params()))
        ri = T @ r
        ref = T.T @ np.array(sh_accel(*ri, m.gm, m.radius, m.C, m.S, 12))
        assert np.abs(a - ref).max() <= 1e-15 * np.linalg.norm(ref)
        ref_mp = T.T @ np.array([float(v) for v in _mp_accel(ri, m.gm, m.radius, m.C, m.S, 12)])
        assert np.abs(a - ref_mp).max() <= 1e-14 * np.linalg.norm(ref_mp), (k, a - ref_mp)


def test_tides_summed_and_split():
    """Two providers (degrees 4 and 10, with 2 < static degree 12 < ...):
    precompute packs their sum; total = static + corrections (sh_accel_delta
    in the ITRS), tides-only = sh_accel_corrections, static-only = sh_accel;
    and total = static + tides to 1e-15 |a| [m/s^2]."""
    tides = (_Tide(4, 1e-9, 1), _Tide(10, 1e-11, 2))
    f = EarthField(12, rotation=_spin_rotation, tides=tides)
    m = f.model
    t = np.linspace(0.0, 86400.0, 7)
    td = f.precompute(EPOCH, t, 0.0)
    rows, cols = np.tril_indices(11)
    for k, r in enumerate(_tianqin_circle(7)):
        dC = np.zeros((11, 11))
        dS = np.zeros((11, 11))
        for p in tides:
            c, s = p(EPOCH, t[k], 0.0)
            dC[: c.shape[0], : c.shape[1]] += c
            dS[: s.shape[0], : s.shape[1]] += s
        assert np.array_equal(td[k, 9:75], dC[rows, cols]) and np.array_equal(td[k, 75:], dS[rows, cols])
        T = _spin_rotation(EPOCH, t[k], 0.0)
        ri = T @ r
        tot = np.array(earth_field_accel(*r, 0, 0, 0, td[k], f.params()))
        sta = np.array(earth_field_static_accel(*r, 0, 0, 0, td[k], f.params()))
        tid = np.array(earth_tides_accel(*r, 0, 0, 0, td[k], f.params()))
        ref_tot = T.T @ np.array(sh_accel_delta(*ri, m.gm, m.radius, m.C, m.S, 12, dC.ravel(), dS.ravel(), 10))
        ref_sta = T.T @ np.array(sh_accel(*ri, m.gm, m.radius, m.C, m.S, 12))
        ref_tid = T.T @ np.array(sh_accel_corrections(*ri, m.gm, m.radius, dC.ravel(), dS.ravel(), 10))
        for got, ref in [(tot, ref_tot), (sta, ref_sta), (tid, ref_tid)]:
            assert np.abs(got - ref).max() <= 1e-15 * np.linalg.norm(ref)
        assert np.abs(tot - sta - tid).max() <= 1e-15 * np.linalg.norm(tot)
    batch = earth_field_accel_batch(_tianqin_circle(7), td, f.params(), "tides")
    assert np.array_equal(batch[3], np.array(earth_tides_accel(*_tianqin_circle(7)[3], 0, 0, 0, td[3], f.params())))


@njit
def _as_in_model(r, tdat_all, params_all, c, o):
    # how forces.model.gravity calls a perturbation kernel: slices from the offsets on
    return earth_field_accel(r[0], r[1], r[2], 0.0, 0.0, 0.0, tdat_all[c:], params_all[o:])


def test_kernel_with_offset_slices():
    """The kernel reads only its own leading block of tdat[c:] and params[o:]."""
    f = EarthField(8, rotation=_spin_rotation, tides=(_Tide(4, 1e-9, 3),))
    td = f.precompute(EPOCH, 1234.5, 0.0)
    p = f.params()
    tdat_all = np.concatenate([np.full(6, 7.0), td, np.full(5, -3.0)])
    params_all = np.concatenate([np.full(4, 9.0), p, np.full(3, 1e30)])
    r = _tianqin_circle(3)[1]
    assert _as_in_model(r, tdat_all, params_all, 6, 4) == earth_field_accel(*r, 0, 0, 0, td, p)


def test_earth_field_errors():
    with pytest.raises(ValueError, match="degree 91 requested.*up to 90"):
        EarthField(91, rotation=_spin_rotation)
    with pytest.raises(ValueError, match="degree 21 requested.*up to 20"):
        EarthField(21, model=gl0660b(20), rotation=_spin_rotation)
    with pytest.raises(ValueError, match="order 13"):
        EarthField(12, order=13, rotation=_spin_rotation)
    with pytest.raises(ValueError, match="< 2"):
        EarthField(1, rotation=_spin_rotation)

    class NoDegree:
        def __call__(self, epoch, t_hi, t_lo):
            return np.zeros((3, 3)), np.zeros((3, 3))

    with pytest.raises(ValueError, match="tide_degree"):
        EarthField(tides=(NoDegree(),), rotation=_spin_rotation)
    f = EarthField(tides=(NoDegree(),), tide_degree=2, rotation=lambda e, a, b: np.eye(3))
    assert f.precompute(EPOCH, 0.0, 0.0).shape == (9 + 2 * 6,)
    with pytest.raises(ValueError, match="rotation provider returned shape"):
        EarthField(rotation=lambda e, a, b: np.eye(3)).precompute(EPOCH, np.zeros(4), 0.0)
    with pytest.raises(ValueError, match="degree 4, above the tide degree 2"):
        EarthField(tides=(_Tide(4, 1e-9, 1),), tide_degree=2, rotation=_spin_rotation).precompute(EPOCH, 0.0, 0.0)
    # permanent tide: tide-free field + mean kept, or zero-tide field + mean removed
    EarthField(tides=(_Tide(4, 1e-9, 1, "included"),), rotation=_spin_rotation)
    EarthField(model=egm2008(12, "zero_tide"), tides=(_Tide(4, 1e-9, 1, "removed"),), rotation=_spin_rotation)
    with pytest.raises(ValueError, match="twice"):
        EarthField(model=egm2008(12, "zero_tide"), tides=(_Tide(4, 1e-9, 1, "included"),), rotation=_spin_rotation)
    with pytest.raises(ValueError, match="omits"):
        EarthField(tides=(_Tide(4, 1e-9, 1, "removed"),), rotation=_spin_rotation)
    with pytest.raises(ValueError, match="part"):
        earth_field_accel_batch(np.zeros((1, 3)) + 1e8, np.zeros(9), EarthField(rotation=_spin_rotation).params(), "j2")


def test_default_rotation_is_frames():
    """Without a rotation provider the term uses tqdyn.astro.earth_orientation.earth_orientation.
    Against erfa.c2t06a with the EOP of the epoch day held constant: < 1e-8
    at the epoch (dX, dY ~ 1e-9 rad are the difference); 5 days later the
    held UT1-UTC is off by ~1.2 ms of LOD (~9e-8 rad), bound 3e-7."""

    f = EarthField()
    t = np.array([0.0, 4.3e5])
    td = f.precompute(EPOCH, t, 0.0)
    for k, tol in enumerate((1e-8, 3e-7)):
        assert np.abs(td[k, :9].reshape(3, 3) - _erfa_rotation(EPOCH, t[k], 0.0)).max() < tol


def test_magnitude_along_tianqin_orbit_gcrs(capsys):
    """EGM2008 degree 12 in GCRS along r = 1e8 m, i = 74.5 deg over one day
    (pyerfa rotation): max |a| ~ 5e-7 m/s^2 (C20 dominated)."""
    f = EarthField(12, rotation=_erfa_rotation)
    pts = _tianqin_circle(48)
    t = np.linspace(0.0, 86400.0, 48, endpoint=False)
    a = earth_field_accel_batch(pts, f.precompute(EPOCH, t, 0.0), f.params())
    mag = np.linalg.norm(a, axis=1)
    with capsys.disabled():
        print(f"\nEarthField(12) along r = 1e8 m, GCRS: max {mag.max():.3e}, min {mag.min():.3e} m/s^2")
    assert 2e-7 < mag.max() < 6e-7
