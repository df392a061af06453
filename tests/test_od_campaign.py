"""Orbit-determination campaigns on Dask (``tqdyn od campaign``, tqdyn.workflows.od_campaign).

A recovery campaign simulates tracking on a truth with 3e-9 m/s^2 of S-frame acceleration along Y_S
injected on every satellite of tianqin-gravity (SLR + ISR over 12 h every 1800 s) and fits the nominal
scenario, one seed per Dask task.  References: the chi-square law of the estimates' normalised errors
(x_hat - x_true)^T P^-1 (x_hat - x_true) of a correct linear(ised) least-squares fit with Gaussian noise,
n degrees of freedom per seed (Tapley, Schutz & Born, "Statistical Orbit Determination", 2004,
section 4.3); the same campaign run undisturbed (for a worker killed mid-campaign: bit-equal results);
tqdyn.od_covariance called directly (for a covariance campaign); the command-line contract (one line,
exit status 2, nothing written, for a campaign with no seeds).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy import stats

from cli_support import run_cli
from dask_support import kill_a_busy_worker
from tqdyn.workflows import od_campaign as oc
from tqdyn.workflows.sweep import read_sweep_netcdf

INJECTED = 3e-9
TRUTH = (f"accelerations.s_frame=[[0.0, {INJECTED}, 0.0], [0.0, {INJECTED}, 0.0], [0.0, {INJECTED}, 0.0]]",)
#: Chi-square acceptance quantiles.
Q_LOW, Q_HIGH = 1e-3, 1.0 - 1e-3


def _spec(tmp, seeds, name="c.nc"):
    return oc.plan_campaign("recovery", "tianqin-gravity", tracking=["slr,isr"], arc=["12h"], seeds=seeds,
                            truth=TRUTH, interval="1800", output=tmp / name)


@pytest.fixture(scope="module")
def twenty(tmp_path_factory):
    """The 20-seed recovery campaign, run undisturbed on a local cluster of 2 workers."""
    d = tmp_path_factory.mktemp("campaign")
    res = oc.run_campaign(_spec(d, 20), n_workers=2, dashboard=None)
    assert not res.failures, res.failures
    return res


def _check_chi2(ds, record_number=None, tag=""):
    chi, dof = float(ds.error_chi2_sum[0, 0, 0]), int(ds.error_chi2_dof[0, 0, 0])
    n = int(ds.sizes["seed"])
    assert dof == 27 * n
    if record_number is not None:
        record_number(f"od.campaign_{tag}_seeds", n)
        record_number(f"od.campaign_{tag}_error_chi2", [chi, dof])
        record_number(f"od.campaign_{tag}_error_chi2_pvalue", float(ds.error_chi2_pvalue[0, 0, 0]))
    assert stats.chi2.ppf(Q_LOW, dof) < chi < stats.chi2.ppf(Q_HIGH, dof), (chi, dof)
    # the injected along-track acceleration is determined: its sigma well below it, its mean near it
    s_y = [k for k, p in enumerate(ds.parameter.values) if p.endswith("/s_y")]
    est = ds.estimate.values[0, 0, 0][:, s_y]
    sig = ds.sigma.values[0, 0, 0][:, s_y]
    assert np.all(sig < INJECTED / 2)
    assert np.all(np.abs(((est - INJECTED) / sig).mean(axis=0)) < 4.0 / np.sqrt(n))
    return chi, dof


def test_recovery_chi_square_over_20_seeds(twenty, record_number):
    """20 seeds on a local Dask cluster: the sum of the 20 x 27 normalised errors lies inside the 1e-3 and
    1 - 1e-3 quantiles of chi-square with 540 degrees of freedom; the file holds the dataset (read back
    with its checksums); a second run of the same campaign skips every member and gives the same file."""
    ds = twenty.dataset
    assert twenty.n_ran == 20 and ds.sizes["seed"] == 20 and bool(ds.ok.all())
    _check_chi2(ds, record_number, "20")
    back = read_sweep_netcdf(twenty.output)
    np.testing.assert_array_equal(back.estimate.values, ds.estimate.values)
    again = oc.run_campaign(_spec(twenty.output.parent, 20), n_workers=2, dashboard=None)
    assert again.n_skipped == 20 and again.n_ran == 0
    np.testing.assert_array_equal(again.dataset.covariance.values, ds.covariance.values)


def _killer(client, state):
    """progress: at the first finished member, SIGKILL a worker process that is running a member."""
    def progress(member, res):
        kill_a_busy_worker(client, state)
    return progress


def test_worker_killed_mid_campaign_loses_nothing(tmp_path, twenty):
    """A worker process SIGKILLed while it runs a member: Dask re-runs the member on the other worker; every
    member succeeds, at least one was re-run, and every number equals the undisturbed campaign's."""
    from distributed import Client, LocalCluster

    spec = _spec(tmp_path, 6)
    state = {}
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None, silence_logs=50) as cluster, Client(cluster) as client:
        res = oc.run_campaign(spec, scheduler=client, progress=_killer(client, state))
    assert state.get("killed"), "no worker was busy to be killed"
    assert not res.failures and len(res.rerun) >= 1
    ref = twenty.dataset.isel(seed=slice(0, 6))
    for var in ("estimate", "sigma", "covariance", "error_chi2", "chi2"):
        np.testing.assert_array_equal(res.dataset[var].values, ref[var].values)
    assert not list(spec.parts.glob(".*.tmp"))


@pytest.mark.parametrize("extra, message", [
    ([], "--seeds: missing; a recovery campaign needs seeds; allowed: a count N >= 1"),
    (["--seeds", "0"], "--seeds: '0' gives no seed; allowed: a count N >= 1"),
    (["--seeds", "5-2"], "--seeds: '5-2' gives no seed; allowed:"),
    (["--seeds", "a"], "--seeds: 'a' is not allowed; allowed:"),
])
def test_a_campaign_with_no_seeds_is_one_line(tmp_path, capsys, extra, message):
    """No seeds (none given, a count of 0, an empty range) or a malformed list: exit status 2, one line on
    stderr naming --seeds and what is allowed; nothing written (no file, no results directory)."""
    out = tmp_path / "c.nc"
    status, _, err = run_cli(["od", "campaign", "recovery", "tianqin-gravity", "--tracking", "slr", "--arc", "1d",
                              "-o", str(out), *extra], capsys)
    assert status == 2 and err.startswith(f"tqdyn: error: {message}") and err.count("\n") == 1, err
    assert list(tmp_path.iterdir()) == []


def test_covariance_campaign_over_plans_and_arcs(tmp_path, capsys):
    """Two plans x two arcs on tianqin-kepler through the command (a local cluster of 1 worker): each cell's
    sigmas equal tqdyn.od_covariance's of the same plan and arc (called directly); --seeds is refused for a
    covariance campaign."""
    import tqdyn

    out = tmp_path / "cov.nc"
    argv = ["od", "campaign", "covariance", "tianqin-kepler", "--tracking", "slr,isr", "--tracking", "gnss,slr,isr",
            "--arc", "12h", "--arc", "1d", "--interval", "1800", "--workers", "1", "-q", "-o", str(out)]
    status, stdout, err = run_cli(argv + ["--seeds", "3"], capsys)
    assert status == 2 and "--seeds: a covariance campaign has no seeds" in err
    status, stdout, err = run_cli(argv, capsys)
    assert status in (0, None), err
    assert "campaign covariance: 4 members: 0 already done, 4 ran, 0 failed" in stdout
    ds = read_sweep_netcdf(out)
    assert list(ds.plan.values) == ["slr,isr", "gnss,slr,isr"] and list(ds.arc_s.values) == [43200.0, 86400.0]
    direct = tqdyn.od_covariance("tianqin-kepler", "gnss,slr,isr", "1d", interval=1800)
    np.testing.assert_array_equal(ds.sigma.values[1, 1, 0], direct.sigma.values)
    status, stdout, _ = run_cli(argv, capsys)
    assert "4 members: 4 already done, 0 ran" in stdout


@pytest.mark.slow
def test_recovery_campaign_of_200_seeds(tmp_path, record_number):
    """200 seeds on a local cluster of 2 workers: the chi-square of the estimates' errors (200 x 27 degrees of
    freedom) inside its 1e-3 quantiles; the distribution of the per-seed values against chi-square with 27
    degrees of freedom (Kolmogorov-Smirnov p > 1e-3); members per minute recorded."""
    res = oc.run_campaign(_spec(tmp_path, 200), n_workers=2, dashboard=None)
    assert not res.failures
    ds = res.dataset
    _check_chi2(ds, record_number, "200")
    per_seed = ds.error_chi2.values[0, 0, 0]
    ks = stats.kstest(per_seed, stats.chi2(27).cdf)
    record_number("od.campaign_200_ks_pvalue", float(ks.pvalue))
    record_number("od.campaign_200_members_per_min", 200 / res.wall_s * 60.0, "1/min")
    record_number("od.campaign_200_wall", res.wall_s, "s")
    assert ks.pvalue > 1e-3
    json.dumps(ds.attrs)
