"""The coupled constellation: attitude + nominal control inside the integrator.

References are independent of the compiled right-hand side:
* the numpy implementations of the attitude (``constellation.attitude``) and
  of the control (``constellation.control``), fed with the propagated states
  and with gravity evaluated separately at the TM positions;
* the three control conditions themselves (paper sec. IV; docs/design.md, Traps 1);
* finite differences of the output frames;
* the pure-gravity propagation (control = "off" must reproduce it bit for bit);
* the free-TM verification mode (TMs as free bodies stay at their EH centers).
Magnitudes are compared with the paper's (sec. V.B) and bounded within ~3x of
the values the README quotes (both sides where a zero would be wrong).
"""

from __future__ import annotations

import numpy as np
import pytest

from tqdyn import cli
from tqdyn.formats import trajectory as io
from tqdyn import dynamics
from tqdyn.workflows import run as runner
from tqdyn.constellation import attitude as att
from tqdyn.constellation import control as ctl
from tqdyn.constellation.spacecraft import TABLE_IV_SELF_GRAVITY, Spacecraft
from tqdyn.scenario import load_scenario
from tqdyn.astro.timescales import Epoch

#: a cheap force model with the same structure (monopole, Moon and Sun in dd,
#: degree-2 Earth field) for the short checks; the full model is the default
#: scenario and is exercised by the CLI tests and the benchmarks.
CHEAP = ["forces.earth_degree=2", "forces.third_bodies=sun,moon", "forces.solid_tides=false",
         "forces.ocean_tides_degree=0", "forces.pole_tides=false", "forces.atmospheric_tides=false",
         "forces.moon_degree=0", "forces.sun_j2=false",
         "forces.relativity=false", "forces.earth_field_indirect=false"]


def _run(tmp_path, name, overrides, duration="2h"):
    scen = load_scenario("tianqin", [f"run.duration={duration}", f"run.output={tmp_path / name}", *overrides])
    summary = runner.run_to_file(scen)
    return scen, io.read_trajectory(summary.path), summary.result


@pytest.fixture(scope="module")
def table_iv_run(tmp_path_factory):
    return _run(tmp_path_factory.mktemp("c"), "tableiv.h5", CHEAP)


@pytest.fixture(scope="module")
def no_sg_run(tmp_path_factory):
    return _run(tmp_path_factory.mktemp("c"), "nosg.h5", CHEAP + ["spacecraft.self_gravity=off"], duration="1d")


def _gravity_at(scen, t_pair, positions_dd, velocities):
    """Total gravity [m/s^2] of the scenario's model at dd positions (n, 3, 2)
    at time t (dd pair): the point-mass right-hand side of tqdyn, evaluated
    separately from the coupled kernel."""
    model = dynamics.check_inputs(scen)
    tdat = model.precompute(Epoch.from_utc(scen.epoch_utc), np.array([t_pair[0]]), np.array([t_pair[1]]))[0]
    y = np.zeros((positions_dd.shape[0], 6, 2))
    y[:, 0:3] = positions_dd
    y[:, 3:6, 0] = velocities
    return dynamics.evaluate_rhs(y, tdat, model)[:, 3:6]


# (the compiled control kernels against the numpy modules: tests/test_mirrors.py)


# ---------------------------------------------------------------------------
# the coupled right-hand side vs the numpy pipeline on propagated states


#: compiled vs numpy on an output row: the README's "T_S_I 5e-16, omega 5e-20 rad/s, A and G 2e-25 m/s^2" and
#: "control conditions 1e-25 m/s^2" are asserted as quoted (measured on rows 0/77/144 of the 2 h run: T_S_I
#: 2.2e-16, omega 6.8e-21 rad/s, A 1.2e-25, G 5.2e-26, condition (a) 7.8e-26 m/s^2); the others 3-10x above
#: the measured omega_dot 1.0e-25 rad/s^2, MOSA angle 1.1e-16 rad, EH centre 5.6e-17 m, alpha 1.3e-25 rad/s^2.
#: a_gravity is the same dd sum rounded once (measured exactly 0): at most 1 ulp of 0.04 m/s^2 (7e-18).
# A, cond_a: float64 round-off of ~1e-10 m/s^2 (ulp 1.3e-26) in two operation orders; it moves by 2x with
# um changes of the orbit (EOP 14 vs 20 C04: A 1.2e-25 vs 2.1e-25, cond_a 0.8e-25 vs 1.1e-25 at row 144)
TOL_ROWS = {"T_S_I": 5e-16, "omega": 5e-20, "omega_dot": 1e-24, "mosa": 5e-16, "tm_r": 3e-16, "a_gravity": 1e-18,
            "A": 3e-25, "G": 2e-25, "alpha": 1e-24, "cond_a": 2e-25}


@pytest.mark.parametrize("row", [0, 77, 144])
def test_coupled_rows_match_numpy_pipeline(table_iv_run, row, record_number):
    """Attitude, differential gravity, suspension, G and TM angular
    acceleration of an output row, recomputed with the numpy modules from
    the row's states and gravity evaluated separately at the TM positions."""
    scen, tr, _ = table_iv_run
    r = tuple(x[row] for x in tr.dd("sat/r"))
    v = tr["sat/v"][row]
    a_tot = tr["sat/a_gravity"][row] + tr["sat/a_dragfree"][row]  # what the orbit follows
    ref = att.attitude(r, v, a_tot, law="global")
    err = {"T_S_I": np.abs(tr["sat/T_S_I"][row] - ref.T_S_I).max(),                 # 1
           "omega": np.abs(tr["sat/omega"][row] - ref.omega).max(),                   # rad/s, |w| 2e-5
           "omega_dot": np.abs(tr["sat/omega_dot"][row] - ref.omega_dot).max(),       # rad/s^2
           "mosa": np.abs(tr["mosa/angle"][row] - ref.mosa_angle).max()}              # rad

    craft = Spacecraft(d_tm=float(scen.spacecraft.d_tm_m), d_p=float(scen.spacecraft.d_p_m))
    r0_I = np.einsum("sji,slj->sli", ref.T_S_I, craft.housing_centers(ref.theta))  # T_I_S r0
    tm_hi, tm_lo = tr.dd("tm/r")
    err["tm_r"] = np.abs((tm_hi[row] - r[0][:, None, :]) + (tm_lo[row] - r[1][:, None, :]) - r0_I).max()  # m
    t_pair = tuple(x[row] for x in tr.dd("t"))
    pos = np.concatenate([np.stack(r, axis=-1), np.stack([tm_hi[row], tm_lo[row]], axis=-1).reshape(6, 3, 2)])
    vel = np.concatenate([v, tr["tm/v"][row].reshape(6, 3)])
    acc = _gravity_at(scen, t_pair, pos, vel)
    # differential gravity in dd, rounded afterwards (no cancellation)
    dg = (acc[3:, :, 0] - acc[:3, None, :, 0].repeat(2, 1).reshape(6, 3)
          + (acc[3:, :, 1] - acc[:3, None, :, 1].repeat(2, 1).reshape(6, 3))).reshape(3, 2, 3)
    err["a_gravity"] = np.abs(tr["sat/a_gravity"][row] - (acc[:3, :, 0] + acc[:3, :, 1])).max()  # m/s^2
    wm, wmd = ctl.mosa_angular_rates(ref.theta_dot, ref.theta_ddot)
    nc = ctl.nominal_control(ref.T_S_I, ref.omega, ref.omega_dot, ref.theta, wm, wmd, dg,
                             Spacecraft(self_gravity=dynamics.self_gravity_oa(scen)))
    # m/s^2; suspension ~1e-10, G ~ 1e-11: agreement at ~1e-16 relative
    err["A"] = np.abs(tr["tm/a_suspension"][row] - nc.a_suspension).max()
    err["G"] = np.abs(tr["sat/a_dragfree"][row] - nc.a_dragfree).max()
    err["alpha"] = np.abs(tr["tm/alpha_suspension"][row] - nc.alpha_suspension).max()  # rad/s^2, as omega_dot
    np.testing.assert_array_equal(tr["tm/self_gravity"], dynamics.self_gravity_oa(scen))

    # the three control conditions, with the compiled A and G and the reference g
    A_S = np.einsum("slji,slj->sli", ctl.oa_rotation(ref.theta), tr["tm/a_suspension"][row])  # T_S_OA A
    G_S = np.einsum("sij,sj->si", ref.T_S_I, tr["sat/a_dragfree"][row])
    err["cond_a"] = np.abs(A_S + nc.g - G_S[:, None, :]).max()                      # (a) G = A_l + g_l
    print(f"\nrow {row}: compiled vs numpy " + ", ".join(f"{k} {x:.1e}" for k, x in err.items()))
    for k, x in err.items():
        assert x <= TOL_ROWS[k], (k, x)
    assert np.all(tr["tm/a_suspension"][row][..., 0] == 0.0)                         # (b) no x actuation
    np.testing.assert_array_equal(tr["tm/a_suspension"][row][:, 0, 2], -tr["tm/a_suspension"][row][:, 1, 2])  # (c)
    record_number(f"coupled.rows_vs_numpy.row{row}", err)


def test_frames_and_pointing_on_trajectory(table_iv_run, record_number):
    _, tr, _ = table_iv_run
    T = tr["sat/T_S_I"]
    err = {"orthonormal": np.abs(T @ np.swapaxes(T, -1, -2) - np.eye(3)).max(),
           "det": np.abs(np.linalg.det(T) - 1.0).max(), "bisect": 0.0, "normal": 0.0, "alpha": 0.0, "mosa": 0.0}
    hi, lo = tr.dd("sat/r")
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        nj = (hi[:, j] - hi[:, i]) + (lo[:, j] - lo[:, i])
        nk = (hi[:, k] - hi[:, i]) + (lo[:, k] - lo[:, i])
        nj /= np.linalg.norm(nj, axis=-1, keepdims=True)
        nk /= np.linalg.norm(nk, axis=-1, keepdims=True)
        X, Z = T[:, i, 0], T[:, i, 2]
        err["bisect"] = max(err["bisect"], np.abs(np.einsum("nq,nq->n", X, nj) - np.einsum("nq,nq->n", X, nk)).max())
        err["normal"] = max(err["normal"], np.abs(np.einsum("nq,nq->n", Z, nj)).max(),
                            np.abs(np.einsum("nq,nq->n", Z, nk)).max())
        alpha = np.arccos(np.clip(np.einsum("nq,nq->n", nj, nk), -1, 1))
        err["alpha"] = max(err["alpha"], np.abs(tr["sat/breathing_angle"][:, i] - alpha).max())   # rad
        err["mosa"] = max(err["mosa"], np.abs(tr["mosa/angle"][:, i, 0] - alpha / 2).max())        # rad
        np.testing.assert_array_equal(tr["mosa/angle"][:, i, 1], -tr["mosa/angle"][:, i, 0])
    print("\nframes on the trajectory: " + ", ".join(f"{k} {x:.1e}" for k, x in err.items()))
    # docs/coupled-dynamics.md; measured 7.8e-16, 8.9e-16, 4.4e-16, 2.2e-16: a few ulp of O(1)
    for key in ("orthonormal", "det", "bisect", "normal"):
        assert err[key] < 1e-15, (key, err[key])
    record_number("coupled.frames_on_trajectory", max(err[k] for k in ("orthonormal", "det", "bisect", "normal")))
    # rad; measured 4.4e-16 (breathing angle, arccos of float64 unit vectors) and 2.2e-16 (MOSA angle)
    assert err["alpha"] < 2e-15 and err["mosa"] < 1e-15, err


@pytest.mark.parametrize("law", ["global", "taylor2", "iterative"])
def test_rates_agree_with_finite_differences(no_sg_run, tmp_path, law, record_number):
    """omega from 5-point differences of T_S_I (50 s grid) and omega_dot from
    5-point differences of omega, along one day of the propagated orbit.
    Truncation h^4 w^5 / 30 ~ 1e-19 rad/s and h^4 n^4 |w_dot| / 30 < 1e-26
    rad/s^2; rounding ~1e-16 / h ~ 3e-18 rad/s (frames) and 4 ulp(2e-5) / h
    ~ 3e-22 rad/s^2 (omega): tolerances 1e-17 and 2e-21."""
    if law == "global":
        _, tr, _ = no_sg_run
    else:  # local laws: the rates must be those of the attitude they produce
        _, tr, _ = _run(tmp_path, "rates.h5", CHEAP + ["spacecraft.self_gravity=off",
                                                       f"constellation.pointing={law}"], duration="1d")
    h = tr.attrs["step_s"]
    T = tr["sat/T_S_I"]
    d5 = lambda x: (x[:-4] - 8 * x[1:-3] + 8 * x[3:-1] - x[4:]) / (12 * h)  # noqa: E731
    dT = d5(T)
    # W[a, b] = e_a . de_b/dt with e = X_S, Y_S, Z_S (rows of T): omega_S =
    # (Z . dY/dt, X . dZ/dt, Y . dX/dt) = (W[2, 1], W[0, 2], W[1, 0])
    W = np.einsum("nsij,nskj->nsik", T[2:-2], dT)
    w_fd = np.stack([W[..., 2, 1], W[..., 0, 2], W[..., 1, 0]], axis=-1)
    err_w = np.abs(w_fd - tr["sat/omega"][2:-2]).max()
    err_wd = np.abs(d5(tr["sat/omega"]) - tr["sat/omega_dot"][2:-2]).max()
    print(f"\n{law}: omega vs 5-point FD {err_w:.1e} rad/s, omega_dot {err_wd:.1e} rad/s^2")
    # the bound derived above; measured global / taylor2 / iterative: 5.8e-18 / 7.6e-18 / 6.3e-18 rad/s and
    # 3.1e-22 / 1.5e-21 / 1.5e-21 rad/s^2
    assert err_w < 1e-17, err_w
    assert err_wd < 2e-21, err_wd
    record_number(f"coupled.rates_vs_fd.{law}", [err_w, err_wd], "rad/s, rad/s^2")


# ---------------------------------------------------------------------------
# magnitudes (paper sec. V.B)


def test_control_magnitudes_without_and_with_self_gravity(no_sg_run, table_iv_run, record_number):
    _, tr0, _ = no_sg_run
    A0 = np.abs(tr0["tm/a_suspension"]).max()
    G0 = np.linalg.norm(tr0["sat/a_dragfree"], axis=-1).max()
    al0 = np.abs(tr0["tm/alpha_suspension"]).max()
    print(f"\nno self-gravity, 1 day: max |A| {A0:.2e} m/s^2, max |G| {G0:.2e} m/s^2, max |alpha| {al0:.2e} rad/s^2")
    # paper: ~1e-13 m/s^2 and ~1e-13 rad/s^2 (Fig. 7); G ~ 1e-13 m/s^2.  Measured (1 day) 1.41e-13 / 1.08e-13 m/s^2 /
    # 3.06e-13 rad/s^2: bounds ~3x either side (none of them vanishes:
    # the breathing, rotating frame S and the gravity differences across the 0.4 m TM baseline need actuation)
    assert 5e-14 < A0 < 4e-13
    assert 3e-14 < G0 < 3e-13
    assert 1e-13 < al0 < 1e-12
    _, tr1, _ = table_iv_run
    A1 = np.abs(tr1["tm/a_suspension"]).max()
    A_S = np.einsum("nslji,nslj->nsli", ctl.oa_rotation(2 * tr1["mosa/angle"][..., 0]), tr1["tm/a_suspension"])
    dA = np.linalg.norm(A_S[:, :, 0] - A_S[:, :, 1], axis=-1).max()
    print(f"Table IV self-gravity: max |A| {A1:.2e} m/s^2, max |A_1 - A_2| (S) {dA:.2e} m/s^2")
    # paper (Fig. 8, sec. V.B.1): ~1e-10 m/s^2, "differential acceleration between the two TMs less
    # than 1e-10": that is the differential-mode actuation of each TM, A_z = +/- dg_z / 2 (eq:E1/E2).
    # The difference A_1 - A_2 itself exceeds 1e-10: Table IV alone gives z: 1.10e-10 + 5.72e-11.
    # Measured 8.36e-11 and 1.75e-10 m/s^2 (docs/coupled-dynamics.md).  Reference: Table IV's z values,
    # dg_z / 2 = 8.36e-11 m/s^2, plus the no-self-gravity control (< 4e-13, above) on top.
    half_dz = (TABLE_IV_SELF_GRAVITY[0, 2] - TABLE_IV_SELF_GRAVITY[1, 2]) / 2
    assert abs(A1 - half_dz) < 1e-12 and A1 < 1e-10
    assert 2 * half_dz - 1e-12 < dA < 2e-10
    record_number("coupled.control_1d", {"A_no_sg": A0, "G_no_sg": G0, "alpha_no_sg": al0, "A_table_iv": A1,
                                         "dA_table_iv": dA})


def test_default_run_control_maxima(default_run):
    """The control maxima of the README's `tqdyn run` (tianqin: full model, Table IV, 10 days), from its file.
    Measured: 6.435e-11 m/s^2, 8.362e-11 m/s^2 and 7.363e-13 rad/s^2 (over 10 days alpha grows as |G| does)."""
    status, _, err, path = default_run
    assert status == 0, err
    tr = io.read_trajectory(path)
    G = np.linalg.norm(tr["sat/a_dragfree"], axis=-1).max()
    A = np.abs(tr["tm/a_suspension"]).max()
    al = np.abs(tr["tm/alpha_suspension"]).max()
    print(f"\ndefault run, 10 days: max |G| {G:.3e} m/s^2, max |A| component {A:.3e} m/s^2, "
          f"max |alpha| component {al:.3e} rad/s^2")
    # Reference for A: Table IV's z difference, dg_z / 2 = 8.36e-11 m/s^2, plus the tidal control (< 1e-12)
    half_dz = (TABLE_IV_SELF_GRAVITY[0, 2] - TABLE_IV_SELF_GRAVITY[1, 2]) / 2
    assert abs(A - half_dz) < 1e-12
    # G: the common part of the Table IV self-gravity the satellite must follow, ~3x either side of 6.43e-11
    assert 2e-11 < G < 2e-10
    # alpha: measured 7.36e-13 rad/s^2, ~3x either side (the rotation of S needs TM angular actuation)
    assert 2.5e-13 < al < 2.5e-12


def test_local_vs_global_pointing_dragfree_difference(tmp_path):
    """README / docs/report.md point 2: taylor2 and global pointing give drag-free accelerations that differ by a
    constant 2.39e-15 m/s^2 along Y_S (X_S 4e-18, Z_S 2e-21 m/s^2), whose secular drift, 3/2 dG T^2, moves the
    orbits apart by 0.217 m in 90 days.  Reference: the tidal model derived there, 3 n^2 (d_TM/2) delta
    cot(theta/2), with delta the measured angle between the two laws' X_S (the aberration angle, 5.77e-6 rad),
    n^2 = GM/r^3 and theta the breathing angle.  1 day, cheap force model (the mechanism is the monopole's
    tide), no self-gravity."""
    sets = CHEAP + ["spacecraft.self_gravity=off"]
    _, glob, _ = _run(tmp_path, "global.h5", sets, duration="1d")
    _, loc, _ = _run(tmp_path, "local.h5", sets + ["constellation.pointing=taylor2"], duration="1d")
    T = glob["sat/T_S_I"]
    dG_S = np.einsum("nsij,nsj->nsi", T, loc["sat/a_dragfree"] - glob["sat/a_dragfree"])
    Xg, Xl = T[:, :, 0], loc["sat/T_S_I"][:, :, 0]
    delta = np.arctan2(np.linalg.norm(np.cross(Xg, Xl), axis=-1), np.einsum("nsk,nsk->ns", Xg, Xl))
    r = np.linalg.norm(glob["sat/r"], axis=-1)
    model = 3 * 3.986004415e14 / r**3 * (0.4 / 2) * delta / np.tan(glob["sat/breathing_angle"] / 2)
    ratio = dG_S[..., 1] / model
    drift_90d = 1.5 * dG_S[..., 1].mean() * (90 * 86400.0) ** 2
    print(f"\nG_taylor2 - G_global in S: Y {dG_S[..., 1].mean():.3e} m/s^2 (model {model.mean():.3e}, ratio "
          f"{ratio.min():.5f}..{ratio.max():.5f}), |X| {np.abs(dG_S[..., 0]).max():.1e}, "
          f"|Z| {np.abs(dG_S[..., 2]).max():.1e}; delta {delta.mean():.3e} rad; 3/2 dG (90 d)^2 = {drift_90d:.3f} m")
    # measured: ratio 0.99989 .. 1.00007; dG_Y 2.389e-15 m/s^2; delta 5.768e-6 rad; 0.217 m
    assert np.abs(ratio - 1).max() < 1e-3
    assert 8e-16 < dG_S[..., 1].min() and dG_S[..., 1].max() < 7e-15      # README 2.39e-15, ~3x either side
    assert 2e-6 < delta.min() and delta.max() < 2e-5                     # README 5.77e-6 rad
    assert 0.07 < drift_90d < 0.65                                       # README 0.217 m
    # the other components: README (30 days, full model) 4e-18 and 2e-21; measured here 7.3e-19 and 1.7e-22
    assert np.abs(dG_S[..., 0]).max() < 2e-17 and np.abs(dG_S[..., 2]).max() < 1e-20


# ---------------------------------------------------------------------------
# switches and verification modes


def test_control_off_is_the_pure_gravity_constellation(tmp_path):
    _, off, _ = _run(tmp_path, "off.h5", CHEAP + ["constellation.control=off"])
    _, pure, _ = _run(tmp_path, "pure.h5", CHEAP + ["constellation.pointing=none", "constellation.control=off"])
    _, on, _ = _run(tmp_path, "on.h5", CHEAP)
    for x, y in zip(off.dd("sat/r"), pure.dd("sat/r")):
        np.testing.assert_array_equal(x, y)
    assert off.attrs["control"] == "off" and pure.attrs["pointing"] == "none" and on.attrs["control"] == "on"
    assert "sat/T_S_I" in off and "sat/T_S_I" not in pure
    # with control on, the orbits move by ~|G| t^2 / 2 (G ~ 5e-11 with Table IV: ~1 mm in 2 h)
    d = np.linalg.norm(on["sat/r"][-1] - pure["sat/r"][-1], axis=-1)
    G = np.linalg.norm(on["sat/a_dragfree"], axis=-1).max(axis=0)
    assert np.all(d < G * 7200.0**2) and np.all(d > 1e-3 * G * 7200.0**2), (d, G)


@pytest.mark.parametrize("law", ["global", "taylor2"])
def test_free_tms_stay_at_their_housing_centers(tmp_path, law, record_number):
    """Free-TM mode: the six TMs are integrated as bodies under gravity at
    their own positions + self-gravity + suspension; the drift from the EH
    centers after one day is the consistency of the control derivation (G
    feedback included), of the attitude rates (for the local laws: the jerk
    model in omega_dot; with the monopole jerk alone the TMs drift 2e-9 m in
    2 days) and of the integration."""
    _, tr, res = _run(tmp_path, "free.h5", CHEAP + ["constellation.free_tms=true", f"constellation.pointing={law}"],
                      duration="1d")
    off = np.linalg.norm(tr["tm/housing_offset"], axis=-1)
    print(f"\nfree TMs, {law}, 1 day: max |TM - EH center| = {off.max():.2e} m")
    # m; the target for 10 days is 1e-12 m.  Measured: global 2.6e-16 m; taylor2 9.8e-14 m: its
    # omega_dot contains the remote jerk / c, and the jerk model leaves out the Earth-rotation jerk of the sectorial
    # degree-2 terms and the CIP tilt of J2 (~1e-13 m/s^3, ~4e-22 rad/s^2, ~7e-23 m/s^2 at the TM).  Bounds ~3-10x
    # either side: an offset of exactly 0 would mean the TMs are not integrated apart from their EH centres, and
    # taylor2 must show the drift its jerk model leaves.
    low, high = (3e-17, 1e-15) if law == "global" else (2e-14, 3e-13)
    assert low < off.max() < high
    record_number(f"coupled.free_tms_1d.{law}", off.max(), "m")
    assert res.y_final.shape == (9, 6, 2)


@pytest.mark.slow  # two 10-day runs of nine bodies on the full model: ~25 s
@pytest.mark.parametrize("law", ["global", "taylor2"])
def test_free_tms_ten_days_full_model(tmp_path, law, record_number):
    """docs/coupled-dynamics.md: free TMs vs their EH centres over 10 days, full model, Table IV (target
    < 1e-12 m); measured global 2.0e-15 m, taylor2 3.6e-13 m.  The default suite checks the same drift over
    one day: both laws on the cheap model (test_free_tms_stay_at_their_housing_centers above) and the global law
    on the full model (tests/test_cli.py::test_checkpoint_resume_bit_identical[free-tms])."""
    _, tr, _ = _run(tmp_path, "free10.h5", ["constellation.free_tms=true", f"constellation.pointing={law}"],
                    duration="10d")
    off = np.linalg.norm(tr["tm/housing_offset"], axis=-1).max()
    print(f"\nfree TMs, {law}, 10 days, full model, Table IV: max |TM - EH center| = {off:.2e} m")
    if law == "global":
        assert 3e-16 < off < 1e-14       # measured 1.96e-15 m
    else:
        # measured 3.63e-13 m; the upper bound is the target 1e-12 m (2.8x), the lower one the drift the taylor2
        # jerk model must leave (see the 1-day test)
        assert 1e-13 < off < 1e-12
    record_number(f"coupled.free_tms_10d.{law}", off, "m")


@pytest.mark.parametrize("override, words", [
    ("spacecraft.d_tm=0", ["spacecraft.d_tm", "d_tm > 0"]),
    ("spacecraft.d_tm=-0.4", ["spacecraft.d_tm", "d_tm > 0"]),
    ("spacecraft.self_gravity=[[1e-10,0,0]]", ["spacecraft.self_gravity", "(2, 3)"]),
    ("spacecraft.self_gravity_common=[1,2]", ["spacecraft.self_gravity_common", "(3,)"]),
    ("constellation.pointing=local", ["constellation.pointing", "iterative"]),
    ("constellation.control=maybe", ["constellation.control", "'on'"]),
    ("spacecraft.tm_axis=w", ["spacecraft.tm_axis", "'y'"]),
])
def test_bad_configuration_is_one_clear_error(tmp_path, capsys, override, words):
    out = tmp_path / "x.h5"
    try:
        status = cli.main(["run", "--duration", "1h", "-o", str(out), "--set", override])
    except SystemExit as exc:
        status = exc.code
    err = capsys.readouterr().err
    assert status == 2 and len(err.strip().splitlines()) == 1, err
    for w in words:
        assert w in err, err
    assert not out.exists()


def test_constellation_needs_three_satellites():
    from tqdyn.scenario import ScenarioError, loads_scenario

    with pytest.raises(ScenarioError, match="^satellites: 1 satellite given; a coupled run .* needs exactly 3"):
        loads_scenario('[constellation]\npointing = "global"\n[[satellites]]\na_km = 1e5\n')


def test_adaptive_mode_matches_fixed(tmp_path):
    """The adaptive driver (dense output on the grid, diagnostics evaluated at
    the interpolated states) agrees with the fixed-step run: positions to the
    ~1e-12 m/day floor of the float64 ephemeris inputs seen at different stage
    times (see the propagation tests), control quantities to ~1e-13 of
    their size."""
    sets = CHEAP + ["spacecraft.self_gravity=off"]
    _, a, _ = _run(tmp_path, "adaptive.h5", sets + ["integrator.mode=adaptive", "integrator.rtol=1e-20"], "6h")
    _, f, _ = _run(tmp_path, "fixed.h5", sets, "6h")
    (ah, al), (fh, fl) = a.dd("sat/r"), f.dd("sat/r")
    assert np.abs((ah - fh) + (al - fl)).max() < 1e-11
    assert np.abs(a["sat/a_dragfree"] - f["sat/a_dragfree"]).max() < 1e-23       # |G| ~ 1e-13 m/s^2
    assert np.abs(a["tm/a_suspension"] - f["tm/a_suspension"]).max() < 1e-23
    np.testing.assert_allclose(a["sat/T_S_I"], f["sat/T_S_I"], rtol=0, atol=1e-15)


@pytest.mark.parametrize("law", ["taylor1", "taylor2", "iterative"])
def test_local_pointing_in_the_loop_matches_post_processing(tmp_path, law, record_number):
    """The attitude integrated with a local pointing law equals the frames
    that constellation.pointing computes afterwards from the propagated
    states (iterative: the light-travel-time equation solved to 1e-20 s on
    the Hermite dense output of the trajectory by tqdyn.lightpath, an
    implementation independent of the compiled Taylor-model solver)."""
    from tqdyn.constellation import pointing as P
    from tqdyn.lightpath import light_travel_times

    _, tr, _ = _run(tmp_path, f"{law}.h5", CHEAP + [f"constellation.pointing={law}"], "2h")
    assert tr.attrs["pointing"] == law
    t, R, V = tr.dd("t"), tr.dd("sat/r"), tr.dd("sat/v")
    A = tr["sat/a_gravity"] + tr["sat/a_dragfree"]
    sl = slice(1, None)  # the first row has no emission time inside the trajectory
    lt = light_travel_times(t, R, V, A, tol=1e-20).select(sl) if law == "iterative" else None
    b = P.beam_directions(law, tuple(x[sl] for x in R), tuple(x[sl] for x in V), A[sl], light_times=lt)
    f = P.pointing_frames(b.n)
    err_T = np.abs(f.T_S_I - tr["sat/T_S_I"][sl]).max()
    err_th = np.abs(0.5 * f.theta - tr["mosa/angle"][sl][..., 0]).max()
    print(f"\n{law}: in-loop vs post-processed attitude {err_T:.1e}, MOSA angle {err_th:.1e} rad")
    # measured 4.4e-16 / 4.4e-16 / 5.6e-16 for T_S_I, 2.2e-16 rad for the MOSA angle; ~4x above
    assert err_T < 2e-15 and err_th < 1e-15
    record_number(f"coupled.in_loop_vs_post.{law}", err_T)


@pytest.mark.slow
def test_ninety_day_acceptance(tmp_path):
    """Issue acceptance over 90 days (full model, ~3 min): the drag-free orbits
    without self-gravity against the pure-gravity orbits, and a common 1e-9
    m/s^2 self-gravity along the flight direction (-Y_S).  References: the
    first-order (Hill) secular along-track drift computed from the stored G
    (report.secular_along_track_drift) and 3/2 f T^2 for a constant
    along-track push.  The paper's "< 1 m" is reported, not asserted: tqdyn
    gives 1.47 m for Sat1 (README, docs/report.md)."""
    from tqdyn.analysis.metrics import breathing_angles_of, orbit_deviation, secular_along_track_drift

    every = ["run.output_every=12", "forces.earth_degree=12"]
    _, grav, _ = _run(tmp_path, "g.h5", every + ["constellation.pointing=none", "constellation.control=off"], "90d")
    _, df, _ = _run(tmp_path, "d.h5", every + ["spacecraft.self_gravity=off"], "90d")
    _, fl, _ = _run(tmp_path, "f.h5", every + ["spacecraft.self_gravity=off",
                                               "spacecraft.self_gravity_common=[0,-1e-9,0]"], "90d")
    # the flight direction is -Y_S: check it on the run rather than assume it
    vS = np.einsum("nsij,nsj->nsi", df["sat/T_S_I"], df["sat/v"]) / np.linalg.norm(df["sat/v"], axis=-1)[..., None]
    assert np.all(vS[..., 1] < -0.9999)
    d = orbit_deviation(df, grav)
    pred = secular_along_track_drift(d.t, df["sat/r"], df["sat/v"], df["sat/a_dragfree"])
    dmax = d.norm.max(axis=0)
    print(f"\ndrag-free vs gravity, 90 d: max |dr| {dmax} m; along-track at 90 d {d.along[-1]} m, "
          f"secular prediction {pred[-1]} m")
    # README: 1.47 / 0.70 / 0.90 m (Sat1/2/3; the paper's "< 1 m" is not reproduced), secular prediction 1.36 m
    # for Sat1.  Bounds 3x either side per satellite: the deviation is the along-track drift of a nonzero mean G
    for s_, quoted in enumerate((1.47, 0.70, 0.90)):
        assert quoted / 3 < dmax[s_] < 3 * quoted, (s_, dmax[s_])
    assert 1.36 / 3 < pred[-1, 0] < 3 * 1.36
    np.testing.assert_allclose(d.along[-1], pred[-1], rtol=0.2, atol=0.05)
    # the mean along-track G of Sat1 (README -6.7e-15 m/s^2, docs/report.md -6.6e-15) and max |G|: 1e-13 on the
    # first day, 4-5.5e-13 m/s^2 over 90 days as the triangle breathes (README)
    r, v, G = df["sat/r"], df["sat/v"], df["sat/a_dragfree"]
    h = np.cross(r, v)
    t_hat = np.cross(h / np.linalg.norm(h, axis=-1, keepdims=True), r / np.linalg.norm(r, axis=-1, keepdims=True))
    G_t = np.einsum("nsk,nsk->ns", G, t_hat)
    G_norm = np.linalg.norm(G, axis=-1)
    day1 = d.t <= 86400.0
    print(f"mean along-track G {G_t.mean(axis=0)} m/s^2; max |G| first day {G_norm[day1].max(axis=0)}, "
          f"90 d {G_norm.max(axis=0)} m/s^2")
    assert -2e-14 < G_t[:, 0].mean() < -2.2e-15
    assert np.all(1.4e-13 < G_norm.max(axis=0)) and np.all(G_norm.max(axis=0) < 1.6e-12)
    assert 3e-14 < G_norm[day1].max() < 4e-13
    # the pure-gravity breathing angles: README / docs/report.md 59.9369 .. 60.0659 deg; the excursion from 60 deg
    # (-0.063 / +0.066 deg) within 3x, and inside the +-0.1 deg requirement
    alpha = np.degrees(breathing_angles_of(grav))
    print(f"gravity-orbit breathing angles {alpha.min():.4f} .. {alpha.max():.4f} deg")
    assert -0.1 < alpha.min() - 60 < -0.021 and 0.022 < alpha.max() - 60 < 0.1
    T = d.t[-1]
    f = orbit_deviation(fl, grav)
    print(f"+flight 1e-9 m/s^2, 90 d: |dr| {f.norm[-1] / 1e3} km; 3/2 f T^2 = {1.5e-9 * T**2 / 1e3:.2f} km")
    # README 90.7 km; reference 3/2 f T^2 (Hill, constant along-track push)
    np.testing.assert_allclose(f.norm[-1], 1.5e-9 * T**2, rtol=0.01)
    # the same-direction push leaves the breathing angles: docs/report.md "change < 1e-4 deg"
    np.testing.assert_array_equal(fl["t"], grav["t"])  # the same 600 s output grid
    dal = np.abs(np.degrees(breathing_angles_of(fl) - breathing_angles_of(grav))).max()
    print(f"+flight breathing-angle change vs gravity orbit: {dal:.2e} deg")
    assert dal < 3e-4


def test_cpu_accounting_of_a_fixed_run():
    """RunResult.cpu_inputs_s / cpu_loop_s (what `tqdyn bench --model coupled`
    reports per simulated day): thread CPU times, so the compiled loop (the
    main thread, between its calls) cannot exceed the run's wall time, and
    both parts are measured (a full-model run has time-only inputs)."""
    scen = load_scenario("tianqin", ["run.duration=1d"])
    res = dynamics.propagate(scen)
    assert 0.0 < res.cpu_inputs_s
    assert 0.0 < res.cpu_loop_s <= res.wall_s * 1.02
    assert res.cpu_inputs_s <= res.wall_s * 1.02  # one worker thread, started after the clock
