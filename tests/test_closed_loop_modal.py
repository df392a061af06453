"""The modal loop gains of the mission-length budget (tqdyn.closedloop.modal): the margins they give equal those of
the exact 20 x 20 solves on the whole grid, their error stays inside the bound that decides where the exact path is
taken, and a loop with ill-conditioned eigenvectors is evaluated exactly everywhere.

References: tqdyn.closedloop.frequency.loop_gains on every point of the margins' grid (the exact path, itself pinned
to each loop's python-control state space in tests/test_closed_loop_budget.py); python-control's interconnection of
the named blocks (tqdyn.closedloop.loop.build_closed_loop) evaluated by an LU solve per frequency
(tqdyn.closedloop.budget.closed_loop_response).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from tqdyn.analysis.closed_loop import MARGIN_GRID
from tqdyn.closedloop import frequency, modal
from tqdyn.closedloop.budget import closed_loop_response, grid_margins
from tqdyn.closedloop.loop import build_closed_loop
from tqdyn.closedloop.missions import default_controllers

from test_closed_loop import _model

FM = np.logspace(math.log10(MARGIN_GRID[0]), math.log10(MARGIN_GRID[1]), MARGIN_GRID[2])


@pytest.fixture(scope="module", params=["tianqin", "lisa"])
def stacked(request):
    mission = request.param
    p, wp = _model(mission)
    ctl = default_controllers(mission)
    st = frequency.stack_loops([(p, wp)], ctl)
    return st, frequency.closed_loops(st)[0], build_closed_loop(p, wp, ctl)


def _exact_counting(st, calls):
    def exact(pos, f):
        calls.append(len(f))
        return frequency.loop_gains(st, pos, f)
    return exact


def test_modal_margins_equal_those_of_the_exact_grid(stacked):
    """Margins of the modal gains (exact where they decide a sign or a value) against grid_margins of the exact
    solves on all 1500 points: equal to 1e-13 relative (measured: identical), with the exact path taken on fewer
    than 20 % of the points (measured 6-9 %: the crossovers' neighbours and the lowest frequencies, where |L| ~ 1e10
    leaves the modal sum no digits)."""
    st, cl, _ = stacked
    calls = []
    L = modal.loop_gains([cl.system], cl.channel_names, FM, _exact_counting(st, calls))
    want = grid_margins(frequency.loop_gains(st, [0], FM), FM)
    got = grid_margins(L, FM)
    for k, w in want.items():
        g = got[k]
        fin = np.isfinite(w) & (w != 0)
        assert np.array_equal(np.isfinite(g), np.isfinite(w)) and np.array_equal(g == 0, w == 0), k
        assert np.max(np.abs(g[fin] / w[fin] - 1), initial=0.0) <= 1e-13, k
    assert 0 < sum(calls) < 0.2 * len(FM), calls


def test_modal_transfer_is_inside_its_error_bound(stacked):
    """The modal T_kk against the state space python-control interconnects (one LU solve per frequency) on 300
    points over 1e-6..10 Hz: the difference stays below 2 % of the bound (the bound carries a factor KAPPA = 10;
    measured 0.06-0.17 %: the bound is what decides where the exact path is taken)."""
    _st, cl, ref = stacked
    f = np.logspace(-6, 1, 300)
    T, bound, ok = modal.transfer([cl.system], cl.channel_names, f)
    chans = list(cl.channel_names)
    G = closed_loop_response(ref, f, [f"c_{c}" for c in chans], [f"d_{c}" for c in chans])
    want = np.array([G[k, k] for k in range(len(chans))])
    assert ok[0]
    assert np.max(np.abs(T[0] - want) / bound[0]) < 0.02


def test_a_loop_with_ill_conditioned_eigenvectors_is_evaluated_exactly(stacked, monkeypatch):
    """With COND_MAX below every loop's condition number the exact path gives every point: the gains equal the
    exact solves on the whole grid (to 1e-14 relative: the same solves, in other batches)."""
    st, cl, _ = stacked
    monkeypatch.setattr(modal, "COND_MAX", 0.0)
    calls = []
    L = modal.loop_gains([cl.system], cl.channel_names, FM, _exact_counting(st, calls))
    want = frequency.loop_gains(st, [0], FM)
    assert sum(calls) == len(FM)
    assert np.max(np.abs(L - want) / np.abs(want)) <= 1e-14


def test_loops_with_other_states_are_evaluated_apart(stacked):
    """Two loops whose states differ (here the same loop with its states renamed, as loops with controllers of
    other orders differ) in one call: each kind is evaluated apart.  The loops of the first kind have the gains
    they have alone (identical: the same evaluations); the renamed one, whose orbit states are no longer known
    as such (its modal sum over all states), the same margins to 1e-13 relative (measured: identical)."""
    import control

    st, cl, _ = stacked
    sys = cl.system
    renamed = control.ss(sys.A, sys.B, sys.C, sys.D, inputs=sys.input_labels, outputs=sys.output_labels,
                         states=[f"other_{x}" for x in sys.state_labels])

    def exact(pos, f):
        return frequency.loop_gains(st, np.zeros(len(pos), dtype=int), f)

    both = modal.loop_gains([sys, renamed, sys], cl.channel_names, FM, exact)
    alone = modal.loop_gains([sys], cl.channel_names, FM, exact)[0]
    assert np.array_equal(both[0], alone) and np.array_equal(both[2], alone)
    want, got = grid_margins(alone, FM), grid_margins(both[1], FM)
    for k, w in want.items():
        fin = np.isfinite(w) & (w != 0)
        assert np.array_equal(np.isfinite(got[k]), np.isfinite(w)), k
        assert np.max(np.abs(got[k][fin] / w[fin] - 1), initial=0.0) <= 1e-13, k
