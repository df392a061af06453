"""Mission-length closed-loop budgets: every loop built and evaluated at once (tqdyn.closedloop.frequency),
the margins, the segments, the file's layout (docs/closed-loop.md, docs/closed-loop-file.md).

References: python-control's ``interconnect`` of the named blocks (the state-space matrices) and the LU solve of
each loop's state space (tqdyn.closedloop.budget.noise_budget, the per-segment evaluation); the identity
x'' = s^2 x (the relative accelerations from the displacements); python-control's ``stability_margins`` on an
exact transfer function (its polynomial method, not a grid); h5py's view of the datasets (character set,
filters); version-1 files made from a version-2 file the way the version-1 writer laid them out.
"""

from __future__ import annotations

import json
import math

import h5py
import numpy as np
import pytest

from tqdyn.closedloop import frequency
from tqdyn.closedloop.budget import closed_loop_response, grid_margins, noise_budget
from tqdyn.closedloop.loop import build_closed_loop, output_names
from tqdyn.closedloop.missions import default_controllers, default_noise
from tqdyn.closedloop.working_point import segment_rows

from test_closed_loop import _model

F = np.logspace(-5, 0, 60)
#: Outputs whose per-segment (LU) evaluation loses digits to cancellation at low frequencies: the relative
#: accelerations (x'' as a sum of large terms; checked against s^2 x below) and the MOSA torques.
_CANCELLING = ("tm1_relative_acceleration", "tm2_relative_acceleration", "mosa1_torque", "mosa2_torque")


@pytest.fixture(scope="module", params=["tianqin", "lisa"])
def loops(request):
    mission = request.param
    p, wp = _model(mission)
    ctl = default_controllers(mission)
    st = frequency.stack_loops([(p, wp)], ctl)
    return mission, st, build_closed_loop(p, wp, ctl)


def test_stacked_matrices_equal_python_controls_interconnection(loops):
    """closed_loop_matrices (the algebra on stacked blocks) against python-control's interconnect of the same
    named blocks: the same state, input and output names and matrices to 1e-15 of their largest entry
    (measured 2e-16; interconnect linearises numerically)."""
    _mission, st, cl = loops
    mine = frequency.closed_loops(st)[0].system
    assert mine.state_labels == cl.system.state_labels and mine.input_labels == cl.system.input_labels
    assert mine.output_labels == cl.system.output_labels
    for a, b in zip((mine.A, mine.B, mine.C, mine.D), (cl.system.A, cl.system.B, cl.system.C, cl.system.D)):
        assert np.max(np.abs(a - b)) <= 1e-15 * np.max(np.abs(b))


def test_vectorised_budget_equals_the_per_segment_evaluation(loops):
    """noise_asd (20 x 20 solves in the plant's coordinates, all loops at once) against noise_budget (an LU
    solve of each loop's 74-state space at each frequency): every output and source agrees to 2e-8 of the
    output's total at that frequency (measured 8e-9 at TianQin's low frequencies, 6e-12 at the median), but
    the outputs the LU evaluation computes by cancellation (_CANCELLING), which agree to 1e-5: the MOSA torques'
    LU error is ~1e-22 N m/Hz^1/2 absolute at 10 uHz (cancellation), against a total there of 3e-17 (LISA) to
    6e-17 (TianQin) N m/Hz^1/2 with the published preset's flat DWS noise (measured 3.4e-6 / 1.5e-6; v0.3's DWS
    noise, rising as (2 mHz/f)^2, made the total 3e-13 and the ratio 5e-10)."""
    mission, st, cl = loops
    noise = default_noise(mission)
    new, src = frequency.noise_asd(st, [0], noise, F)
    old, src_old = noise_budget(cl, noise, F)
    assert src == src_old
    total = np.sqrt(np.sum(old ** 2, axis=1))[:, None, :]
    err = np.max(np.abs(new[0] - old) / total, axis=(1, 2))
    names = output_names()
    for o, e in zip(names, err):
        assert e <= (1e-5 if o in _CANCELLING else 2e-8), (o, e)


def test_relative_acceleration_is_s2_times_the_displacement(loops):
    """The relative acceleration of TM 1 along its sensitive axis equals s^2 e.x_1, e.x_1 from the displacement
    outputs of the state space's LU evaluation (no cancellation there), to 1e-13 of its largest input's
    (measured 1.7e-15; the state space's own relative acceleration is off by up to 1e-7)."""
    _mission, st, cl = loops
    G = frequency.noise_response(st, [0], F)[0]
    names = output_names()
    e = np.array(_model(loops[0])[0].sensitive_axes[0], dtype=float)
    e /= np.linalg.norm(e)
    disp = closed_loop_response(cl, F, [f"tm1_displacement_{a}" for a in "xyz"])
    x = np.einsum("i,ijf->jf", e, disp)
    s2 = (2j * math.pi * F) ** 2
    want = s2 * x
    got = G[names.index("tm1_relative_acceleration")]
    assert np.max(np.abs(got - want) / np.max(np.abs(want), axis=0)) < 1e-13


def test_loop_gains_equal_the_state_space(loops):
    """frequency.loop_gains against -T/(1 + T) from each loop's state space (closed_loop_response d -> c) where
    |L| <= 100 (the margins' region; where |L| is large, 1 + T is a cancellation in both): 1e-10 relative
    (measured 8e-12)."""
    _mission, st, cl = loops
    f = np.logspace(-6, 1, 200)
    new = frequency.loop_gains(st, [0], f)[0]
    chans = list(cl.channel_names)
    T = closed_loop_response(cl, f, [f"c_{c}" for c in chans], [f"d_{c}" for c in chans])
    Tkk = np.array([T[k, k] for k in range(len(chans))])
    old = -Tkk / (1 + Tkk)
    m = np.abs(old) <= 100
    assert m.sum() > 1000 and np.max(np.abs(new - old)[m] / np.abs(old)[m]) < 1e-10


def test_margins_of_a_loop_with_both_gain_margins_equal_python_control():
    """grid_margins on 1500 points against python-control's stability_margins (polynomial method, exact) on
    L = 2 (s + 1)^2 / (s^3 (s/10 + 1)(s/20 + 1)), stable with a lower (0.356) and an upper (10.5) gain margin:
    lower, upper, phase margin and crossover to 5e-5 (measured 1.1e-5: the linear interpolation on the grid)."""
    import control

    s = control.tf("s")
    L = 2.0 * (s + 1) ** 2 / (s ** 3 * (s / 10 + 1) * (s / 20 + 1))
    assert np.all(control.poles(control.feedback(L, 1)).real < 0)
    gm, pm, _sm, wg, wp, _ws = control.stability_margins(L, returnall=True)
    assert len(gm) == 2 and gm.min() < 1 < gm.max()
    f = np.logspace(-3, 2, 1500)
    m = grid_margins(L(2j * np.pi * f), f)
    assert abs(m["gain_margin_lower"] / gm.min() - 1) < 5e-5
    assert abs(m["gain_margin_upper"] / gm.max() - 1) < 5e-5
    assert abs(m["phase_margin"] / pm[0] - 1) < 5e-5
    assert abs(m["crossover"] / (wp[0] / (2 * math.pi)) - 1) < 5e-5
    pc = control.stability_margins(L)                       # python-control's choice: the one closest to 1 in dB
    assert abs(m["gain_margin"] / pc[0] - 1) < 5e-5


def test_a_loop_without_phase_crossover_has_no_gain_margin():
    """L = 1/(s (s + 1)): no phase crossover, so neither margin (lower 0, upper inf), phase margin of
    python-control (52 deg)."""
    import control

    s = control.tf("s")
    L = 1 / (s * (s + 1))
    f = np.logspace(-3, 2, 1500)
    m = grid_margins(L(2j * np.pi * f), f)
    assert m["gain_margin_lower"] == 0 and m["gain_margin_upper"] == math.inf and m["gain_margin"] == math.inf
    assert abs(m["phase_margin"] / control.stability_margins(L)[1] - 1) < 5e-5


@pytest.mark.parametrize("days", [1, 3, 90])
def test_a_run_of_exactly_n_days_has_n_segments(days):
    """segment_rows of a run of exactly n days (rows every 600 s) gives n one-day segments, the last holding the
    final row; a run of n days and 6 h gives n + 1."""
    t = np.arange(0.0, days * 86400.0 + 1.0, 600.0)
    rows = segment_rows(t, 86400.0)
    assert len(rows) == days and rows[-1][1] == len(t) and all(b - a >= 144 for a, b, _m in rows)
    t2 = np.arange(0.0, days * 86400.0 + 21600.0 + 1.0, 600.0)
    assert len(segment_rows(t2, 86400.0)) == days + 1


@pytest.fixture(scope="module")
def budget_file(tmp_path_factory):
    import tqdyn
    from tqdyn.analysis.closed_loop import closed_loop_budget
    from tqdyn.closedloop.model import closed_loop_model

    from test_closed_loop_file import _write

    traj = tqdyn.propagate("tianqin", {"run.duration": "2h", "integrator.step": 600})
    model = closed_loop_model(traj)
    budget = closed_loop_budget(model, f=np.logspace(-4, 0, 100))
    return model, budget, _write(tmp_path_factory.mktemp("clb") / "cl.h5", model, budget, duration=10.0)


def test_strings_are_utf8_and_the_budget_is_compressed(budget_file):
    """Text datasets carry HDF5's UTF-8 character set (h5py.check_string_dtype); every budget dataset is
    chunked with shuffle + gzip; the per-source ASDs take at most 0.8 of their bytes (measured 0.67)."""
    _model_, budget, path = budget_file
    with h5py.File(path, "r") as h5:
        g = h5["budget"]
        for name in ("dominant", "source", "output", "unit", "sat_name"):
            info = h5py.check_string_dtype(g[name].dtype)
            assert info is not None and info.encoding == "utf-8", name
        assert g["asd"].compression == "gzip" and g["asd"].shuffle and g["asd"].fletcher32
        assert g["asd"].id.get_storage_size() <= 0.8 * budget["asd"].values.nbytes


def test_a_version_1_file_is_read_into_the_new_layout(budget_file, tmp_path):
    """A version-1 file (ASCII strings, ``gain_margin`` python-control's choice, no lower/upper) reads: the
    strings as text, ``gain_margin_lower``/``_upper`` from what version 1 recorded (0.5 -> lower 0.5, upper
    unknown; 2 -> upper 2; inf -> neither margin), ``gain_margin`` the lower one."""
    import shutil

    from tqdyn.formats.closed_loop import read_closed_loop
    from tqdyn.formats.trajectory.reader import text_array

    _model_, budget, path = budget_file
    old = tmp_path / "v1.h5"
    shutil.copy(path, old)
    with h5py.File(old, "r+") as h5:
        h5.attrs["format_version"] = 1
        g = h5["budget"]
        shape = g["gain_margin"].shape
        v1 = np.resize(np.array([0.5, 2.0, np.inf]), shape)
        for name in ("gain_margin", "gain_margin_lower", "gain_margin_upper", "dominant"):
            attrs = dict(g[name].attrs)
            del g[name]
            if name == "gain_margin":
                ds = g.create_dataset(name, data=v1, chunks=shape, fletcher32=True)
            elif name == "dominant":
                ds = g.create_dataset(name, data=text_array(budget["dominant"].values), chunks=True,
                                      fletcher32=True)
            else:
                continue
            ds.attrs.update(attrs)
        g.attrs["variables"] = json.dumps([v for v in json.loads(g.attrs["variables"])
                                           if v not in ("gain_margin_lower", "gain_margin_upper")])
    cl = read_closed_loop(old)
    b = cl.budget
    assert (b["dominant"].values == budget["dominant"].values).all()
    lower, upper = b["gain_margin_lower"].values.ravel(), b["gain_margin_upper"].values.ravel()
    v = v1.ravel()
    assert np.all(lower[v == 0.5] == 0.5) and np.all(np.isnan(upper[v == 0.5]))
    assert np.all(upper[v == 2.0] == 2.0) and np.all(np.isnan(lower[v == 2.0]))
    assert np.all(lower[np.isinf(v)] == 0.0) and np.all(np.isinf(upper[np.isinf(v)]))
    assert np.array_equal(b["gain_margin"].values, b["gain_margin_lower"].values, equal_nan=True)


def test_collinear_scheme_stacked_as_interconnected_and_evaluated_as_per_loop():
    """LISA Pathfinder's "collinear" loops through the stacked engine: the matrices equal python-control's
    interconnect of the same named blocks to 1e-15 of their largest entry (measured 2.3e-16), and noise_asd
    equals the LU evaluation of the state space (noise_budget) to 1e-6 of the output's total for the outputs
    computed by cancellation (_CANCELLING; measured 7.1e-7), 1e-7 for the spacecraft's position (free and
    Hill modes at low frequencies; measured 2.1e-8) and 5e-9 for the rest (measured 1.1e-9).  "single_tm"
    (TianQin-1, a sensor reading a controller's output) is refused by the stacked engine in one line."""
    from tqdyn.closedloop.model import static_closed_loop_model

    m = static_closed_loop_model("lpf")
    assert m.stack is not None and static_closed_loop_model("tianqin-1").stack is None
    p, wp = m.parts[0][0]
    z = m.settings["attitude_z_sensor"]
    st = frequency.stack_loops([(p, wp)], m.controllers, z, "collinear")
    cl = build_closed_loop(p, wp, m.controllers, z, "collinear")
    mine = frequency.closed_loops(st)[0].system
    assert mine.state_labels == cl.system.state_labels and mine.output_labels == cl.system.output_labels
    for a, b in zip((mine.A, mine.B, mine.C, mine.D), (cl.system.A, cl.system.B, cl.system.C, cl.system.D)):
        assert np.max(np.abs(a - b)) <= 1e-15 * np.max(np.abs(b))
    new, src = frequency.noise_asd(st, [0], m.noise, F)
    old, src_old = noise_budget(cl, m.noise, F)
    assert src == src_old
    total = np.sqrt(np.sum(old ** 2, axis=1))[:, None, :]
    err = np.max(np.abs(new[0] - old) / np.where(total > 0, total, 1.0), axis=(1, 2))
    for o, e in zip(output_names(), err):
        assert e <= (1e-6 if o in _CANCELLING else 1e-7 if o.startswith("sc_position") else 5e-9), (o, e)
    with pytest.raises(ValueError, match=r"^closed_loop\.scheme: 'single_tm' [^\n]*$"):
        frequency.stack_loops([(p, wp)], m.controllers, z, "single_tm")


def test_stacked_budget_of_a_run_equals_the_per_loop_python_control_path(budget_file):
    """closed_loop_budget of a short coupled run (3 spacecraft) evaluated at once (tqdyn.closedloop.frequency) against
    the same model without its stack: each loop's python-control state space evaluated by an LU solve per
    frequency (noise_budget, loop_gains of tqdyn.closedloop.budget).  The per-source ASDs agree to 3e-10 of the
    output's total at each frequency (measured 4.2e-11), 3e-9 for the outputs that path computes by cancellation
    (_CANCELLING; measured 4.8e-10); the margins to 1e-11 relative (measured 1.4e-12)."""
    from dataclasses import replace

    from tqdyn.analysis.closed_loop import closed_loop_budget

    model, fast, _path = budget_file
    slow = closed_loop_budget(replace(model, stack=None), f=fast["frequency"].values)
    tot = slow["total"].values[:, :, :, None, :]
    err = np.max(np.abs(fast["asd"].values - slow["asd"].values) / tot, axis=(0, 1, 3, 4))
    for o, e in zip(output_names(), err):
        assert e <= (3e-9 if o in _CANCELLING else 3e-10), (o, e)
    for k in ("gain_margin_lower", "gain_margin_upper", "phase_margin", "crossover"):
        a, b = fast[k].values, slow[k].values
        fin = np.isfinite(b) & (b != 0)
        assert np.array_equal(np.isfinite(a), np.isfinite(b)) and np.array_equal(a == 0, b == 0), k
        assert np.max(np.abs(a[fin] / b[fin] - 1), initial=0.0) < 1e-11, (k, np.max(np.abs(a[fin] / b[fin] - 1)))
    assert (fast["dominant"].values == slow["dominant"].values).all()
