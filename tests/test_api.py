"""The front door (tqdyn/api.py): scenario, in-memory propagation, files, light paths, spectra.

References: the file ``tqdyn run`` writes for the same scenario (the
in-memory trajectory must hold the same arrays and attributes bit for bit),
and the library functions each front-door function composes.
"""

import numpy as np
import pytest

import tqdyn
from tqdyn.formats.trajectory import read_trajectory

SHORT = {"run.duration": "2h", "forces.earth_degree": 2, "forces.ocean_tides_degree": 0}


def test_import_is_cheap_and_lazy():
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", "import sys, tqdyn; print('numba' in sys.modules, "
                          "sorted(set(dir(tqdyn)) - {'__version__'})[:3])"], capture_output=True, text=True, check=True)
    assert out.stdout.startswith("False")   # nothing heavy until a function is used
    assert "propagate" in dir(tqdyn) and "load_scenario" in tqdyn.__all__


def test_load_scenario_overrides_as_dict_or_list():
    a = tqdyn.load_scenario("tianqin", {"run.duration": "1d", "satellites.2.nu_deg": 151, "forces.pole_tides": False})
    b = tqdyn.load_scenario("tianqin", ["run.duration=1d", "satellites.2.nu_deg=151", "forces.pole_tides=false"])
    assert a == b and float(a.run.duration_s) == 86400 and not a.forces.pole_tides
    assert tqdyn.load_scenario(a) is a
    assert float(tqdyn.load_scenario(a, {"run.duration": "2d"}).run.duration_s) == 172800
    assert "tianqin" in tqdyn.builtin_scenarios()
    with pytest.raises(tqdyn.ScenarioError, match=r"run.duration: '-1d'.*allowed"):
        tqdyn.load_scenario("tianqin", {"run.duration": "-1d"})


def test_in_memory_trajectory_equals_the_file(tmp_path):
    out = tmp_path / "run.h5"
    summary = tqdyn.run("tianqin", SHORT, output=str(out))
    mem = tqdyn.propagate("tianqin", dict(SHORT, **{"run.output": str(out)}))
    disk = tqdyn.open_trajectory(summary.path)
    assert mem.path is None and disk.path == out
    assert mem.fields == disk.fields and mem.n_rows == disk.n_rows == 145
    for f in disk.fields:
        for a, b in zip(mem._data[f], disk._data[f]):
            assert np.array_equal(a, b), f
    skip = {"tqdyn_version"}
    assert {k: v for k, v in mem.attrs.items() if k not in skip} == {k: v for k, v in disk.attrs.items() if k not in skip}
    assert mem.reference == disk.reference and mem.result.n_steps == 144
    ds = mem.to_xarray()
    assert ds.sat_breathing_angle.dims == ("time", "sat") and ds.sizes["time"] == 145
    # the numpy breathing angles against the compiled ones the file stores (a mirror pair: rounding only)
    np.testing.assert_allclose(tqdyn.breathing_angles(mem), read_trajectory(out)["sat/breathing_angle"], rtol=0, atol=1e-15)


def test_light_paths_and_range_asd():
    traj = tqdyn.propagate("tianqin-kepler", {"run.duration": "1d"})
    lt = tqdyn.light_travel_times(traj)
    assert lt.source == "sat" and lt.tau[0].shape == (1729, 6)
    res = tqdyn.range_asd(lt, 13)
    assert res.f.shape == res.asd.shape and np.all(res.asd[1:] > 0)
    assert tqdyn.range_asd(lt, "13").asd.tolist() == res.asd.tolist()
    np.testing.assert_allclose(tqdyn.requirement_asd(np.array([7e-3])), 0.3e-12 * np.sqrt(2), rtol=1e-15)
    with pytest.raises(ValueError, match="link: '14' is not a link; allowed: 12, 23, 31, 13, 32, 21"):
        tqdyn.range_asd(lt, "14")


@pytest.mark.parametrize("old, new", [("tqdyn.io", "tqdyn.formats.trajectory"), ("tqdyn.sweep", "tqdyn.workflows.sweep"),
                                      ("tqdyn.analysis.lisa_estimates", "tqdyn.constellation.estimates")])
def test_old_import_paths_warn_and_reexport(old, new):
    """The 0.1 shims and the 0.2 path of the LISA estimates still give the same objects, and importing
    them warns."""
    import importlib
    import sys

    sys.modules.pop(old, None)
    with pytest.warns(DeprecationWarning, match=new.replace(".", r"\.")):
        shim = importlib.import_module(old)
    target = importlib.import_module(new)
    assert shim.__all__ == list(target.__all__)
    assert all(getattr(shim, n) is getattr(target, n) for n in target.__all__)
