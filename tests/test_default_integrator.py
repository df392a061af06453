"""The integrator of a run whose scenario names none (``integrator.method`` not given).

Fixed-step runs integrate with the multistep method
(:data:`tqdyn.scenario.config.DEFAULT_METHOD`), adaptive runs with DP87 (the
only adaptive method); ``integrator.method = "dp87"`` gives DP87 back.

References: the documented keys and defaults (docs/scenarios.md,
"[integrator]"); for what the default changed in the outputs of
``tqdyn run``, the DP87 run of the same scenario (the default of versions
0.1 and 0.2), whose agreement with the multistep method and its own
reproducibility at half the step are measured in tests/test_multistep.py
(1 and 90 days).
"""

from __future__ import annotations

import numpy as np
import pytest

from tqdyn import dynamics
from tqdyn.dynamics import Rows
from tqdyn.formats import trajectory as io
from tqdyn.numerics import multistep as ms
from tqdyn.numerics.dd import np_dd_add
from tqdyn.scenario import (DEFAULT_METHOD, IntegratorConfig, ScenarioError, builtin_scenarios, load_scenario,
                            loads_scenario)
from tqdyn.workflows import run as runner
from tqdyn.workflows.numbers import machine

DP87 = ["integrator.method=dp87"]


def test_tqdyn_run_resolves_to_the_multistep_method():
    """The scenario ``tqdyn run`` resolves with no argument (the built-in tianqin): the multistep method of
    the documented default order and corrector; ``--set integrator.method=dp87`` gives DP87, nothing else
    changed."""
    scen, notes = runner.load_run_scenario(None, ())
    assert DEFAULT_METHOD == "multistep" and not notes
    g = scen.integrator
    assert (g.method, g.mode, g.order, g.corrector) == ("multistep", "fixed", ms.DEFAULT_ORDER, ms.DEFAULT_CORRECTOR)
    assert runner.integrator_label(g) == f"multistep-{ms.DEFAULT_ORDER}-{ms.DEFAULT_CORRECTOR}-dp87-corrected"
    dp, _ = runner.load_run_scenario(None, DP87)
    assert dp.integrator.method == "dp87" and runner.integrator_label(dp.integrator) == "dp87-fixed-corrected"
    assert dp.integrator.step_s == g.step_s and dp.forces == scen.forces and dp.run == scen.run


@pytest.mark.parametrize("name", builtin_scenarios())
def test_builtin_scenarios_take_the_default(name):
    """No built-in scenario names an integrator method: each integrates with the default."""
    assert load_scenario(name).integrator.method == DEFAULT_METHOD


def test_adaptive_runs_fall_back_to_dp87():
    """The multistep method has a fixed step only: an adaptive run that names no method is DP87; one that
    names the multistep method is refused in one line naming integrator.mode."""
    assert IntegratorConfig().method == DEFAULT_METHOD
    assert IntegratorConfig(mode="adaptive").method == "dp87"
    scen = load_scenario("tianqin-dragfree-local", ["integrator.mode=adaptive", "integrator.rtol=1e-18"])
    assert (scen.integrator.method, scen.integrator.mode) == ("dp87", "adaptive")
    with pytest.raises(ScenarioError) as err:
        load_scenario("tianqin", ["integrator.mode=adaptive", "integrator.method=multistep"])
    text = str(err.value)
    assert text.startswith("integrator.mode: 'adaptive'") and "method = \"dp87\"" in text and "\n" not in text


@pytest.mark.parametrize("mission", ["tianqin", "lisa"])
def test_studies_keep_the_papers_dp87(mission):
    """``tqdyn report --studies`` (both study sets) integrates every run with DP87, the paper's method, set
    before the run's own overrides (an extra override still wins)."""
    from tqdyn.workflows import studies, studies_lisa

    runs = studies.RUNS if mission == "tianqin" else studies_lisa.RUNS
    for spec in runs.values():
        assert spec.scenario_for(duration_scale=1e-3).integrator.method == "dp87", spec.name
    spec = next(iter(runs.values()))
    assert spec.scenario_for(duration_scale=1e-3, extra=["integrator.method=multistep"]).integrator.method == "multistep"


def test_recorded_scenarios_keep_their_method():
    """A resolved scenario (the one a trajectory file records) names its method, so a file written with
    DP87 is re-run with DP87 whatever the default: the resolved text reads back to the same scenario."""
    for overrides in (DP87, ()):
        scen = load_scenario("tianqin", overrides)
        text = scen.to_toml()
        assert f'method = "{scen.integrator.method}"' in text
        assert loads_scenario(text) == scen


def test_default_run_banner_and_file(default_run):
    """``tqdyn run`` (the session fixture ``default_run``, conftest.py) says which method it runs and records
    it in the file's ``integrator`` attribute."""
    status, _, err, path = default_run
    assert status == 0, err
    assert (f"dd precision, multistep order {ms.DEFAULT_ORDER} {ms.DEFAULT_CORRECTOR.upper()} (DP87 start-up) "
            "50.0 s x 17280 steps") in err
    tr = io.read_trajectory(path)
    assert tr.attrs["integrator"] == f"multistep-{ms.DEFAULT_ORDER}-{ms.DEFAULT_CORRECTOR}-dp87-corrected"


def _warm(scen):
    """Compile the kernels of ``scen`` and load its data: a run of its first steps (a multistep run's start-up
    and two steps), as ``tqdyn bench`` does before it times a run."""
    import dataclasses

    n = scen.integrator.order + 2 if scen.integrator.method == "multistep" else 1
    dynamics.warm_up(scen.run.precision, scen.integrator.method, model=dynamics.check_inputs(scen))
    dynamics.propagate(dataclasses.replace(scen, run=dataclasses.replace(scen.run, duration_s=scen.integrator.step_s * n)))


def _run(scen):
    """Rows and result of ``scen`` (``res.wall_s``: the propagation's wall time [s], the number ``tqdyn run``
    prints)."""
    blocks = []
    res = dynamics.propagate(scen, sink=blocks.append)
    return Rows.concatenate(blocks), res


def _dd_norm(a, b) -> np.ndarray:
    """|a - b| [m or m/s] of two (hi, lo) arrays of vectors (last axis), from their dd difference."""
    h, lo = np_dd_add(a[0], a[1], -b[0], -b[1])
    return np.linalg.norm(h + lo, axis=-1)


@pytest.mark.slow
def test_default_change_on_the_default_run(record_number):
    """What the default changed in ``tqdyn run`` (built-in tianqin: full force model, global pointing,
    Table IV self-gravity, drag-free control; 10 days at 50 s, 17,281 rows): the multistep rows against the
    DP87 rows of the same scenario, and the propagation wall time of each (same process, kernels compiled).

    Measured (2 cores, load average ~7-8): satellites 6.8e-14 m and 1.4e-18 m/s apart at most, the TM housing
    centres 6.8e-14 m; the drag-free accelerations G_i 5.9e-26 m/s^2 (9.2e-16 of max |G_i|), the suspensions
    5.8e-26 m/s^2 (7.0e-16 relative); the TM angular accelerations did not differ in any row.  The yardstick,
    DP87 at 25 s against DP87 at 50 s: 3.9e-14 m (ratio 1.7; after 1 and 90 days, tests/test_multistep.py:
    multistep vs DP87 1.2e-15 and 4.6e-13 m, DP87 50 s vs 25 s 2.7e-16 and 2.6e-13 m, ratios 4.4 and 1.8).
    Bounds 3e-13 m, 1e-17 m/s, 5e-15 relative, the ratio 5.  Wall time: 2.3-4.1 s against 15-26 s for DP87
    (6.4-7.1x; the 90-day coupled benchmark: 5.9x); bound: DP87 more than 2x as long.
    """
    where = machine()  # the load average at the start
    scenarios = load_scenario(), load_scenario(None, DP87)
    for scen in scenarios:
        _warm(scen)
    (ms_rows, ms_res), (dp_rows, dp_res) = (_run(scen) for scen in scenarios)
    assert len(ms_rows) == len(dp_rows) == 17281
    # the yardstick: DP87 at 25 s against DP87 at 50 s (rows on the same grid)
    fine, _ = _run(load_scenario(None, [*DP87, "integrator.step=25", "run.output_every=2"]))
    floor = float(_dd_norm(fine.sat_r, dp_rows.sat_r).max())
    d = {"sat_r_m": float(_dd_norm(ms_rows.sat_r, dp_rows.sat_r).max()),
         "sat_v_mps": float(_dd_norm(ms_rows.sat_v, dp_rows.sat_v).max()),
         "tm_r_m": float(_dd_norm(ms_rows.tm_r, dp_rows.tm_r).max())}
    for f, vector in (("sat_a_dragfree", True), ("tm_a_suspension", False), ("tm_alpha_suspension", False)):
        a, b = getattr(ms_rows, f), getattr(dp_rows, f)
        diff = np.linalg.norm(a - b, axis=-1) if vector else np.abs(a - b)
        size = np.linalg.norm(b, axis=-1) if vector else np.abs(b)
        d[f] = float(diff.max())
        d[f + "_rel"] = float(diff.max() / size.max())
    d |= {"dp87_50s_vs_25s_sat_r_m": floor, "wall_multistep_s": ms_res.wall_s, "wall_dp87_s": dp_res.wall_s, "dp87_over_multistep": dp_res.wall_s /
          ms_res.wall_s, "n_rhs_multistep": ms_res.n_rhs, "n_rhs_dp87": dp_res.n_rhs, "machine": where["summary"],
          "load_average": where["load_average"]}
    print(f"\ntqdyn run, multistep vs DP87: {d}")
    record_number("default_integrator.tianqin_10d", d, "m, m/s, m/s^2, rad/s^2 (*_rel: relative), s (wall_*)")
    assert d["sat_r_m"] < 3e-13 and d["tm_r_m"] < 3e-13 and d["sat_v_mps"] < 1e-17
    assert floor < 3e-13 and d["sat_r_m"] < 5 * floor
    assert max(d["sat_a_dragfree_rel"], d["tm_a_suspension_rel"], d["tm_alpha_suspension_rel"]) < 5e-15
    assert d["dp87_over_multistep"] > 2.0
