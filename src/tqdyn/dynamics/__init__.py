"""The dynamics layer: what is propagated and how.

=======================  ==========================================================
module                   job
=======================  ==========================================================
:mod:`.layout`           array layouts shared with the compiled code (cpar, aux, state)
:mod:`.rhs`              the compiled right-hand side (point masses; the coupled
                         drag-free constellation, paper eq. coreEquation)
:mod:`.system`           a scenario's constellation as the system's parameters
:mod:`.initial`          initial states (elements -> state; free TMs at their housings)
:mod:`.fixed`            fixed-step DP87 loop, chunked and compiled
:mod:`.multistep`        fixed-step Gauss-Jackson / summed Adams loop (DP87 start-up)
:mod:`.adaptive`         adaptive DP87 with dense output on the output grid
:mod:`.results`          typed output rows, checkpoints, the run result
:mod:`.propagation`      :func:`propagate`, the entry point
=======================  ==========================================================
"""

from .initial import initial_state
from .layout import PRECISIONS
from .propagation import check_inputs, propagate, two_body_energy, warm_up
from .results import Checkpoint, NonFiniteStateError, Rows, RunResult, row_names
from .rhs import evaluate_rhs
from .system import System, build_system, self_gravity_oa

__all__ = ["PRECISIONS", "Checkpoint", "NonFiniteStateError", "Rows", "RunResult", "System", "build_system", "check_inputs",
           "evaluate_rhs", "initial_state", "propagate", "row_names", "self_gravity_oa", "two_body_energy",
           "warm_up"]
