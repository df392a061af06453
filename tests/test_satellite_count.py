"""How many satellites a run takes: any number for point masses, exactly 3 when coupled.

Reference values: the analytic two-body solution (mpmath, 50 digits;
:func:`tqdyn.astro.elements.kepler_state_at`) of six Keplerian orbits -- the
TianQin I triangle of Table I and a second triangle ("TianQin II") whose orbit
plane is turned by 90 deg of RAAN -- under the Earth monopole: independent of
the integrator and of the number of bodies it propagates.  Each satellite is a
body of its own, so it must meet its orbit as the 3-satellite runs do
(tests/test_cli.py::test_run_kepler_matches_analytic; the dd propagation of
these elements is good to ~1e-22 m after a day): measured 7.2e-23 m for each of
the six after 1 day at 50 s, bound 5e-22 m.
"""

from __future__ import annotations

import contextlib
import io as _stringio

import mpmath
import numpy as np
import pytest

import tqdyn
from tqdyn.astro import elements
from tqdyn import cli
from tqdyn.formats import trajectory as io
from tqdyn.numerics.dd import mp_from_dd
from tqdyn.scenario import ScenarioError, load_scenario, loads_scenario
from cli_support import run_cli as _run

#: (name, a_km, raan_deg, nu_deg): TianQin I (Table I) and a second triangle 90 deg of RAAN away.
SIX = (("TQ1-1", "100000.0", "211.6", "30.0"), ("TQ1-2", "100009.5", "211.6", "150.0"),
       ("TQ1-3", "99995.0", "211.6", "270.0"), ("TQ2-1", "100000.0", "301.6", "90.0"),
       ("TQ2-2", "100000.0", "301.6", "210.0"), ("TQ2-3", "100000.0", "301.6", "330.0"))


def _scenario_text(sats=SIX, extends="tianqin-kepler", extra="") -> str:
    out = [f'[scenario]\nextends = "{extends}"\nname = "nsat"\n{extra}']
    for name, a, raan, nu in sats:
        out.append(f'[[satellites]]\nname = "{name}"\na_km = {a}\ne = 0.0\ni_deg = 74.5\n'
                   f'raan_deg = {raan}\nargp_deg = 0.0\nnu_deg = {nu}\n')
    return "\n".join(out)


def _analytic_errors(scen, r_hi, r_lo) -> list[float]:
    """|r - r_kepler| [m] of each satellite at the end of the run (mpmath, 50 digits)."""
    got = mp_from_dd(np.stack([r_hi[-1], r_lo[-1]], axis=-1))
    out = []
    with mpmath.workdps(50):
        for sat, row in zip(scen.satellites, got):
            ref, _ = elements.kepler_state_at(sat.a_m, sat.e, elements.deg(sat.i_deg), elements.deg(sat.raan_deg),
                                              elements.deg(sat.argp_deg), elements.deg(sat.nu_deg),
                                              scen.forces.gm_earth, scen.run.duration_s)
            out.append(float(mpmath.sqrt(sum((a - b) ** 2 for a, b in zip(row, ref)))))
    return out


@pytest.fixture(scope="module")
def six_run(tmp_path_factory):
    """The six Kepler orbits, 1 day at 50 s, through `tqdyn run` (CLI, in-process)."""
    d = tmp_path_factory.mktemp("six")
    path = d / "six.toml"
    path.write_text(_scenario_text(), encoding="utf-8")
    out = d / "six.h5"
    o, e = _stringio.StringIO(), _stringio.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        try:
            status = cli.main(["run", str(path), "--duration", "1d", "-o", str(out), "-q"])
        except SystemExit as exc:
            status = exc.code
    return status, o.getvalue(), e.getvalue(), path, out


def test_six_satellites_cli_matches_kepler(six_run):
    """`tqdyn run` of six point-mass satellites: the file holds all six (shapes
    (N, 6, 3), the scenario's names), and each final position agrees with its
    analytic two-body orbit to < 5e-22 m (measured: <= 7.2e-23 m)."""
    status, out, err, path, h5 = six_run
    assert status == 0, err
    assert "6 satellite(s)" in err and all(name in out for name, *_ in SIX)
    tr = io.read_trajectory(h5)
    scen = load_scenario(str(path), ["run.duration=1d", f"run.output={h5}"])
    n = scen.n_steps + 1
    assert tr.n_sat == 6 and tr.n_rows == n
    for f in ("sat/r", "sat/v", "sat/a_gravity"):
        assert tr[f].shape == (n, 6, 3), f
    assert tr.satellite_names == tuple(name for name, *_ in SIX)
    ds = tr.to_xarray()
    assert ds.sizes["sat"] == 6 and list(ds["sat_name"].values) == [name for name, *_ in SIX]
    errs = _analytic_errors(scen, *tr.dd("sat/r"))
    print(f"\nsix satellites, 1 d: |r - r_kepler| = {', '.join(f'{x:.1e}' for x in errs)} m")
    assert max(errs) < 5e-22
    # sat/a_gravity is the monopole at each satellite's own position
    r = tr["sat/r"][-1]
    np.testing.assert_allclose(np.linalg.norm(tr["sat/a_gravity"][-1], axis=1),
                               float(scen.forces.gm_earth) / np.linalg.norm(r, axis=1) ** 2, rtol=1e-14)
    # the scenario in the file reads back with its six satellites
    assert loads_scenario(tr.scenario_toml) == scen


def test_six_satellites_python_api_same_as_file(six_run):
    """`tqdyn.propagate` of the same scenario: an in-memory trajectory of six
    satellites, bit-identical to the file `tqdyn run` wrote."""
    _, _, _, path, h5 = six_run
    traj = tqdyn.propagate(str(path), {"run.duration": "1d"})
    tr = io.read_trajectory(h5)
    assert traj.n_sat == 6 and traj.satellite_names == tr.satellite_names
    for f in tr.fields:
        for a, b in zip(traj.dd(f) if f != "sat/a_gravity" else (traj[f],),
                        tr.dd(f) if f != "sat/a_gravity" else (tr[f],)):
            np.testing.assert_array_equal(a, b, err_msg=f)
    assert max(_analytic_errors(load_scenario(str(path), ["run.duration=1d"]), *traj.dd("sat/r"))) < 5e-22


def test_six_satellites_resume_bit_identical(tmp_path, capsys, monkeypatch, six_run):
    """A 6-satellite run interrupted after its checkpoints and resumed gives the
    same file as the uninterrupted run, bit for bit (the checkpoint holds the
    six bodies)."""
    from cli_support import run_cli_interrupted

    _, _, _, path, h5 = six_run
    out = tmp_path / "resumed.h5"
    args = ["run", str(path), "--duration", "1d", "--checkpoint-every", "200", "-o", str(out), "-q"]
    status, _, err = run_cli_interrupted(args, capsys, monkeypatch)
    assert status == 130, err
    status, _, err = _run(args + ["--resume"], capsys)
    assert status == 0, err
    a, b = io.read_trajectory(out), io.read_trajectory(h5)
    for f in a.fields:
        np.testing.assert_array_equal(a[f], b[f], err_msg=f)
        if f != "sat/a_gravity":
            np.testing.assert_array_equal(a.dd(f)[1], b.dd(f)[1], err_msg=f)


def test_six_satellites_exports_and_report(six_run, tmp_path, capsys):
    """`tqdyn export --format oem` writes one file per satellite (named after
    the scenario's satellites); `--format lisa` refuses in one line (a LISA
    file has the six links of 3 satellites); `tqdyn report` works and says
    what it skipped; the triangle's analyses refuse in one line."""
    _, _, _, _, h5 = six_run
    status, out, err = _run(["export", str(h5), "--format", "oem", str(tmp_path / "six.oem")], capsys)
    assert status == 0, err
    assert sorted(p.name for p in tmp_path.glob("*.oem")) == sorted(f"six-{name}.oem" for name, *_ in SIX)
    lisa = tmp_path / "lisa.h5"
    status, out, err = _run(["export", str(h5), "--format", "lisa", str(lisa)], capsys)
    assert status == 2 and len(err.strip().splitlines()) == 1 and "n_sat = 6" in err and "allowed" in err, err
    assert not lisa.exists()
    status, out, err = _run(["report", str(h5), "--out", str(tmp_path / "rep"), "-q"], capsys)
    assert status == 0, err
    assert "6 satellite(s): no arm lengths, breathing angles" in out
    tr = io.read_trajectory(h5)
    for call in (tqdyn.breathing_angles, tqdyn.light_travel_times):
        with pytest.raises(ValueError, match="n_sat = 6") as info:
            call(tr)
        assert "\n" not in str(info.value)


def test_coupled_four_satellites_refused_before_banner(tmp_path, capsys):
    """A coupled scenario (the built-in tianqin) with 4 satellites: exit 2,
    one line naming `satellites`, the value and what is allowed, printed
    before the banner, and no output file."""
    sats = SIX[:4]
    path = tmp_path / "four.toml"
    path.write_text(_scenario_text(sats, extends="tianqin"), encoding="utf-8")
    out = tmp_path / "four.h5"
    status, stdout, err = _run(["run", str(path), "--duration", "1h", "-o", str(out)], capsys)
    assert status == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("tqdyn: error: satellites: 4 satellites given") and "exactly 3" in lines[0]
    assert 'allowed: 3 satellites, or constellation.pointing = "none"' in lines[0]
    assert stdout == "" and not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["four.toml"]


@pytest.mark.parametrize("n", [1, 2, 4])
def test_coupled_count_refused_in_python(n):
    given = "satellite given" if n == 1 else "satellites given"
    with pytest.raises(ScenarioError, match=rf"^satellites: {n} {given}; a coupled run .* needs exactly 3") as info:
        loads_scenario(_scenario_text(SIX[:n], extends="tianqin"))
    assert info.value.field == "satellites" and info.value.value == n


def test_centre_pull_needs_three():
    """spacecraft.self_gravity_center pulls toward the centroid of a triangle:
    a point-mass scenario with it and 4 satellites is refused in one line."""
    sats = "\n".join(f"[[satellites]]\nr_km = [{1.496e8 + k * 1e6}, 0, 0]\nv_kmps = [0, 29.8, 0]\n" for k in range(4))
    text = ('[scenario]\ncentral_body = "sun"\nepoch_tdb = "2035-01-01T00:00:00"\n[forces]\nearth_monopole = false\n'
            '[spacecraft]\nself_gravity_center = [-2e-9, 2e-9]\n'
            'self_gravity_center_span = ["2035-01-01T00:00:00 TDB", "2036-01-01T00:00:00 TDB"]\n' + sats)
    with pytest.raises(ScenarioError, match="^satellites: 4 satellites given; spacecraft.self_gravity_center"):
        loads_scenario(text)


@pytest.mark.parametrize("n", [1, 2])
def test_one_and_two_satellites_still_run(n):
    """Point-mass runs of 1 and 2 satellites: shapes (N, n, 3) and the analytic
    two-body orbits to < 2e-22 m after 6 h (measured <= 3e-23 m)."""
    traj = tqdyn.propagate(loads_scenario(_scenario_text(SIX[:n])), {"run.duration": "6h"})
    scen = loads_scenario(_scenario_text(SIX[:n]), ["run.duration=6h"])
    assert traj.n_sat == n and traj["sat/r"].shape == (scen.n_steps + 1, n, 3)
    errs = _analytic_errors(scen, *traj.dd("sat/r"))
    print(f"\n{n} satellite(s), 6 h: |r - r_kepler| = {', '.join(f'{x:.1e}' for x in errs)} m")
    assert max(errs) < 2e-22


def test_writer_and_reader_take_any_satellite_count(tmp_path):
    """The file layout is [time, satellite, ...] with any satellite count >= 1:
    7 satellites round-trip bit-exactly; 0 is refused."""
    rng = np.random.default_rng(1)
    attrs = {"scenario": "", "epoch_utc": "2004-06-06T00:00:00", "precision": "dd", "step_s": 50.0,
             "integrator": "dp87-fixed-corrected", "pointing": "none", "control": "off"}
    r = (rng.normal(size=(5, 7, 3)) * 1e8, rng.normal(size=(5, 7, 3)) * 1e-9)
    with io.TrajectoryWriter(tmp_path / "seven.h5", attrs, ["t", "sat/r"], n_sat=7) as w:
        w.append({"t": (np.arange(5.0), np.zeros(5)), "sat/r": r})
    tr = io.read_trajectory(tmp_path / "seven.h5")
    assert tr.n_sat == 7 and tr.satellite_names == tuple(f"Sat{k}" for k in range(1, 8))
    np.testing.assert_array_equal(tr.dd("sat/r")[0], r[0])
    np.testing.assert_array_equal(tr.dd("sat/r")[1], r[1])
    with pytest.raises(ValueError, match="n_sat = 0; allowed: an integer >= 1"):
        io.TrajectoryWriter(tmp_path / "none.h5", attrs, ["t", "sat/r"], n_sat=0)
