"""CCSDS Tracking Data Messages (TDM, CCSDS 503.0-B-2, June 2020): KVN read and write.

A :class:`Tdm` holds the header (CCSDS_TDM_VERS, COMMENT, CREATION_DATE,
ORIGINATOR, MESSAGE_ID) and a list of :class:`TdmSegment` (metadata
keywords in file order with their comments, and data lines ``KEYWORD =
epoch value`` with their comments).  Values and epochs are kept as the text
of the file, so that reading and writing a file written here gives it back
byte for byte; :meth:`TdmSegment.observations` returns the numbers.

Checks (a ``ValueError`` with ONE line ``"<file>, line <n>: <field>: <what
is wrong>"``): the first keyword is CCSDS_TDM_VERS (1.0 or 2.0); header,
metadata and data keywords belong to the standard's tables (503.0-B-2
tables 3-2, 3-3 and 3-5; ``PARTICIPANT_n``, ``EPHEMERIS_NAME_n``,
``TRANSMIT_DELAY_n``, ``RECEIVE_DELAY_n``, ``TRANSMIT_FREQ_n`` and the like
for n = 1..5); the mandatory CREATION_DATE, ORIGINATOR, TIME_SYSTEM,
PARTICIPANT_1 are present; blocks are opened and closed in order; a data
line has an epoch and a number; a keyword appears once in the header or a
metadata block; epochs (data lines, START_TIME, STOP_TIME in the block's TIME_SYSTEM,
CREATION_DATE in UTC) are calendar dates and times that exist
(:func:`tqdyn.readers.dates.calendar_problem`: month, day, day of year, hour, minute, a second 60
only in a UTC leap second) and START_TIME is not after STOP_TIME; data values are finite numbers
(``1e999`` is refused at its line).  Writes are atomic (:func:`tqdyn.formats.atomic.replacing`).

XML: the PyPI package ``ccsds-ndm`` (3.1.1, GPL-3.0-or-later, depends on
``lxml`` and ``xsdata``) reads and writes TDM XML and KVN through an object
tree generated from the CCSDS schemas; it is not a tqdyn dependency (the tests use it as an
independent reader and writer of tqdyn's measurement files, tests/test_od_files.py).
:func:`read_tdm` refuses an XML file with a message that says so.
"""

from __future__ import annotations

import datetime
import math
import pathlib
import re
from dataclasses import dataclass, field
from decimal import Decimal
from typing import NamedTuple

import numpy as np

from .._choices import allowed, did_you_mean
from ..readers.dates import calendar_problem
from .atomic import replacing

__all__ = ["Tdm", "TdmEpoch", "TdmSegment", "read_tdm", "parse_epoch", "parse_tdm", "format_tdm", "write_tdm"]

_HEADER = ("CREATION_DATE", "ORIGINATOR", "MESSAGE_ID")
_META = {
    "TRACK_ID", "DATA_TYPES", "TIME_SYSTEM", "START_TIME", "STOP_TIME", "MODE", "PATH", "PATH_1", "PATH_2",
    "TRANSMIT_BAND", "RECEIVE_BAND", "TURNAROUND_NUMERATOR", "TURNAROUND_DENOMINATOR", "TIMETAG_REF",
    "INTEGRATION_INTERVAL", "INTEGRATION_REF", "FREQ_OFFSET", "RANGE_MODE", "RANGE_MODULUS", "RANGE_UNITS",
    "ANGLE_TYPE", "REFERENCE_FRAME", "INTERPOLATION", "INTERPOLATION_DEGREE", "DOPPLER_COUNT_BIAS",
    "DOPPLER_COUNT_SCALE", "DOPPLER_COUNT_ROLLOVER", "DATA_QUALITY", "CORRECTION_ANGLE_1",
    "CORRECTION_ANGLE_2", "CORRECTION_DOPPLER", "CORRECTION_MAG", "CORRECTION_RANGE", "CORRECTION_RCS",
    "CORRECTION_RECEIVE", "CORRECTION_TRANSMIT", "CORRECTION_ABERRATION_YEARLY",
    "CORRECTION_ABERRATION_DIURNAL", "CORRECTIONS_APPLIED",
}
_META_N = re.compile(r"^(PARTICIPANT|EPHEMERIS_NAME|TRANSMIT_DELAY|RECEIVE_DELAY)_[1-5]$")
_DATA = {
    "ANGLE_1", "ANGLE_2", "CARRIER_POWER", "CLOCK_BIAS", "CLOCK_DRIFT", "DOPPLER_COUNT",
    "DOPPLER_INSTANTANEOUS", "DOPPLER_INTEGRATED", "DOR", "MAG", "PC_N0", "PR_N0", "PRESSURE", "RANGE",
    "RCS", "RECEIVE_FREQ", "RHUMIDITY", "STEC", "TEMPERATURE", "TROPO_DRY", "TROPO_WET", "VLBI_DELAY",
}
_DATA_N = re.compile(r"^(RECEIVE_FREQ|TRANSMIT_FREQ|TRANSMIT_FREQ_RATE|RECEIVE_PHASE_CT|TRANSMIT_PHASE_CT)_[1-5]$")
_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eEdD][+-]?\d+)?$")
_EPOCH = re.compile(r"^(\d{4})-(?:(\d{2})-(\d{2})|(\d{3}))T(\d{2}):(\d{2}):(\d{2})(?:\.(\d*))?Z?$")
_EPOCH_FORMS = "YYYY-MM-DDThh:mm:ss[.d] or YYYY-DDDThh:mm:ss[.d]"


class TdmEpoch(NamedTuple):
    """The fields of a TDM epoch text: calendar date (``day_of_year`` for the YYYY-DDD form, else
    0), hour, minute, whole second and the fraction's digits (text, may be empty)."""

    year: int
    month: int
    day: int
    hour: int
    minute: int
    second: int
    fraction: str
    day_of_year: int = 0

    def key(self) -> tuple:
        """A key that orders the epochs of one time scale in time."""
        return (datetime.date(self.year, self.month, self.day).toordinal(), self.hour, self.minute, self.second,
                Decimal("0." + self.fraction) if self.fraction else Decimal(0))


def parse_epoch(text: str, time_system: str) -> TdmEpoch:
    """The fields of the epoch ``text`` (YYYY-MM-DDThh:mm:ss[.d] or YYYY-DDDThh:mm:ss[.d], optional
    trailing Z) of the time scale ``time_system``; ValueError with one phrase (what is wrong and
    what is allowed: :func:`tqdyn.readers.dates.calendar_problem`) if it is not an instant."""
    m = _EPOCH.match(text)
    if m is None:
        raise ValueError(f"epoch {text!r} is not {_EPOCH_FORMS}")
    y, mo, d, doy, hh, mi, ss, frac = m.groups()
    y, hh, mi, ss = int(y), int(hh), int(mi), int(ss)
    sec = ss + (float("0." + frac) if frac else 0.0)
    if doy is not None:
        why = calendar_problem(y, None, None, hh, mi, sec, day_of_year=int(doy), scale=time_system)
    else:
        why = calendar_problem(y, int(mo), int(d), hh, mi, sec, scale=time_system)
    if why is not None:
        raise ValueError(f"epoch {text!r}: {why}")
    if doy is not None:
        date = datetime.date(y, 1, 1) + datetime.timedelta(days=int(doy) - 1)
        return TdmEpoch(y, date.month, date.day, hh, mi, ss, frac or "", int(doy))
    return TdmEpoch(y, int(mo), int(d), hh, mi, ss, frac or "")


@dataclass
class TdmSegment:
    """One metadata block and its data block.  metadata: keyword -> value
    text (file order); meta_comments, data_comments: COMMENT texts; data:
    list of (keyword, epoch text, value text); lines: the file's line number
    of each data line (empty for a message built in memory; not compared)."""

    metadata: dict = field(default_factory=dict)
    meta_comments: list = field(default_factory=list)
    data: list = field(default_factory=list)
    data_comments: list = field(default_factory=list)
    lines: list = field(default_factory=list, compare=False, repr=False)

    def observations(self, keyword: str) -> tuple[list[str], np.ndarray]:
        """Epoch texts and float values (n,) of the data lines with ``keyword``
        (phase counts may carry more digits than a float keeps)."""
        rows = [(e, v) for k, e, v in self.data if k == keyword]
        return [e for e, _ in rows], np.array([float(v.replace("d", "e").replace("D", "e")) for _, v in rows])


@dataclass
class Tdm:
    """A Tracking Data Message: version text, header keywords (text),
    header comments and segments."""

    version: str = "2.0"
    header: dict = field(default_factory=dict)
    comments: list = field(default_factory=list)
    segments: list = field(default_factory=list)


def _is_meta(k: str) -> bool:
    return k in _META or bool(_META_N.match(k))


def _is_data(k: str) -> bool:
    return k in _DATA or bool(_DATA_N.match(k))


def parse_tdm(text: str, name: str = "<tdm>") -> Tdm:
    """Parse the KVN text of a TDM (``name`` labels the error messages)."""
    tdm = Tdm()
    state = "start"            # start, header, meta, between, data
    seg: TdmSegment | None = None
    last = 0
    meta_lines: dict = {}      # keyword -> line of the current metadata block

    def bad(n: int, fld: str, why: str) -> ValueError:
        return ValueError(f"{name}, line {n}: {fld}: {why}")

    def epoch(n: int, fld: str, text: str, time_system: str) -> TdmEpoch:
        try:
            return parse_epoch(text, time_system)
        except ValueError as exc:
            raise bad(n, fld, str(exc)) from None

    for n, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line:
            continue
        last = n
        if state == "start":
            if line.lstrip().startswith("<"):
                raise bad(n, "format", "XML TDM is not read by tqdyn (the PyPI package ccsds-ndm reads it); "
                                       "expected KVN")
            k, _, v = line.partition("=")
            if k.strip() != "CCSDS_TDM_VERS" or v.strip() not in ("1.0", "2.0"):
                raise bad(n, "CCSDS_TDM_VERS", f"{line!r} is not allowed; expected 'CCSDS_TDM_VERS = 2.0' (or 1.0) "
                                               "as the first line")
            tdm.version = v.strip()
            state = "header"
            continue
        word = line.split(None, 1)[0]
        if word == "COMMENT":
            c = line[len("COMMENT"):].strip()
            target = {"header": tdm.comments, "meta": seg.meta_comments if seg else None,
                      "data": seg.data_comments if seg else None}.get(state)
            if target is None or (state == "meta" and seg.metadata) or (state == "data" and seg.data):
                raise bad(n, "COMMENT", "comments are allowed only at the start of the header, a metadata or a data block")
            target.append(c)
            continue
        if line in ("META_START", "META_STOP", "DATA_START", "DATA_STOP"):
            expected = {"META_START": ("header", "between"), "META_STOP": ("meta",),
                        "DATA_START": ("between",), "DATA_STOP": ("data",)}[line]
            if state not in expected:
                raise bad(n, line, f"unexpected here (in the {state} part of the message)")
            if line == "META_START":
                if state == "header":
                    for req in ("CREATION_DATE", "ORIGINATOR"):
                        if req not in tdm.header:
                            raise bad(n, req, "missing from the header (mandatory)")
                elif seg is not None and not seg.data:
                    raise bad(n, "DATA_START", "the previous metadata block has no data block")
                seg = TdmSegment()
                tdm.segments.append(seg)
                meta_lines = {}
                state = "meta"
            elif line == "META_STOP":
                for req in ("TIME_SYSTEM", "PARTICIPANT_1"):
                    if req not in seg.metadata:
                        raise bad(n, req, "missing from the metadata block (mandatory)")
                span = {k: epoch(meta_lines[k], k, seg.metadata[k], seg.metadata["TIME_SYSTEM"])
                        for k in ("START_TIME", "STOP_TIME") if k in seg.metadata}
                if len(span) == 2 and span["START_TIME"].key() > span["STOP_TIME"].key():
                    raise bad(meta_lines["STOP_TIME"], "STOP_TIME", f"{seg.metadata['STOP_TIME']!r} is before "
                              f"START_TIME {seg.metadata['START_TIME']!r}; allowed: STOP_TIME >= START_TIME")
                state = "between"
            elif line == "DATA_START":
                state = "data"
            else:
                if not seg.data:
                    raise bad(n, "DATA_STOP", "the data block is empty")
                state = "between"          # a new META_START may follow
            continue
        k, eq, v = line.partition("=")
        k, v = k.strip(), v.strip()
        if not eq or not k or " " in k:
            raise bad(n, "line", f"{line!r} is not 'KEYWORD = value'")
        if state == "header":
            if k not in _HEADER:
                raise bad(n, k, f"not a TDM header keyword{did_you_mean(k, _HEADER)}; expected one of "
                                f"{allowed(_HEADER)} or COMMENT")
            if k in tdm.header:
                raise bad(n, k, "appears twice in the header")
            if not v:
                raise bad(n, k, "has no value")
            if k == "CREATION_DATE":
                epoch(n, k, v, "UTC")
            tdm.header[k] = v
        elif state == "meta":
            if not _is_meta(k):
                raise bad(n, k, "not a TDM metadata keyword (CCSDS 503.0-B-2 table 3-3)")
            if k in seg.metadata:
                raise bad(n, k, "appears twice in the metadata block")
            if not v:
                raise bad(n, k, "has no value")
            seg.metadata[k] = v
            meta_lines[k] = n
        elif state == "data":
            if not _is_data(k):
                raise bad(n, k, "not a TDM data keyword (CCSDS 503.0-B-2 table 3-5)")
            parts = v.split()
            if len(parts) != 2:
                raise bad(n, k, f"{v!r} is not 'epoch value'")
            if not _NUMBER.match(parts[1]):
                raise bad(n, k, f"value {parts[1]!r} is not a number")
            if not math.isfinite(float(parts[1].replace("d", "e").replace("D", "e"))):
                raise bad(n, k, f"value {parts[1]!r} is not finite; allowed: a number within float64's range "
                                "(|x| < 1.8e308)")
            epoch(n, k, parts[0], seg.metadata["TIME_SYSTEM"])
            seg.data.append((k, parts[0], parts[1]))
            seg.lines.append(n)
        else:
            raise bad(n, k, "keyword outside the header, a metadata or a data block")
    if state == "start":
        raise ValueError(f"{name}, line 1: CCSDS_TDM_VERS: the file is empty")
    if state != "between" or not tdm.segments:
        raise ValueError(f"{name}, line {last}: DATA_STOP: the message ends inside a block or has no data block")
    return tdm


def read_tdm(path) -> Tdm:
    """Read a KVN TDM file; one-line ValueError naming the file, line and field."""
    p = pathlib.Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"{p}, line 1: text: not UTF-8/ASCII ({exc.reason})") from None
    return parse_tdm(text, str(p))


def format_tdm(tdm: Tdm) -> str:
    """The KVN text of ``tdm`` (one ``KEY = value`` per line, no padding;
    metadata indented by two spaces as in the standard's examples)."""
    out = [f"CCSDS_TDM_VERS = {tdm.version}"]
    out += [f"COMMENT {c}" for c in tdm.comments]
    out += [f"{k} = {v}" for k, v in tdm.header.items()]
    for seg in tdm.segments:
        out.append("META_START")
        out += [f"  COMMENT {c}" for c in seg.meta_comments]
        out += [f"  {k} = {v}" for k, v in seg.metadata.items()]
        out += ["META_STOP", "DATA_START"]
        out += [f"  COMMENT {c}" for c in seg.data_comments]
        out += [f"  {k} = {e} {v}" for k, e, v in seg.data]
        out.append("DATA_STOP")
    return "\n".join(out) + "\n"


def write_tdm(path, tdm: Tdm) -> pathlib.Path:
    """Write ``tdm`` as KVN to ``path`` atomically (checked by parsing the
    text first: a message this module cannot read back is refused)."""
    p = pathlib.Path(path)
    text = format_tdm(tdm)
    parse_tdm(text, str(p))
    with replacing(p, "TDM") as tmp:
        tmp.write_text(text, encoding="utf-8")
    return p
