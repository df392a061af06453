"""Tests for tqdyn.scenario (TOML scenarios -> frozen dataclasses).

Reference values: Table I of the TianQin paper, typed in here: epoch
2004-06-06T00:00:00 UTC; all e = 0, i = 74.5 deg, raan = 211.6 deg, argp = 0;
Sat1 a = 100000.0 km, nu = 30 deg; Sat2 a = 100009.5 km, nu = 150 deg;
Sat3 a = 99995.0 km, nu = 270 deg.  EGM2008 GM = 3.986004415e14 m^3/s^2.
Durations: 1 d = 86400 s exactly, so 90 d = 7776000 s and 10 d = 864000 s.
"""

from __future__ import annotations

import dataclasses
from decimal import Decimal

import pytest

from tqdyn.scenario import (
    ForcesConfig,
    IntegratorConfig,
    RunConfig,
    SatelliteConfig,
    Scenario,
    ScenarioError,
    SpacecraftConfig,
    builtin_scenarios,
    load_scenario,
    loads_scenario,
    parse_duration,
)

TABLE_I = (
    ("Sat1", Decimal("100000.0"), Decimal("30")),
    ("Sat2", Decimal("100009.5"), Decimal("150")),
    ("Sat3", Decimal("99995.0"), Decimal("270")),
)

MINIMAL = """
[[satellites]]
name = "Sat1"
a_km = 100000.0
i_deg = 74.5
raan_deg = 211.6
nu_deg = 30.0
"""


def _check_table_i(s: Scenario) -> None:
    assert s.epoch_utc == "2004-06-06T00:00:00"
    assert len(s.satellites) == 3
    for sat, (name, a_km, nu) in zip(s.satellites, TABLE_I):
        assert sat.name == name
        assert sat.a_m == a_km * 1000
        assert sat.e == 0
        assert sat.i_deg == Decimal("74.5")
        assert sat.raan_deg == Decimal("211.6")
        assert sat.argp_deg == 0
        assert sat.nu_deg == nu
    assert s.forces.earth_monopole is True
    assert s.forces.gm_earth == Decimal("3.986004415e14")


# ----------------------------------------------------------------- built-ins


def test_builtin_names():
    assert {"tianqin", "tianqin-kepler"} <= set(builtin_scenarios())


@pytest.mark.parametrize("name", ["tianqin", "tianqin-kepler"])
def test_builtins_equal_table_i(name):
    s = load_scenario(name)
    assert s.name == name
    _check_table_i(s)
    assert s.run.duration_s == 864000  # "10d"
    assert s.integrator == IntegratorConfig()  # the default method, fixed, 50 s, corrected, 1e-22
    assert s.spacecraft.d_tm_m == Decimal("0.40") and s.spacecraft.d_p_m == 0
    assert s.n_steps == 17280  # 864000 s / 50 s
    assert s.description


def test_default_is_tianqin():
    assert load_scenario() == load_scenario("tianqin")


def test_decimal_exactness():
    sat = load_scenario("tianqin").satellites[0]
    assert isinstance(sat.raan_deg, Decimal)
    assert str(sat.raan_deg) == "211.6"
    assert sat.raan_deg == Decimal("211.6")
    assert isinstance(sat.a_m, Decimal) and sat.a_m == Decimal(100000000)
    assert load_scenario("tianqin").satellites[1].a_m == Decimal("100009500")


def test_frozen():
    s = load_scenario("tianqin")
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.name = "x"
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.satellites[0].e = Decimal("0.1")
    hash(s)


# ----------------------------------------------------------------- to_toml round trip


@pytest.mark.parametrize(
    "name, overrides",
    [
        ("tianqin", ()),
        ("tianqin-kepler", ()),
        ("tianqin", ("integrator.mode=adaptive", "integrator.rtol=3e-20", "run.duration=1.5d",
                     "run.precision=float64", "run.output_every=7", "forces.gm_earth=3.986004418E+14",
                     'scenario.description="quote \\" backslash \\\\ newline \\n tab \\t unicode \u00e9"',
                     "satellites.2.e=0.00012345678901234567890123456789", "spacecraft.d_p=0.0125",
                     "scenario.epoch_utc=2034-05-06T07:08:09.125")),
    ],
)
def test_to_toml_round_trip(tmp_path, name, overrides):
    s = load_scenario(name, overrides)
    text = s.to_toml()
    path = tmp_path / "resolved.toml"
    path.write_text(text, encoding="utf-8")
    back = load_scenario(str(path))
    assert back == s
    assert loads_scenario(text) == s
    assert back.to_toml() == text


def test_minimal_file_defaults(tmp_path):
    path = tmp_path / "mini.toml"
    path.write_text(MINIMAL, encoding="utf-8")
    s = load_scenario(str(path))
    assert s.name == "mini"  # file stem
    assert s.run == RunConfig() and s.integrator == IntegratorConfig()
    assert s.forces == ForcesConfig() and s.spacecraft == SpacecraftConfig()
    assert s.satellites[0] == SatelliteConfig("Sat1", Decimal("1e8"), Decimal(0), Decimal("74.5"), Decimal("211.6"),
                                              Decimal(0), Decimal(30))


# ----------------------------------------------------------------- overrides


def test_overrides_nested_and_satellite():
    s = load_scenario(
        "tianqin",
        [
            "integrator.mode=adaptive",
            "integrator.step=25",
            "run.duration=90d",
            "forces.earth_monopole=false",
            "satellites.2.a_km=100010.25",
            "satellites.3.name=TQ3",
            "satellites.1.e=0.001",
            "run.output=out/run.h5",
            'scenario.epoch_utc="2035-01-01T00:00:00"',
        ],
    )
    assert s.integrator.mode == "adaptive"
    assert s.integrator.step_s == 25
    assert s.run.duration_s == Decimal(7776000)
    assert s.forces.earth_monopole is False
    assert s.satellites[1].a_m == Decimal("100010250")
    assert s.satellites[2].name == "TQ3"
    assert s.satellites[0].e == Decimal("0.001")
    assert s.run.output == "out/run.h5"
    assert s.epoch_utc == "2035-01-01T00:00:00"
    assert s.n_steps == 7776000 // 25


def test_override_unquoted_datetime_and_string_keys():
    s = load_scenario("tianqin", ["scenario.epoch_utc=2004-06-07T00:00:00", "scenario.name=123"])
    assert s.epoch_utc == "2004-06-07T00:00:00"
    assert s.name == "123"


@pytest.mark.parametrize(
    "override, needles",
    [
        ("satellites.4.e=0", ["satellites.4", "1..3"]),
        ("satellites.0.e=0", ["satellites.0", "1..3"]),
        ("satellites.1.mass=3", ["mass", "a_km", "nu_deg"]),
        ("orbit.a=1", ["orbit.a", "docs/scenarios.md#keys"]),
        ("run.nope=1", ["nope", "duration", "output_every"]),
        ("run.duration", ["run.duration", "key=value"]),
    ],
)
def test_bad_overrides(override, needles):
    with pytest.raises(ScenarioError) as info:
        load_scenario("tianqin", [override])
    for needle in needles:
        assert needle in str(info.value)


# ----------------------------------------------------------------- durations


def test_parse_duration():
    assert parse_duration("90d") == Decimal(7776000)
    assert isinstance(parse_duration("90d"), Decimal)
    assert parse_duration("1.5d") == Decimal(129600)
    assert parse_duration("12h") == 43200
    assert parse_duration("30min") == 1800
    assert parse_duration("3600s") == 3600
    assert parse_duration("3600") == 3600
    assert parse_duration(3600) == 3600
    assert parse_duration(Decimal("0.25")) == Decimal("0.25")
    assert str(parse_duration("0.1d")) == "8640.0"  # exact decimal arithmetic


@pytest.mark.parametrize("bad", ["90 days", "d", "1.5x", "", "nan", True, [1]])
def test_parse_duration_bad(bad):
    with pytest.raises(ScenarioError) as info:
        parse_duration(bad)
    assert repr(bad) in str(info.value) and "duration" in str(info.value)
    assert isinstance(info.value, ValueError)


# ----------------------------------------------------------------- validation errors

_BAD_CASES = [
    # (overrides, field named, bad value shown)
    (["integrator.step=0"], "integrator.step", "0"),
    (["integrator.step=-50"], "integrator.step", "-50"),
    (["integrator.step=7"], "run.duration", "864000"),  # 864000 s is not a multiple of 7 s
    (["run.duration=1000", "integrator.step=7"], "run.duration", "1000"),
    (["run.duration=0d"], "run.duration", "0d"),
    (["run.duration=-10"], "run.duration", "-10"),
    (["run.duration=10 weeks"], "run.duration", "10 weeks"),
    (["integrator.step=\"50\""], "integrator.step", "'50'"),  # string where a number is needed
    (["integrator.step=true"], "integrator.step", "True"),  # bool where a number is needed
    (["forces.earth_monopole=1"], "forces.earth_monopole", "1"),
    (["forces.gm_earth=nan"], "forces.gm_earth", "NaN"),
    (["forces.gm_earth=-3.9e14"], "forces.gm_earth", "-3.9E+14"),
    (["satellites.2.e=1"], "satellites.2.e", "1"),
    (["satellites.2.e=1.5"], "satellites.2.e", "1.5"),
    (["satellites.3.e=-0.1"], "satellites.3.e", "-0.1"),
    (["satellites.1.a_km=0"], "satellites.1.a_km", "0"),
    (["satellites.1.a_km=-100000.0"], "satellites.1.a_km", "-100000.0"),
    (["satellites.1.a_km=\"1e5\""], "satellites.1.a_km", "'1e5'"),
    (["satellites.1.i_deg=inf"], "satellites.1.i_deg", "Infinity"),
    (["satellites.2.raan_deg=-inf"], "satellites.2.raan_deg", "-Infinity"),
    (["satellites.3.nu_deg=nan"], "satellites.3.nu_deg", "NaN"),
    (["satellites.1.e=true"], "satellites.1.e", "True"),
    (["satellites.2.name=Sat1"], "satellites.2.name", "'Sat1'"),
    (["run.precision=quad"], "run.precision", "'quad'"),
    (["run.precision=3"], "run.precision", "3"),
    (["integrator.mode=stepper"], "integrator.mode", "'stepper'"),
    (["integrator.tableau=fancy"], "integrator.tableau", "'fancy'"),
    (["integrator.method=rk4"], "integrator.method", "'rk4'"),
    (["integrator.rtol=0"], "integrator.rtol", "0"),
    (["integrator.rtol=0.01"], "integrator.rtol", "0.01"),
    (["run.output_every=0"], "run.output_every", "0"),
    (["run.output_every=2.5"], "run.output_every", "2.5"),
    (["spacecraft.d_tm=0"], "spacecraft.d_tm", "0"),
    (["spacecraft.d_p=-0.1"], "spacecraft.d_p", "-0.1"),
    (["scenario.epoch_utc=2004-13-01"], "scenario.epoch_utc", "2004-13-01"),
    (["scenario.epoch_utc=yesterday"], "scenario.epoch_utc", "'yesterday'"),
    (["scenario.epoch_utc=1900-01-01T00:00:00"], "scenario.epoch_utc", "1900-01-01T00:00:00"),
]


@pytest.mark.parametrize("overrides, field, value", _BAD_CASES)
def test_bad_values(overrides, field, value):
    with pytest.raises(ScenarioError) as info:
        load_scenario("tianqin", overrides)
    msg = str(info.value)
    assert msg.startswith(field + ":"), msg
    assert value in msg, msg
    assert "allowed:" in msg and "\n" not in msg


@pytest.mark.parametrize(
    "text, needles",
    [
        ("[orbit]\nx = 1\n" + MINIMAL, ["orbit", "is not a known key", "docs/scenarios.md#keys"]),
        ("[run]\nsteps = 3\n" + MINIMAL, ["run.steps", "duration", "output_every"]),
        (MINIMAL + "mass = 3\n", ["satellites.1.mass", "a_km"]),
        ("[run]\nduration = 100\n", ["satellites", "missing"]),
        ("satellites = []\n", ["satellites", "at least one"]),
        ("[satellites]\na_km = 1\n", ["satellites", "array of tables"]),
        ("[[satellites]]\ne = 0.1\n", ["satellites.1.a_km", "missing"]),
        ("run = 5\n" + MINIMAL, ["run", "5", "table"]),
        (MINIMAL + MINIMAL, ["satellites.2.name", "Sat1", "unique"]),
    ],
)
def test_bad_structure(text, needles):
    with pytest.raises(ScenarioError) as info:
        loads_scenario(text)
    for needle in needles:
        assert needle in str(info.value), str(info.value)


def test_malformed_toml_names_file_and_position(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("[run]\nduration = \n", encoding="utf-8")
    with pytest.raises(ScenarioError) as info:
        load_scenario(str(path))
    msg = str(info.value)
    assert str(path) in msg and "line 2" in msg and "column" in msg


def test_missing_file_points_to_the_builtins(tmp_path):
    path = tmp_path / "nope.toml"
    with pytest.raises(ScenarioError) as info:
        load_scenario(str(path))
    msg = str(info.value)
    assert str(path) in msg and "docs/scenarios.md#built-in-scenarios" in msg
    with pytest.raises(ScenarioError, match="did you mean 'tianqin-kepler'"):
        load_scenario("tianqin-keplr")


def test_adaptive_mode_does_not_need_a_multiple():
    s = load_scenario("tianqin", ["integrator.mode=adaptive", "integrator.step=7"])
    assert s.n_steps == -(-864000 // 7)  # ceil: number of output intervals


def test_direct_construction_validates():
    with pytest.raises(ScenarioError, match="integrator.mode: 'x'"):
        IntegratorConfig(mode="x")
    with pytest.raises(ScenarioError, match="satellite.e: 2"):
        SatelliteConfig("S", Decimal(1), Decimal(2), 0, 0, 0, 0)
    sat = SatelliteConfig("S", "7e6", 0, "97.5", 0, 0, 0)  # str/int coerced to exact Decimal
    assert sat.i_deg == Decimal("97.5") and isinstance(sat.e, Decimal)
    s = Scenario("x", "", "2004-06-06 00:00", satellites=[sat])
    assert s.epoch_utc == "2004-06-06T00:00:00" and s.satellites == (sat,)


def test_extends_a_builtin_scenario():
    # a file that extends "tianqin" changes only what it names
    s = loads_scenario('[scenario]\nname = "mine"\nextends = "tianqin"\n[forces]\nearth_degree = 4\n'
                       '[constellation]\ncontrol = "off"\n')
    base = load_scenario("tianqin")
    assert s.name == "mine" and s.forces.earth_degree == 4 and s.constellation.control == "off"
    assert s.satellites == base.satellites and s.forces.third_bodies == base.forces.third_bodies
    assert s.constellation.pointing == base.constellation.pointing and s.run == base.run
    assert loads_scenario(s.to_toml()) == s      # the resolved TOML stands alone
    # the study scenarios chain: tianqin-dragfree-local -> tianqin-dragfree -> tianqin
    local = load_scenario("tianqin-dragfree-local")
    assert local.constellation.pointing == "taylor2" and local.spacecraft.self_gravity == "off"
    with pytest.raises(ScenarioError, match="scenario.extends: 'nope' is not a built-in scenario; allowed: .*#built-in"):
        loads_scenario('[scenario]\nextends = "nope"\n')


def test_unquoted_epoch_override_keeps_every_decimal():
    """``--set scenario.epoch_tdb=2040-03-04T23:11:53.47537616`` (unquoted, a TOML
    date-time, which holds microseconds) keeps the text's 8 decimals: at LISA's
    30 km/s the lost 0.16 us would be 5 mm.  Reference: the text itself."""
    from tqdyn.scenario import load_scenario

    s = load_scenario("lisa-esa", ["scenario.epoch_tdb=2040-03-04T23:11:53.47537616"])
    assert s.epoch_tdb == "2040-03-04T23:11:53.47537616"
    s = load_scenario("tianqin", ["scenario.epoch_utc=2004-06-06 00:00:00.123456789"])
    assert s.epoch_utc == "2004-06-06T00:00:00.123456789"
