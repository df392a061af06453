"""The single-link displacement budget of a closed-loop model (docs/tilt-to-length.md): tilt-to-length
from the closed loop's angle jitter, the interferometer readout noise and the TM acceleration noise as
displacement, against each mission's single-link requirement, as an ``xarray.Dataset``.

Units: m/Hz^1/2 (one-sided ASDs), Hz.  Links in LISA Instrument's order (``tqdyn.closedloop.ttl.MOSAS``).
"""

from __future__ import annotations

import math

import numpy as np

from ..closedloop.budget import noise_budget
from ..closedloop.noise import AsdModel
from ..closedloop.ttl import MOSAS, RANDOM_HALF_WIDTH_M_PER_RAD, TTLCoefficients
from ..closedloop.ttl_budget import link_ttl_asd, tm_displacement_asd

__all__ = ["READOUT", "SINGLE_LINK_REQUIREMENT", "single_link_budget", "worst_case_coefficients"]

#: Single-link displacement requirement [m/Hz^1/2] per mission:
#: TianQin 1 pm/Hz^1/2, flat (Luo et al. 2016, CQG 33 035010; S_x = 1e-24 m^2/Hz in Hu et al. 2018,
#: CQG 35 095008); LISA 15 pm/Hz^1/2 sqrt(1 + (2 mHz/f)^4), the single-link optical metrology noise of
#: the LISA science requirements' sensitivity model, P_OMS = (1.5e-11 m)^2 (1 + (2 mHz/f)^4) / Hz as quoted
#: by Robson, Cornish & Liu 2019, CQG 36 105011, eq. 10; Taiji 8 pm/Hz^1/2 (Luo et al. 2020, Results in
#: Physics 16 102918) with LISA's low-frequency shape (an assumption).
SINGLE_LINK_REQUIREMENT = {
    "tianqin": AsdModel(1e-12, (), "m", "requirement"),
    "lisa": AsdModel(15e-12, ((2e-3, -2.0),), "m", "requirement"),
    "taiji": AsdModel(8e-12, ((2e-3, -2.0),), "m", "requirement"),
}
#: Default readout noise of the science interferometer [m/Hz^1/2]: LISA (and Taiji, as LISA) LISA
#: Instrument 2.3's ``oms_asds`` science carrier, 6.35 pm/Hz^1/2 sqrt(1 + (2 mHz/f)^4); TianQin None: the
#: closed loop's ``interferometer`` noise (its displacement requirement, src/tqdyn/data/SOURCES.md).
READOUT = {"lisa": AsdModel(6.35e-12, ((2e-3, -2.0),), "m", "readout"),
           "taiji": AsdModel(6.35e-12, ((2e-3, -2.0),), "m", "readout"), "tianqin": None}


def worst_case_coefficients() -> TTLCoefficients:
    """Every MOSA's linear coefficients at the half-widths of LISA Instrument 2.3's random draw (m/rad):
    2.2 mm/rad local, 2.4 mm/rad distant (the bound of ``ttl_coeffs="random"``)."""
    w = RANDOM_HALF_WIDTH_M_PER_RAD
    return TTLCoefficients.constant(w["local"], w["local"], w["distant"], w["distant"])


def single_link_budget(model, coeffs: TTLCoefficients | None = None, f=None, segment: int = 0,
                       readout: AsdModel | None = None, dt: float | None = None):
    """The single-link displacement budget of segment ``segment`` of a closed-loop model
    (:func:`tqdyn.analysis.closed_loop.closed_loop_model`) as an ``xarray.Dataset`` over (link, source,
    frequency): ``ttl`` the TTL ASD per source (:func:`tqdyn.closedloop.ttl_budget.link_ttl_asd`),
    ``ttl_total``; ``tm_acceleration`` the two TMs' residual acceleration over (2 pi f)^2 per source
    and its total; ``readout`` the science interferometer's readout noise; ``total`` their power sum;
    ``requirement`` :data:`SINGLE_LINK_REQUIREMENT`; ``margin`` requirement / total.  ``coeffs``
    default :func:`worst_case_coefficients`; ``readout`` default :data:`READOUT`; ``dt`` [s] the
    discretised loops' budget.  All m/Hz^1/2, one-sided."""
    import xarray as xr

    s = model.settings
    f = np.logspace(math.log10(s["f_min"]), math.log10(s["f_max"]), s["n_freq"]) if f is None else np.asarray(f)
    n_seg = len(model.loops[0])
    if not (isinstance(segment, int) and 0 <= segment < n_seg):
        raise ValueError(f"segment = {segment!r}: not a segment; allowed: 0 .. {n_seg - 1}")
    coeffs = worst_case_coefficients() if coeffs is None else coeffs
    loops = [model.loops[i][segment][1] for i in range(len(model.loops))]
    theta = [model.parts[i][segment][1].theta for i in range(len(model.loops))]
    ttl, sources = link_ttl_asd(loops, model.noise, f, coeffs, theta, dt)
    acc = np.array([noise_budget(cl, model.noise, f, ["tm1_acceleration", "tm2_acceleration"], dt)[0]
                    for cl in loops])                                    # (3, 2, n_source, n_f)
    tm = tm_displacement_asd(acc, f)                                     # (6, n_source, n_f)
    ro = readout if readout is not None else (READOUT[model.mission] or model.noise["interferometer"])
    ro_asd = np.broadcast_to(ro.asd(f), (6, len(f)))
    ttl_t, tm_t = np.sqrt(np.sum(ttl ** 2, axis=1)), np.sqrt(np.sum(tm ** 2, axis=1))
    total = np.sqrt(ttl_t ** 2 + tm_t ** 2 + ro_asd ** 2)
    req = SINGLE_LINK_REQUIREMENT[model.mission].asd(f)
    S, F = ("link", "source", "frequency"), ("link", "frequency")
    ds = xr.Dataset({"ttl": (S, ttl), "ttl_total": (F, ttl_t), "tm_acceleration": (S, tm),
                     "tm_acceleration_total": (F, tm_t), "readout": (F, ro_asd.copy()), "total": (F, total),
                     "requirement": (("frequency",), req), "margin": (F, req[None, :] / total)},
                    coords={"link": list(MOSAS), "source": sources, "frequency": f},
                    attrs={"mission": model.mission, "asd": "one-sided", "units": "m/Hz^1/2", "frequency_unit": "Hz",
                           "segment": float(model.loops[0][segment][0]),
                           "discretised_dt": float(dt) if dt is not None else 0.0})
    for k in ("ttl", "ttl_total", "tm_acceleration", "tm_acceleration_total", "readout", "total", "requirement"):
        ds[k].attrs["units"] = "m/Hz^1/2"
    return ds
