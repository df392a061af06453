"""What a run uses besides its scenario keys: the constants record of a
trajectory file (root attribute ``constants``, JSON), and its comparison
with what this tqdyn would use.

A run is fixed by its resolved scenario (every key, exact decimals,
including the GMs of every body: ``forces.gm_earth``, ``forces.gm_sun``,
``forces.gm_moon`` ...) and by what tqdyn itself holds.  The record states
the latter so that the file alone says what the run used:

* ``constants``: the fixed constants, each ``{"value", "unit", "source"}``:
  c, L_G, L_B (defining constants), the central body's radius of the
  above-surface check, and the constants of each force term that is on --
  the Earth's and the Moon's field GM and reference radius (from their
  coefficient files' headers), the Sun's J2, its reference radius and pole,
  the PPN parameters and the Earth's angular momentum of the relativity
  term, the tide models' reference values;
* ``data_files``: the data files the run reads (ephemeris, coefficient and
  tide tables, orientation kernels, OEM files of the initial states), each
  ``{"file", "sha256"}``; the Earth-orientation data are recorded by the
  root attributes ``eop_sources`` / ``eop_data``;
* ``force_model_sha256``: the SHA-256 of every number the compiled model
  holds (the force model's packed parameters and layout, the constellation
  parameters: every GM, radius, coefficient and switch the right-hand side
  reads).

:func:`compare_constants` lists, one line each, what differs between a
file's record and the one this tqdyn makes for the same scenario: re-running
a file reproduces it bit for bit when there is nothing (and the library
versions match, ``tqdyn info``).  Units SI.
"""

from __future__ import annotations

import hashlib
import json
import os
from importlib import resources

__all__ = ["RECORD_VERSION", "compare_constants", "constants_json", "run_constants"]

#: Version of the record's layout (the key ``record``).
RECORD_VERSION = 1

_HASHES: dict = {}


def _sha256(path) -> str:
    """SHA-256 (hex) of a file, cached per (absolute path, size, modification time)."""
    p = os.path.abspath(os.fspath(path))
    st = os.stat(p)
    key = (p, st.st_size, st.st_mtime_ns)
    if key not in _HASHES:
        h = hashlib.sha256()
        with open(p, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
        _HASHES[key] = h.hexdigest()
    return _HASHES[key]


def _data(*parts) -> str:
    return str(resources.files("tqdyn").joinpath("data", *parts))


def _c(value, unit: str, source: str) -> dict:
    if hasattr(value, "tolist"):
        value = value.tolist()
    return {"value": value, "unit": unit, "source": source}


def _term_constants(term, out: dict) -> None:
    """The named constants of one force term (and of the tide models summed into the Earth field)."""
    name = getattr(term, "name", "")
    if name == "earth_field":
        m = term.model
        src = f"{m.name} coefficient file header ({m.tide_system}): {m.source}"
        out["earth_field.gm"] = _c(float(m.gm), "m^3/s^2", src)
        out["earth_field.radius"] = _c(float(m.radius), "m", src)
        for tide in term.tides:
            _term_constants(tide, out)
    elif name == "moon_field":
        m = term.model()
        src = f"{m.name} coefficient file header: {m.source}"
        out["moon_field.gm"] = _c(float(m.gm), "m^3/s^2", src)
        out["moon_field.radius"] = _c(float(m.radius), "m", src)
    elif name in ("sun_j2", "central_j2"):
        p = term.params()
        out["sun_j2.j2"] = _c(float(term.j2), "1", term.source)
        out["sun_j2.radius"] = _c(float(term.radius), "m", term.source)
        out["sun_j2.pole"] = _c(p[2:5], "1 (unit vector, ICRF axes)", term.source)
    elif name == "relativity":
        out["relativity.beta"] = _c(float(term.beta), "1", "PPN beta (general relativity: 1)")
        out["relativity.gamma"] = _c(float(term.gamma), "1", "PPN gamma (general relativity: 1)")
        if getattr(term, "lense_thirring", False):
            out["relativity.j_earth"] = _c(float(term.j_earth), "m^2/s", "the Earth's angular momentum per unit "
                                           "mass, IERS Conventions 2010 (TN36) sec. 10.3")
    elif name == "solid_tides":
        out["solid_tides.radius"] = _c(float(term.r_ref), "m", "reference radius of the Love-number expansion "
                                       "(the static field's, EGM2008)")
    elif name == "atmospheric_tides":
        from ..forces.atmospheric_tides import G_NEWTON, LOAD_LOVE_NUMBERS

        src = "Biancale & Bode (2006) surface-pressure load model (forces/atmospheric_tides.py)"
        out["atmospheric_tides.gm"] = _c(float(term.gm), "m^3/s^2", src + ": GM of its Stokes factors (EGM2008)")
        out["atmospheric_tides.radius"] = _c(float(term.r_ref), "m", src + ": reference radius (EGM2008)")
        out["atmospheric_tides.g"] = _c(float(term.g), "m/s^2", "standard gravity (CGPM 1901)")
        out["atmospheric_tides.G"] = _c(float(G_NEWTON), "m^3/(kg s^2)", "Newtonian constant of gravitation "
                                        "(CODATA 2018)")
        out["atmospheric_tides.load_love_numbers"] = _c([LOAD_LOVE_NUMBERS[n] for n in sorted(LOAD_LOVE_NUMBERS)],
                                                        "1", "k'_n, n = 2..8: TN36 sec. 6.3.1 (Farrell 1972), "
                                                        "Gegout for n = 7, 8")


def _data_files(scenario) -> dict:
    """{what: {"file", "sha256"}} of the data files a run of ``scenario`` reads (besides the EOP data)."""
    f, geo = scenario.forces, scenario.central_body == "earth"
    files: dict = {}
    uses_ephemeris = bool(f.third_bodies) or (geo and bool(f.relativity or f.moon_degree or f.sun_j2
                                                          or f.solid_tides or f.earth_field_indirect))
    if uses_ephemeris:
        from ..astro.ephemeris import ephemeris_named

        files["ephemeris"] = ephemeris_named(f.ephemeris).path
    if geo and f.earth_degree:
        from ..readers.gravity_fields import EGM2008_FILE

        files["earth_field"] = _data(EGM2008_FILE)
        if f.eop != "off":  # the tidal EOP corrections of TN36 Tables 8.2, 8.3, 5.1a
            for t in ("tab8.2ab.txt", "tab8.3ab.txt", "tab5.1a.txt"):
                files[f"earth_orientation.{t}"] = _data("iers2010", t)
    if geo and f.earth_degree and f.solid_tides:
        for t in ("tab6.3.txt", "tab6.5a.txt", "tab6.5b.txt", "tab6.5c.txt"):
            files[f"solid_tides.{t}"] = _data("iers2010", t)
    if geo and f.earth_degree and f.ocean_tides_degree:
        from ..readers.fes2004 import FES2004_FILE

        files["ocean_tides"] = _data(FES2004_FILE)
    if geo and f.earth_degree and f.atmospheric_tides:
        from ..readers.bb2006 import BB2006_FILE

        files["atmospheric_tides"] = _data(BB2006_FILE)
    if geo and f.moon_degree:
        from ..readers.gravity_fields import GL0660B_FILE

        files["moon_field"] = _data(GL0660B_FILE)
        files["moon_orientation"] = _data("moon_pa_de421_1900-2050.bpc" if f.moon_libration == "de421"
                                          else "pck00010.tpc")
    if f.sun_j2:
        files["sun_pole"] = _data("pck00010.tpc")
    for k, path in enumerate(scenario.initial.oem, start=1):
        files[f"initial.oem.{k}"] = path
    return {what: {"file": os.path.basename(str(p)), "sha256": _sha256(p)} for what, p in files.items()}


def run_constants(scenario, model=None) -> dict:
    """The constants record (see the module docstring) of a run of
    ``scenario`` with ``model`` (its force model, built if None): a
    JSON-ready dict ``{"record", "constants", "data_files",
    "force_model_sha256"}``."""
    import numpy as np

    from ..astro.constants import C_LIGHT, L_B, L_G
    from ..dynamics.system import build_system
    from ..forces.model import build_force_model
    from .initial import BODY_RADII_M

    model = build_force_model(scenario.forces, scenario.reference) if model is None else model
    body = scenario.central_body
    check = ("" if not scenario.allow_below_surface
             else "; not applied to this run (scenario.allow_below_surface = true)")
    constants = {
        "c": _c(C_LIGHT, "m/s", "speed of light, exact (SI definition of the metre, 1983)"),
        "L_G": _c(L_G, "1", "d(TT)/d(TCG) = 1 - L_G, defining constant (IAU 2000 Resolution B1.9)"),
        "L_B": _c(L_B, "1", "d(TDB)/d(TCB) = 1 - L_B, defining constant (IAU 2006 Resolution B3)"),
        "surface_radius": _c(float(BODY_RADII_M[body]), "m", f"radius of the central body ({body}) below which no "
                             "satellite may start (the Earth's equatorial radius, WGS84 / IERS 2010; the Sun's "
                             f"nominal radius, IAU 2015 B3){check}"),
    }
    for term in model.terms:
        _term_constants(term, constants)
    system = build_system(scenario, model)
    h = hashlib.sha256()
    for a in (model.params, model.layout, system.cpar):
        h.update(np.ascontiguousarray(a).tobytes())
    return {"record": RECORD_VERSION, "constants": constants, "data_files": _data_files(scenario),
            "force_model_sha256": h.hexdigest()}


def constants_json(record: dict) -> str:
    """The record as the JSON text of the root attribute ``constants`` (sorted keys, exact float repr)."""
    return json.dumps(record, sort_keys=True, allow_nan=False)


def compare_constants(recorded, current: dict) -> list[str]:
    """One line per difference between a file's record (``recorded``: the
    attribute's JSON text or its dict) and ``current`` (:func:`run_constants`
    of the file's scenario in this tqdyn); empty when they agree."""
    try:
        rec = json.loads(recorded) if isinstance(recorded, str) else dict(recorded)
        rec_c, rec_f = dict(rec.get("constants", {})), dict(rec.get("data_files", {}))
    except (TypeError, ValueError, AttributeError) as exc:
        return [f"the recorded constants cannot be read ({exc})"]
    out = []
    cur_c, cur_f = current["constants"], current["data_files"]
    for key in sorted(set(rec_c) | set(cur_c)):
        a, b = rec_c.get(key), cur_c.get(key)
        if a is None or b is None:
            out.append(f"constant {key}: " + ("recorded, not used by this tqdyn" if b is None else
                                              "used by this tqdyn, not recorded"))
        elif a.get("value") != b["value"]:
            out.append(f"constant {key}: the file records {a.get('value')!r} {b['unit']}, this tqdyn uses "
                       f"{b['value']!r} ({b['source']})")
    for key in sorted(set(rec_f) | set(cur_f)):
        a, b = rec_f.get(key), cur_f.get(key)
        if a is None or b is None:
            out.append(f"data file {key}: " + ("recorded, not read by this tqdyn" if b is None else
                                               f"{b['file']} read by this tqdyn, not recorded"))
        elif a.get("sha256") != b["sha256"]:
            out.append(f"data file {key}: {b['file']} differs from the file the run read ({a.get('file')}, SHA-256 "
                       f"{str(a.get('sha256'))[:12]}.. recorded, {b['sha256'][:12]}.. now)")
    if rec.get("force_model_sha256") != current["force_model_sha256"]:
        out.append("the compiled force model's numbers (GMs, radii, coefficients, switches) differ from the run's "
                   f"(SHA-256 {str(rec.get('force_model_sha256'))[:12]}.. recorded, "
                   f"{current['force_model_sha256'][:12]}.. now)")
    return out
