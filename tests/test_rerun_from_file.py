"""A run is reproduced from its trajectory file alone: `tqdyn run RUN.h5` and `tqdyn.propagate("RUN.h5")`.

Reference: the file itself.  A heliocentric run (`lisa`, 30 days: coupled,
iterative pointing, ESA's OEM initial states and self-gravity ramp, the Sun,
the Earth, the Moon and the planets) and a geocentric one (`tianqin`, 6 h:
the full force model of the paper's Table II, coupled) are written; then the
package's default GMs (``data/gm_de431.tpc``, through the functions every
default goes through: ``tqdyn.readers.pck.shipped_gm`` and
``tqdyn.astro.ephemeris._planetary_gm``) are changed by 1 part in 1e6.  A run
of the built-in scenario now differs from the file (so the GMs do enter the
run: measured 1.8e4 m for `lisa` after 30 d, 2.8e-3 m for `tianqin` after
6 h), while the run from the file's resolved scenario and constants record
is byte-equal to it in every dataset: nothing the file records is read from
the package's defaults.  Fixed constants the file records but a scenario
cannot set (c, L_G, L_B, the coefficient files' GMs and radii, the data
files' SHA-256) are compared with this tqdyn's: a difference is reported in
one warning line.
"""

from __future__ import annotations

import json
import shutil
from decimal import Decimal

import h5py
import numpy as np
import pytest

import tqdyn
from tqdyn.formats import trajectory as io
from tqdyn.workflows.run import scenario_of_trajectory
from cli_support import run_cli as _run

_SCALE = Decimal("1.000001")  # the changed package defaults: every GM of gm_de431.tpc times this


def _datasets(path) -> dict[str, bytes]:
    out = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: out.__setitem__(name, obj[()].tobytes())
                     if isinstance(obj, h5py.Dataset) else None)
    return out


def _patch_default_gms(monkeypatch):
    """Every GM default of the package (gm_de431.tpc) times _SCALE, in both readers of the file."""
    from tqdyn.astro import ephemeris
    from tqdyn.readers import pck

    changed = {k: v * _SCALE for k, v in pck.shipped_gm(exact=True).items()}
    planetary = tuple((name, float(changed[naif])) for name, naif in ephemeris.NAIF_ID.items())

    def shipped_gm(exact_values: bool = False, *, exact: bool | None = None) -> dict:
        return changed if (exact_values or exact) else {k: float(v) for k, v in changed.items()}

    monkeypatch.setattr(pck, "shipped_gm", shipped_gm)
    monkeypatch.setattr(ephemeris, "_planetary_gm", lambda: planetary)
    assert tqdyn.load_scenario("lisa").forces.gm_sun == changed[10].normalize()


@pytest.mark.parametrize("name, duration", [("lisa", "30d"), ("tianqin", "6h")])
def test_rerun_from_the_file_alone_is_bit_identical(tmp_path, capsys, monkeypatch, name, duration):
    a, b, c = (tmp_path / f"{name}-{x}.h5" for x in "abc")
    status, _, err = _run(["run", name, "--duration", duration, "-o", str(a), "-q"], capsys)
    assert status == 0, err
    _patch_default_gms(monkeypatch)
    # the defaults matter: the built-in scenario now runs differently
    status, _, err = _run(["run", name, "--duration", duration, "-o", str(b), "-q"], capsys)
    assert status == 0, err
    da, db = _datasets(a), _datasets(b)
    assert da.keys() == db.keys() and da["sat/r/hi"] != db["sat/r/hi"]
    moved = np.abs(io.read_trajectory(a)["sat/r"] - io.read_trajectory(b)["sat/r"]).max()
    with capsys.disabled():
        print(f"\n{name}: the changed default GMs move the satellites by up to {moved:.3g} m")
    # the file alone: its resolved scenario and constants record, byte-equal in every dataset, no warning
    status, out, err = _run(["run", str(a), "-o", str(c), "-q"], capsys)
    assert status == 0, err
    assert "warning" not in err, err
    dc = _datasets(c)
    assert dc.keys() == da.keys()
    for key in da:
        assert dc[key] == da[key], key
    ta, tc = io.read_attributes(a), io.read_attributes(c)
    assert ta["constants"] == tc["constants"]
    assert ta["scenario"].replace(str(a.name), "X") == tc["scenario"].replace(str(c.name), "X")
    if name == "lisa":  # the Python API: the same from tqdyn.propagate("RUN.h5")
        traj = tqdyn.propagate(str(a))
        ref = io.read_trajectory(a)
        for f in ref.fields:
            np.testing.assert_array_equal(traj[f], ref[f], err_msg=f)
            if len(ref._get(f)) == 2:
                np.testing.assert_array_equal(traj.dd(f)[1], ref.dd(f)[1], err_msg=f)


def test_recorded_gms_and_constants(tmp_path, capsys):
    """What the file records: the GMs as scenario keys (exact decimals, the
    shipped DE430/DE431 values by default; the Sun's one the run integrated
    with), and the fixed constants with unit and source."""
    out = tmp_path / "k.h5"
    status, _, err = _run(["run", "lisa-kepler", "--duration", "1d", "--set", "forces.gm_sun=1.3271244e20",
                           "-o", str(out), "-q"], capsys)
    assert status == 0, err
    attrs = io.read_attributes(out)
    scen = tqdyn.load_scenario(str(out), {"run.output": str(tmp_path / "x.h5")})
    assert scen.forces.gm_sun == Decimal("1.3271244e20")  # lisaconstants' nominal value, not DE430's
    assert "gm_sun = 1.3271244E+20" in attrs["scenario"] and "gm_moon = 4902800066163.7961" in attrs["scenario"]
    rec = json.loads(attrs["constants"])
    assert rec["constants"]["c"] == {"value": 299792458.0, "unit": "m/s",
                                     "source": "speed of light, exact (SI definition of the metre, 1983)"}
    assert rec["constants"]["L_B"]["value"] == 1.550519768e-8 and rec["constants"]["L_G"]["value"] == 6.969290134e-10
    assert rec["constants"]["surface_radius"]["value"] == 696e6
    # the Keplerian design used the scenario's GM too: the initial states are on its orbits
    tr = io.read_trajectory(out)
    r = tr["sat/r"][0]
    v = tr["sat/v"][0]
    a = 1 / (2 / np.linalg.norm(r, axis=1) - np.sum(v * v, axis=1) / 1.3271244e20)
    np.testing.assert_allclose(a, 149597870700.0, rtol=1e-12)


def test_changed_fixed_constant_is_reported(tmp_path, capsys):
    """A file whose record says another c (or lacks the record) still runs,
    with one warning line saying what this tqdyn does differently."""
    a = tmp_path / "a.h5"
    status, _, err = _run(["run", "tianqin-kepler", "--duration", "1h", "-o", str(a), "-q"], capsys)
    assert status == 0, err
    b = tmp_path / "b.h5"
    shutil.copy(a, b)
    with h5py.File(b, "r+") as f:
        rec = json.loads(f.attrs["constants"])
        rec["constants"]["c"]["value"] = 3e8
        f.attrs["constants"] = json.dumps(rec)
    scen, notes = scenario_of_trajectory(b, [f"run.output={tmp_path / 'c.h5'}"])
    assert len(notes) == 1 and "constant c: the file records 300000000.0 m/s, this tqdyn uses 299792458.0" in notes[0]
    status, _, err = _run(["run", str(b), "-o", str(tmp_path / "c.h5"), "-q"], capsys)
    lines = err.strip().splitlines()
    assert status == 0 and len([x for x in lines if x.startswith("tqdyn: warning:")]) == 1, err
    with h5py.File(b, "r+") as f:
        del f.attrs["constants"]
    _, notes = scenario_of_trajectory(b, [f"run.output={tmp_path / 'd.h5'}"])
    assert len(notes) == 1 and "records no constants" in notes[0]
    with pytest.warns(UserWarning, match="records no constants"):
        tqdyn.load_scenario(str(b), {"run.output": str(tmp_path / "e.h5")})


def test_rerun_refuses_to_replace_its_source(tmp_path, capsys, monkeypatch):
    """`tqdyn run RUN.h5` whose recorded output is RUN.h5 itself: one line, exit 2, the file untouched."""
    monkeypatch.chdir(tmp_path)
    status, _, err = _run(["run", "tianqin-kepler", "--duration", "1h", "-o", "run.h5", "-q"], capsys)
    assert status == 0, err
    before = (tmp_path / "run.h5").read_bytes()
    status, out, err = _run(["run", "run.h5"], capsys)
    assert status == 2 and len(err.strip().splitlines()) == 1 and "run.output: 'run.h5' is the trajectory" in err
    assert (tmp_path / "run.h5").read_bytes() == before


@pytest.mark.parametrize("value, words", [("0", ["forces.gm_moon", "is not positive"]),
                                          ('"big"', ["forces.gm_moon", "'big'", "a number"])])
def test_gm_keys_validated_in_one_line(tmp_path, capsys, value, words):
    out = tmp_path / "x.h5"
    status, _, err = _run(["run", "tianqin-kepler", "--duration", "1h", "--set", f"forces.gm_moon={value}",
                           "-o", str(out)], capsys)
    assert status == 2 and len(err.strip().splitlines()) == 1, err
    assert all(w in err for w in words), err
    assert not out.exists()


def test_old_file_without_eop_interpolation_reruns_with_lagrange4(tmp_path, capsys):
    """A file written before forces.eop_interpolation existed (its resolved
    scenario lacks the key) ran with the IERS 4-point scheme: re-running it
    uses "lagrange4", not the default "spline"; an override still wins."""
    a = tmp_path / "a.h5"
    status, _, err = _run(["run", "tianqin-kepler", "--duration", "1h", "-o", str(a), "-q"], capsys)
    assert status == 0, err
    scen, _ = scenario_of_trajectory(a, [f"run.output={tmp_path / 'b.h5'}"])
    assert scen.forces.eop_interpolation == "spline"
    with h5py.File(a, "r+") as f:
        text = f.attrs["scenario"]
        assert 'eop_interpolation = "spline"' in text
        f.attrs["scenario"] = "\n".join(x for x in text.splitlines() if not x.startswith("eop_interpolation"))
    scen, _ = scenario_of_trajectory(a, [f"run.output={tmp_path / 'b.h5'}"])
    assert scen.forces.eop_interpolation == "lagrange4"
    scen, _ = scenario_of_trajectory(a, [f"run.output={tmp_path / 'b.h5'}", "forces.eop_interpolation=spline"])
    assert scen.forces.eop_interpolation == "spline"
