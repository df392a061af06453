"""The registry of measurement types (:class:`~tqdyn.od.measurement_type.MeasurementType`): the
one list that tracking plans (:mod:`.tracking`), the problem (:mod:`.problem`), the workflows,
the TDM files (:mod:`tqdyn.formats.od_tdm`) and the figures read.  Adding a type is a module
with its class and one line in :data:`TYPES` (:mod:`.measurements_ttc` is one).

Built-in types:

* ``gnss_pseudorange`` (kind gnss): GPS / BeiDou pseudoranges at the satellite
  (:mod:`.measurements_gnss`; receiver clock eliminated by the fit);
* ``slr_range`` (slr): two-way SLR ranges from ILRS stations (:mod:`.measurements_slr`);
* ``isr_range`` (isr): one-way inter-satellite light-path ranges of the six links
  (:mod:`.measurements_isr`);
* ``dsn_range``, ``dsn_range_rate`` (dsn): two-way range and range rate from deep-space stations
  (:mod:`.measurements_dsn`);
* ``ttc_range``, ``ttc_range_rate`` (ttc): two-way range and range rate from the mission's TT&C
  ground stations, listed in a stations file the user can replace (:mod:`.measurements_ttc`).
"""

from __future__ import annotations

import numpy as np

from ..astro.ephemeris import ephemeris_named, planetary_gm
from ..constellation.indices import LINK_EMITTER, LINK_RECEIVER
from .measurement_type import MeasurementType, Rows, flat_rows
from .measurements_dsn import DEEP_SPACE_STATIONS, DSN_DOPPLER_SIGMA_M_S, DSN_RANGE_SIGMA_M, dsn_tracking
from .measurements_gnss import BEIDOU_MEO, GNSS_SIGMA_M, GPS, pseudorange
from .measurements_isr import ISR_ABSOLUTE_SIGMA_M, isr_range
from .measurements_slr import ILRS_STATIONS, SLR_SIGMA_M, slr_range
from .measurements_ttc import TTC_TYPES

__all__ = ["BIAS_TYPES", "KIND_TYPES", "MEASUREMENT_TYPES", "TRACKING_KINDS", "TYPES", "kind_of", "measurement_type",
           "unit_text"]


class GnssPseudorange(MeasurementType):
    name, kind, unit, sigma = "gnss_pseudorange", "gnss", "m", GNSS_SIGMA_M
    receiver_clock = True
    participants = "GNSS transmitter PARTICIPANT_1 to spacecraft PARTICIPANT_2; pseudorange c tau + receiver clock"

    def evaluate(self, ctx, t, states):
        tr = ctx.tracking
        sources = (((GPS, "G"), (BEIDOU_MEO, "C")) if tr.gnss_orbits is None
                   else tuple((o, None) for o in tr.gnss_orbits))
        out = []
        for b in range(states.shape[1]):
            for const, prefix in sources:
                o = pseudorange(t, states[:, b, :3], states[:, b, 3:], const, mode=tr.gnss_mode)
                ids = list(const.ids) if prefix is None else [f"{prefix}{k + 1:02d}" for k in range(o.value.shape[1])]
                out.append(flat_rows(self.name, b, ids, o))
        return out


class SlrRange(MeasurementType):
    name, kind, unit, sigma, bias = "slr_range", "slr", "m", SLR_SIGMA_M, "station"
    path, stations_label = "1,2,1", "SLR"
    participants = "SLR station PARTICIPANT_1 to spacecraft PARTICIPANT_2 and back"

    def station_catalogue(self):
        return tuple(ILRS_STATIONS)

    def evaluate(self, ctx, t, states):
        names = ctx.station_names(self.kind)
        out = []
        for b in range(states.shape[1]):
            o = slr_range(ctx.scen.epoch, t, states[:, b, :3], states[:, b, 3:], names, eop=ctx.eop,
                          use_eop=ctx.use_eop)
            out.append(flat_rows(self.name, b, o.extra["stations"], o, o.extra["tau_down"]))
        return out


class IsrRange(MeasurementType):
    name, kind, unit, sigma, bias = "isr_range", "isr", "m", ISR_ABSOLUTE_SIGMA_M, "link"
    heliocentric = True
    participants = "inter-satellite one-way light-path range, emitted by PARTICIPANT_1, received by PARTICIPANT_2"

    def evaluate(self, ctx, t, states):
        gm = planetary_gm()["sun"] if ctx.heliocentric else float(ctx.scen.forces.gm_earth)
        o = isr_range(t, states[..., :3], states[..., 3:], gm=gm)
        n, nl = o.value.shape
        d = np.concatenate([o.d_r, o.d_v], axis=-1).reshape(n * nl, 2, 6)
        rec, emi = np.asarray(LINK_RECEIVER), np.asarray(LINK_EMITTER)
        return [Rows(self.name, np.repeat(np.arange(n), nl), np.tile(rec, n),
                     np.tile(np.array([str(e) for e in emi], object), n), o.value.ravel(), o.visible.ravel(), d,
                     np.tile(emi, n))]


class _DeepSpace(MeasurementType):
    kind, bias, heliocentric, path, stations_label = "dsn", "station", True, "1,2,1", "deep-space"

    def station_catalogue(self):
        return tuple(DEEP_SPACE_STATIONS)

    def evaluate(self, ctx, t, states):
        key = ("dsn", id(t), id(states))
        if key not in ctx.cache:
            names = ctx.station_names(self.kind)
            eph = ephemeris_named(ctx.scen.forces.ephemeris)
            ctx.cache[key] = [dsn_tracking(ctx.scen.epoch, t, states[:, b, :3], states[:, b, 3:], names,
                                           heliocentric=ctx.heliocentric, ephemeris=eph, eop=ctx.eop,
                                           use_eop=ctx.use_eop) for b in range(states.shape[1])]
        i = 1 if self.unit == "m/s" else 0
        return [flat_rows(self.name, b, pair[i].extra["stations"], pair[i], pair[i].extra["tau_down"])
                for b, pair in enumerate(ctx.cache[key])]


class DsnRange(_DeepSpace):
    name, unit, sigma = "dsn_range", "m", DSN_RANGE_SIGMA_M
    participants = "deep-space two-way range, station PARTICIPANT_1 to spacecraft PARTICIPANT_2 and back"


class DsnRangeRate(_DeepSpace):
    name, unit, sigma = "dsn_range_rate", "m/s", DSN_DOPPLER_SIGMA_M_S
    tdm_keyword = "DOPPLER_INSTANTANEOUS"
    participants = "deep-space two-way range rate, station PARTICIPANT_1 to spacecraft PARTICIPANT_2"


#: Every measurement type, by name, in the row order of the measurement tables.
TYPES: dict[str, MeasurementType] = {x.name: x for x in (GnssPseudorange(), SlrRange(), IsrRange(), DsnRange(),
                                                         DsnRangeRate(), *TTC_TYPES)}
MEASUREMENT_TYPES = tuple(TYPES)
#: Tracking kinds, and the types of each.
TRACKING_KINDS = tuple(dict.fromkeys(x.kind for x in TYPES.values()))
KIND_TYPES = {k: tuple(n for n, x in TYPES.items() if x.kind == k) for k in TRACKING_KINDS}
#: Types with a constant bias parameter (per station and type, or per one-way link).
BIAS_TYPES = tuple(n for n, x in TYPES.items() if x.bias)


def measurement_type(name: str) -> MeasurementType:
    """The :class:`MeasurementType` of a type name (KeyError if unknown)."""
    return TYPES[name]


def kind_of(name: str) -> str:
    """The tracking kind of a measurement type."""
    return TYPES[name].kind


def unit_text(types=None) -> str:
    """"m, m/s for dsn_range_rate, ..." : the units of the measurement types (default all)."""
    rates = [n for n in (types or MEASUREMENT_TYPES) if TYPES[n].unit != "m"]
    return "m" + (f", m/s for {', '.join(rates)}" if rates else "")
