"""The residuals' figure of an orbit-determination fit (tqdyn.analysis.figures_od, ``tqdyn od fit --figure``,
``tqdyn.plot_od_residuals``; docs/od-files.md, "The residuals' figure").

The problem is the linear stand-in tests/od_fake_problem.py (as in tests/test_od_cli.py), whose design
matrix numpy can use directly.  References: the normalised residual of a row is r_i / sqrt(v_i) with
the post-fit residual variance v_i = sigma_i^2 -+ (H P H^T)_ii (P = (J^T J)^-1 of the kept whitened rows;
minus for a kept row, plus for an edited one: the estimator's definition, computed here with numpy);
the histogram holds every kept row once; the GNSS rows of the fit follow the clock elimination of
tqdyn.od.problem (n_k pseudoranges of an epoch and satellite -> n_k - 1 rows, none for n_k = 1), counted
by hand on a small table.  The run is tianqin-kepler, 1 day at 600 s (a few seconds).
"""

from __future__ import annotations

import sys

import numpy as np
import pytest

import od_fake_problem as fake
from od_fake_problem import fake_problem  # noqa: F401  (autouse: the stand-in replaces tqdyn.od.problem)
from cli_support import run_cli
from tqdyn.od import problem as real_problem      # before the stand-in replaces it


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """(run file, TDM, estimate file, figure) of a fit with 2.5-sigma editing and --figure."""
    import tqdyn
    from tqdyn.cli import main

    d = tmp_path_factory.mktemp("od-figure")
    run, tdm, est, fig = d / "run.h5", d / "m.tdm", d / "est.h5", d / "res.png"
    tqdyn.run("tianqin-kepler", {"run.duration": "1d", "integrator.step": 600}, output=str(run))
    mp = pytest.MonkeyPatch()
    import tqdyn.od

    mp.setitem(sys.modules, "tqdyn.od.problem", fake)
    mp.setattr(tqdyn.od, "problem", fake, raising=False)
    try:
        for argv in (["od", "simulate", str(run), "--tracking", "slr,isr,dsn", "--arc", "12h", "--seed", "5",
                      "--output", str(tdm), "-q"],
                     ["od", "fit", str(run), str(tdm), "--output", str(est), "--edit-sigma", "2.5",
                      "--figure", str(fig), "-q"]):
            try:
                status = main(argv)
            except SystemExit as exc:
                status = exc.code
            assert status in (0, None), argv
    finally:
        mp.undo()
    return run, tdm, est, fig


def test_fit_writes_the_figure(fitted):
    """--figure writes a PNG (its signature) of more than 10 kB beside the estimate file."""
    fig = fitted[3]
    data = fig.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
    assert not [p for p in fig.parent.iterdir() if p.name.startswith(".")]


def test_plotted_points_are_residuals_over_post_fit_sigma(fitted, tmp_path):
    """The points drawn per type and satellite are r_i / sqrt(sigma_i^2 -+ (H P H^T)_ii) computed with
    numpy from the stand-in's design matrix (kept and edited rows), at t_i / 3600 h; the histogram's
    counts sum to the number of kept rows."""
    import tqdyn
    from tqdyn.formats.od_estimate import read_estimate_file

    _, _, est_path, _ = fitted
    est = read_estimate_file(est_path)
    m = est.measurements
    drawn = tqdyn.plot_od_residuals(est_path, tmp_path / "r.pdf")
    assert (tmp_path / "r.pdf").read_bytes()[:5] == b"%PDF-"
    scen = type("S", (), {"satellites": [None] * 3})
    H = fake.design(scen, fake.Measurements(**{k: m[k] for k in ("t", "type", "sat", "peer", "value", "sigma")}))
    kept = ~m["edited"]
    assert 0 < m["edited"].sum() < 0.2 * kept.size          # 2.5-sigma editing leaves some rows out
    J = H / m["sigma"][:, None]
    P = np.linalg.inv(J[kept].T @ J[kept])
    hph = np.einsum("ij,jk,ik->i", H, P, H)
    z_ref = m["residual"] / np.sqrt(np.where(kept, m["sigma"] ** 2 - hph, m["sigma"] ** 2 + hph))
    n_points = 0
    for typ in dict.fromkeys(m["type"].tolist()):
        for s in range(3):
            sel = (m["type"] == typ) & (m["sat"] == s) & kept
            x, z = drawn.points[typ][s]
            np.testing.assert_allclose(x, m["t"][sel] / 3600.0, rtol=0, atol=1e-12)
            np.testing.assert_allclose(z, z_ref[sel], rtol=1e-9, atol=0)
            n_points += z.size
        off = (m["type"] == typ) & ~kept
        if off.any():
            np.testing.assert_allclose(drawn.edited[typ][1], z_ref[off], rtol=1e-9, atol=0)
    assert n_points == drawn.kept == int(kept.sum())
    assert int(drawn.hist_counts.sum()) == int(kept.sum())
    assert drawn.time_unit == "h"


def test_gnss_rows_of_the_fit_point_to_their_epoch():
    """od.problem.residual_rows: SLR rows map to themselves; GNSS epochs of 3, 1 and 2 pseudoranges
    give 2, 0 and 1 rows, each pointing to the epoch's first pseudorange (counted by hand)."""
    real = real_problem
    t = np.array([0.0, 0.0, 0.0, 0.0, 600.0, 600.0, 1200.0, 1200.0])
    typ = np.array(["slr_range", "gnss_pseudorange", "gnss_pseudorange", "gnss_pseudorange", "gnss_pseudorange",
                     "slr_range", "gnss_pseudorange", "gnss_pseudorange"])
    sat = np.array([0, 1, 1, 1, 2, 0, 0, 0])
    meas = real.Measurements(t, typ, sat, np.array(["Graz", "G01", "G02", "G03", "G04", "Graz", "G05", "G06"]),
                             np.zeros(8), np.full(8, 3.0))
    assert real.residual_rows(meas).tolist() == [0, 5, 1, 1, 6]


def test_figure_from_rows_that_are_not_the_measurements(fitted, tmp_path):
    """A file whose residual rows are not the measurement rows and that does not map them is refused in
    one line; with residual_row the points sit at the time of the row's measurement."""
    from tqdyn.analysis.figures_od import plot_od_residuals
    from tqdyn.formats.od_estimate import read_estimate_file

    est = read_estimate_file(fitted[2])
    m = est.measurements
    keep = np.arange(0, len(m["residual"]), 2)
    for k in ("residual", "normalised_residual", "edited"):
        m[k] = m[k][keep]
    m["residual_row"] = keep
    drawn = plot_od_residuals(est, tmp_path / "half.png")
    assert drawn.kept == int((~m["edited"]).sum())
    typ, s = m["type"][keep[0]], int(m["sat"][keep[0]])
    assert drawn.points[typ][s][0][0] == m["t"][keep[0]] / 3600.0
    del m["residual_row"]
    with pytest.raises(ValueError, match=r"^est.h5: \d+ residual rows for \d+ measurements and no "
                                         r"/measurements/residual_row; allowed: .*$") as info:
        plot_od_residuals(est, tmp_path / "none.png")
    assert "\n" not in str(info.value) and not (tmp_path / "none.png").exists()


@pytest.mark.parametrize("case, pattern", [
    ("suffix", r"--figure: '.*res\.svg' has an unsupported extension \.svg; allowed: a file name ending in \.pdf, "
               r"\.png$"),
    ("no-suffix", r"--figure: '.*res' has no file extension; allowed: a file name ending in \.pdf, \.png$"),
    ("directory", r"--figure: '.*missing/res\.png' is in a directory that does not exist"),
    ("is-output", r"--figure: '.*out\.png' is the output EST\.h5; allowed: another file$"),
])
def test_bad_figure_is_refused_before_the_fit(fitted, tmp_path, capsys, monkeypatch, case, pattern):
    """A bad --figure: exit status 2, one line naming --figure, the fit never runs, no estimate file
    and no figure (nor a temporary file) written."""
    run, tdm = fitted[0], fitted[1]

    def never(*a, **k):
        raise AssertionError("the fit ran")

    monkeypatch.setattr(fake, "fit", never)
    out = tmp_path / ("out.png" if case == "is-output" else "est.h5")
    figure = {"suffix": tmp_path / "res.svg", "no-suffix": tmp_path / "res", "directory": tmp_path / "missing" /
              "res.png", "is-output": out}[case]
    status, _, err = run_cli(["od", "fit", str(run), str(tdm), "--output", str(out), "--figure", str(figure)],
                             capsys)
    assert status == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("tqdyn: error: --figure: "), err
    import re

    assert re.search(pattern, lines[0]), lines[0]
    assert list(tmp_path.iterdir()) == []


def test_file_without_residual_row_reads_as_the_identity(fitted, tmp_path):
    """An estimate file written before /measurements/residual_row (its rows are the measurements') reads
    with residual_row = 0..m-1 and draws the same points."""
    import shutil

    import h5py

    from tqdyn.analysis.figures_od import plot_od_residuals
    from tqdyn.formats.od_estimate import read_estimate_file

    old = tmp_path / "old.h5"
    shutil.copyfile(fitted[2], old)
    with h5py.File(old, "a") as h5:
        del h5["measurements/residual_row"]
    est = read_estimate_file(old)
    assert est.measurements["residual_row"].tolist() == list(range(len(est.measurements["t"])))
    a = plot_od_residuals(est, tmp_path / "a.png")
    b = plot_od_residuals(read_estimate_file(fitted[2]), tmp_path / "b.png")
    assert np.array_equal(a.hist_counts, b.hist_counts) and a.kept == b.kept
