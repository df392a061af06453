"""The initial states of a scenario: :class:`SatelliteConfig` (one
satellite's Keplerian elements or Cartesian state) and :class:`InitialConfig`
(section ``[initial]``: their axes, or an equal-arm constellation design, or
CCSDS OEM files), and :func:`derived_satellites`, which turns a design or OEM
files into Cartesian satellites at the scenario epoch."""

from __future__ import annotations

from dataclasses import dataclass
from decimal import Decimal, localcontext

from ..astro.constants import C_LIGHT
from ..astro.timescales import Epoch
from .values import _EXACT, ScenarioError, _num_array, _require, _require_choice, _set, _to_decimal

__all__ = ["AU_M", "BODY_RADII_M", "INITIAL_AXES", "INITIAL_DESIGNS", "OEM_EME2000", "ROTATIONS", "InitialConfig", "SatelliteConfig",
           "check_above_surface", "derived_satellites", "epoch_from_label", "oem_first_common_epoch"]


@dataclass(frozen=True)
class SatelliteConfig:
    """Initial state of one satellite at the scenario epoch, relative to the
    central body, in the axes of ``initial.axes`` (:class:`InitialConfig`).

    Either osculating Keplerian elements: ``a_m`` semi-major axis [m] (> 0),
    ``e`` eccentricity [-] (0 <= e < 1), ``i_deg``, ``raan_deg``,
    ``argp_deg``, ``nu_deg``: inclination, longitude (right ascension) of
    the ascending node, argument of pericentre, true anomaly [deg]; the
    inclination in 0 <= i <= 180 (an angle between the orbit's normal and
    the pole: 200 or -10 is no inclination), the other three any finite
    value (they are angles around a circle and wrap: 370 = 10, -90 = 270);
    or a Cartesian state: ``r_m`` position [m] and ``v_mps`` velocity [m/s],
    3 numbers each (then the elements are None).  All numbers are exact
    ``Decimal``.
    """

    name: str
    a_m: Decimal | None = None
    e: Decimal | None = None
    i_deg: Decimal | None = None
    raan_deg: Decimal | None = None
    argp_deg: Decimal | None = None
    nu_deg: Decimal | None = None
    r_m: tuple | None = None
    v_mps: tuple | None = None

    def __post_init__(self) -> None:
        _require(isinstance(self.name, str) and self.name.strip() != "", "satellite.name", self.name, "is not a non-empty string", "a non-empty string")
        elements = ("a_m", "e", "i_deg", "raan_deg", "argp_deg", "nu_deg")
        if self.r_m is not None or self.v_mps is not None:
            given = [f for f in elements if getattr(self, f) is not None]
            _require(not given, f"satellite.{given[0] if given else 'a_m'}", getattr(self, given[0]) if given else None,
                     "is given together with a Cartesian state", "either elements or r and v")
            for f, unit in (("r_m", "m"), ("v_mps", "m/s")):
                _require(getattr(self, f) is not None, f"satellite.{f}", None, "is missing",
                         f"3 finite numbers [{unit}] (a Cartesian state needs both r and v)")
                _set(self, f, _num_array(getattr(self, f), f"satellite.{f}", ((3,),), unit))
            with localcontext() as ctx:
                ctx.prec = _EXACT
                r, v = (sum(x * x for x in getattr(self, f)).sqrt() for f in ("r_m", "v_mps"))
            _require(r > 0, "satellite.r_m", list(self.r_m), "is the centre of the central body",
                     "|r| > 0 (the point-mass gravity is singular there)")
            _require(v < _C_LIGHT, "satellite.v_mps", list(self.v_mps), f"has |v| = {float(v):.4g} m/s, not below "
                     "the speed of light", f"|v| < c = {_C_LIGHT} m/s")
            return
        _require(self.a_m is not None, "satellite.a_m", None, "is missing", "a > 0 m (or a Cartesian state r, v)")
        for f in elements:
            _set(self, f, _to_decimal(Decimal(0) if getattr(self, f) is None else getattr(self, f), f"satellite.{f}"))
        _require(self.a_m > 0, "satellite.a_m", self.a_m, "is not positive", "a > 0 m")
        _require(0 <= self.e < 1, "satellite.e", self.e, "is not an elliptic eccentricity", "0 <= e < 1")
        _require(0 <= self.i_deg <= 180, "satellite.i_deg", self.i_deg, "is not an inclination",
                 "0 <= i <= 180 deg (raan, argp and nu: any finite angle)")

    @property
    def cartesian(self) -> bool:
        """True when the state is given as r, v (else Keplerian elements)."""
        return self.r_m is not None


INITIAL_AXES = ("equatorial", "ecliptic")
INITIAL_DESIGNS = ("none", "keplerian")
ROTATIONS = ("clockwise", "counterclockwise")
#: How OEM states labelled REF_FRAME = EME2000 are read: rotated by the IAU 2006 frame bias to ICRF (the
#: standard), or taken as ICRF axes already (ESA's CReMA 2.0 LISA files, docs/lisa-orbits.md).
OEM_EME2000 = ("frame-bias", "icrf")
AU_M = Decimal(149597870700)
_C_LIGHT = Decimal(repr(C_LIGHT))


def epoch_from_label(text: str, name: str) -> Epoch:
    """An :class:`Epoch` from an ISO date with an optional " UTC" (default)
    or " TDB" suffix; ScenarioError naming ``name`` otherwise."""
    parts = text.strip().rsplit(" ", 1)
    scale = parts[1].upper() if len(parts) == 2 and parts[1].upper() in ("UTC", "TDB") else "UTC"
    iso = parts[0] if len(parts) == 2 and parts[1].upper() in ("UTC", "TDB") else text
    try:
        return Epoch.from_tdb(iso) if scale == "TDB" else Epoch.from_utc(iso)
    except ValueError as exc:
        raise ScenarioError(name, text, f"is not a valid {scale} date ({getattr(exc, 'reason', exc)})",
                            'an ISO date YYYY-MM-DDTHH:MM:SS[.fff] with an optional " UTC" or " TDB" suffix') from None


@dataclass(frozen=True)
class InitialConfig:
    """Where the satellites' initial states come from (TOML section ``[initial]``).

    ``axes``: the axes of the satellites' elements or Cartesian states,
    "equatorial" (ICRF axes: the GCRS or BCRS of the run) or "ecliptic"
    (the IAU 2006 mean ecliptic and equinox of J2000.0, which includes the
    frame bias; rotated to ICRF exactly).
    ``design``: "none" (the [[satellites]] tables give the states) or
    "keplerian": the equal-arm Keplerian constellation of
    :mod:`tqdyn.astro.constellation_design` (heliocentric, 3 satellites)
    with ``arm_length_m`` [m], ``displacement_deg`` (mean angle from the
    Earth, negative trailing), ``rotation`` ("clockwise" or
    "counterclockwise") and ``semi_major_axis_m`` [m] (default 1 au).
    ``oem``: CCSDS OEM files, one per satellite in satellite order (the
    states interpolated at the epoch as each file says; default epoch the
    files' first common record); ``oem_eme2000``: how states labelled
    REF_FRAME = EME2000 are read, "frame-bias" (rotated by the IAU 2006
    frame bias, ~23 mas, to ICRF: the standard) or "icrf" (taken as ICRF
    axes: ESA's CReMA 2.0 LISA files, whose states fit ICRF-axes dynamics,
    docs/lisa-orbits.md).  ``names``: satellite names for a design
    or OEM files (default Sat1, Sat2, ...).
    """

    axes: str = "equatorial"
    design: str = "none"
    arm_length_m: Decimal = Decimal("2.5e9")
    displacement_deg: Decimal = Decimal(-20)
    rotation: str = "clockwise"
    semi_major_axis_m: Decimal = AU_M
    oem: tuple[str, ...] = ()
    oem_eme2000: str = "frame-bias"
    names: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        _require_choice(self.axes, "initial.axes", INITIAL_AXES)
        _require_choice(self.design, "initial.design", INITIAL_DESIGNS)
        _require_choice(self.rotation, "initial.rotation", ROTATIONS)
        _require_choice(self.oem_eme2000, "initial.oem_eme2000", OEM_EME2000)
        for f in ("arm_length_m", "displacement_deg", "semi_major_axis_m"):
            _set(self, f, _to_decimal(getattr(self, f), f"initial.{f}"))
        _require(self.semi_major_axis_m > 0, "initial.semi_major_axis", self.semi_major_axis_m, "is not positive",
                 "a > 0 m")
        _require(0 < self.arm_length_m < self.semi_major_axis_m / 10, "initial.arm_length", self.arm_length_m,
                 "is out of range", "0 < L < a/10 (the design expands in L/2a)")
        oem = tuple(self.oem)
        _require(all(isinstance(x, str) and x.strip() for x in oem), "initial.oem", list(oem),
                 "is not a list of file names", "a list of OEM file paths, one per satellite")
        _set(self, "oem", oem)
        _require(not (oem and self.design != "none"), "initial.oem", list(oem),
                 f"is given together with initial.design = {self.design!r}", 'design = "none" with OEM files')
        _set(self, "names", tuple(self.names))

    @property
    def derived(self) -> bool:
        """True when the satellites' states follow from a design or OEM files."""
        return self.design != "none" or bool(self.oem)




def _decimal_vector(values) -> tuple:
    """3 exact Decimals from mpmath numbers or floats (mpmath: 40 significant digits)."""
    return tuple(Decimal(str(x)) for x in values)


def derived_satellites(initial: InitialConfig, epoch: Epoch, central_body: str,
                       gm_sun=None) -> tuple[SatelliteConfig, ...]:
    """Cartesian satellites [m, m/s; relative to the central body, ICRF
    axes] at ``epoch`` from ``initial.design`` (with the Sun's GM ``gm_sun``
    [m^3/s^2], the scenario's ``forces.gm_sun``; None: DE430) or
    ``initial.oem``; named ``initial.names`` (default Sat1, Sat2, ...).  ScenarioError naming the
    key for a file that cannot be read or does not cover the epoch."""
    if initial.design == "keplerian":
        import mpmath

        from ..astro.constellation_design import keplerian_constellation
        from ..forces.heliocentric import SunMonopole

        with mpmath.workdps(40):
            try:
                design = keplerian_constellation(initial.arm_length_m, initial.displacement_deg, initial.rotation,
                                                 epoch.tdb, a=initial.semi_major_axis_m,
                                                 gm=SunMonopole().gm if gm_sun is None else str(gm_sun))
            except ValueError as exc:
                raise ScenarioError("initial.design", initial.design, f"cannot be built ({exc})",
                                    "arm_length, displacement_deg, rotation, semi_major_axis in range") from None
            states = list(zip(design.r, design.v))
            rv = [(_decimal_vector(r), _decimal_vector(v)) for r, v in states]
    else:
        from ..astro.oem_states import states_at

        rv = []
        for k, path in enumerate(initial.oem, start=1):
            try:
                traj = _heliocentric_oem(path, initial.oem_eme2000)
            except (OSError, ValueError) as exc:
                raise _oem_error(k, path, exc) from None
            try:
                r, v = states_at(traj, *epoch.tdb)
            except ValueError as exc:
                t = epoch.tdb
                if (t[0] - traj.start[0]) + (t[1] - traj.start[1]) < 0:
                    exc = f"starts at {_tdb_text(traj.start)[:19]} TDB, after {epoch.iso}"
                elif (t[0] - traj.stop[0]) + (t[1] - traj.stop[1]) > 0:
                    exc = f"ends at {_tdb_text(traj.stop)[:19]} TDB, before {epoch.iso}"
                raise _oem_error(k, path, exc, allowed="an epoch in every file's span") from None
            rv.append((_decimal_vector(r), _decimal_vector(v)))
    names = list(initial.names) + [f"Sat{k}" for k in range(len(initial.names) + 1, len(rv) + 1)]
    if len(names) > len(rv):
        raise ScenarioError("satellites", names, f"names {len(names)} satellites, the initial states give {len(rv)}",
                            f"at most {len(rv)} [[satellites]] names")
    return tuple(SatelliteConfig(name=n, r_m=r, v_mps=v) for n, (r, v) in zip(names, rv))


def oem_first_common_epoch(paths, eme2000: str = "frame-bias") -> str:
    """The TDB ISO date of the OEM files' first common record (the latest
    of their first epochs), the default epoch of ``initial.oem``."""
    firsts = []
    for k, path in enumerate(paths, start=1):
        try:
            traj = _heliocentric_oem(path, eme2000)
            firsts.append((traj.start, _tdb_text(traj.start)))
        except (OSError, ValueError) as exc:
            raise _oem_error(k, path, exc) from None
    return max(firsts, key=lambda x: x[0][0] + x[0][1])[1]


def oem_common_span(paths, eme2000: str = "frame-bias") -> tuple[str, str]:
    """The OEM files' common span (latest first epoch, earliest last epoch)
    as two TDB ISO dates with the suffix " TDB" (the default span of
    ``spacecraft.self_gravity_center``)."""
    spans = []
    for k, path in enumerate(paths, start=1):
        try:
            traj = _heliocentric_oem(path, eme2000)
            spans.append(((traj.start, _tdb_text(traj.start)), (traj.stop, _tdb_text(traj.stop))))
        except (OSError, ValueError) as exc:
            raise _oem_error(k, path, exc) from None
    first = max((s[0] for s in spans), key=lambda x: x[0][0] + x[0][1])
    last = min((s[1] for s in spans), key=lambda x: x[0][0] + x[0][1])
    return f"{first[1]} TDB", f"{last[1]} TDB"


#: What ``initial.oem`` reads (the "allowed" of its messages).
_OEM_ALLOWED = "see docs/scenarios.md#oem-files"


def _oem_error(k: int, path, exc, problem: str | None = None, allowed: str | None = None) -> ScenarioError:
    """The one-line error of ``initial.oem.k``: the file (its name alone for a file shipped with
    tqdyn, whose directory is long), then ``problem`` (default: "cannot be read" for an OSError)
    and what the reader says of it (``exc``: without the file, which it names first, and with its
    own "allowed" if it gives one, else ``allowed``)."""
    import os

    if problem is None:
        problem = "cannot be read" if isinstance(exc, OSError) else ""
    text = " ".join(str(exc).split())
    for p in (str(path), os.path.abspath(str(path))):
        text = text.removeprefix(f"{p}: ").removeprefix(f"{p} ")
    text, _, own = text.partition("; allowed: ")
    data = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "data") + os.sep
    shown = os.path.basename(path) if os.path.abspath(str(path)).startswith(data) else path
    if "(allowed: " not in text:  # else the reader's message says what is allowed itself
        allowed = allowed or own or _OEM_ALLOWED
    return ScenarioError(f"initial.oem.{k}", shown, f"{problem}: {text}" if problem else text, allowed)


def _heliocentric_oem(path: str, eme2000: str = "frame-bias"):
    """An OEM file (its segment, or its continuous segments joined) as Sun-centred ICRF/TDB states
    (:func:`tqdyn.astro.oem_states.to_heliocentric`; ``eme2000``: see
    :class:`InitialConfig`); ValueError naming the file.  Cached per file
    (absolute path, size, modification time) and reading: resolving one
    scenario reads its OEM files several times (epoch, span, states), a
    study plan dozens of times.  The result is shared: do not modify it."""
    import os

    try:
        st = os.stat(path)
    except OSError:
        key = None
    else:
        key = (os.path.abspath(path), st.st_size, st.st_mtime_ns, eme2000)
    if key is not None and key in _OEM_CACHE:
        return _OEM_CACHE[key]
    from ..astro.oem_states import to_heliocentric
    from ..readers.oem import read_oem

    traj = to_heliocentric(read_oem(path), eme2000_frame_bias=eme2000 == "frame-bias")
    if key is not None:
        if len(_OEM_CACHE) >= 16:
            _OEM_CACHE.pop(next(iter(_OEM_CACHE)))
        _OEM_CACHE[key] = traj
    return traj


_OEM_CACHE: dict = {}


def _tdb_text(jd) -> str:
    """ISO TDB date (1 ns digits) of a two-part TDB Julian date."""
    import erfa

    y, mo, d, hmsf = erfa.d2dtf("TDB", 9, jd[0], jd[1])
    return (f"{int(y):04d}-{int(mo):02d}-{int(d):02d}T{int(hmsf['h']):02d}:{int(hmsf['m']):02d}:"
            f"{int(hmsf['s']):02d}.{int(hmsf['f']):09d}")


#: Radii [m] of the central bodies below which no satellite may start (unless
#: ``scenario.allow_below_surface``): the Earth's equatorial radius (WGS84 / IERS 2010 a = 6378137 m;
#: EGM2008's reference radius 6378136.3 m differs by 0.7 m) and the Sun's nominal radius (IAU 2015
#: B3, 696000 km, as :data:`tqdyn.forces.sun.R_SUN_IAU_M`).
BODY_RADII_M = {"earth": Decimal(6378137), "sun": Decimal(696000000)}
_BODY_NAMES = {"earth": "the Earth", "sun": "the Sun"}


def check_above_surface(satellites, initial: "InitialConfig", central_body: str) -> None:
    """Each satellite's pericentre (Cartesian: its distance) at least the
    central body's radius (:data:`BODY_RADII_M`); ScenarioError naming the
    key (the satellite's, or ``initial.design`` / ``initial.oem.N`` for a
    derived state) otherwise."""
    radius = BODY_RADII_M[central_body]
    body = _BODY_NAMES[central_body]
    with localcontext() as ctx:
        ctx.prec = _EXACT
        r_km = radius / 1000
        override = "or scenario.allow_below_surface = true"
        for k, sat in enumerate(satellites, start=1):
            where = f"satellites.{k}"
            if sat.cartesian:
                dist = sum(x * x for x in sat.r_m).sqrt()
                if dist < radius:
                    inside = f"inside {body} (|r| = {float(dist / 1000):.7g} km < its radius {r_km} km)"
                    if initial.derived:  # the state comes from a design or an OEM file
                        key, value = ((f"initial.oem.{k}", initial.oem[k - 1]) if initial.oem
                                      else ("initial.design", initial.design))
                        raise ScenarioError(key, value, f"puts {where} ({sat.name!r}) {inside}",
                                            f"|r| >= {r_km} km, {override}")
                    raise ScenarioError(f"{where}.r_km", [x / 1000 for x in sat.r_m], f"is {inside}",
                                        f"|r| >= {r_km} km, {override}")
                continue
            if sat.a_m < radius:
                raise ScenarioError(f"{where}.a_km", sat.a_m / 1000,
                                    f"is inside {body} (its radius {r_km} km)",
                                    f"a_km and a (1 - e) >= {r_km} km, {override}")
            peri = sat.a_m * (1 - sat.e)
            if peri < radius:
                e_max = (1 - radius / sat.a_m).quantize(Decimal("1e-9"), rounding="ROUND_FLOOR")
                raise ScenarioError(f"{where}.e", sat.e,
                                    f"puts the pericentre a (1 - e) = {float(peri / 1000):.7g} km inside {body} "
                                    f"(radius {r_km} km)",
                                    f"e <= {e_max}, {override}")
