"""GNSS tracking at high altitude: GPS and BeiDou pseudoranges received above
the constellations (TianQin's 1e5 km orbit), through the main lobe and the
side lobes of the transmit antennas, past the Earth's limb.

Transmitters (:class:`WalkerConstellation`): nominal Walker delta
constellations on circular Keplerian orbits about the Earth (GM of EGM2008),
node longitudes counted from the GCRS x axis at the epoch:

* :data:`GPS`: Walker 24/6/2, i = 55 deg, a = 26,560 km -- the 24 baseline
  slots in six planes A-F of the GPS SPS Performance Standard (5th ed.,
  2020, section 3.2, Table 3.2-1) are close to, but not exactly, a Walker
  pattern (their in-plane spacing is uneven); the Walker 24/6/2 stand-in
  keeps the count, the planes, the inclination and the radius.
* :data:`BEIDOU_MEO`: Walker 24/3/1, i = 55 deg, a = 27,906 km -- the BDS-3
  MEO constellation as given by the China Satellite Navigation Office
  ("Development of the BeiDou Navigation Satellite System (Version 4.0)",
  2019: 24 MEO in a Walker 24/3/1 at 21,528 km altitude).

Precise orbits from SP3 files a user supplies are the alternative
(:class:`tqdyn.od.gnss_sp3.SP3Constellation`, same interface plus the
satellites' ids; the files are read by :func:`tqdyn.readers.sp3.read_sp3`:
no maintained PyPI reader was found -- ``sp3`` 1.1.1, 2022, downloads and
interpolates through astropy; ``georinex`` 1.16.2, 2023, reads SP3 into
xarray).  A tracking plan names which (``Tracking.gnss_orbits``).

Visibility (:func:`gnss_visibility`), per transmitter and epoch:

* Earth occultation: the straight line of sight must pass the Earth's
  centre farther than R_E + the grazing altitude (default 100 km, which
  keeps the ray above the bulk of the troposphere and ionosphere);
* the transmit antenna's off-boresight angle theta (boresight = nadir).
  Reception modes: ``"main"``, theta <= 21.3 deg (GPS L1 main lobe);
  ``"ssv"``, theta <= 23.5 deg (the L1 reference half-beam of the Space
  Service Volume, including the first side lobes: "The Interoperable
  Global Navigation Satellite Systems Space Service Volume", ICG/UNOOSA,
  2nd ed. 2021); ``"sidelobes"`` (default), a link budget
  C/N0 = EIRP(theta) - FSPL(L) + G_r - N_0 >= threshold with a simplified
  transmit pattern :class:`LinkBudget`: EIRP_main within 23.5 deg, taken
  from the SSV booklet's minimum received L1 C/A power at GEO at the
  reference angle (-184.0 dBW for a 0 dBi antenna, at 65,166 km: EIRP =
  8.7 dBW, a conservative minimum), side lobes out to 60 deg at
  EIRP_main - 10 dB (the GPS Antenna Characterization Experiment,
  Donaldson et al. 2020, NAVIGATION 67(4), measured side lobes roughly
  10-20 dB below the main-lobe peak out to ~60-80 deg; round values).

Pseudorange (:func:`pseudorange`): c tau + c dt_r, with c tau =
|r(t) - r_G(t - tau)| + c (Earth Shapiro delay, ~2-3 cm) solved by fixed
point (transmitter on its orbit at the emission time), the
receiver clock bias c dt_r [m] an estimated nuisance per epoch (partial 1:
``extra["d_clock"]``), transmitter clocks assumed corrected, no
ionosphere (rays passing > 100 km above the surface cross it only near the
limb: metres, calibrated with dual frequencies).  Partials: d rho/dr =
c u / (c - u . v_G) at the reception time, d rho/dv = 0.  Noise: metres
(:data:`GNSS_SIGMA_M`).  The simpler alternative, position fixes, is the
state itself with a covariance.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..astro.constants import C_LIGHT, GM_EARTH_EGM2008, R_EARTH_EGM2008
from ..lightpath.shapiro import shapiro_delay
from .measurements import Observable

__all__ = ["BEIDOU_MEO", "GNSS_SIGMA_M", "GPS", "LinkBudget", "WalkerConstellation", "gnss_visibility",
           "pseudorange"]

#: Default pseudorange noise at high altitude [m] (weak signals: a few m).
GNSS_SIGMA_M = 3.0
_L1_HZ = 1575.42e6


@dataclass(frozen=True)
class WalkerConstellation:
    """Walker delta constellation t/p/f on circular orbits: total satellites,
    planes, phasing f, inclination [deg], semi-major axis [m]; gm [m^3/s^2]."""

    name: str
    total: int
    planes: int
    phasing: int
    inclination_deg: float
    a_m: float
    gm: float = float(GM_EARTH_EGM2008)

    def states(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Positions [m] and velocities [m/s] (N, K, 3) at t (N,) [s since the
        epoch], GCRS: plane j has node 360 j / p deg, satellite k of the
        plane the argument of latitude 360 k p / t + 360 f j / t deg at t = 0."""
        t = np.atleast_1d(np.asarray(t, np.float64))
        per = self.total // self.planes
        j = np.repeat(np.arange(self.planes), per)
        k = np.tile(np.arange(per), self.planes)
        node = 2 * np.pi * j / self.planes
        u0 = 2 * np.pi * (k * self.planes + self.phasing * j) / self.total
        n = np.sqrt(self.gm / self.a_m ** 3)
        u = u0[None, :] + n * t[:, None]                                 # (N, K)
        inc = np.radians(self.inclination_deg)
        cO, sO, ci, si = np.cos(node), np.sin(node), np.cos(inc), np.sin(inc)
        p = np.stack([cO, sO, np.zeros_like(cO)], -1)                    # node direction (K, 3)
        q = np.stack([-sO * ci, cO * ci, np.full_like(cO, si)], -1)      # in-plane normal to it
        cu, su = np.cos(u)[..., None], np.sin(u)[..., None]
        return self.a_m * (cu * p + su * q), self.a_m * n * (-su * p + cu * q)


GPS = WalkerConstellation("GPS", 24, 6, 2, 55.0, 26_560e3)
BEIDOU_MEO = WalkerConstellation("BeiDou MEO", 24, 3, 1, 55.0, 27_906e3)


@dataclass(frozen=True)
class LinkBudget:
    """Simplified L1 link budget (see the module docstring for the sources).

    main_lobe_deg, ssv_deg, side_lobe_deg : half-angles [deg] of the main
    lobe, of the SSV reference beam (with the first side lobes) and of the
    outer side lobes; eirp_main_dbw, side_lobe_drop_db : EIRP [dBW] within
    ssv_deg and the side lobes' level below it [dB]; receive_gain_dbi : the
    receiver antenna's gain [dBi] (a high-gain antenna facing the Earth);
    n0_dbw_hz : noise density [dBW/Hz] (kT, T = 290 K); threshold_dbhz :
    the receiver's tracking threshold C/N0 [dB-Hz] (weak-signal space
    receivers: ~15-20); graze_altitude_m : occultation altitude [m]."""

    main_lobe_deg: float = 21.3
    ssv_deg: float = 23.5
    side_lobe_deg: float = 60.0
    eirp_main_dbw: float = 8.7
    side_lobe_drop_db: float = 10.0
    receive_gain_dbi: float = 10.0
    n0_dbw_hz: float = -204.0
    threshold_dbhz: float = 15.0
    graze_altitude_m: float = 100e3


def gnss_visibility(r, r_gnss, *, mode: str = "sidelobes", budget: LinkBudget = LinkBudget()):
    """Visibility of GNSS transmitters from a receiver.

    r : (N, 3) receiver positions [m]; r_gnss : (N, K, 3) transmitters [m]
    (GCRS); mode : "main", "ssv" or "sidelobes" (module docstring).
    Returns (visible (N, K) bool, off-boresight angle (N, K) [rad], C/N0
    (N, K) [dB-Hz], occulted (N, K) bool)."""
    if mode not in ("main", "ssv", "sidelobes"):
        raise ValueError(f"GNSS reception mode {mode!r} is not allowed; expected 'main', 'ssv' or 'sidelobes'")
    r = np.asarray(r, np.float64)[:, None, :]
    g = np.asarray(r_gnss, np.float64)
    d = r - g
    L = np.linalg.norm(d, axis=-1)
    s = np.clip(-np.einsum("nki,nki->nk", g, d) / L ** 2, 0.0, 1.0)
    closest = np.linalg.norm(g + s[..., None] * d, axis=-1)
    occulted = closest < R_EARTH_EGM2008 + budget.graze_altitude_m
    cos_theta = -np.einsum("nki,nki->nk", g, d) / (np.linalg.norm(g, axis=-1) * L)
    theta = np.arccos(np.clip(cos_theta, -1.0, 1.0))
    th = np.degrees(theta)
    fspl = 20.0 * np.log10(4.0 * np.pi * L * _L1_HZ / C_LIGHT)
    eirp = np.where(th <= budget.ssv_deg, budget.eirp_main_dbw,
                    np.where(th <= budget.side_lobe_deg, budget.eirp_main_dbw - budget.side_lobe_drop_db, -np.inf))
    cn0 = eirp - fspl + budget.receive_gain_dbi - budget.n0_dbw_hz
    if mode == "main":
        ok = th <= budget.main_lobe_deg
    elif mode == "ssv":
        ok = th <= budget.ssv_deg
    else:
        ok = cn0 >= budget.threshold_dbhz
    return ok & ~occulted, theta, cn0, occulted


def pseudorange(t, r, v, constellation: WalkerConstellation = GPS, *, mode: str = "sidelobes",
                budget: LinkBudget = LinkBudget(), shapiro: bool = True) -> Observable:
    """GNSS pseudoranges (without the receiver clock bias) at a receiver.

    t : (N,) reception times [s TT since the epoch]; r, v : (N, 3) receiver
    GCRS position [m] and velocity [m/s] at t; constellation : transmitters
    (a :class:`WalkerConstellation` or anything with its ``states(t)``, e.g.
    :class:`tqdyn.od.gnss_sp3.SP3Constellation`; NaN states are not visible).

    Returns an Observable: value (N, K) = c tau [m] (add the clock bias
    c dt_r (N,) [m] per epoch, e.g. ``simulate(obs, sigma, bias=clock[:, None])``),
    d_r (N, K, 3), d_v (N, K, 3) zeros, visible (N, K); extra ``tau`` [s],
    ``d_clock`` (N, K) ones (partial with respect to c dt_r), ``cn0``
    [dB-Hz], ``off_boresight`` [rad], ``occulted``, ``r_emit`` (N, K, 3).
    """
    t = np.asarray(t, np.float64)
    r = np.asarray(r, np.float64)
    g0, _ = constellation.states(t)
    tau = np.linalg.norm(r[:, None, :] - g0, axis=-1) / C_LIGHT
    for _ in range(4):   # contraction |v_G|/c ~ 1e-5: 4 steps reach float64 resolution
        g = np.empty_like(g0)
        vg = np.empty_like(g0)
        for k in range(g0.shape[1]):
            gk, vk = constellation.states(t - tau[:, k])
            g[:, k], vg[:, k] = gk[np.arange(t.size), k], vk[np.arange(t.size), k]
        D = r[:, None, :] - g
        L = np.linalg.norm(D, axis=-1)
        extra = 0.0
        if shapiro:     # diverges on rays through the Earth's centre (occulted): 0 there
            with np.errstate(divide="ignore", invalid="ignore"):
                extra = np.nan_to_num(shapiro_delay(g, r[:, None, :]), nan=0.0, posinf=0.0)
        tau = L / C_LIGHT + extra
    u = D / L[..., None]
    d_r = C_LIGHT * u / (C_LIGHT - np.einsum("nki,nki->nk", u, vg))[..., None]
    visible, theta, cn0, occ = gnss_visibility(r, g, mode=mode, budget=budget)
    return Observable(C_LIGHT * tau, d_r, np.zeros_like(d_r), visible, "pseudorange", "m",
                      {"tau": tau, "d_clock": np.ones_like(tau), "cn0": cn0, "off_boresight": theta,
                       "occulted": occ, "r_emit": g})
