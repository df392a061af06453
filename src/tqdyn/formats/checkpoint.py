"""Run checkpoint files (``<output>.checkpoint``, numpy npz): writing and reading (I/O only).

A checkpoint lets an interrupted run continue (``tqdyn run --resume``) to
the same trajectory bit for bit.  It holds the resolved scenario (TOML
text), the precision, the step count, the state (all propagated bodies, TMs
included in the free-TM mode) and its compensation, the partial trajectory
file and how many of its rows the checkpoint covers.  What to do with it
(checking that it belongs to the run, continuing the partial trajectory) is
:mod:`tqdyn.workflows.run`'s job.
"""

from __future__ import annotations

import os
import pathlib
from dataclasses import dataclass

import numpy as np

__all__ = ["CheckpointFile", "write_checkpoint", "read_checkpoint"]


@dataclass(frozen=True)
class CheckpointFile:
    """Contents of a checkpoint file.

    scenario : the resolved scenario as TOML text; precision : "dd" |
    "float64"; n : steps done; y, comp : the state and its compensation
    (float64 arrays); partial : path of the partial trajectory file; rows :
    time rows of it the checkpoint covers.
    """

    scenario: str
    precision: str
    n: int
    y: np.ndarray
    comp: np.ndarray
    partial: str
    rows: int


def write_checkpoint(path, *, scenario: str, precision: str, n: int, y, comp, partial, rows: int) -> None:
    """Atomically write a run checkpoint (npz): the resolved scenario, the
    step count, the state (all propagated bodies, TMs included in the free-TM
    mode) and its compensation, the partial trajectory file and how many of
    its rows the checkpoint covers."""
    path = pathlib.Path(path)
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "wb") as fh:
        np.savez(fh, scenario=np.array(scenario), precision=np.array(precision), n=np.array(n),
                 y=y, comp=comp, partial=np.array(partial), rows=np.array(rows))
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)


def read_checkpoint(path) -> CheckpointFile:
    """Read a checkpoint written by :func:`write_checkpoint`."""
    with np.load(path, allow_pickle=False) as data:
        return CheckpointFile(scenario=str(data["scenario"]), precision=str(data["precision"]),
                              n=int(data["n"]), y=np.array(data["y"]), comp=np.array(data["comp"]),
                              partial=str(data["partial"]), rows=int(data["rows"]))
