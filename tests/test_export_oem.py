"""``tqdyn export RUN.h5 --format oem OUT.oem``: one CCSDS OEM file per
satellite, in the trajectory's own system, read back by tqdyn's reader and
by the ``oem`` package (the reference: the trajectory's own rows and epoch)."""

from __future__ import annotations

import numpy as np
import pytest

from tqdyn.formats.trajectory import read_trajectory
from tqdyn.readers.oem import read_oem
from tqdyn.scenario import load_scenario
from tqdyn.workflows.export_oem import export_oem
from tqdyn.workflows.run import run_to_file


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("oem")
    helio = d / "lisa.h5"
    run_to_file(load_scenario("lisa-esa", ["run.duration=2d", f"run.output={helio}"]))
    geo = d / "tq.h5"
    run_to_file(load_scenario("tianqin-kepler", ["run.duration=2h", "integrator.step=600", f"run.output={geo}"]))
    return d, helio, geo


@pytest.mark.parametrize("which, system", [("helio", ("SUN", "ICRF", "TDB")), ("geo", ("EARTH", "GCRF", "TT"))])
def test_one_file_per_satellite_round_trip(runs, which, system):
    d, helio, geo = runs
    run = helio if which == "helio" else geo
    paths = export_oem(run, d / f"{which}.oem")
    tr = read_trajectory(run)
    ep = tr.epoch
    start = ep.tdb if which == "helio" else ep.tt
    names = ["LISA1", "LISA2", "LISA3"] if which == "helio" else ["Sat1", "Sat2", "Sat3"]
    assert [p.name for p in paths] == [f"{which}-{n}.oem" for n in names]
    r, v = tr["sat/r"], tr["sat/v"]
    t = tr["t"]
    for k, p in enumerate(paths):
        o = read_oem(p)
        assert (o.center_name, o.ref_frame, o.time_system) == system and o.object_name == names[k]
        # 16 significant digits in km: 1e-16 * 1.5e11 m (heliocentric) and the epochs to the ns digits
        assert np.max(np.abs(o.r - r[:, k])) < 2e-4 * (1 if which == "helio" else 1e-3)
        assert np.max(np.abs(o.v - v[:, k])) < 1e-10
        dt = ((o.jd1 - start[0]) + (o.jd2 - start[1])) * 86400.0 - t
        assert np.max(np.abs(dt)) < 2e-9  # s
        import oem as _oem

        assert len(_oem.OrbitEphemerisMessage.open(str(p)).states) == len(t)  # the oem package reads it too


def test_bad_out_name_and_nothing_written(runs, tmp_path):
    _, helio, _ = runs
    with pytest.raises(ValueError, match="does not end in .oem"):
        export_oem(helio, tmp_path / "x.txt")
    assert not list(tmp_path.iterdir())


def test_exported_files_read_back_as_initial_states(runs, tmp_path):
    """The round trip of ``tqdyn export --format oem``: the heliocentric files read back by the reader as
    ``initial.oem`` of a scenario starting at the run's row 4 (1 d after the epoch; the epoch as the file
    writes it, 9 decimals) give that row (16 digits: 2e-4 m, 1e-10 m/s), and interpolated (Hermite 7, as
    written) at the rows' epochs give the rows themselves."""
    from tqdyn.astro.oem_states import states_at
    from tqdyn.readers.oem import epoch_text

    _, helio, _ = runs
    paths = export_oem(helio, tmp_path / "h.oem")
    tr = read_trajectory(helio)
    first = read_oem(paths[0])
    when = epoch_text(first.jd1[4], first.jd2[4])
    scen = load_scenario("lisa-esa", ["initial.oem=[" + ", ".join(f'"{p}"' for p in paths) + "]",
                                      "initial.oem_eme2000=frame-bias", f'scenario.epoch_tdb="{when}"'])
    r, v = tr["sat/r"], tr["sat/v"]
    for k, (sat, p) in enumerate(zip(scen.satellites, paths)):
        assert np.max(np.abs(np.array([float(x) for x in sat.r_m]) - r[4, k])) < 2e-4
        assert np.max(np.abs(np.array([float(x) for x in sat.v_mps]) - v[4, k])) < 1e-10
        o = read_oem(p)
        rr, vv = states_at(o, o.jd1, o.jd2)
        assert np.max(np.abs(rr - r[:, k])) < 2e-4 and np.max(np.abs(vv - v[:, k])) < 1e-10
