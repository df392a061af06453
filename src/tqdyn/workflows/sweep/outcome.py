"""What happened to one sweep member (:class:`MemberOutcome`), shared by
running (:mod:`.execute`) and gathering (:mod:`.gathering`)."""

from __future__ import annotations

from dataclasses import dataclass

from .plan import Member

__all__ = ["MemberOutcome"]


@dataclass(frozen=True)
class MemberOutcome:
    """What happened to one member: ``status`` is "done" (its file was
    already complete; skipped), "ran" or "failed"; ``error``: one line
    ``"<ExceptionType>: <message>"`` for failures; ``traceback``: the
    worker's traceback text (failures during the run); ``wall_s`` /
    ``compile_s``: propagation / JIT time of a run [s]; ``rows``: time rows
    written; ``lost_workers``: times its worker was lost while running it
    (Dask re-ran it elsewhere; its file is that of the complete re-run)."""

    member: Member
    status: str
    error: str = ""
    traceback: str = ""
    wall_s: float = 0.0
    compile_s: float = 0.0
    rows: int = 0
    lost_workers: int = 0

    @property
    def ok(self) -> bool:
        """True if the member's trajectory file is complete."""
        return self.status != "failed"
