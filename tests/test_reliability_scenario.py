"""Physically meaningless scenarios are refused before anything runs (issue 14, item 4):
one line ``tqdyn: error: <field>: ...; allowed: ...`` on stderr, exit status 2, no
output file; the override keys ``scenario.allow_below_surface`` and
``run.max_steps`` let a user run them on purpose."""

from decimal import Decimal

import pytest

from cli_support import run_cli
from tqdyn.scenario import load_scenario, loads_scenario
from tqdyn.scenario.config import BODY_RADII_M, MAX_STEPS, ScenarioError

GEO_CARTESIAN = """
[scenario]
name = "cart"
epoch_utc = "2004-06-06T00:00:00"
{extra}
[run]
duration = "1h"
[integrator]
step = 60.0
[forces]
earth_monopole = true
eop = false
[[satellites]]
name = "S"
r_km = [{x}, 0.0, 0.0]
v_kmps = [0.0, 7.9, 0.0]
"""


def _refused(argv, capsys, tmp_path, field):
    out = tmp_path / "out.h5"
    status, _, err = run_cli(["run", *argv, "-q", "-o", str(out)], capsys)
    lines = err.strip().splitlines()
    assert status == 2, err
    assert len(lines) == 1, err
    assert lines[0].startswith(f"tqdyn: error: {field}: "), lines[0]
    assert "; allowed: " in lines[0]
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".out.h5")] == []
    return lines[0]


@pytest.mark.parametrize("sets, field, words", [
    (["satellites.1.a_km=1000"], "satellites.1.a_km", ["inside the Earth", "6378.137"]),
    (["satellites.2.a_km=6378.0"], "satellites.2.a_km", ["inside the Earth"]),
    (["satellites.1.e=0.95"], "satellites.1.e", ["pericentre", "6378.137", "allow_below_surface"]),
    (["satellites.3.a_km=7000", "satellites.3.e=0.1"], "satellites.3.e", ["pericentre"]),
    (["satellites.1.i_deg=200"], "satellites.1.i_deg", ["0 <= i <= 180"]),
    (["satellites.2.i_deg=-10"], "satellites.2.i_deg", ["0 <= i <= 180"]),
    (["run.duration=1e12d"], "run.duration", ["max_steps"]),
    (["integrator.step=1e-6"], "integrator.step", ["max_steps"]),
    (["integrator.step=2e6"], "integrator.step", ["longer than run.duration"]),
    (["integrator.mode=adaptive", "integrator.step=2e6"], "integrator.step", ["longer than run.duration"]),
    (["integrator.mode=adaptive", "run.duration=1e12d"], "run.duration", ["output intervals"]),
    (["run.max_steps=0"], "run.max_steps", ["integer >= 1"]),
    (["scenario.allow_below_surface=1"], "scenario.allow_below_surface", ["true or false"]),
])
def test_kepler_scenario_refused(sets, field, words, capsys, tmp_path):
    argv = ["tianqin-kepler"] + [x for s in sets for x in ("--set", s)]
    line = _refused(argv, capsys, tmp_path, field)
    for w in words:
        assert w in line


def test_angles_wrap_are_accepted():
    s = load_scenario("tianqin-kepler", ["satellites.1.raan_deg=-400", "satellites.1.argp_deg=725",
                                         "satellites.1.nu_deg=-30", "satellites.1.i_deg=180",
                                         "satellites.2.i_deg=0"])
    assert s.satellites[0].raan_deg == Decimal(-400)


def test_cartesian_inside_earth_refused(capsys, tmp_path):
    path = tmp_path / "cart.toml"
    path.write_text(GEO_CARTESIAN.format(extra="", x="6000.0"))
    line = _refused([str(path)], capsys, tmp_path, "satellites.1.r_km")
    assert "|r| = 6000 km" in line and "6378.137" in line
    ok = tmp_path / "ok.toml"
    ok.write_text(GEO_CARTESIAN.format(extra="", x="6378.137"))  # on the equatorial radius: allowed
    assert loads_scenario(ok.read_text()).satellites[0].r_m[0] == BODY_RADII_M["earth"]


def test_inside_sun_refused(capsys, tmp_path):
    line = _refused(["lisa-kepler", "--set", "initial.semi_major_axis=5e8", "--set", "initial.arm_length=1e6"],
                    capsys, tmp_path, "initial.design")
    assert "inside the Sun" in line and "696000" in line


def test_allow_below_surface_runs(capsys, tmp_path):
    out = tmp_path / "below.h5"
    status, _, err = run_cli(["run", "tianqin-kepler", "-q", "-o", str(out), "--duration", "1h",
                              "--set", "satellites.1.a_km=1000", "--set", "scenario.allow_below_surface=true"], capsys)
    assert status == 0, err
    assert out.exists()
    s = load_scenario("tianqin-kepler", ["satellites.1.a_km=1000", "scenario.allow_below_surface=true"])
    assert "allow_below_surface = true" in s.to_toml()
    assert loads_scenario(s.to_toml()) == s


def test_allow_below_surface_cartesian(tmp_path):
    text = GEO_CARTESIAN.format(extra="allow_below_surface = true", x="1000.0")
    s = loads_scenario(text)
    assert s.allow_below_surface and loads_scenario(s.to_toml()) == s


def test_max_steps_override(capsys, tmp_path):
    with pytest.raises(ScenarioError) as exc:
        load_scenario("tianqin-kepler", ["run.max_steps=100"])
    assert exc.value.field == "run.duration"
    s = load_scenario("tianqin-kepler", ["run.max_steps=17280"])  # 10 d at 50 s: exactly the limit
    assert s.n_steps == 17280 and "max_steps = 17280" in s.to_toml()
    assert loads_scenario(s.to_toml()) == s
    out = tmp_path / "few.h5"
    status, _, err = run_cli(["run", "tianqin-kepler", "-q", "-o", str(out), "--duration", "1h",
                              "--set", "run.max_steps=72"], capsys)
    assert status == 0, err and out.exists()
    s = load_scenario("tianqin-kepler", ["run.duration=1e12d", "run.max_steps=2000000000000000"])
    assert s.n_steps == 1728000000000000


def test_builtins_valid_with_defaults():
    from tqdyn.scenario import builtin_scenarios

    for name in builtin_scenarios():
        s = load_scenario(name)
        assert s.run.max_steps == MAX_STEPS and s.allow_below_surface is False
        assert s.n_steps <= MAX_STEPS


def test_sun_radius_matches_force_model():
    from tqdyn.forces.sun import R_SUN_IAU_M

    assert float(BODY_RADII_M["sun"]) == R_SUN_IAU_M


def test_ephemeris_span_refused_before_output(capsys, tmp_path):
    """Durations beyond DE421 (2053-10-09 TDB) are refused in one line by the run's input checks."""
    out = tmp_path / "out.h5"
    status, _, err = run_cli(["run", "tianqin", "-q", "-o", str(out), "--set", "run.duration=20000d"], capsys)
    lines = err.strip().splitlines()
    assert status == 2 and len(lines) == 1, err
    assert lines[0].startswith("tqdyn: error: ephemeris DE421") and "outside its span" in lines[0]
    assert list(tmp_path.iterdir()) == []
