"""The explicit reference system: the scenario resolves it, the force model and
the propagation carry it, the trajectory file records it (issue: origin,
frame and time scale as values, not implicit)."""

import pytest

from tqdyn.astro.reference import CENTRAL_BODIES, GEOCENTRIC, GEOCENTRIC_V1, reference_system
from tqdyn.dynamics import propagate
from tqdyn.forces.model import build_force_model
from tqdyn.formats.trajectory import Trajectory
from tqdyn.scenario import ScenarioError, load_scenario, loads_scenario


def test_scenario_resolves_the_reference_system():
    scen = load_scenario("tianqin-kepler", ["run.duration=100s"])
    assert scen.central_body == "earth" and scen.reference is GEOCENTRIC
    assert (GEOCENTRIC.origin, GEOCENTRIC.frame) == ("earth", "GCRS")
    assert 'central_body = "earth"' in scen.to_toml()
    assert loads_scenario(scen.to_toml()).reference is GEOCENTRIC
    assert CENTRAL_BODIES == ("earth", "sun")


def test_unknown_central_body_is_one_clear_line():
    with pytest.raises(ScenarioError) as err:
        load_scenario("tianqin-kepler", ["scenario.central_body=jupiter"])
    msg = str(err.value)
    assert "\n" not in msg and "scenario.central_body" in msg and "'jupiter'" in msg and "'earth'" in msg
    with pytest.raises(ValueError, match="allowed: 'earth'"):
        reference_system("mars")


def test_force_model_and_result_carry_it():
    scen = load_scenario("tianqin-kepler", ["run.duration=100s"])
    model = build_force_model(scen.forces, scen.reference)
    assert model.reference is GEOCENTRIC
    assert propagate(scen, model=model).reference is GEOCENTRIC


def test_trajectory_records_it(tmp_path):
    from tqdyn.formats.trajectory import read_trajectory
    from tqdyn.workflows.run import run_to_file

    out = tmp_path / "k.h5"
    run_to_file(load_scenario("tianqin-kepler", ["run.duration=100s", f"run.output={out}"]))
    tr = read_trajectory(out)
    assert (tr.attrs["origin"], tr.attrs["frame"], tr.attrs["time_scale"]) == ("earth", "GCRS", "TT")
    assert tr.reference is GEOCENTRIC
    # a file of format version 1 (tqdyn 0.1) has no origin attribute and t labelled TDB
    old = Trajectory(out, dict({k: v for k, v in tr.attrs.items() if k != "origin"}, format_version=1,
                               time_scale="TDB"), {}, 0)
    assert old.reference is GEOCENTRIC_V1 and old.reference.time_scale == "TDB"
