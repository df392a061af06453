"""Run checkpoint files (``<output>.checkpoint``, numpy npz): writing and reading (I/O only).

A checkpoint lets an interrupted run continue (``tqdyn run --resume``) to
the same trajectory bit for bit.  It holds the resolved scenario (TOML
text), the precision, the step count, the state (all propagated bodies, TMs
included in the free-TM mode) and its compensation, the multistep
integrator's table (``integrator.method = "multistep"`` only: one flat
float64 array, absent for DP87), the partial trajectory file and how many of
its rows the checkpoint covers.  What to do with it
(checking that it belongs to the run, continuing the partial trajectory) is
:mod:`tqdyn.workflows.run`'s job.

Everything in it is a plain array (unicode strings, integers, float64): it
is read with ``allow_pickle=False`` and never needs object data.  A damaged
or foreign file raises :class:`CheckpointError` (a ``ValueError``) naming
the file and saying what to do.
"""

from __future__ import annotations

import os
import pathlib
from dataclasses import dataclass

import numpy as np

__all__ = ["CheckpointFile", "CheckpointError", "write_checkpoint", "read_checkpoint"]


class CheckpointError(ValueError):
    """A checkpoint file cannot be read (truncated, corrupted, not a
    checkpoint): one-line message naming the file and the remedy."""


@dataclass(frozen=True)
class CheckpointFile:
    """Contents of a checkpoint file.

    scenario : the resolved scenario as TOML text; precision : "dd" |
    "float64"; n : steps done; y, comp : the state and its compensation
    (float64 arrays); partial : path of the partial trajectory file; rows :
    time rows of it the checkpoint covers; table : the multistep
    integrator's table (flat float64 array) or None (DP87).
    """

    scenario: str
    precision: str
    n: int
    y: np.ndarray
    comp: np.ndarray
    partial: str
    rows: int
    table: np.ndarray | None = None


def write_checkpoint(path, *, scenario: str, precision: str, n: int, y, comp, partial, rows: int,
                     table=None) -> None:
    """Atomically write a run checkpoint (npz): the resolved scenario, the
    step count, the state (all propagated bodies, TMs included in the free-TM
    mode) and its compensation, the multistep table if any, the partial
    trajectory file and how many of its rows the checkpoint covers."""
    path = pathlib.Path(path)
    tmp = path.with_name(path.name + ".tmp")
    arrays = dict(scenario=np.array(str(scenario)), precision=np.array(str(precision)),
                  n=np.array(int(n), dtype=np.int64), y=np.asarray(y, dtype=np.float64),
                  comp=np.asarray(comp, dtype=np.float64), partial=np.array(str(partial)),
                  rows=np.array(int(rows), dtype=np.int64))
    if table is not None:
        arrays["table"] = np.asarray(table, dtype=np.float64).ravel()
    try:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:  # disk full, interrupted: the previous checkpoint stays valid
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def read_checkpoint(path) -> CheckpointFile:
    """Read a checkpoint written by :func:`write_checkpoint`; a file that is
    truncated, corrupted or not a checkpoint raises :class:`CheckpointError`."""
    try:
        with np.load(path, allow_pickle=False) as data:
            kinds = {"scenario": "U", "precision": "U", "partial": "U", "n": "iu", "rows": "iu",
                     "y": "f", "comp": "f"}
            arrays = {}
            for key, kind in kinds.items():
                a = data[key]
                if a.dtype.kind not in kind or (kind in ("U", "iu") and a.ndim != 0):
                    raise ValueError(f"entry {key!r} has dtype {a.dtype} shape {a.shape}")
                arrays[key] = a
            table = None
            if "table" in data.files:  # multistep runs only
                table = data["table"]
                if table.dtype.kind != "f" or table.ndim != 1:
                    raise ValueError(f"entry 'table' has dtype {table.dtype} shape {table.shape}")
                table = np.array(table, dtype=np.float64)
            return CheckpointFile(scenario=str(arrays["scenario"]), precision=str(arrays["precision"]),
                                  n=int(arrays["n"]), y=np.array(arrays["y"], dtype=np.float64),
                                  comp=np.array(arrays["comp"], dtype=np.float64),
                                  partial=str(arrays["partial"]), rows=int(arrays["rows"]), table=table)
    except FileNotFoundError:
        raise
    except Exception as exc:  # noqa: BLE001 - BadZipFile, EOFError, KeyError, numpy's pickle refusal, ...
        reason = " ".join(str(exc).split())
        if "allow_pickle" in reason:
            reason = "it holds object data, which a checkpoint never does"
        reason = reason if len(reason) <= 40 else reason[:37] + "..."
        raise CheckpointError(
            f"checkpoint {str(path)!r} is damaged ({type(exc).__name__}: {reason}); remove it (and "
            f".<output>.*.tmp) and run again without --resume") from None
