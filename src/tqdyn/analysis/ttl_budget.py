"""The single-link displacement budget of a closed-loop model (docs/tilt-to-length.md): tilt-to-length
from the closed loop's angle jitter, the interferometer readout noise and the TM acceleration noise as
displacement, against each mission's single-link requirement, as an ``xarray.Dataset``.

Units: m/Hz^1/2 (one-sided ASDs), Hz.  Links in LISA Instrument's order (``tqdyn.ttl.coupling.MOSAS``).
"""

from __future__ import annotations

import math

import numpy as np

from ..closedloop.budget import dominant_sources, noise_budget
from ..closedloop.noise import AsdModel
from ..ttl.coupling import MOSAS, RANDOM_HALF_WIDTH_M_PER_RAD, TTLCoefficients
from ..ttl.budget import link_ttl_asd, tm_displacement_asd

__all__ = ["READOUT", "SINGLE_LINK_REQUIREMENT", "SUMMARY_BANDS_HZ", "SUMMARY_BAND_HZ", "SUMMARY_FREQUENCIES_HZ",
           "TTL_ALLOCATION", "link_budget_summary", "single_link_budget", "ttl_budget_values",
           "worst_case_coefficients"]

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

#: Frequencies [Hz] at which :func:`link_budget_summary` quotes the ASDs.
SUMMARY_FREQUENCIES_HZ = (1e-3, 1e-2)
#: The band [Hz] of the summary's worst margin, largest TTL, dominant TTL source and TTL-over-readout band.
SUMMARY_BAND_HZ = (1e-4, 1.0)
#: The decades [Hz] of the summary's dominant TTL source per band.
SUMMARY_BANDS_HZ = ((1e-4, 1e-3), (1e-3, 1e-2), (1e-2, 1e-1), (1e-1, 1.0))
#: The TTL left after subtraction [m/Hz^1/2, flat] to which the summary compares the TTL (missions with one):
#: TianQin 0.3 pm/Hz^1/2, the reference curve for the TTL residual after subtraction of Wang et al. 2024,
#: "Postprocessing of tilt-to-length noise with coefficient drifts in TianQin using a null time-delay
#: interferometry channel", arXiv:2410.20121 (also Fang et al. 2025, arXiv:2510.17499).
TTL_ALLOCATION = {"tianqin": 0.3e-12}
#: The random draw of :func:`ttl_budget_values` (``TTLCoefficients.random(seed)``).
RANDOM_SEED = 1


def worst_case_coefficients() -> TTLCoefficients:
    """Every MOSA's linear coefficients at the half-widths of LISA Instrument 2.3's random draw (m/rad):
    2.2 mm/rad local, 2.4 mm/rad distant (the bound of ``ttl_coeffs="random"``)."""
    w = RANDOM_HALF_WIDTH_M_PER_RAD
    return TTLCoefficients.constant(w["local"], w["local"], w["distant"], w["distant"])


def single_link_budget(model, coeffs: TTLCoefficients | None = None, f=None, segment: int = 0,
                       readout: AsdModel | None = None, dt: float | None = None):
    """The single-link displacement budget of segment ``segment`` of a closed-loop model
    (:func:`tqdyn.closedloop.model.closed_loop_model`) as an ``xarray.Dataset`` over (link, source,
    frequency): ``ttl`` the TTL ASD per source (:func:`tqdyn.ttl.budget.link_ttl_asd`),
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


def _argmax_in(x, m):
    return int(np.argmax(np.where(m, x, -np.inf)))


def link_budget_summary(ds, points, band=SUMMARY_BAND_HZ, bands=SUMMARY_BANDS_HZ,
                        allocation: float | None = None) -> dict:
    """Per link, the numbers of a single-link budget ``ds`` (:func:`single_link_budget` on a frequency grid)
    and ``points`` (the same on a few named frequencies), as JSON-ready floats and strings:

    * ``frequencies_hz``, ``requirement``, ``readout`` [m/Hz^1/2] at ``points``' frequencies; ``band_hz``;
    * ``links[link]``: ``ttl``, ``tm_acceleration``, ``total`` [m/Hz^1/2] and ``margin`` (requirement /
      total) at those frequencies; ``worst_margin`` (the smallest margin on the grid in ``band``),
      ``worst_margin_f_hz``, ``ttl_at_worst_margin``, ``total_at_worst_margin`` and ``worst_margin_limited_by``
      (the largest term there: ``ttl``, ``tm_acceleration`` or ``readout``); ``ttl_max`` and
      ``ttl_max_f_hz``; ``ttl_over_requirement_max`` (the factor by which subtraction must reduce the TTL to
      bring it to the requirement) and its frequency; ``ttl_over_allocation_max`` (the same against a flat
      ``allocation`` [m/Hz^1/2], None without one); ``dominant_source`` (the source with the largest mean TTL
      power in ``band``) and its ``dominant_source_share`` of that power; ``dominant_by_band`` (per band of
      ``bands``, :func:`tqdyn.closedloop.budget.dominant_sources`); ``ttl_exceeds_readout_hz`` [f_lo, f_hi]
      (the lowest and highest grid frequencies in ``band`` where the TTL exceeds the readout noise, None if
      nowhere) and ``ttl_exceeds_readout_throughout`` (it does at every grid point between them);
    * ``worst_link``: the link with the largest ``ttl_over_requirement_max``."""
    f = ds["frequency"].values
    m = (f >= band[0]) & (f <= band[1])
    if not np.any(m):
        raise ValueError(f"band = {tuple(band)!r}: holds no frequency of the budget's grid "
                         f"({f[0]:.3g} .. {f[-1]:.3g} Hz); allowed: a band (f_lo, f_hi) [Hz] that overlaps it")
    if allocation is not None and not (math.isfinite(allocation) and allocation > 0):
        raise ValueError(f"allocation = {allocation!r}: must be a finite ASD > 0 (m/Hz^1/2) or None")
    sources = [str(x) for x in ds["source"].values]
    band_names = [f"{lo:g}-{hi:g} Hz" for lo, hi in bands]
    req = ds["requirement"].values
    out = {"frequencies_hz": points["frequency"].values.tolist(), "band_hz": [float(band[0]), float(band[1])],
           "requirement": points["requirement"].values.tolist(), "readout": points["readout"].values[0].tolist(),
           "allocation": allocation, "links": {}}
    for n, link in enumerate(str(x) for x in ds["link"].values):
        ttl, tot, ro = ds["ttl_total"].values[n], ds["total"].values[n], ds["readout"].values[n]
        tm = ds["tm_acceleration_total"].values[n]
        k = int(np.argmin(np.where(m, ds["margin"].values[n], np.inf)))
        kt = _argmax_in(ttl, m)
        r = ttl / req
        kr = _argmax_in(r, m)
        power = np.mean(ds["ttl"].values[n][:, m] ** 2, axis=1)
        j = int(np.argmax(power))
        dom = dominant_sources(ds["ttl"].values[n][None], sources, f, bands)[0]
        over = m & (ttl > ro)
        idx = np.flatnonzero(over)
        terms = {"ttl": ttl[k], "tm_acceleration": tm[k], "readout": ro[k]}
        out["links"][link] = {
            "ttl": points["ttl_total"].values[n].tolist(),
            "tm_acceleration": points["tm_acceleration_total"].values[n].tolist(),
            "total": points["total"].values[n].tolist(), "margin": points["margin"].values[n].tolist(),
            "worst_margin": float(ds["margin"].values[n, k]), "worst_margin_f_hz": float(f[k]),
            "ttl_at_worst_margin": float(ttl[k]), "total_at_worst_margin": float(tot[k]),
            "worst_margin_limited_by": max(terms, key=terms.get),
            "ttl_max": float(ttl[kt]), "ttl_max_f_hz": float(f[kt]),
            "ttl_over_requirement_max": float(r[kr]), "ttl_over_requirement_f_hz": float(f[kr]),
            "ttl_over_allocation_max": float(np.max(ttl[m]) / allocation) if allocation else None,
            "dominant_source": sources[j], "dominant_source_share": float(power[j] / np.sum(power)),
            "dominant_by_band": dict(zip(band_names, dom)),
            "ttl_exceeds_readout_hz": [float(f[idx[0]]), float(f[idx[-1]])] if idx.size else None,
            "ttl_exceeds_readout_throughout": bool(idx.size and np.all(over[idx[0]:idx[-1] + 1])),
        }
    out["worst_link"] = max(out["links"], key=lambda x: out["links"][x]["ttl_over_requirement_max"])
    return out


def ttl_budget_values(model, frequencies=SUMMARY_FREQUENCIES_HZ, band=SUMMARY_BAND_HZ, seed: int | None = RANDOM_SEED,
                      segment: int = 0, dt: float | None = None) -> tuple[dict, object]:
    """The single-link budget of a closed-loop model as the closed-loop report gives it: (values, ds).

    ``ds``: :func:`single_link_budget` with the worst-case coefficients (:func:`worst_case_coefficients`) on
    the model's frequency grid; ``values``: :func:`link_budget_summary` of it at ``frequencies`` [Hz] and in
    ``band`` [Hz] (against :data:`TTL_ALLOCATION` of the mission), with ``coefficients`` (their description,
    ``local_m_per_rad``, ``distant_m_per_rad``) and, unless ``seed`` is None, ``random``: the same summary
    (``seed``, ``worst_link``, ``ttl_over_requirement_range`` [smallest, largest] over the links, per link
    ``ttl`` at ``frequencies``, ``ttl_max``, ``ttl_max_f_hz``, ``ttl_over_requirement_max``,
    ``dominant_source``) for the coefficients ``TTLCoefficients.random(seed)`` (LISA Instrument's uniform
    draw within those half-widths).  Units: m/Hz^1/2, Hz, m/rad."""
    fq = np.atleast_1d(np.asarray(frequencies, dtype=np.float64))
    if fq.ndim != 1 or not np.all(np.isfinite(fq) & (fq > 0)):
        raise ValueError(f"frequencies = {frequencies!r}: must be finite frequencies > 0 (Hz)")
    w = RANDOM_HALF_WIDTH_M_PER_RAD
    ds = single_link_budget(model, segment=segment, dt=dt)
    allocation = TTL_ALLOCATION.get(model.mission)
    values = {"coefficients": ("worst case: every MOSA's linear coefficients (phi and eta, local and distant) at "
                               "the half-widths of LISA Instrument 2.3's random draw"),
              "local_m_per_rad": w["local"], "distant_m_per_rad": w["distant"],
              **link_budget_summary(ds, single_link_budget(model, f=fq, segment=segment, dt=dt), band,
                                    allocation=allocation)}
    if seed is not None:
        c = TTLCoefficients.random(seed)
        rd = single_link_budget(model, c, segment=segment, dt=dt)
        rs = link_budget_summary(rd, single_link_budget(model, c, f=fq, segment=segment, dt=dt), band,
                                 allocation=allocation)
        keep = ("ttl", "ttl_max", "ttl_max_f_hz", "ttl_over_requirement_max", "dominant_source")
        ratios = [v["ttl_over_requirement_max"] for v in rs["links"].values()]
        values["random"] = {"seed": int(seed), "worst_link": rs["worst_link"],
                            "ttl_over_requirement_range": [min(ratios), max(ratios)],
                            "links": {k: {q: v[q] for q in keep} for k, v in rs["links"].items()}}
    return values, ds
