"""TT&C ground stations of the mission: two-way range and range rate (Doppler) of geocentric runs
(TianQin), the measurement types ``ttc_range`` [m] and ``ttc_range_rate`` [m/s] of the tracking
kind ``ttc`` (:mod:`.registry`).

Stations: a TOML file the user can replace (like the SP3 files of the GNSS transmitters), by
default the shipped ``tqdyn/data/ttc_stations.toml`` (the Chinese deep-space stations Kashi,
Jiamusi and Neuquen; its comments give the source and accuracy of the positions), else the file
named by the environment variable ``TQDYN_TTC_STATIONS`` or given to :func:`use_ttc_stations`.
Each ``[[station]]`` has a ``name``, the measurement ``types`` it provides, and a position
``geodetic = [east longitude deg, latitude deg, height m]`` (WGS84, ``erfa.gd2gc``) or ``itrf =
[x, y, z]`` [m].  A malformed file is refused in one line naming the file, the station, the field,
the value and what is allowed.

Model: the two-way light time of :func:`tqdyn.od.measurements.geocentric_two_way` (the station
moving in the GCRS along the ITRS -> GCRS transformation with the scenario's EOP, re-evaluated at
the transmit and receive instants, the Earth's Shapiro delay on each leg), satellite state at the
bounce time (the time tag); range c (tau_up + tau_down) / 2, range rate its exact time derivative
(instantaneous Doppler).  Visibility: elevation >= 10 deg at the time tag.  Noise (defaults):
1 m range, 1 mm/s range rate (S/X-band TT&C ranging and 60 s Doppler).  Not modelled: troposphere,
ionosphere, antenna offsets, transponder delays (the station bias parameter absorbs a constant).
"""

from __future__ import annotations

import functools
import os
import pathlib
import tomllib

import erfa
import numpy as np

from .._choices import unknown
from .measurement_type import MeasurementType, flat_rows
from .measurements import Observable, geocentric_two_way

__all__ = ["TTC_TYPES", "TtcRange", "TtcRangeRate", "ttc_stations", "use_ttc_stations"]

_SHIPPED = pathlib.Path(__file__).resolve().parent.parent / "data" / "ttc_stations.toml"
_chosen: list = []


def use_ttc_stations(path=None) -> None:
    """Use the TT&C stations file ``path`` from now on (None: back to the default, the environment
    variable ``TQDYN_TTC_STATIONS`` or the shipped file); checked now (ValueError, one line)."""
    _chosen[:] = [] if path is None else [os.fspath(path)]
    ttc_stations()


def _path() -> str:
    return _chosen[0] if _chosen else os.environ.get("TQDYN_TTC_STATIONS") or str(_SHIPPED)


def ttc_stations() -> dict:
    """{name: (ITRS position (3,) [m], measurement types)} of the current stations file."""
    return _read(_path())


@functools.lru_cache(maxsize=8)
def _read(path: str) -> dict:
    where = f"TT&C stations file {pathlib.Path(path).name!r}"
    try:
        doc = tomllib.loads(pathlib.Path(path).read_text(encoding="utf-8"))
    except OSError as exc:
        raise ValueError(f"{where}: cannot be read ({exc.strerror}); allowed: a TOML file of [[station]]") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{where}: not TOML ({exc}); allowed: a TOML file of [[station]]") from None
    items = doc.get("station")
    if not isinstance(items, list) or not items:
        raise ValueError(f"{where}: no [[station]]; allowed: one or more [[station]] tables")
    out: dict = {}
    for k, st in enumerate(items, start=1):
        name = st.get("name")
        if not isinstance(name, str) or not name.strip() or name in out:
            raise ValueError(f"{where}: station {k}: name = {name!r}; allowed: a distinct non-empty name")
        at = f"{where}: station {name!r}"
        types = st.get("types", list(_NAMES))
        if isinstance(types, str) or not isinstance(types, list) or not types:
            raise ValueError(f"{at}: types = {types!r}; allowed: a list of {', '.join(_NAMES)}")
        for t in types:
            if t not in _NAMES:
                raise ValueError(unknown(f"{at}: types", t, _NAMES))
        has = [f for f in ("geodetic", "itrf") if f in st]
        if len(has) != 1:
            raise ValueError(f"{at}: position {'missing' if not has else 'given twice'}; allowed: one of "
                             "geodetic = [lon deg, lat deg, height m] or itrf = [x, y, z] m")
        field = has[0]
        v = st[field]
        ok = (isinstance(v, list) and len(v) == 3 and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                          and np.isfinite(x) for x in v))
        if ok and field == "geodetic":
            ok = -180.0 <= v[0] <= 360.0 and -90.0 <= v[1] <= 90.0 and -1e4 < v[2] < 1e4
        if not ok:
            raise ValueError(f"{at}: {field} = {v!r}; allowed: three finite numbers"
                             + (" (lon -180..360 deg, lat -90..90 deg, |height| < 10 km)" if field == "geodetic"
                                else " (m)"))
        extra = sorted(set(st) - {"name", "types", "geodetic", "itrf"})
        if extra:
            raise ValueError(unknown(f"{at}: field", extra[0], ("name", "types", "geodetic", "itrf")))
        pos = (np.asarray(erfa.gd2gc(1, np.radians(v[0]), np.radians(v[1]), float(v[2])), np.float64)
               if field == "geodetic" else np.asarray(v, np.float64))
        out[name] = (pos, tuple(types))
    return out


class _Ttc(MeasurementType):
    kind, bias, path, stations_label = "ttc", "station", "1,2,1", "TT&C"

    def station_catalogue(self):
        return tuple(ttc_stations())

    def evaluate(self, ctx, t, states):
        cat = ttc_stations()
        names = list(ctx.station_names(self.kind) or cat)
        key = ("ttc", id(t), id(states))
        if key not in ctx.cache:
            itrs = np.array([cat[s][0] for s in names])
            ctx.cache[key] = [geocentric_two_way(ctx.scen.epoch, t, states[:, b, :3], states[:, b, 3:], itrs,
                                                 eop=ctx.eop, use_eop=ctx.use_eop) for b in range(states.shape[1])]
        provides = np.array([self.name in cat[s][1] for s in names])
        out = []
        for b, (res, sel) in enumerate(ctx.cache[key]):
            visible = (sel >= np.sin(np.radians(10.0))) & provides[None, :]
            if self.unit == "m":
                obs = Observable(res["range"], res["range_dr"], np.zeros_like(res["range_dr"]), visible,
                                 "two-way range", "m", {})
            else:
                obs = Observable(res["range_rate"], res["range_rate_dr"], res["range_rate_dv"], visible,
                                 "two-way range rate", "m/s", {})
            out.append(flat_rows(self.name, b, names, obs, res["tau_down"]))
        return out


class TtcRange(_Ttc):
    name, unit, sigma = "ttc_range", "m", 1.0
    participants = "TT&C two-way range, station PARTICIPANT_1 to spacecraft PARTICIPANT_2 and back"


class TtcRangeRate(_Ttc):
    name, unit, sigma = "ttc_range_rate", "m/s", 1e-3
    tdm_keyword = "DOPPLER_INSTANTANEOUS"
    participants = "TT&C two-way range rate, station PARTICIPANT_1 to spacecraft PARTICIPANT_2"


#: The TT&C measurement types (registered in :mod:`.registry`).
TTC_TYPES = (TtcRange(), TtcRangeRate())
_NAMES = tuple(x.name for x in TTC_TYPES)
