"""Orbit-determination measurements as CCSDS Tracking Data Messages (KVN, 503.0-B-2): the measurement
file of ``tqdyn od simulate`` and ``tqdyn od fit`` (I/O only; docs/od-files.md).

A measurement table has one row per scalar measurement: ``t`` (m,) [s since the scenario epoch, the
run's time scale], ``type`` (m,) str (:data:`TYPES`), ``sat`` (m,) int (the satellite's index in the
scenario), ``peer`` (m,) str (a station name, a GNSS transmitter "G07"/"C12" or the other satellite's
index), ``value`` (m,) [m or m/s] and ``sigma`` (m,) [m or m/s] (any object with these attributes is
written; the reader returns them as a dict of arrays).

Layout.  One segment per participant set and sigma -- (type, sat, peer, sigma) -- in the order of the
rows' first appearance, with the standard's keywords:

* ``TIME_SYSTEM`` the run's time scale (TT geocentric, TDB heliocentric) and the epochs
  ``scenario epoch + t`` in it, ``YYYY-MM-DDThh:mm:ss.fffffffff`` (1 ns digits);
* ``PARTICIPANT_1`` the peer (the station, the GNSS transmitter, the other satellite: its name in the
  scenario when known), ``PARTICIPANT_2`` the satellite (its name in the scenario, else ``SAT<k>``);
* ``MODE = SEQUENTIAL``; ``PATH`` and the keyword of the measurement type (the registry,
  :data:`tqdyn.od.registry.TYPES`); every segment states ``TIMETAG_REF = RECEIVE``:
* one-way types (``PATH = 1,2``: GNSS pseudorange, inter-satellite range): tagged at the reception at
  the satellite (the models' own tag), ``RANGE`` with ``RANGE_UNITS = km``;
* two-way types (``PATH = 1,2,1``: SLR, deep-space and TT&C range and range rate): tagged at the
  reception at the station, the model's tag (the bounce at the satellite) plus the row's downlink
  light time (``Measurements.tau_down``; a table without it: half the round trip, what the reader
  takes back, ~1e-6 s from the reception geocentric); ``RANGE`` with ``RANGE_UNITS = s``: the round-trip light
  time 2 v / c (v the model's two-way range c (tau_up + tau_down) / 2 [m]); ``DOPPLER_INSTANTANEOUS``
  [km/s]: the range rate with respect to the reception time, v c / (c + v) for the rate v with
  respect to the bounce time (d t_receive / d t_bounce = 1 + tau_down' and tau_down' = v / c to
  ~1e-10, 1e-7 m/s);
* the values as decimals: one-way ranges the shortest decimal that gives the float64 back (Python's
  ``repr``) with its point moved three places (m -> km), the two-way conversions to 40 digits, so
  that ``value`` reads back bit for bit (a pm-level difference of two ranges survives as far as
  float64 holds it).

Reading: ``TIMETAG_REF`` RECEIVE (or TRANSMIT, two-way) gives the bounce instant back as the tag
less (plus) half the round-trip light time (range rates: their range row's, at the same epoch),
within ~1e-6 s of the bounce geocentric, moved onto the caller's grid (``grid_s``); an unknown
``TIMETAG_REF`` is refused in one line.  Files of tqdyn 0.3 (two-way segments without
``TIMETAG_REF``, tagged at the bounce, ranges in km) read as before.

What the standard lacks goes into tqdyn's own COMMENT lines, ``COMMENT tqdyn <key> = <value>``: in
the metadata block the measurement ``type``, ``sat``, ``peer`` and ``sigma`` (m or m/s, repr), and in
the header the scenario ``epoch`` (t = 0) and ``time_scale`` plus the writer's keys (``info``).

Round trip: ``value``, ``sigma``, ``type``, ``sat`` and ``peer`` are exact; ``t`` comes back rounded to
1 ns (the epoch digits; two-way rows: on the grid ``grid_s``), exactly when t and the epoch in the run's time scale are whole nanoseconds
(a geocentric run from a UTC epoch, t on a grid of nanoseconds); rows come back in time order, rows
of equal t in the order of their segments -- the order written when the table is in that order.
Errors: one-line ``ValueError`` naming the file, the segment or the line, and the field (the TDM
reader's checks, :mod:`tqdyn.formats.tdm`; a value whose metres overflow float64; a negative
``tqdyn sat``).  The rows' epochs against a run (its span, its step grid) are checked by the caller
with the rows' lines (``with_lines``; ``tqdyn od fit``: :func:`tqdyn.workflows.od_files.fit_to_file`).
"""

from __future__ import annotations

import datetime
import pathlib
from decimal import Decimal, InvalidOperation, localcontext

import erfa
import numpy as np
from scipy.constants import c as SPEED_OF_LIGHT

from .._choices import unknown
from ..astro.timescales import tdb_after, tt_jd
from ..od.registry import MEASUREMENT_TYPES
from ..od.registry import TYPES as REGISTRY
from .tdm import Tdm, TdmSegment, parse_epoch, read_tdm, write_tdm

__all__ = ["TYPES", "TIME_SCALES", "measurements_to_tdm", "read_measurements_tdm", "tdm_to_measurements",
           "write_measurements_tdm"]

#: The measurement types (:data:`tqdyn.od.registry.TYPES`: keyword, path, unit, participants).
TYPES = MEASUREMENT_TYPES
#: The time-tag references of the standard (``TIMETAG_REF``).
TIMETAG_REFS = ("TRANSMIT", "RECEIVE")
_C = Decimal(int(SPEED_OF_LIGHT))           # m/s, exact
_DIGITS = 40                                 # significant digits of the light-time and Doppler conversions
#: Largest distance [s] of a two-way row's bounce (tag less half the round trip) from the grid that is
#: moved onto it: (tau_down - tau_up) / 2 is ~1e-6 s geocentric, < 0.02 s heliocentric.
_SNAP_S = 0.1
#: run time scale -> the function (epoch, t) -> two-part JD in it
TIME_SCALES = {"TT": tt_jd, "TDB": tdb_after}
_FIELDS = ("t", "type", "sat", "peer", "value", "sigma")
_NS = 9


def _km_text(v: float) -> str:
    """The decimal of repr(v) [m] divided by 1000 exactly (km)."""
    d = Decimal(repr(float(v))).scaleb(-3)
    return str(d)


def _two_way_text(v: float, keyword: str) -> str:
    """A two-way row's value [m, m/s] as tagged at reception: RANGE the round-trip light time
    2 v / c [s]; DOPPLER_INSTANTANEOUS the range rate with respect to the reception time,
    v c / (c + v) [km/s] (v the rate with respect to the bounce time; module docstring)."""
    with localcontext() as ctx:
        ctx.prec = _DIGITS
        x = Decimal(repr(float(v)))
        return str(x * 2 / _C if keyword == "RANGE" else (x * _C / (_C + x)).scaleb(-3))


def _two_way_value(text: str, keyword: str) -> float:
    """The inverse of :func:`_two_way_text`: m (RANGE in s) or m/s (km/s), rounded once to float64."""
    with localcontext() as ctx:
        ctx.prec = _DIGITS
        x = Decimal(text.replace("d", "e").replace("D", "e"))
        if keyword == "RANGE":
            return float(x * _C / 2)
        x = x.scaleb(3)
        return float(x * _C / (_C - x))


def _si_value(text: str) -> float:
    """A km (or km/s) value text -> m (m/s), the exact decimal times 1000 rounded once to float64."""
    return float(Decimal(text.replace("d", "e").replace("D", "e")).scaleb(3))


def _epoch_texts(epoch, time_scale: str, t: np.ndarray) -> list[str]:
    jd1, jd2 = TIME_SCALES[time_scale](epoch, np.asarray(t, np.float64))
    iy, im, iday, ihmsf = erfa.d2dtf(time_scale, _NS, np.atleast_1d(jd1), np.atleast_1d(jd2))
    return [f"{y:04d}-{m:02d}-{d:02d}T{h:02d}:{mi:02d}:{s:02d}.{f:0{_NS}d}"
            for y, m, d, (h, mi, s, f) in zip(iy.tolist(), im.tolist(), iday.tolist(), ihmsf.tolist())]


def _t_of(texts: list[str], epoch, time_scale: str) -> np.ndarray:
    """Seconds since the epoch (the time scale's) of calendar epoch texts, rounded to 1 ns (the texts were
    checked by the TDM reader, :func:`tqdyn.formats.tdm.parse_epoch`)."""
    e1, e2 = TIME_SCALES[time_scale](epoch, 0.0)
    out = np.empty(len(texts))
    for i, s in enumerate(texts):
        f = parse_epoch(s, time_scale)
        d1, d2 = erfa.dtf2d(time_scale, f.year, f.month, f.day, f.hour, f.minute, float(f.second))
        sec = (float(d1) - float(e1)) * 86400.0 + (float(d2) - float(e2)) * 86400.0  # error ~1e-11 s
        sec += float(Decimal("0." + f.fraction)) if f.fraction else 0.0
        base = np.floor(sec)  # whole seconds, then the fraction rounded to the 1 ns of the digits
        out[i] = base + np.round((sec - base) * 1e9) / 1e9
    return out


def measurements_to_tdm(meas, *, epoch, time_scale: str, satellite_names=None, info=None,
                        originator: str = "tqdyn", creation_date: str | None = None) -> Tdm:
    """The :class:`~tqdyn.formats.tdm.Tdm` of a measurement table (module docstring).

    epoch: the scenario epoch (:class:`tqdyn.astro.timescales.Epoch`, t = 0); time_scale: "TT" or
    "TDB" (the run's); satellite_names: names of the scenario's satellites (by index; None: SAT<k>);
    info: {key: value} written as header comments ``tqdyn key = value`` (the writer's own keys).
    Raises ValueError (one line) for an unknown type, a non-finite value, a sigma that is not > 0."""
    if time_scale not in TIME_SCALES:
        raise ValueError(unknown("time_scale", time_scale, TIME_SCALES))
    cols = {f: np.asarray(getattr(meas, f)) for f in _FIELDS}
    m = cols["t"].size
    if any(c.shape != (m,) for c in cols.values()):
        raise ValueError("measurements: t, type, sat, peer, value, sigma must be (m,) arrays of one length")
    if m == 0:
        raise ValueError("measurements: none to write (a TDM needs a data line)")
    for f in ("t", "value"):
        bad = np.flatnonzero(~np.isfinite(cols[f].astype(np.float64)))
        if bad.size:
            raise ValueError(f"measurements.{f}[{bad[0]}] = {cols[f][bad[0]]}: must be finite")
    sig = cols["sigma"].astype(np.float64)
    bad = np.flatnonzero(~(np.isfinite(sig) & (sig > 0)))
    if bad.size:
        raise ValueError(f"measurements.sigma[{bad[0]}] = {sig[bad[0]]}: must be finite and > 0")
    names = list(satellite_names or [])

    def sat_name(k: int) -> str:
        return names[k] if 0 <= k < len(names) else f"SAT{k}"

    for i in range(m):
        if str(cols["type"][i]) not in REGISTRY:
            raise ValueError(unknown(f"measurements.type[{i}]", str(cols["type"][i]), TYPES))
    tau = _light_times(cols, getattr(meas, "tau_down", None))
    groups: dict = {}
    for i in range(m):
        typ = str(cols["type"][i])
        key = (typ, int(cols["sat"][i]), str(cols["peer"][i]), float(sig[i]))
        groups.setdefault(key, []).append(i)
    t_tag = cols["t"].astype(np.float64) + np.where(np.isfinite(tau), tau, 0.0)
    epochs = _epoch_texts(epoch, time_scale, t_tag)
    if creation_date is None:
        creation_date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%S")
    tdm = Tdm(version="2.0", header={"CREATION_DATE": creation_date, "ORIGINATOR": originator})
    tdm.comments = [f"tqdyn epoch = {epoch.iso}", f"tqdyn time_scale = {time_scale}"]
    tdm.comments += [f"tqdyn {k} = {v}" for k, v in (info or {}).items()]
    for (typ, sat, peer, sigma), rows in groups.items():
        mt = REGISTRY[typ]
        kw = mt.tdm_keyword
        p1 = sat_name(int(peer)) if mt.bias == "link" and peer.lstrip("-").isdigit() else peer
        meta = {"TIME_SYSTEM": time_scale, "PARTICIPANT_1": p1, "PARTICIPANT_2": sat_name(sat), "MODE": "SEQUENTIAL",
                "PATH": mt.path, "TIMETAG_REF": "RECEIVE"}
        if kw == "RANGE":
            meta["RANGE_UNITS"] = "s" if mt.two_way else "km"
        meta["START_TIME"], meta["STOP_TIME"] = epochs[rows[0]], epochs[rows[-1]]
        what = mt.participants + ("; tagged at reception at PARTICIPANT_1, "
                                  + ("round-trip light time" if kw == "RANGE" else "range rate") if mt.two_way else "")
        comments = [f"tqdyn type = {typ}", f"tqdyn sat = {sat}", f"tqdyn peer = {peer}",
                    f"tqdyn sigma = {sigma!r} {mt.unit}", what]
        if peer != peer.strip() or "\n" in peer or not peer:
            raise ValueError(f"measurements.peer[{rows[0]}] = {peer!r}: must be a non-empty name without "
                             "leading or trailing blanks")
        data = [(kw, epochs[i], _two_way_text(cols["value"][i], kw) if mt.two_way else _km_text(cols["value"][i]))
                for i in rows]
        tdm.segments.append(TdmSegment(metadata=meta, meta_comments=comments, data=data))
    return tdm


def _light_times(cols: dict, tau) -> np.ndarray:
    """The downlink light time [s] of each row (m,): the table's ``tau_down`` where finite; else, on
    a two-way row, half its round trip (a range: value / c; a range rate: its range row's at the same
    t, satellite and peer, else 0) -- what the reader takes back (module docstring); NaN elsewhere."""
    m = cols["t"].size
    out = np.full(m, np.nan) if tau is None else np.array(tau, np.float64)
    typ = cols["type"].astype(str)
    two = np.array([REGISTRY[x].two_way for x in typ.tolist()], bool)
    rng = two & np.array([REGISTRY[x].tdm_keyword == "RANGE" for x in typ.tolist()], bool)
    half = {(t, s, p): v / SPEED_OF_LIGHT for t, s, p, v, r in zip(cols["t"].tolist(), cols["sat"].tolist(),
                                                                    cols["peer"].astype(str).tolist(),
                                                                    cols["value"].astype(np.float64).tolist(), rng)
            if r}
    for i in np.flatnonzero(two & ~np.isfinite(out)):
        key = (cols["t"][i].item(), cols["sat"][i].item(), str(cols["peer"][i]))
        out[i] = float(cols["value"][i]) / SPEED_OF_LIGHT if rng[i] else half.get(key, 0.0)
    return out


def write_measurements_tdm(path, meas, **kw) -> pathlib.Path:
    """Write :func:`measurements_to_tdm` ``(meas, **kw)`` to ``path`` atomically."""
    return write_tdm(path, measurements_to_tdm(meas, **kw))


def _tqdyn_comments(comments) -> dict:
    out = {}
    for c in comments:
        if c.startswith("tqdyn ") and " = " in c:
            k, _, v = c[len("tqdyn "):].partition(" = ")
            out[k.strip()] = v.strip()
    return out


def tdm_to_measurements(tdm: Tdm, *, epoch=None, time_scale: str | None = None, name: str = "<tdm>",
                        with_lines: bool = False, grid_s: float | None = None):
    """(fields, info) of a TDM written by :func:`measurements_to_tdm`: fields = {t (m,) float64 [s],
    type (m,) str, sat (m,) int64, peer (m,) str, value (m,) float64 [m, m/s], sigma (m,) float64}
    in time order, with ``with_lines`` also line (m,) int64 (each row's line in the file; 0 for a
    message built in memory); info = the header's ``tqdyn`` comments (epoch, time_scale and the
    writer's keys).

    epoch, time_scale: the scenario's (t = 0 and its scale); None: the file's own (``tqdyn epoch``),
    given as an Epoch they must agree with it.  grid_s [s]: the grid of the time tags (a run's
    ``integrator.step``): the bounce instants of two-way rows tagged at reception or transmission
    (the tag less or plus half the round-trip light time, within ~1e-6 s geocentric) are moved onto
    it when within 0.1 s and 1 % of a step of it (None: not moved).  Raises ValueError (one line naming ``name``)."""
    from ..astro.timescales import Epoch

    info = _tqdyn_comments(tdm.comments)
    file_epoch, file_scale = info.get("epoch"), info.get("time_scale")
    if file_epoch is None or file_scale is None:
        raise ValueError(f"{name}: header: no 'COMMENT tqdyn epoch' / 'COMMENT tqdyn time_scale'; allowed: a "
                         "measurement file written by tqdyn od simulate")
    if time_scale is not None and file_scale != time_scale:
        raise ValueError(f"{name}: header: time scale {file_scale}, the scenario's is {time_scale}; allowed: "
                         "measurements of this scenario")
    if epoch is not None and file_epoch != epoch.iso:
        raise ValueError(f"{name}: header: epoch {file_epoch}, the scenario's is {epoch.iso}; allowed: "
                         "measurements of this scenario")
    if epoch is None:
        try:
            iso, _, scale = file_epoch.rpartition(" ")
            epoch = Epoch.from_tdb(iso) if scale == "TDB" else Epoch.from_utc(iso)
        except ValueError as exc:
            raise ValueError(f"{name}: header: tqdyn epoch = {file_epoch!r} ({exc})") from None
    if file_scale not in TIME_SCALES:
        raise ValueError(unknown(f"{name}: header: tqdyn time_scale", file_scale, TIME_SCALES))
    parts = {f: [] for f in _FIELDS + ("line",)}
    light: dict = {}                  # (sat, peer, epoch text) -> half the round-trip light time [s]
    pending = []                      # two-way rows whose tag offset comes from a range row of theirs
    for k, seg in enumerate(tdm.segments, start=1):
        where = f"{name}, segment {k}"
        c = _tqdyn_comments(seg.meta_comments)
        missing = [f for f in ("type", "sat", "peer", "sigma") if f not in c]
        if missing:
            raise ValueError(f"{where}: metadata: no 'COMMENT tqdyn {missing[0]}'; allowed: a measurement file "
                             "written by tqdyn od simulate")
        typ = c["type"]
        if typ not in REGISTRY:
            raise ValueError(unknown(f"{where}: tqdyn type", typ, TYPES))
        mt = REGISTRY[typ]
        kw, unit = mt.tdm_keyword, mt.unit
        if seg.metadata.get("TIME_SYSTEM") != file_scale:
            raise ValueError(f"{where}: TIME_SYSTEM = {seg.metadata.get('TIME_SYSTEM')!r}; allowed: {file_scale} "
                             "(the header's tqdyn time_scale)")
        tag = seg.metadata.get("TIMETAG_REF")
        tag = None if tag is None else str(tag).upper()
        if tag is not None and tag not in TIMETAG_REFS:
            raise ValueError(unknown(f"{where}: TIMETAG_REF", seg.metadata["TIMETAG_REF"], TIMETAG_REFS))
        if not mt.two_way and tag not in (None, "RECEIVE"):
            raise ValueError(f"{where}: TIMETAG_REF = {tag!r} for the one-way {typ}; allowed: RECEIVE")
        tagged = mt.two_way and tag is not None          # else: one-way, or a two-way row of a 0.3 file (bounce)
        want = "s" if tagged else "km"
        if kw == "RANGE" and str(seg.metadata.get("RANGE_UNITS", want)) != want:
            raise ValueError(f"{where}: RANGE_UNITS = {seg.metadata['RANGE_UNITS']!r}; allowed: {want}"
                             + (" (two-way: the round-trip light time)" if tagged else ""))
        try:
            sat = int(c["sat"])
            sig_text, _, sig_unit = c["sigma"].partition(" ")
            sigma = float(sig_text)
        except ValueError:
            raise ValueError(f"{where}: tqdyn sat = {c['sat']!r}, sigma = {c['sigma']!r}; allowed: an integer and "
                             f"a number with its unit {unit}") from None
        if sig_unit != unit or not (np.isfinite(sigma) and sigma > 0):
            raise ValueError(f"{where}: tqdyn sigma = {c['sigma']!r}; allowed: a number > 0 followed by {unit}")
        if sat < 0:
            raise ValueError(f"{where}: tqdyn sat = {c['sat']!r}; allowed: a satellite index >= 0 (0 the first)")
        other = sorted({d[0] for d in seg.data} - {kw})
        if other:
            raise ValueError(f"{where}: data keyword {other[0]}; allowed: {kw} for {typ}")
        epochs = [e for _, e, _ in seg.data]
        lines = list(seg.lines) if len(seg.lines) == len(seg.data) else [0] * len(seg.data)
        try:
            values = np.array([_two_way_value(v, kw) if tagged else _si_value(v) for _, _, v in seg.data], np.float64)
        except InvalidOperation:
            raise ValueError(f"{where}: {kw}: a value is not a number") from None
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            i = int(bad[0])
            raise ValueError(f"{name}, line {lines[i]}: {kw}: value {seg.data[i][2]!r} ({want}) is {values[i]} in "
                             f"{unit}; allowed: |value| <= 1.7e305 ({want})")
        t = _t_of(epochs, epoch, file_scale)
        if tagged:
            sign = -1.0 if tag == "RECEIVE" else 1.0
            if kw == "RANGE":
                for e, x in zip(epochs, values.tolist()):
                    light[(sat, c["peer"], tag, e)] = x / SPEED_OF_LIGHT
                t = t + sign * values / SPEED_OF_LIGHT
            else:
                pending.append((len(parts["t"]), sat, c["peer"], tag, sign, epochs))
        parts["t"].append(t)
        parts["value"].append(values)
        parts["line"].append(np.array(lines, np.int64))
        n = len(epochs)
        parts["type"].append(np.full(n, typ, dtype=object))
        parts["sat"].append(np.full(n, sat, dtype=np.int64))
        parts["peer"].append(np.full(n, c["peer"], dtype=object))
        parts["sigma"].append(np.full(n, sigma))
    for j, sat, peer, tag, sign, epochs in pending:   # a range rate's bounce: its range row's light time
        parts["t"][j] = parts["t"][j] + sign * np.array([light.get((sat, peer, tag, e), 0.0) for e in epochs])
    if grid_s is not None:
        for j, typ in enumerate(x[0] for x in parts["type"]):
            if REGISTRY[typ].two_way:
                snapped = np.round(parts["t"][j] / grid_s) * grid_s
                near = np.abs(parts["t"][j] - snapped) <= min(0.01 * grid_s, _SNAP_S)
                parts["t"][j] = np.where(near, snapped, parts["t"][j])
    cat = {f: np.concatenate(v) for f, v in parts.items()}
    order = np.argsort(cat["t"], kind="stable")
    fields = {f: v[order] for f, v in cat.items()}
    fields["type"] = fields["type"].astype(str)
    fields["peer"] = fields["peer"].astype(str)
    if not with_lines:
        del fields["line"]
    return fields, info


def read_measurements_tdm(path, *, epoch=None, time_scale: str | None = None, with_lines: bool = False,
                          grid_s: float | None = None):
    """(fields, info) of the measurement file ``path`` (:func:`tdm_to_measurements`, ``with_lines``:
    each row's line in the file too, ``grid_s`` the time-tag grid); the TDM reader's one-line errors
    for a malformed file."""
    return tdm_to_measurements(read_tdm(path), epoch=epoch, time_scale=time_scale, name=str(path),
                               with_lines=with_lines, grid_s=grid_s)
