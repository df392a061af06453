"""Reliability of `tqdyn sweep` (issue 14: items 5-8, the sweep part).

The faults are made here: an output_dir that is a file, a scheduler port
nobody listens on, a worker process killed with SIGKILL in the middle of a
sweep (on a LocalCluster and on a `dask scheduler` + `dask worker` cluster
started as subprocesses), bytes flipped inside the written netCDF file.
TLS: certificates made with the openssl command (self-signed CA), a real
`dask scheduler --protocol tls` cluster.  Reference: the same sweep run
undisturbed; member results must be identical (bit for bit: hi + lo).
"""

from __future__ import annotations

import json
import os
import shutil
import socket
import subprocess
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
import xarray as xr

from cli_support import run_cli
from dask_support import kill_a_busy_worker
from test_sweep import SIX_DIRECTIONS, _CHEAP, _toml_list
from tqdyn.workflows import sweep as sw

SRC = str(Path(__file__).resolve().parents[1] / "src")

TWO = f"""
[sweep]
name = "two"
scenario = "tianqin"
output_dir = "two-out"
set = {_toml_list(_CHEAP)}

[[sweep.parameter]]
key = "satellites.1.a_km"
values = [100000.0, 100001.0]
"""


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _env():
    env = dict(os.environ)
    env["PYTHONPATH"] = SRC + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    return env


# --------------------------------------------------------------------------- (5) one line, nothing written


def test_output_dir_that_is_a_file_gives_one_line(tmp_path, capsys):
    (tmp_path / "sg-out").write_text("not a directory")
    path = tmp_path / "s.toml"
    path.write_text(SIX_DIRECTIONS)
    status, out, err = run_cli(["sweep", str(path), "-q"], capsys)
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("tqdyn: error: sweep.output_dir:") and "not a directory" in err
    assert (tmp_path / "sg-out").read_text() == "not a directory"


def test_unreachable_scheduler_gives_one_line_and_no_folder(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text(SIX_DIRECTIONS)
    addr = f"tcp://127.0.0.1:{_free_port()}"
    t0 = time.perf_counter()
    status, out, err = run_cli(["sweep", str(path), "-q", "--scheduler", addr, "--connect-timeout", "1"], capsys)
    # not a speed claim: the wait ends after --connect-timeout (1 s), not the default 10 s (~2 s in all measured)
    assert time.perf_counter() - t0 < 9
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith(f"tqdyn: error: scheduler: {addr!r} cannot be reached")
    assert not (tmp_path / "sg-out").exists()


@pytest.mark.parametrize("argv, fragment", [
    (["--dashboard", "nohost"], "--dashboard: 'nohost' is not an address"),
    (["--scheduler", "tcp://x:1", "--dashboard", "off"], "--dashboard: applies to the local cluster only"),
    (["--tls-ca-file", "ca.pem"], "apply to a remote --scheduler only"),
    (["--scheduler", "tls://127.0.0.1:1", "--tls-ca-file", "/nonexistent.pem", "--tls-cert", "/x.pem"],
     "--tls-ca-file: '/nonexistent.pem' is not a readable file"),
    (["--scheduler", "tls://127.0.0.1:1"], "is a tls:// address but no TLS certificates are configured"),
    (["--scheduler", "tcp://127.0.0.1:1", "--connect-timeout", "nan"], "--connect-timeout: nan is not a duration"),
])
def test_bad_connection_options_one_line(tmp_path, capsys, argv, fragment):
    path = tmp_path / "s.toml"
    path.write_text(SIX_DIRECTIONS)
    status, out, err = run_cli(["sweep", str(path), "-q", *argv], capsys)
    assert status == 2 and out == "" and err.count("\n") == 1 and fragment in err, err
    assert not (tmp_path / "sg-out").exists()


# --------------------------------------------------------------------------- (6) loopback dashboard, TLS


def test_local_cluster_listens_on_loopback_only():
    with sw.dask_client(None, 1, 1) as client:
        assert client.scheduler.address.startswith("tcp://127.0.0.1:")
        link = client.dashboard_link
        assert link.startswith("http://127.0.0.1:"), link
        for w in client.scheduler_info()["workers"]:
            assert w.startswith("tcp://127.0.0.1:")
        assert _http_status(link) == 200
    with sw.dask_client(None, 1, 1, dashboard=None) as client:
        link = client.dashboard_link  # the scheduler's plain HTTP routes, no dashboard
        assert link.startswith("http://127.0.0.1:") and not link.startswith("http://127.0.0.1:8787/"), link
        assert _http_status(link) == 404


def _http_status(url):
    import urllib.error
    import urllib.request

    try:
        with urllib.request.urlopen(url, timeout=10) as r:
            return r.status
    except urllib.error.HTTPError as exc:
        return exc.code


def test_tls_options_build_the_security_passed_to_client(tmp_path, monkeypatch):
    import distributed
    from distributed.security import Security

    for name in ("ca.pem", "cert.pem", "key.pem"):
        (tmp_path / name).write_text("-----BEGIN CERTIFICATE-----\n")
    sec = sw.make_security(tmp_path / "ca.pem", tmp_path / "cert.pem", tmp_path / "key.pem")
    assert isinstance(sec, Security) and sec.require_encryption
    assert (sec.tls_ca_file, sec.tls_client_cert, sec.tls_client_key) == \
        tuple(str(tmp_path / n) for n in ("ca.pem", "cert.pem", "key.pem"))
    assert sw.make_security() is None
    seen = {}

    class FakeClient:
        def __init__(self, address, **kwargs):
            seen.update(kwargs, address=address)

    monkeypatch.setattr(distributed, "Client", FakeClient)
    sw.connect("tls://host:8786", security=sec, timeout=3)
    assert seen == {"address": "tls://host:8786", "security": sec, "timeout": 3}


def _make_certs(d: Path) -> dict:
    """A self-signed CA and a certificate it signs for 127.0.0.1 (openssl command)."""
    def ossl(*args):
        subprocess.run(["openssl", *args], cwd=d, check=True, capture_output=True)

    ossl("req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", "ca.key", "-out", "ca.pem", "-days", "2",
         "-subj", "/CN=tqdyn-test-ca")
    (d / "ext.cnf").write_text("subjectAltName=IP:127.0.0.1,DNS:localhost\n")
    ossl("req", "-newkey", "rsa:2048", "-nodes", "-keyout", "node.key", "-out", "node.csr", "-subj", "/CN=127.0.0.1")
    ossl("x509", "-req", "-in", "node.csr", "-CA", "ca.pem", "-CAkey", "ca.key", "-CAcreateserial", "-out",
         "node.pem", "-days", "2", "-extfile", "ext.cnf")
    return {"ca": d / "ca.pem", "cert": d / "node.pem", "key": d / "node.key"}


def _start_cluster(tmp_path, n_workers=1, tls=None, nanny=True):
    """`dask scheduler` + `dask worker` subprocesses; returns (address, scheduler proc, worker procs)."""
    sf = tmp_path / "scheduler.json"
    tls_args = [] if tls is None else ["--tls-ca-file", str(tls["ca"]), "--tls-cert", str(tls["cert"]),
                                       "--tls-key", str(tls["key"])]
    sched = subprocess.Popen([shutil.which("dask"), "scheduler", "--host", "127.0.0.1", "--port", "0",
                              "--no-dashboard", "--scheduler-file", str(sf),
                              *(["--protocol", "tls"] if tls else []), *tls_args],
                             env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    t0 = time.time()
    while not sf.exists() or not sf.read_text().strip():
        assert time.time() - t0 < 30 and sched.poll() is None, "dask scheduler did not start"
        time.sleep(0.1)
    time.sleep(0.2)
    address = json.loads(sf.read_text())["address"]
    workers = [subprocess.Popen([shutil.which("dask"), "worker", address, "--nthreads", "1", "--no-dashboard",
                                 "--host", "127.0.0.1", "--nanny" if nanny else "--no-nanny", *tls_args],
                                env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
               for _ in range(n_workers)]
    return address, sched, workers


def _stop(procs):
    for p in procs:
        if p.poll() is None:
            p.terminate()
    for p in procs:
        try:
            p.wait(10)
        except subprocess.TimeoutExpired:
            p.kill()


def _wait_workers(client, n, timeout=60):
    client.wait_for_workers(n, timeout=timeout)


@pytest.mark.slow  # 9-55 s measured (a fresh worker process may compile the kernels)
@pytest.mark.skipif(shutil.which("openssl") is None or shutil.which("dask") is None, reason="needs openssl, dask")
def test_sweep_on_a_tls_cluster(tmp_path, capsys):
    certs = _make_certs(tmp_path)
    address, sched, workers = _start_cluster(tmp_path, 1, tls=certs)
    try:
        assert address.startswith("tls://")
        from distributed import Client

        with Client(address, security=sw.make_security(certs["ca"], certs["cert"], certs["key"]), timeout=20) as c:
            _wait_workers(c, 1)
        path = tmp_path / "two.toml"
        path.write_text(TWO)
        # without certificates: refused up front, one line, nothing written
        status, out, err = run_cli(["sweep", str(path), "-q", "--scheduler", address], capsys)
        assert status == 2 and err.count("\n") == 1 and not (tmp_path / "two-out").exists()
        status, out, err = run_cli(["sweep", str(path), "-q", "--scheduler", address, "--tls-ca-file",
                                    str(certs["ca"]), "--tls-cert", str(certs["cert"]), "--tls-key",
                                    str(certs["key"])], capsys)
        assert status == 0, err
        assert "2 members: 0 already done, 2 ran, 0 failed" in out and f"cluster at {address}" in err
    finally:
        _stop([*workers, sched])


# --------------------------------------------------------------------------- (7) a worker killed mid-sweep


def _killer(client, state):
    """progress callback: at the first finished member, SIGKILL a worker process that is running a member."""
    def progress(outcome):
        kill_a_busy_worker(client, state)
    return progress


def _reference(tmp_path_factory, text):
    """The sweep run undisturbed (LocalCluster of 2)."""
    d = tmp_path_factory.mktemp("reference")
    (d / "s.toml").write_text(text)
    res = sw.run_sweep(d / "s.toml", n_workers=2)
    assert not res.failures
    return res


def _assert_same_members(res, ref):
    assert [o.status for o in res.outcomes] == ["ran"] * len(ref.outcomes)
    for a, b in zip(res.outcomes, ref.outcomes):
        assert a.member.path.name == b.member.path.name
        with h5py.File(a.member.path) as ha, h5py.File(b.member.path) as hb:
            for field in ("sat/r", "sat/v", "tm/r"):
                for part in ("hi", "lo"):
                    np.testing.assert_array_equal(ha[field][part][()], hb[field][part][()])
    with xr.open_dataset(res.output, engine=sw.netcdf_engine()) as d1, \
            xr.open_dataset(ref.output, engine=sw.netcdf_engine()) as d2:
        for var in ("sat_r", "sat_r_lo", "sat_v", "ok"):
            np.testing.assert_array_equal(d1[var].values, d2[var].values)
    assert not list(res.output.parent.glob(".*.tmp")), "temporary files left behind"


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    return _reference(tmp_path_factory, SIX_DIRECTIONS)


def test_worker_killed_on_local_cluster(tmp_path, reference):
    from distributed import Client, LocalCluster

    (tmp_path / "s.toml").write_text(SIX_DIRECTIONS)
    state = {}
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None, silence_logs=50) as cluster, Client(cluster) as client:
        res = sw.run_sweep(tmp_path / "s.toml", scheduler=client, progress=_killer(client, state))
    assert state.get("killed"), "no worker was busy to be killed"
    assert not res.failures, [o.error for o in res.failures]
    assert len(res.rerun) >= 1 and all(o.lost_workers == 1 for o in res.rerun)
    _assert_same_members(res, reference)


@pytest.mark.skipif(shutil.which("dask") is None, reason="needs the dask command")
def test_worker_killed_on_dask_command_line_cluster(tmp_path, reference, capsys):
    """`dask scheduler` + two `dask worker --no-nanny`: one is killed and not
    restarted; the other finishes the sweep; the CLI says what happened."""
    from distributed import Client

    address, sched, workers = _start_cluster(tmp_path, 2, nanny=False)
    try:
        (tmp_path / "s.toml").write_text(SIX_DIRECTIONS)
        state = {}
        with Client(address, timeout=20) as client:
            _wait_workers(client, 2)
            res = sw.run_sweep(tmp_path / "s.toml", scheduler=client, progress=_killer(client, state))
            assert len(client.scheduler_info()["workers"]) == 1
        assert state.get("killed") and sum(p.poll() is not None for p in workers) == 1
        assert not res.failures, [o.error for o in res.failures]
        assert len(res.rerun) >= 1
        _assert_same_members(res, reference)
    finally:
        _stop([*workers, sched])


def test_cli_reports_members_re_run_after_worker_loss(tmp_path, capsys, monkeypatch):
    """What the command prints when Dask re-ran a member (the count comes from the scheduler)."""
    from tqdyn.workflows.sweep import execute

    real = execute._lost_counts
    monkeypatch.setattr(execute, "_lost_counts", lambda client, keys: {k: 1 for k in real(client, keys)})
    path = tmp_path / "two.toml"
    path.write_text(TWO)
    status, out, err = run_cli(["sweep", str(path), "-q", "--workers", "1"], capsys)
    assert status == 0, err
    assert "2 ran, 0 failed" in out and "; 2 re-run after a worker was lost" in out
    assert err.count("was re-run after its Dask worker was lost (1 time)") == 2


# --------------------------------------------------------------------------- (8) checksums of the sweep file


def test_sweep_file_has_checksums_and_corruption_is_one_line(tmp_path, reference):
    nc = tmp_path / "copy.nc"
    shutil.copy(reference.output, nc)
    with h5py.File(nc) as h5:
        numeric = [k for k, v in reference.dataset.variables.items() if v.dtype.kind in "fiub" and v.ndim]
        assert "sat_r" in numeric and "ok" in numeric
        for k in numeric:
            assert h5[k].fletcher32, k
        info = h5["sat_r"].id.get_chunk_info(0)
        offset, size = info.byte_offset, info.size
    ds = sw.read_sweep_netcdf(nc)
    np.testing.assert_array_equal(ds["sat_r"].values, reference.dataset["sat_r"].values)
    with open(nc, "r+b") as f:  # flip bytes in the middle of the first sat_r chunk
        f.seek(offset + size // 2)
        b = f.read(8)
        f.seek(offset + size // 2)
        f.write(bytes(x ^ 0xFF for x in b))
    with pytest.raises(sw.SweepFileError) as exc:
        sw.read_sweep_netcdf(nc)
    msg = str(exc.value)
    assert "\n" not in msg and str(nc) in msg and "corrupted" in msg
    nc.write_bytes(nc.read_bytes()[:2000])  # truncated
    with pytest.raises(sw.SweepFileError):
        sw.read_sweep_netcdf(nc)
