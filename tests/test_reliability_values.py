"""Reliability of the values of a run (issue 34, item 4; docs/reliability.md, docs/scenarios.md).

Values that are not finite, booleans where numbers belong, reversed ranges and values out of their
physical size are refused at load in one line naming the key; a propagation whose state stops being
finite stops at that step with one line naming the step, the time and the satellite, and leaves no
file.  References: the bounds documented in docs/scenarios.md (|acceleration| <= 1e-3 m/s^2, |v| < c);
for where a satellite moving at v stops being finite, float64's largest number 1.8e308: the dd
point-mass force overflows once |r|^3 does (|r| > 5.64e102 m), a float64 position once |r| does.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from cli_support import run_cli
from tqdyn import dynamics
from tqdyn.scenario import ScenarioError, load_scenario


@pytest.mark.parametrize("override, message", [
    ("accelerations.rtn=[[0, 1e300, 0], [0, 0, 0], [0, 0, 0]]",
     "accelerations.rtn: [[0, 1E+300, 0], [0, 0, 0], [0, 0, 0]] has 1E+300 m/s^2, too large for the small force this "
     "key models; allowed: |each value| <= 0.001 m/s^2 (docs/scenarios.md)"),
    ("accelerations.rtn_sin=[[0, 0, -2e-3], [0, 0, 0], [0, 0, 0]]",
     "accelerations.rtn_sin: [[0, 0, -0.002], [0, 0, 0], [0, 0, 0]] has -0.002 m/s^2, too large for the small force "
     "this key models; allowed: |each value| <= 0.001 m/s^2 (docs/scenarios.md)"),
    ("accelerations.rtn=[[0, true, 0], [0, 0, 0], [0, 0, 0]]",
     "accelerations.rtn: [[0, True, 0], [0, 0, 0], [0, 0, 0]] contains a boolean; allowed: an array of shape (3, 3) of "
     "finite numbers [m/s^2, one row per satellite]"),
    ("accelerations.rtn=[[0, inf, 0], [0, 0, 0], [0, 0, 0]]",
     "accelerations.rtn: [[0, Infinity, 0], [0, 0, 0], [0, 0, 0]] is not finite; allowed: an array of shape (3, 3) of "
     "finite numbers [m/s^2, one row per satellite]"),
    ("spacecraft.self_gravity_common=[1, 0, 0]",
     "spacecraft.self_gravity_common: [1, 0, 0] has 1 m/s^2, too large for the small force this key models; "
     "allowed: |each value| <= 0.001 m/s^2 (docs/scenarios.md)"),
    ("integrator.step=true", "integrator.step: True is a boolean; allowed: a number"),
])
def test_scenario_values_refused_at_load(override, message):
    """Accelerations above the documented bound (1e300 gave a trajectory of NaN, exit 0), booleans
    and inf where numbers belong: one ScenarioError line naming the key."""
    with pytest.raises(ScenarioError) as info:
        load_scenario("tianqin-kepler", [override])
    assert str(info.value) == message


def test_acceleration_at_the_bound_is_accepted():
    """1e-3 m/s^2 itself (and the 1e-9 of the docs' examples) loads."""
    s = load_scenario("tianqin-kepler", ["accelerations.rtn=[[0, 1e-3, 0], [0, -1e-3, 0], [1e-9, 0, 0]]"])
    assert s.accelerations.values(3)[0, 4] == 1e-3


@pytest.fixture(scope="module")
def cartesian(tmp_path_factory):
    """A TOML file of tianqin-kepler with Cartesian states (satellites.N.r_km / v_kmps)."""
    path = tmp_path_factory.mktemp("cart") / "cart.toml"
    sats = "".join(f'[[satellites]]\nname = "S{k}"\nr_km = [{1e5 * (k + 1)}, 0, 0]\nv_kmps = [0, 2, 0]\n'
                   for k in range(3))
    path.write_text(f'[scenario]\nextends = "tianqin-kepler"\nname = "cart"\n{sats}')
    return str(path)


@pytest.mark.parametrize("overrides, message", [
    (["satellites.1.r_km=[0, 0, 0]", "scenario.allow_below_surface=true"],
     "satellites.1.r_km: [0, 0, 0] is the centre of the central body; allowed: |r| > 0 (the point-mass gravity is "
     "singular there)"),
    (["satellites.2.v_kmps=[3e5, 0, 0]"],
     "satellites.2.v_kmps: [3E+5, 0, 0] has |v| = 3e+08 m/s, not below the speed of light; allowed: |v| < c = "
     "299792458.0 m/s"),
])
def test_cartesian_state_out_of_physics_is_refused(cartesian, overrides, message):
    """r = 0 (a ZeroDivisionError traceback from the compiled force model, even with
    allow_below_surface) and |v| >= c are refused at load naming the key."""
    with pytest.raises(ScenarioError) as info:
        load_scenario(cartesian, overrides)
    assert str(info.value) == message
    assert load_scenario(cartesian).satellites[1].v_mps[1] == 2000


@pytest.mark.parametrize("overrides, message", [
    (["closed_loop.f_min=2"], "closed_loop.f_min: 2 leaves no band: f_min = 2 Hz, f_max = 1 Hz (the other one's "
                              "default); allowed: f_min < f_max [Hz]"),
    (["closed_loop.f_min=0.5", "closed_loop.f_max=0.5"],
     "closed_loop.f_min: 0.5 leaves no band: f_min = 0.5 Hz, f_max = 0.5 Hz; allowed: f_min < f_max [Hz]"),
    (["closed_loop.fs=true"], "closed_loop.fs: True is not a positive number; allowed: a frequency > 0 Hz"),
])
def test_closed_loop_frequency_grid(overrides, message):
    """A reversed or empty budget grid (it ran on a reversed grid) and a boolean sample rate are
    refused naming the key; f_min and f_max's defaults are docs/scenarios.md's 1e-5 and 1 Hz."""
    with pytest.raises(ScenarioError) as info:
        load_scenario("tianqin-dragfree", overrides)
    assert str(info.value) == message


@pytest.mark.parametrize("value, shown", [("true", "True"), ('"1e-3"', "'1e-3'"), ("nan", "nan")])
def test_ttl_coefficient_file_takes_numbers_only(tmp_path, value, shown):
    """`true` in a TTL coefficient file was read as 1 m/rad: a boolean, a string, nan are refused
    naming the file, the table and the MOSA."""
    from tqdyn.workflows.export_ttl import read_coefficient_file

    mosas = ("12", "23", "31", "13", "32", "21")
    tables = {f: {m: 1e-3 for m in mosas} for f in ("local_phi", "local_eta", "distant_phi", "distant_eta")}
    good = tmp_path / "c.json"
    good.write_text(json.dumps(tables))
    assert read_coefficient_file(good).local_phi["23"] == 1e-3
    text = "\n".join(f"[{f}]\n" + "\n".join(f'"{m}" = {value if (f, m) == ("local_eta", "31") else 1e-3}'
                                            for m in mosas) for f in tables)
    bad = tmp_path / "c.toml"
    bad.write_text(text)
    with pytest.raises(ValueError) as info:
        read_coefficient_file(bad)
    assert str(info.value) == (f"{bad}: ttl.local_eta['31'] = {shown}: must be a finite number (m/rad), not a boolean "
                               "or a string")


# ------------------------------------------------------------------ a state that stops being finite

#: float64's largest number, and where |r|^3 overflows it (the dd point-mass force then gives inf - inf)
DBL_MAX = float(np.finfo(np.float64).max)
CUBE_LIMIT = DBL_MAX ** (1.0 / 3.0)          # 5.64e102 m


def _y0(scen, v):
    """tianqin-kepler's dd initial states with satellite 2 moving at v [m/s] along x."""
    from tqdyn.forces.model import build_force_model

    model = build_force_model(scen.forces, scen.reference)
    y0 = np.array(dynamics.initial_state(scen, model, dynamics.build_system(scen, model)), np.float64)
    y0[1, 3:6] = 0.0
    y0[1, 3, 0] = v
    return y0


def _stop(sets, v, duration="6h"):
    scen = load_scenario("tianqin-kepler", [f"run.duration={duration}", "integrator.step=50", *sets])
    with pytest.raises(dynamics.NonFiniteStateError) as info:
        dynamics.propagate(scen, y0=_y0(scen, v))
    exc = info.value
    assert exc.body == 1 and exc.step >= 1, str(exc)
    assert str(exc) == (f"propagation: the state of 'Sat2' is not finite at step {exc.step} (t = {exc.t:.9g} s TT after "
                        "the epoch): a force, acceleration or initial state is out of range")
    return exc


def _finite_before(sets, v, step):
    """The same run to the step before ``step`` ends with finite states."""
    scen = load_scenario("tianqin-kepler", [f"run.duration={50 * (step - 1)}", "integrator.step=50", *sets])
    assert np.all(np.isfinite(dynamics.propagate(scen, y0=_y0(scen, v)).y_final))


@pytest.mark.parametrize("sets", [[], ["integrator.method=multistep"]])
def test_non_finite_state_stops_at_its_step_dd(sets):
    """dd, v = 4e99 m/s: |r| = v t passes the cube root of float64's largest number (5.64e102 m) between
    step 28 (5.6e102 m) and step 29, whose force evaluations see |r|^3 overflow: the run stops at step
    29 (t = 1450 s), naming Sat2; the run to step 28 is finite."""
    v = 4e99
    exc = _stop(sets, v)
    assert 28 * 50 * v < CUBE_LIMIT < 29 * 50 * v
    assert exc.step == 29 and exc.t == 1450.0
    _finite_before(sets, v, exc.step)


def test_non_finite_state_stops_at_its_step_float64():
    """float64, v = 1e304 m/s: the float64 force stays finite (1/|r|^3 -> 0); the position itself
    overflows once v t > 1.8e308 m (step 360), the DP87 stages' partial sums (up to ~30 h v past the
    state) a few percent earlier: the stop lies in the last 10 % before step 360; the run to the step
    before it is finite."""
    v = 1e304
    exc = _stop(["run.precision=float64"], v)
    last = int(np.ceil(DBL_MAX / (50 * v)))
    assert last == 360 and 0.9 * last <= exc.step <= last, exc.step
    _finite_before(["run.precision=float64"], v, exc.step)


def test_non_finite_state_stops_the_adaptive_run():
    """Adaptive dd run (rtol 1e-10), v = 4e99 m/s: the attempted step whose end sees |r|^3 overflow
    stops the run, its time t with v t between the limit and 1.2 times it (the steps grow the
    radius by ~13 % at most: h <= 0.13 |r| / |v|, the dense-output bound)."""
    exc = _stop(["integrator.mode=adaptive", "integrator.rtol=1e-10"], 4e99)
    assert CUBE_LIMIT <= 4e99 * exc.t <= 1.2 * CUBE_LIMIT, exc.t


def test_non_finite_initial_state_stops_at_step_0():
    """A NaN in the initial state given through the API: step 0, t = 0, nothing propagated."""
    scen = load_scenario("tianqin-kepler", ["run.duration=1h"])
    y0 = _y0(scen, 2000.0)
    y0[2, 0, 1] = np.nan
    with pytest.raises(dynamics.NonFiniteStateError, match=r"^propagation: the state of 'Sat3' is not finite at step "
                                                           r"0 \(t = 0 s TT after the epoch\)"):
        dynamics.propagate(scen, y0=y0)


def test_run_with_a_non_finite_state_exits_2_and_leaves_nothing(tmp_path, capsys, monkeypatch):
    """`tqdyn run` (checkpoints every 10 steps): exit 2, one error line naming step, time and
    satellite, and no trajectory, no checkpoint, no hidden temporary file."""
    real = dynamics.propagate

    def with_fast_satellite(scen, **kw):
        return real(scen, y0=_y0(scen, 4e99), **kw)

    monkeypatch.setattr(dynamics, "propagate", with_fast_satellite)
    out = tmp_path / "run.h5"
    status, _, err = run_cli(["run", "tianqin-kepler", "--duration", "2h", "--step", "50", "--checkpoint-every", "10",
                              "-o", str(out), "-q"], capsys)
    assert status == 2, err
    errors = [ln for ln in err.splitlines() if ln.startswith("tqdyn: error:")]
    assert len(errors) == 1 and "Traceback" not in err, err
    assert errors[0].startswith("tqdyn: error: propagation: the state of 'Sat2' is not finite at step 29 (t = 1450 s ")
    assert errors[0].endswith("; no output file written")
    assert list(tmp_path.iterdir()) == []


def test_run_with_a_huge_acceleration_exits_2_before_anything(tmp_path, capsys):
    """The issue's case: `[accelerations] rtn = [[0, 1e300, 0], ...]` (exit 0 and a trajectory of NaN
    before): exit 2, one line naming the key, no file."""
    out = tmp_path / "run.h5"
    status, _, err = run_cli(["run", "tianqin-kepler", "--duration", "1h", "-o", str(out), "-q", "--set",
                              "accelerations.rtn=[[0, 1e300, 0], [0, 0, 0], [0, 0, 0]]"], capsys)
    assert status == 2
    assert err.strip().startswith("tqdyn: error: accelerations.rtn: ") and len(err.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []
