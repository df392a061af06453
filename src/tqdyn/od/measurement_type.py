"""The measurement interface of orbit determination (modelled on Orekit's estimation package):
each measurement type is a :class:`MeasurementType` object that carries its name, tracking kind,
unit, default sigma, bias key convention, CCSDS TDM keyword, signal path and time-tag convention,
and computes its rows with ``evaluate(context, t, states)``.  The types are listed once, in
:mod:`.registry`, which every user (tracking plans, problem, workflows, TDM files, figures) reads.

Time tags t [s since the scenario epoch, the run's time scale: TT geocentric, TDB heliocentric];
states [m, m/s] in the run's frame (GCRS geocentric, Sun-centred BCRS axes heliocentric).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Context", "MeasurementType", "Rows", "flat_rows", "scenario_eop"]


@dataclass
class Rows:
    """Computed measurements of one type on a time grid, row arrays (r,): ``t_idx`` index into
    the grid, ``sat`` the satellite, ``peer`` the station / transmitter / emitter name,
    ``value`` [the type's unit], ``visible`` bool, ``d`` (r, 2, 6) partials with respect to the
    satellite's and the emitter's (r, v) at the tag, ``sat2`` the emitter's index (links) or -1,
    ``tau_down`` [s] the downlink light time of a two-way row (bounce to reception; NaN: none)."""

    type: str
    t_idx: np.ndarray
    sat: np.ndarray
    peer: np.ndarray
    value: np.ndarray
    visible: np.ndarray
    d: np.ndarray
    sat2: np.ndarray
    tau_down: np.ndarray | None = None


def flat_rows(mtype: str, b: int, names, obs, tau_down=None) -> Rows:
    """Rows of an :class:`~tqdyn.od.measurements.Observable` (N, S) of satellite b toward the
    peers ``names`` (S,); tau_down (N, S) [s] or None."""
    n, s = obs.value.shape
    d = np.zeros((n * s, 2, 6))
    d[:, 0, :3] = obs.d_r.reshape(-1, 3)
    d[:, 0, 3:] = obs.d_v.reshape(-1, 3)
    return Rows(mtype, np.repeat(np.arange(n), s), np.full(n * s, b), np.tile(np.asarray(names, object), n),
                obs.value.ravel(), obs.visible.ravel(), d, np.full(n * s, -1),
                None if tau_down is None else np.asarray(tau_down, np.float64).ravel())


@dataclass
class Context:
    """What a measurement model needs besides the states: the scenario ``scen``, the tracking
    plan, ``stations`` {kind: names} overriding the plan's, the scenario's EOP table ``eop``
    (:func:`tqdyn.astro.eop_sources.eop_table` of ``forces.eop`` and ``forces.eop_interpolation``)
    and ``use_eop`` (False when ``forces.eop = "off"``), and a cache shared by the types of one
    kind (a model computing two types at once)."""

    scen: object
    tracking: object
    stations: dict = field(default_factory=dict)
    eop: object = None
    use_eop: bool = True
    cache: dict = field(default_factory=dict)

    @property
    def heliocentric(self) -> bool:
        return self.scen.reference.central_body == "sun"

    def station_names(self, kind: str):
        """The stations of a station kind: the override, else the plan's (None: the model's)."""
        return self.stations.get(kind, self.tracking.station_names(kind))


class MeasurementType:
    """One measurement type (class attributes; subclasses implement :meth:`evaluate`).

    name: the type string (measurement rows, TDM ``tqdyn type``, scenario and command-line keys);
    kind: the tracking kind that produces it (``Tracking.kinds``, ``--tracking``); unit: "m" or
    "m/s"; sigma: default noise [unit]; bias: the bias key convention, "station"
    (``bias/<type>/<station>``), "link" (``bias/<type>/<emitter>-><receiver>``) or None (no bias
    parameter); receiver_clock: rows carry a receiver clock bias per epoch and satellite,
    eliminated by the fit; heliocentric: allowed on heliocentric runs; tdm_keyword: the TDM data
    keyword (``RANGE`` [km, or s for two-way light time], ``DOPPLER_INSTANTANEOUS`` [km/s]);
    path: the TDM ``PATH`` ("1,2" one-way: PARTICIPANT_1 emits, PARTICIPANT_2 the satellite
    receives; "1,2,1" two-way: the station PARTICIPANT_1 transmits and receives); participants:
    what PARTICIPANT_1 and _2 are; stations_label: the name of a station kind's stations in
    messages (None: not a station kind)."""

    name: str = ""
    kind: str = ""
    unit: str = "m"
    sigma: float = 1.0
    bias: str | None = None
    receiver_clock: bool = False
    heliocentric: bool = False
    tdm_keyword: str = "RANGE"
    path: str = "1,2"
    participants: str = ""
    stations_label: str | None = None

    @property
    def two_way(self) -> bool:
        return self.path == "1,2,1"

    def station_catalogue(self) -> tuple:
        """The names of the stations a plan may name for this kind (() for no stations)."""
        return ()

    def evaluate(self, context: Context, t: np.ndarray, states: np.ndarray) -> list[Rows]:
        """Every computable row at t (n,) [s] from states (n, n_sat, 6) [m, m/s]: values,
        partials with respect to the states at t, visibility (:class:`Rows`)."""
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"<measurement type {self.name} ({self.kind}, {self.unit})>"


def scenario_eop(scen) -> dict:
    """{"eop": table, "use_eop": bool} of the scenario's Earth orientation, for every station,
    GNSS and SP3 model: the table of ``forces.eop`` interpolated as ``forces.eop_interpolation``
    (:func:`tqdyn.astro.eop_sources.eop_table`, the table the dynamics use); ``forces.eop =
    "off"``: no EOP (use_eop False)."""
    from ..astro.eop_sources import eop_table

    forces = scen.forces
    eop = eop_table(forces.eop, forces.eop_interpolation)
    return {"eop": eop, "use_eop": eop is not None}
