"""Variational equations (tqdyn.od.variational) and the acceleration parameters
(tqdyn.dynamics.empirical, [accelerations]).

References: the Clohessy-Wiltshire (Hill) solution, exact for the first-order partials of a
circular Kepler orbit; central finite differences of double-double propagations (whose
round-off, ~1e-25 relative, is negligible; the finite-difference truncation error is
measured by halving the step: central differences err by ~ delta^2, so a change d between
steps delta and 2 delta means an error ~ d / 3 at delta).
"""

from __future__ import annotations

import numpy as np
import pytest

from tqdyn.dynamics.empirical import PARAMETER_NAMES
from tqdyn.od.parameters import OrbitParameters, parameter_names
from tqdyn.od.variational import propagate_dd, propagate_with_partials
from tqdyn.scenario import ScenarioError, load_scenario

DAY = 86400.0


def _cw(n, t):
    """Clohessy-Wiltshire STM (6, 6) in the rotating RTN frame (x radial, y along-track,
    z normal) at time t [s] for mean motion n [rad/s]."""
    c, s = np.cos(n * t), np.sin(n * t)
    return np.array([
        [4 - 3 * c, 0, 0, s / n, 2 * (1 - c) / n, 0],
        [6 * (s - n * t), 1, 0, -2 * (1 - c) / n, (4 * s - 3 * n * t) / n, 0],
        [0, 0, c, 0, 0, s / n],
        [3 * n * s, 0, 0, c, 2 * s, 0],
        [-6 * n * (1 - c), 0, 0, -2 * s, 4 * c - 3, 0],
        [0, 0, -n * s, 0, 0, c]])


def _to_rotating(y):
    """(6, 6) map of an inertial perturbation (dr, dv) to the rotating RTN frame of the
    circular orbit through y: (Q^T dr, Q^T (dv - w x dr)), w = (r x v) / r^2."""
    r, v = y[:3], y[3:]
    R = r / np.linalg.norm(r)
    h = np.cross(r, v)
    N = h / np.linalg.norm(h)
    Q = np.stack([R, np.cross(N, R), N], axis=1)
    w = h / (r @ r)
    W = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    M = np.zeros((6, 6))
    M[:3, :3] = Q.T
    M[3:, 3:] = Q.T
    M[3:, :3] = -Q.T @ W
    return M


def test_stm_and_transverse_drift_against_clohessy_wiltshire(record_number):
    """Kepler (tianqin-kepler, circular, a = 1e8 m), 1 day: the STM mapped into the
    rotating frame equals the CW STM, and the sensitivity to a constant transverse
    acceleration equals the CW response x = 2 a/n^2 (n t - sin n t),
    y = a/n^2 (4 (1 - cos n t) - 3/2 n^2 t^2) (the along-track drift -3/2 a t^2)."""
    scen = load_scenario("tianqin-kepler", ["run.duration=1d", "integrator.step=300"])
    t_out = np.array([0.25, 0.5, 1.0]) * DAY
    p = propagate_with_partials(scen, None, t_out)
    gm = float(scen.forces.gm_earth)
    worst_stm = worst_t = 0.0
    y0 = propagate_dd(scen, None, [0.0])[1][0]
    y0 = y0[..., 0] + y0[..., 1]
    for b in range(3):
        n = np.sqrt(gm / np.linalg.norm(y0[b, :3]) ** 3)
        for k, t in enumerate(t_out):
            rot = _to_rotating(p.states[k, b]) @ p.stm[k, b] @ np.linalg.inv(_to_rotating(y0[b]))
            ref = _cw(n, t)
            worst_stm = max(worst_stm, np.max(np.abs(rot - ref)) / np.max(np.abs(ref)))
            sens = p.sensitivities[k, b][:3, PARAMETER_NAMES.index("rtn_t")]
            R = p.states[k, b, :3] / np.linalg.norm(p.states[k, b, :3])
            N = np.cross(p.states[k, b, :3], p.states[k, b, 3:])
            N /= np.linalg.norm(N)
            T = np.cross(N, R)
            x_ref = 2 / n ** 2 * (n * t - np.sin(n * t))
            y_ref = 1 / n ** 2 * (4 * (1 - np.cos(n * t)) - 1.5 * (n * t) ** 2)
            worst_t = max(worst_t, abs(sens @ R - x_ref) / abs(y_ref), abs(sens @ T - y_ref) / abs(y_ref),
                          abs(sens @ N) / abs(y_ref))
    record_number("od.cw_stm_rel", worst_stm)
    record_number("od.cw_transverse_rel", worst_t)
    # the CW solution is exact for the partials of a circular orbit: what is left is the
    # finite-difference Jacobian (~1e-10 relative) and the integration; measured 1.7e-11, 1.1e-10
    assert worst_stm < 1e-10
    assert worst_t < 1e-9


def _fd(scen, t_out, column, delta):
    """Central difference (n, n_sat, 6) of dd states for a perturbation of one parameter
    column (0..5: initial-state component, 6..17: acceleration parameter) of every
    satellite at once (the satellites are independent at zero parameters)."""
    _, y = propagate_dd(scen, None, [0.0])
    y0 = y[0]
    out = []
    for sign in (1.0, -1.0):
        par = OrbitParameters()
        if column < 6:
            yp = y0.copy()
            yp[:, column, 0] += sign * delta
            par.y0 = yp
        else:
            acc = np.zeros((len(scen.satellites), 12))
            acc[:, column - 6] = sign * delta
            par.accelerations = acc
        _, ys = propagate_dd(scen, par, t_out)
        out.append(ys)
    d = (out[0][..., 0] - out[1][..., 0]) + (out[0][..., 1] - out[1][..., 1])
    return d / (2 * delta)


def _rel(partial, fd):
    """Largest relative error over satellites and times, position and velocity rows apart."""
    e = 0.0
    for rows in (slice(0, 3), slice(3, 6)):
        num = np.max(np.abs(partial[..., rows] - fd[..., rows]), axis=-1)
        den = np.max(np.abs(fd[..., rows]), axis=-1)
        e = max(e, float(np.max(num / den)))
    return e


_DELTAS = {"pos": 1.0, "vel": 1e-4, "acc": 1e-10}  # m, m/s, m/s^2


def _check_against_fd(scen, t_out, step, columns, record_number, key, halving=()):
    p = propagate_with_partials(scen, None, t_out, step=step)
    worst, trunc = {}, {}
    for col in columns:
        delta = _DELTAS["pos" if col < 3 else "vel" if col < 6 else "acc"]
        fd = _fd(scen, t_out, col, delta)
        part = p.stm[..., :, col] if col < 6 else p.sensitivities[..., :, col - 6]
        name = ("x", "y", "z", "vx", "vy", "vz")[col] if col < 6 else PARAMETER_NAMES[col - 6]
        worst[name] = _rel(part, fd)
        if col in halving:
            fd2 = _fd(scen, t_out, col, 2 * delta)
            trunc[name] = _rel(fd, fd2) / 3
    record_number(f"od.{key}_fd_rel", max(worst.values()))
    if trunc:
        record_number(f"od.{key}_fd_truncation", max(trunc.values()))
    return worst, trunc


def test_partials_against_finite_differences_tianqin_short(record_number):
    """tianqin-gravity (full geocentric model), 1 day at 600 s: the x and rtn_t columns
    against central differences of dd runs (all columns: the slow 10-day test)."""
    scen = load_scenario("tianqin-gravity", ["run.duration=1d", "integrator.step=600"])
    worst, trunc = _check_against_fd(scen, np.array([0.5, 1.0]) * DAY, None, (0, 10), record_number,
                                     "tianqin_1d", halving=(0,))
    assert max(worst.values()) < 5e-10, worst  # measured 7.3e-11
    assert max(trunc.values()) < 1e-8, trunc  # the reference's own error: far below the bound


def test_partials_against_finite_differences_lisa(record_number):
    """lisa-gravity (heliocentric, Sun + planets), 10 days at the run's 6 h step: every STM
    and parameter column against central differences of dd runs."""
    scen = load_scenario("lisa-gravity", ["run.duration=10d"])
    worst, trunc = _check_against_fd(scen, np.array([5.0, 10.0]) * DAY, None, range(18), record_number,
                                     "lisa_10d", halving=(0, 6))
    assert max(worst.values()) < 1e-7, worst  # measured 1.1e-8
    assert max(trunc.values()) < 1e-8, trunc  # the reference's own error: far below the bound


@pytest.mark.slow
def test_partials_against_finite_differences_tianqin_10d(record_number):
    """tianqin-gravity (full geocentric model), 10 days at 300 s: every STM and parameter
    column within 1e-6 relative of the central differences (measured 4.6e-8, bound 3e-7)."""
    scen = load_scenario("tianqin-gravity", ["run.duration=10d", "integrator.step=300"])
    worst, trunc = _check_against_fd(scen, np.array([5.0, 10.0]) * DAY, None, range(18), record_number,
                                     "tianqin_10d", halving=(0, 3, 9))
    assert max(worst.values()) < 3e-7, worst
    assert max(trunc.values()) < 1e-8, trunc  # the reference's own error: far below the bound


def test_parameters_from_scenario_keys_and_python_agree():
    """[accelerations] keys and OrbitParameters.accelerations give the same dd run; zero keys
    write nothing into the resolved scenario."""
    base = load_scenario("tianqin-kepler", ["run.duration=6h", "integrator.step=600"])
    assert "[accelerations]" not in base.to_toml()
    keyed = load_scenario("tianqin-kepler", [
        "run.duration=6h", "integrator.step=600", "accelerations.rtn=[[0, 1e-9, 0], [0, 0, 0], [0, 0, 0]]",
        "accelerations.s_frame=[[0, 0, 0], [2e-9, 0, 0], [0, 0, 0]]"])
    assert "[accelerations]" in keyed.to_toml()
    acc = np.zeros((3, 12))
    acc[0, 4] = 1e-9
    acc[1, 0] = 2e-9
    _, a = propagate_dd(keyed, None, [6 * 3600.0])
    _, b = propagate_dd(base, OrbitParameters(accelerations=acc), [6 * 3600.0])
    _, c = propagate_dd(base, None, [6 * 3600.0])
    assert np.array_equal(a, b)
    # the along-track displacement of satellite 1 ~ -3/2 a t^2 ~ 0.7 m; satellite 3 untouched
    assert 0.1 < np.linalg.norm(a[0, 0, :3, 0] - c[0, 0, :3, 0]) < 10.0
    assert np.array_equal(a[0, 2], c[0, 2])
    assert parameter_names(keyed)[:2] == ["Sat1/s_x", "Sat1/s_y"]


def test_bad_acceleration_keys_are_one_line():
    """Wrong row counts, S frame without three satellites, coupled runs: one ScenarioError line."""
    with pytest.raises(ScenarioError, match=r"^accelerations.rtn: .* has 2 rows for 3 satellites"):
        load_scenario("tianqin-kepler", ["accelerations.rtn=[[0, 1e-9, 0], [0, 0, 0]]"])
    with pytest.raises(ScenarioError, match=r"^accelerations.rtn_cos: .* acts on point-mass satellites only"):
        load_scenario("tianqin", ["accelerations.rtn_cos=[[0, 1e-9, 0], [0, 0, 0], [0, 0, 0]]"])
    with pytest.raises(ScenarioError, match=r"^accelerations.s_frame: .*wrong shape"):
        load_scenario("tianqin-kepler", ["accelerations.s_frame=[1e-9, 0, 0]"])


def test_s_frame_is_the_global_pointing_frame():
    """The S frame of the parameter accelerations (rows X_S, Y_S, Z_S) equals the global
    law's T_S_I of tqdyn.constellation.attitude at the same positions (to rounding)."""
    from tqdyn.constellation.attitude import attitude
    from tqdyn.dynamics.empirical import s_frame_rows

    _, y = propagate_dd(load_scenario("tianqin-kepler", ["run.duration=6h", "integrator.step=600"]), None, [0.0])
    y = y[0]
    ref = attitude(y[:, :3, 0] + y[:, :3, 1], law="global").T_S_I
    out = np.empty((3, 3))
    for i in range(3):
        s_frame_rows(y, i, out)
        assert np.max(np.abs(out - ref[i])) < 1e-14


def test_coupled_partials_lisa_esa(record_number):
    """lisa-esa (self-gravity toward the constellation centre, which couples the
    satellites), 10 days, with a non-zero S-frame acceleration on every satellite: the full
    STM column of satellite 1's x and the sensitivity to its s_x, all 18 rows, against
    central differences of dd runs perturbing satellite 1 alone."""
    scen = load_scenario("lisa-esa", ["run.duration=10d"])
    acc = np.zeros((3, 12))
    acc[:, 0] = 1e-9
    t_out = np.array([5.0, 10.0]) * DAY
    p = propagate_with_partials(scen, OrbitParameters(accelerations=acc), t_out)
    y0 = propagate_dd(scen, OrbitParameters(accelerations=acc), [0.0])[1][0]
    out = {}
    # larger steps than above: the ramp's direction is float64 in the dd runs too (~1e-25 m/s^2
    # noise, ~1e-13 m in 10 days), and the other satellites' responses are only ~1e-7 of the
    # perturbed one's (the error halves to thirds with each tenfold step: noise, not truncation)
    for name, delta in (("x", 1000.0), ("s_x", 1e-7)):
        ys = []
        for sign in (1.0, -1.0):
            par = OrbitParameters(accelerations=acc.copy())
            if name == "x":
                yp = y0.copy()
                yp[0, 0, 0] += sign * delta
                par.y0 = yp
            else:
                par.accelerations[0, 0] += sign * delta
            ys.append(propagate_dd(scen, par, t_out)[1])
        fd = ((ys[0][..., 0] - ys[1][..., 0]) + (ys[0][..., 1] - ys[1][..., 1])) / (2 * delta)
        part = (p.stm_full[:, :, 0] if name == "x" else p.sensitivities_full[:, :, 0]).reshape(fd.shape)
        out[name] = _rel(part, fd)
        # the other satellites respond too (through the ramp's and the S frame's directions)
        assert np.max(np.abs(fd[:, 1:, :3])) > 1e-8 * np.max(np.abs(fd[:, 0, :3]))
    record_number("od.lisa_esa_coupled_fd_rel", max(out.values()))
    # relative to each satellite's own response: for satellites 2 and 3 that is the ~1e-7
    # coupling itself (measured 7.6e-8, limited by the differences' float64 ramp noise)
    assert max(out.values()) < 3e-7, out
