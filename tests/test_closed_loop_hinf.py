"""The H-infinity design option (``closed_loop.design = "hinf"``, tqdyn.closedloop.hinf) and the robustness
Monte Carlo (tqdyn.closedloop.robust, tqdyn.workflows.closed_loop_mc).

References: the closed loop's poles are recomputed here from the blocks' matrices (numpy eigenvalues of
the interconnection written out by hand: x' = A x + B u, u = actuators c, c = controller(e), e = sensors y),
not through python-control's interconnect; gamma against the H-infinity norm of the weighted closed loop
(SLICOT ab13dd, unscaled) and against an independent frequency sweep of [W1 S; W2 K S] built
here from the design plant's and the controller's matrices; the margin bound from the weights (a
sensitivity peak of at most gamma M_s); the error lines against docs/reliability.md's rule (one line naming
the key and what is allowed, nothing written).  One synthesis (TianQin's static working point) serves every
test (it is cached by tqdyn.workflows.closed_loop_mc).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from cli_support import error_line, run_cli


@pytest.fixture(scope="module")
def tianqin():
    """{design: (model, controllers)} of TianQin's static working point (one synthesis)."""
    from tqdyn.workflows.closed_loop_mc import _designs

    return _designs("tianqin", ())


def _hinf(tianqin):
    model, k = tianqin["hinf"]
    return model, k


def test_closed_loop_poles_from_the_matrices(tianqin):
    """Every pole of plant + sensors + actuators + H-infinity controller (but the orbit displacement's, which
    no sensor sees) lies left of -eps, the synthesis' axis shift: K_s stabilises G(s - eps), so the true loop's
    poles are the synthesised ones moved left by eps."""
    from tqdyn.closedloop.loop import loop_blocks

    model, k = _hinf(tianqin)
    p, wp = model.parts[0][0]
    b = loop_blocks(p, wp)
    A, B, C, D, pin, pout, pst = b["plant"]
    Ds, sin, sout = b["sensors"]
    Da, ain, aout = b["actuators"]
    # sensors read plant outputs (coordinates: D rows zero) -> Se C x; actuators map c_* to plant inputs
    Se = np.zeros((len(sout), len(pout)))
    for j, s in enumerate(sin):
        if s in pout:
            Se[:, pout.index(s)] = Ds[:, j]
    assert not np.any(Se @ D)
    Ac = np.zeros((len(pin), len(b["channels"])))
    for j, ch in enumerate(b["channels"]):
        Ac[:, j] = [Da[aout.index(u), ain.index(f"c_{ch}")] for u in pin]
    K = k.system
    assert list(K.input_labels) == [f"e_{c}" for c in b["channels"]] == list(sout)
    Ak, Bk, Ck, Dk = (np.asarray(m) for m in (K.A, K.B, K.C, K.D))
    SC = Se @ C
    Acl = np.block([[A + B @ Ac @ Dk @ SC, B @ Ac @ Ck], [Bk @ SC, Ak]])
    keep = [i for i, s in enumerate(pst) if not s.startswith(("u[", "du["))] + list(range(len(pst), len(Acl)))
    ev = np.linalg.eigvals(Acl[np.ix_(keep, keep)])
    assert np.max(ev.real) < -k.shift, np.max(ev.real)
    # the same poles as the package's closed loop
    sys = model.loops[0][0][1].system
    kp = [i for i, s in enumerate(sys.state_labels) if not s.startswith(("plant_u[", "plant_du["))]
    ev2 = np.linalg.eigvals(sys.A[np.ix_(kp, kp)])
    assert len(ev2) == len(ev)
    assert np.max(ev2.real) < -k.shift
    # the same spectrum: the poles beyond 1e-2 rad/s one by one (to 1e-6); the clusters near -eps, -2 eps and the
    # TMs' 1e-3 rad/s (nearly repeated poles, each sensitive as the m-th root of a rounding error) by their
    # number and their mean (the trace of the invariant subspace: its first-order sensitivity to a perturbation
    # dA is ||dA|| ||P|| / n, P the cluster's spectral projector; the two constructions and the eigenvalue solver
    # differ by a few tens of eps ||A||: bound 30 eps ||A|| ||P|| / n, ~1e-8 here; measured 2.3e-9 with the
    # published 1.1e-3 cross-talk, 1.7e-10 with 1e-3)
    e1, e2 = np.sort_complex(ev), np.sort_complex(ev2)
    far1, far2 = np.abs(e1) > 1e-2, np.abs(e2) > 1e-2
    assert np.array_equal(far1, far2) and np.allclose(e2[far2], e1[far1], rtol=1e-6)
    A2 = sys.A[np.ix_(kp, kp)]
    w, V = np.linalg.eig(A2)
    near = np.abs(w) <= 1e-2
    proj = np.linalg.norm(V[:, near] @ np.linalg.inv(V)[near, :], 2)
    tol = 30 * np.finfo(float).eps * np.linalg.norm(A2, 2) * proj / np.count_nonzero(near)
    assert abs(np.mean(e1[~far1]) - np.mean(e2[~far2])) < tol


def test_gamma_is_the_norm_of_the_weighted_closed_loop(tianqin):
    """gamma (SLICOT sb10ad) equals the H-infinity norm of the weighted closed loop it returns (SLICOT ab13dd
    without scaling; python-control 0.10's ``control.norm``, which scales, gives 0.87 for this 102-state loop
    whose poles span 3e-6 to 2e3 rad/s, above the sweep's peak: not used), and the largest singular value of [W1 S; W2 K_s S] (S = (I + G_s K_s)^-1, the shifted
    design plant G_s and K_s = -C(s - eps), built here at each frequency) over a log grid reaches it within the
    grid's resolution (2 %) and never exceeds it."""
    from tqdyn.closedloop.hinf import design_plant, weights

    model, k = _hinf(tianqin)
    assert 0 < k.gamma <= 1
    from slycot import ab13dd

    cl = k.weighted
    norm, _f = ab13dd("C", "I", "N", "D", cl.nstates, cl.ninputs, cl.noutputs, cl.A, np.eye(cl.nstates), cl.B, cl.C,
                      cl.D)
    assert abs(norm / k.gamma - 1) < 1e-3, (norm, k.gamma)
    p, wp = model.parts[0][0]
    G = design_plant(p, wp)
    W1, W2, _w = weights(k.channels)
    Km = k.system
    n = len(k.channels)
    peak = 0.0
    for f in np.logspace(-7, 1, 500):
        s = 2j * math.pi * f
        x = s - k.shift                                  # G_s(s) = G(s - eps), K_s(s) = -C(s - eps)
        g = G.C @ np.linalg.solve(x * np.eye(G.nstates) - G.A, G.B) + G.D
        c = Km.C @ np.linalg.solve(x * np.eye(Km.nstates) - Km.A, Km.B) + Km.D
        S = np.linalg.inv(np.eye(n) - g @ c)
        w1 = np.asarray(W1(s)).reshape(n, n)
        w2 = np.asarray(W2(s)).reshape(n, n)
        M = np.vstack([w1 @ S, -w2 @ c @ S])
        peak = max(peak, np.linalg.svd(M, compute_uv=False)[0])
    assert peak <= k.gamma * (1 + 1e-3)          # ab13dd's peak is gamma (1 + 7e-6); the solves here lose ~1e-4
    assert peak >= 0.98 * k.gamma, (peak, k.gamma)


def test_margins_of_the_hinf_loops(tianqin):
    """Every channel's loop-at-a-time phase margin is at least 2 asin(1 / (2 gamma M_s)) (38 deg for gamma 0.76,
    M_s 2: the bound a sensitivity peak of gamma M_s gives a loop; measured ~81 deg) and every channel crosses
    over once (a finite crossover)."""
    from tqdyn.closedloop.budget import loop_margins
    from tqdyn.closedloop.hinf import PEAK_SENSITIVITY

    model, k = _hinf(tianqin)
    ms = loop_margins(model.loops[0][0][1])
    bound = math.degrees(2 * math.asin(1 / (2 * k.gamma * PEAK_SENSITIVITY)))
    assert len(ms) == 17
    assert all(math.isfinite(m.f_phase_margin) for m in ms)
    assert min(m.phase_margin for m in ms) >= bound


def test_budget_takes_the_synthesised_controller(tianqin):
    """The budget (tqdyn.analysis.closed_loop) evaluates the H-infinity loop as a state-space block: its TM
    acceleration equals the per-loop path's noise_budget of the same loop (one source at 1 mHz), margins
    for all 17 channels."""
    from tqdyn.analysis.closed_loop import closed_loop_budget
    from tqdyn.closedloop.budget import noise_budget

    model, _k = _hinf(tianqin)
    f = np.array([1e-3, 1e-2])
    ds = closed_loop_budget(model, f=f, per_source=False)
    b, _src = noise_budget(model.loops[0][0][1], model.noise, f, outputs=["tm1_acceleration"])
    assert np.allclose(ds.total.sel(output="tm1_acceleration").values[0, 0], np.sqrt(np.sum(b[0] ** 2, axis=0)),
                       rtol=1e-12)
    assert ds.phase_margin.shape == (1, 1, 17) and np.all(np.isfinite(ds.phase_margin.values))


def test_small_monte_carlo(tianqin):
    """Two draws, both designs, in this process: every draw of the nominal-stable designs stays stable under
    the draws' spreads, the ratios are positive, the dataset carries the draws and gamma."""
    import json

    from tqdyn.workflows.closed_loop_mc import monte_carlo, summarise

    ds = monte_carlo("tianqin", 2, seed=1, workers=0)
    assert ds.requirement_ratio.dims == ("design", "sample") and ds.sizes["sample"] == 2
    assert list(ds.design.values) == ["per_loop", "hinf"]
    assert ds.stable.values.all()
    assert np.all(ds.requirement_ratio.values > 0)
    assert ds.stiffness.shape == (2, 2, 3) and ds.actuator_gain.shape == (2, 20)
    assert json.loads(ds.attrs["gamma"])["hinf"] == tianqin["hinf"][1].gamma
    s = summarise(ds)
    assert s["hinf"]["stable_fraction"] == 1.0 and s["per_loop"]["requirement_ratio"]["p05"] > 0


def test_unmeetable_weights_and_schemes_refused(tmp_path, capsys):
    """A scheme without the design (LISA Pathfinder's collinear one) and an unknown design name: one line
    naming closed_loop.design and what is allowed, nothing written; --monte-carlo without a mission: one line."""
    out = tmp_path / "cl.h5"
    status, _o, err = run_cli(["closed-loop", "--mission", "lpf", "-q", "-o", str(out), "--set",
                               "closed_loop.design=hinf"], capsys)
    error_line(status, err, "closed_loop.design", "'collinear'", "allowed")
    status, _o, err = run_cli(["closed-loop", "--mission", "tianqin", "-q", "-o", str(out), "--set",
                               "closed_loop.design=lqg"], capsys)
    error_line(status, err, "closed_loop.design", "hinf", "per_loop")
    status, _o, err = run_cli(["closed-loop", "-q", "-o", str(tmp_path / "mc.nc"), "--monte-carlo", "2"], capsys)
    error_line(status, err, "--monte-carlo", "--mission")
    assert not list(tmp_path.iterdir())


def test_weights_that_cannot_be_met(tianqin):
    """An actuator authority of 3x the bandwidth leaves gamma > 1 (30x gives ~0.76): refused in one line naming
    closed_loop.design, gamma and the weights' keys."""
    from tqdyn.closedloop.budget import DesignError
    from tqdyn.closedloop.hinf import synthesise

    model, _k = _hinf(tianqin)
    p, wp = model.parts[0][0]
    with pytest.raises(DesignError) as exc:
        synthesise(p, wp, where="tianqin", authority_ratio=3.0)
    msg = str(exc.value)
    assert msg.startswith("closed_loop.design: ") and "gamma" in msg and "hinf_authority_ratio = 3" in msg
    assert "\n" not in msg and len(msg) <= 200


def test_monte_carlo_command_on_a_local_cluster(tianqin, tmp_path, capsys):
    """``tqdyn closed-loop --mission tianqin --monte-carlo 1 --workers 1``: the draws run as Dask tasks on a
    one-worker local cluster; the netCDF file holds both designs' results and the draw, the same numbers as
    the in-process evaluation of the same seed (the reference: workers=0)."""
    import xarray as xr

    from tqdyn.workflows.closed_loop_mc import monte_carlo

    out = tmp_path / "mc.nc"
    status, stdout, err = run_cli(["closed-loop", "--mission", "tianqin", "--monte-carlo", "1", "--workers", "1",
                                   "--seed", "3", "-q", "-o", str(out)], capsys)
    assert status == 0, err
    assert "hinf: stable 100%" in stdout and out.exists()
    ds = xr.open_dataset(out)
    ref = monte_carlo("tianqin", 1, seed=3, workers=0)
    assert np.allclose(ds.requirement_ratio.values, ref.requirement_ratio.values, rtol=1e-12)
    assert ds.attrs["scheduler"] == "local" and ds.crosstalk.shape == (1,)
    ds.close()


def test_file_configuration_records_the_synthesised_controllers(tianqin):
    """The closed-loop file's configuration (tqdyn.workflows.closed_loop.resolved_configuration) of an
    H-infinity model names what ran: per satellite the controller's order and gamma as the synthesis returned
    them (HinfController, the reference) and its bandwidths; without controllers there is no ``hinf`` key."""
    import json

    from tqdyn.scenario.loader import closed_loop_config
    from tqdyn.workflows.closed_loop import resolved_configuration

    model, _ = _hinf(tianqin)
    cfg = closed_loop_config({"mission": "tianqin", "design": "hinf"}, ())
    conf = json.loads(json.dumps(resolved_configuration(cfg, "tianqin", dict(model.settings), model.hinf)))
    assert len(conf["hinf"]) == len(model.hinf) > 0
    for rec, k in zip(conf["hinf"], model.hinf):
        assert rec["order"] == k.system.nstates and rec["gamma"] == k.gamma < 1
        assert len(rec["bandwidth_hz"]) == len(k.channels)
    assert "hinf" not in resolved_configuration(cfg, "tianqin", dict(model.settings))
