"""A sweep resolved into members (:class:`Member`, :class:`SweepPlan`, :func:`plan_sweep`).

Each member is the base scenario + the sweep's ``set`` + its parameter
values; its trajectory file is ``<output_dir>/member-<hash>.h5`` (a short
SHA-256 of its resolved scenario TOML with ``run.output`` normalised), and
:func:`member_done` tells whether that file is already complete.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from ...formats import trajectory as io
from ...scenario import ScenarioError, load_scenario
from ...scenario.toml_text import toml_value
from .spec import SweepSpec, _err, load_sweep

__all__ = ["Member", "SweepPlan", "member_done", "plan_sweep"]

#: ``run.output`` of the scenario that is hashed (the real one is the member file).
_OUTPUT_PLACEHOLDER = "sweep-member.h5"
_DIGEST_CHARS = 12


@dataclass(frozen=True)
class Member:
    """One scenario of a sweep.

    ``index``: 0-based member number (C order over the grid in product
    mode); ``position``: its index along each member dimension;
    ``params``: ``(coordinate name, displayed value)`` pairs;
    ``overrides``: the scenario overrides that make it; ``digest``: short
    hash of ``canonical_toml`` (its resolved scenario with ``run.output``
    normalised); ``path``: its trajectory file; ``scenario_toml``: the
    resolved scenario it runs (``run.output`` = ``path``).
    """

    index: int
    position: tuple[int, ...]
    params: tuple[tuple[str, str], ...]
    overrides: tuple[str, ...]
    canonical_toml: str
    digest: str
    path: Path
    scenario_toml: str

    @property
    def label(self) -> str:
        """``"member 3 (a_km=100010, direction=+y)"`` (1-based number)."""
        return f"member {self.index + 1} (" + ", ".join(f"{k}={v}" for k, v in self.params) + ")"


def _positions(spec: SweepSpec) -> Iterator[tuple[tuple[int, ...], tuple[int, ...]]]:
    """(position in the dataset, value index of each parameter) of every member, in member order."""
    if spec.mode == "product":
        for pos in itertools.product(*(range(len(p.values)) for p in spec.parameters)):
            yield pos, pos
    else:
        for k in range(len(spec.parameters[0].values)):
            yield (k,), (k,) * len(spec.parameters)


def _time_grid(scen) -> tuple:
    return (scen.run.duration_s, scen.integrator.step_s, scen.run.output_every, len(scen.satellites))


def _resolve_members(spec: SweepSpec) -> tuple[Member, ...]:
    try:
        load_scenario(spec.scenario)
    except ScenarioError as exc:
        raise _err(f"sweep.scenario {spec.scenario!r}", problem=str(exc)) from None
    try:
        load_scenario(spec.scenario, spec.common)
    except ScenarioError as exc:
        raise _err("sweep.set", problem=str(exc)) from None
    for i, p in enumerate(spec.parameters, start=1):
        try:
            load_scenario(spec.scenario, spec.common + (f"{p.key}={toml_value(p.values[0])}",))
        except ScenarioError as exc:
            if exc.field.startswith("override"):
                raise _err(f"sweep.parameter.{i}.key", problem=str(exc)) from None
    members: list[Member] = []
    by_digest: dict[str, Member] = {}
    grid0 = None
    for index, (position, which) in enumerate(_positions(spec)):
        params = tuple((p.dim, p.display(j)) for p, j in zip(spec.parameters, which))
        label = f"sweep member {index + 1} (" + ", ".join(f"{k}={v}" for k, v in params) + ")"
        overrides = spec.common + tuple(f"{p.key}={toml_value(p.values[j])}" for p, j in zip(spec.parameters, which))
        try:
            scen = load_scenario(spec.scenario, overrides + (f"run.output={_OUTPUT_PLACEHOLDER}",))
        except ScenarioError as exc:
            raise _err(label, problem=str(exc)) from None
        grid = _time_grid(scen)
        if grid0 is None:
            grid0 = grid
        elif grid != grid0:
            names = ("run.duration", "integrator.step", "run.output_every")
            diff = ", ".join(f"{n} {g} vs {g0}" for n, g, g0 in zip(names, grid, grid0) if g != g0)
            raise _err(label, problem=f"has another time grid than member 1 ({diff})",
                       allowed="these keys in sweep.set, not varied")
        canonical = scen.to_toml()
        digest = hashlib.sha256(canonical.encode("utf-8")).hexdigest()[:_DIGEST_CHARS]
        if digest in by_digest:
            other = by_digest[digest]
            raise _err(label, problem=f"is the same scenario as sweep {other.label}",
                       allowed="distinct members (a value repeated, or a parameter without effect?)")
        path = spec.output_dir / f"member-{digest}.h5"
        final = dataclasses.replace(scen, run=dataclasses.replace(scen.run, output=str(path)))
        m = Member(index=index, position=position, params=params, overrides=overrides, canonical_toml=canonical,
                   digest=digest, path=path, scenario_toml=final.to_toml())
        by_digest[digest] = m
        members.append(m)
    return tuple(members)


def member_done(member: Member) -> bool:
    """True if ``member.path`` is a complete run of this member
    (:func:`tqdyn.formats.trajectory.run_is_complete`: the stored resolved
    scenario equals the member's, ``run.output`` aside, and the last time row
    is ``run.duration``); anything else is False and the member is run."""
    return io.run_is_complete(member.path, member.canonical_toml, _OUTPUT_PLACEHOLDER)


@dataclass(frozen=True)
class SweepPlan:
    """A sweep resolved into members: ``spec``, ``members`` (in member order)
    and ``done`` (per member: its file is complete, see :func:`member_done`)."""

    spec: SweepSpec
    members: tuple[Member, ...]
    done: tuple[bool, ...]

    @property
    def pending(self) -> tuple[Member, ...]:
        """Members still to run."""
        return tuple(m for m, d in zip(self.members, self.done) if not d)


def plan_sweep(path_or_spec: str | os.PathLike | SweepSpec) -> SweepPlan:
    """Validate a sweep completely (file, base scenario, common overrides,
    every member's scenario, one time grid, no two identical members) and
    find which members are already done.  Submits and writes nothing.
    Raises :class:`SweepError` / ``FileNotFoundError``."""
    spec = path_or_spec if isinstance(path_or_spec, SweepSpec) else load_sweep(path_or_spec)
    members = _resolve_members(spec)
    return SweepPlan(spec=spec, members=members, done=tuple(member_done(m) for m in members))
