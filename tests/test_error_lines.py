"""Errors a person reads: an unknown key or value is one line of at most ~200 characters naming
the field and the value, the closest allowed names ("did you mean ...") and, for a long list,
where the full list is documented (docs/reliability.md, "Error messages").

References: the allowed names are the package's own tables (the scenario schema of
``tqdyn.scenario.loader``, the closed-loop tables, the command-line choices); each case below
misspells one of them by a letter or two, so the misspelt name is the one a reader expects to be
suggested.  The documentation pages are the repository's docs/*.md; an anchor is the heading's
GitHub slug (lower case, punctuation dropped, blanks to hyphens).  Every in-process command-line
test also checks the length of its error lines (tests/conftest.py, ``_cli_error_lines_short``).
"""

from __future__ import annotations

import pathlib
import re

import pytest

from cli_support import MAX_ERROR_LINE, error_line, run_cli
from tqdyn._choices import MAX_LISTED, allowed, closest, did_you_mean, unknown
from tqdyn.scenario import closed_loop as cl
from tqdyn.scenario.loader import _SAT_SCHEMA, _SCHEMA, _TOP_KEYS

ROOT = pathlib.Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "tqdyn"

#: A scenario file extending the fast built-in Kepler case, with the tables given.
BASE = '[scenario]\nextends = "tianqin-kepler"\n'
SATELLITE = '[[satellites]]\nname = "S1"\na_km = 100000.0\n'


def _line(status, err, tmp_path, *words) -> str:
    line = error_line(status, err, *words, tmp_root=tmp_path)
    assert "did you mean" in line.lower(), line
    return line


# ------------------------------------------------------------------ the mechanism


def test_closest_names_ignore_case_and_suggest_nothing_far():
    """difflib's ratio: 'gm_mon' is 12/13 like 'gm_moon'; 'xyz' is like none of them."""
    names = ("gm_sun", "gm_moon", "gm_mars")
    assert closest("gm_mon", names)[0] == "gm_moon"
    assert closest("GM_MOON", names) == ["gm_moon"]
    assert closest("xyz", names) == [] and did_you_mean("xyz", names) == ""
    assert did_you_mean("multstep", ("dp87", "multistep")) == " (did you mean 'multistep'?)"
    assert closest(None, names) == [] and closest(["gm_moon"], names) == []


def test_short_lists_in_full_long_ones_by_their_page():
    """A list that fits in MAX_LISTED characters is given whole; a longer one by its number and page,
    or, without a page, by its first names and number (never longer than MAX_LISTED)."""
    assert allowed(("dp87", "multistep")) == "dp87, multistep"
    assert allowed(("dp87", "multistep"), quote=repr) == "'dp87', 'multistep'"
    many = [f"name_{i}" for i in range(31)]
    assert allowed(many, "docs/x.md#y", noun="keys") == "one of the 31 keys in docs/x.md#y"
    head = allowed(many)
    assert head.startswith("name_0, name_1") and head.endswith("... (31 names)") and len(head) <= MAX_LISTED
    msg = unknown("forces", "gm_mon", ["gm_moon"] + many, "docs/x.md#y", problem="is not a key")
    assert msg == "forces: 'gm_mon' is not a key (did you mean 'gm_moon'?); allowed: one of the 32 names in docs/x.md#y"


# ------------------------------------------------------------------ the corpus of bad invocations

#: Unknown keys in every table of a scenario file: (TOML text, field, expected suggestion).
FILE_KEYS = [
    (BASE + "nmae = 'x'\n", "scenario.nmae", "name"),
    (BASE + "[run]\nduratoin = 10\n", "run.duratoin", "duration"),
    (BASE + "[integrator]\nmetod = 'dp87'\n", "integrator.metod", "method"),
    (BASE + "[forces]\ngm_mon = 1\n", "forces.gm_mon", "gm_moon"),
    (BASE + "[spacecraft]\narchitecure = 'lisa'\n", "spacecraft.architecure", "architecture"),
    (BASE + "[initial]\naxs = 'ecliptic'\n", "initial.axs", "axes"),
    (BASE + "[constellation]\npointng = 'none'\n", "constellation.pointng", "pointing"),
    (BASE + "[accelerations]\nrtn_cso = 0\n", "accelerations.rtn_cso", "rtn_cos"),
    (BASE + "[forcse]\nx = 1\n", "forcse", "forces"),
    (BASE + SATELLITE + "a_kn = 1\n", "satellites.1.a_kn", "a_km"),
    (BASE + "[closed_loop]\nf_mn = 1\n", "closed_loop.f_mn", "f_min"),
    (BASE + "[closed_loop.plant]\nsc_mas = 1\n", "closed_loop.plant.sc_mas", "sc_mass"),
    (BASE + "[closed_loop.controllers.dragfre]\ngain = 1\n", "closed_loop.controllers.dragfre", "dragfree"),
    (BASE + "[closed_loop.noise.thruster_forc]\nlevel = 1\n", "closed_loop.noise.thruster_forc", "thruster_force"),
    ('[scenario]\nextends = "tianqin-keplr"\n', "scenario.extends", "tianqin-kepler"),
]


@pytest.mark.parametrize("text, field, hint", FILE_KEYS, ids=[c[1] for c in FILE_KEYS])
def test_unknown_keys_of_a_scenario_file(text, field, hint, tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    status, _, err = run_cli(["run", str(path), "-q", "-o", str(tmp_path / "x.h5")], capsys)
    _line(status, err, tmp_path, field, f"'{hint}'")
    assert not (tmp_path / "x.h5").exists()


#: Overrides of unknown keys and of enumerated keys with an unknown value: (--set, field, suggestion).
OVERRIDES = [
    ("forces.gm_mon=1", "forces.gm_mon", "gm_moon"),
    ("integrator.metod=dp87", "integrator.metod", "method"),
    ("forcse.x=1", "forcse.x", "forces"),
    ("satellites.1.a_kn=1", "satellites.1.a_kn", "a_km"),
    ("integrator.method=multstep", "integrator.method", "multistep"),
    ("integrator.mode=adaptiv", "integrator.mode", "adaptive"),
    ("integrator.tableau=corected", "integrator.tableau", "corrected"),
    ("integrator.corrector=pecce", "integrator.corrector", "pece"),
    ("run.precision=float46", "run.precision", "float64"),
    ("forces.moon_libration=de42", "forces.moon_libration", "de421"),
    ("forces.relativity_model=eih2", "forces.relativity_model", "eih"),
    ("forces.eop_interpolation=splin", "forces.eop_interpolation", "spline"),
    ("forces.eop=finls", "forces.eop", "finals"),
    ("forces.third_bodies=sun,mon", "forces.third_bodies", "moon"),
    ("forces.third_bodies_extended=jupter", "forces.third_bodies_extended", "jupiter"),
    ("constellation.pointing=globl", "constellation.pointing", "global"),
    ("constellation.control=of", "constellation.control", "off"),
    ("constellation.tm_gravity=diferential", "constellation.tm_gravity", "differential"),
    ("spacecraft.architecture=tianqn", "spacecraft.architecture", "tianqin"),
    ("spacecraft.dragfree=lsa", "spacecraft.dragfree", "lisa"),
    ("spacecraft.tm_axis=Y", "spacecraft.tm_axis", "y"),
    ("spacecraft.self_gravity=table-4", "spacecraft.self_gravity", "table-iv"),
    ("initial.axes=ecliptc", "initial.axes", "ecliptic"),
    ("initial.design=keplerain", "initial.design", "keplerian"),
    ("initial.rotation=clockwis", "initial.rotation", "clockwise"),
    ("initial.oem_eme2000=icfr", "initial.oem_eme2000", "icrf"),
    ("scenario.central_body=eart", "scenario.central_body", "earth"),
    ("closed_loop.mission=lisaa", "closed_loop.mission", "lisa"),
    ("closed_loop.attitude_z_sensor=dw", "closed_loop.attitude_z_sensor", "dws"),
    ("closed_loop.design=hnf", "closed_loop.design", "hinf"),
    ("closed_loop.defaults=publishd", "closed_loop.defaults", "published"),
]


@pytest.mark.parametrize("override, field, hint", OVERRIDES, ids=[c[0] for c in OVERRIDES])
def test_unknown_keys_and_values_of_overrides(override, field, hint, tmp_path, capsys):
    status, _, err = run_cli(["run", "tianqin-kepler", "-q", "-o", str(tmp_path / "x.h5"), "--set", override], capsys)
    _line(status, err, tmp_path, field, f"'{hint}'")
    assert not (tmp_path / "x.h5").exists()


def _sweep(tmp_path, text):
    path = tmp_path / "s.toml"
    path.write_text(text, encoding="utf-8")
    return ["sweep", str(path), "--dry-run"]


_P = '[[sweep.parameter]]\nkey = "satellites.1.e"\nvalues = [0.0, 0.001]\n'
#: Command lines with an unknown command, option, choice or name: (argv, words, suggestion).
COMMANDS = [
    (lambda d: ["rnu"], ["rnu"], "run"),
    (lambda d: ["run", "--precison", "dd"], ["--precison"], "--precision"),
    (lambda d: ["run", "--precision", "float46"], ["--precision", "float46"], "float64"),
    (lambda d: ["run", "tianqin-keplr", "-o", str(d / "x.h5")], ["scenario", "tianqin-keplr"], "tianqin-kepler"),
    (lambda d: ["bench", "--model", "kepplr"], ["--model", "kepplr"], "kepler"),
    (lambda d: ["export", str(d / "x.h5"), str(d / "y.h5"), "--format", "lisa-injectoin"],
     ["--format", "lisa-injectoin"], "lisa-injection"),
    (lambda d: ["export", str(d / "x.h5"), str(d / "y.h5"), "--frame", "gcsr"], ["--frame", "gcsr"], "gcrs"),
    (lambda d: ["export", str(d / "x.h5"), str(d / "y.h5"), "--time-origin", "j200"], ["--time-origin"], "j2000"),
    (lambda d: ["report", str(d / "x.h5"), "--mission", "lisaa"], ["--mission", "lisaa"], "lisa"),
    (lambda d: ["report", "--studies", "--study", "pointng", "--out", str(d / "r")], ["study", "pointng"],
     "pointing"),
    (lambda d: ["od", "simulat"], ["simulat"], "simulate"),
    (lambda d: ["od", "covariance", "tianqin-kepler", "--tracking", "gnss,slrr", "--arc", "1d"],
     ["--tracking", "slrr"], "slr"),
    (lambda d: ["od", "covariance", "tianqin-kepler", "--tracking", "slr", "--arc", "1d", "--estimate", "stat"],
     ["tracking.estimate", "stat"], "state"),
    (lambda d: ["od", "covariance", "tianqin-kepler", "--tracking", "slr", "--arc", "1d", "--stations", "Gratz"],
     ["tracking.stations", "Gratz"], "Graz"),
    (lambda d: ["od", "simulate", str(d / "x.h5"), "--tracking", "slr", "--arc", "1d", "-o", str(d / "m.tdm"),
                "--bias", "slr_rnage=1"], ["--bias", "slr_rnage"], "slr_range"),
    (lambda d: _sweep(d, '[sweep]\nscenaro = "tianqin-kepler"\n' + _P), ["sweep.scenaro"], "scenario"),
    (lambda d: _sweep(d, '[sweep]\nmode = "zipp"\n' + _P), ["sweep.mode", "zipp"], "zip"),
    (lambda d: _sweep(d, '[sweep]\n[[sweep.parameter]]\nkey = "satellites.1.e"\nvaleus = [0.0]\n'),
     ["sweep.parameter.1.valeus"], "values"),
    (lambda d: _sweep(d, '[sweep]\nscenario = "tianqin-kepler"\n[[sweep.parameter]]\nkey = "forces.gm_mon"\n'
                         'values = [1, 2]\n'), ["forces.gm_mon"], "gm_moon"),
    (lambda d: _sweep(d, '[sweep]\nscenario = "tianqin-keplr"\n' + _P), ["sweep.scenario"], "tianqin-kepler"),
]


@pytest.mark.parametrize("argv, words, hint", COMMANDS, ids=[" ".join(c[1]) for c in COMMANDS])
def test_unknown_commands_options_and_names(argv, words, hint, tmp_path, capsys):
    (tmp_path / "x.h5").write_bytes(b"not used: refused before it is read")
    status, _, err = run_cli(argv(tmp_path), capsys)
    _line(status, err, tmp_path, *words, f"'{hint}'")
    assert not (tmp_path / "y.h5").exists() and not (tmp_path / "m.tdm").exists()


def test_an_unknown_forces_key_was_520_characters_and_is_one_short_line(tmp_path, capsys):
    """The line of issue 33 (all 31 [forces] keys, 520 characters): now the closest key and the page."""
    status, _, err = run_cli(["run", "tianqin-kepler", "--set", "forces.gm_mon=1", "-o", str(tmp_path / "x.h5")],
                             capsys)
    line = _line(status, err, tmp_path, "'gm_moon'", "docs/scenarios.md#forces")
    assert "earth_monopole" not in line and len(line) < 160, line


# ------------------------------------------------------------------ where the lists are documented

_DOC = re.compile(r"docs/([\w.-]+\.md)#([\w-]+)")


def _slugs(page: pathlib.Path) -> dict[str, str]:
    """GitHub's anchors of a page's headings -> the text up to the next heading of the same or a higher level."""
    lines = page.read_text(encoding="utf-8").split("\n")
    heads, fence = [], False
    for i, ln in enumerate(lines):
        fence ^= ln.startswith("```")
        m = None if fence else re.match(r"^(#{1,6}) (.*)$", ln)
        if m:
            heads.append((i, len(m[1]), re.sub(r"[^\w\- ]", "", m[2].strip().lower()).replace(" ", "-")))
    out = {}
    for k, (i, level, slug) in enumerate(heads):
        end = next((j for j, lv, _ in heads[k + 1:] if lv <= level), len(lines))
        out[slug] = "\n".join(lines[i:end])
    return out


def test_every_page_and_anchor_named_in_a_message_exists():
    """Every "docs/<page>.md#<anchor>" written in the source is a page of docs/ with that heading."""
    named = {m.groups() for p in SRC.rglob("*.py") for m in _DOC.finditer(p.read_text(encoding="utf-8"))}
    named |= {("scenarios.md", t or "keys") for t in list(_SCHEMA) + ["satellites", "closed_loop", ""]}
    assert len(named) >= 15
    missing = [f"{page}#{anchor}" for page, anchor in sorted(named)
               if anchor not in _slugs(ROOT / "docs" / page)]
    assert not missing, missing


def test_the_keys_section_lists_every_key_and_name():
    """docs/scenarios.md#<table> lists every key of the table (and #closed_loop the loops and sources,
    #forces the bodies), so that the page a message names holds the full list."""
    from tqdyn.scenario.config import THIRD_BODIES

    pages = _slugs(ROOT / "docs" / "scenarios.md")
    tables = {**{t: keys for t, keys in _SCHEMA.items()}, "satellites": _SAT_SCHEMA,
              "closed_loop": (*cl.CLOSED_LOOP_KEYS, *cl.PLANT_KEYS, *{k for loops in cl.SCHEME_LOOPS.values() for k in loops}, *cl.SOURCES),
              "keys": _TOP_KEYS}
    tables["forces"] = (*tables["forces"], *THIRD_BODIES)
    missing = [f"{t}: {k}" for t, keys in tables.items() for k in keys
               if (f"`{k}`" if t != "keys" else f"[{k}]") not in pages[t]]
    assert not missing, missing


def test_the_pages_a_message_names_list_the_names():
    """The sections that messages of long lists point to hold every name of the list."""
    from tqdyn.cli.bench import MODELS
    from tqdyn.formats.trajectory.schema import FIELDS, FIELDS_DOC
    from tqdyn.formats.ttl import ATTRS_DOC, TQDYN_ATTRS
    from tqdyn.od.measurements_dsn import DEEP_SPACE_STATIONS
    from tqdyn.od.measurements_slr import ILRS_STATIONS
    from tqdyn.od.tracking import STATIONS_DOC
    from tqdyn.workflows import studies, studies_lisa
    from tqdyn.workflows.sweep.spec import _DOC as SWEEP_DOC, _PARAM_KEYS, _SWEEP_KEYS

    lists = {studies.STUDIES_DOC: [*studies.STUDIES, *studies_lisa.STUDIES], "docs/commands.md#tqdyn-bench":
             [*MODELS, "all"], FIELDS_DOC: list(FIELDS), STATIONS_DOC: [*ILRS_STATIONS, *DEEP_SPACE_STATIONS],
             SWEEP_DOC: [*_SWEEP_KEYS, *_PARAM_KEYS], ATTRS_DOC: list(TQDYN_ATTRS)}
    missing = []
    for doc, names in lists.items():
        page, anchor = _DOC.fullmatch(doc).groups()
        section = _slugs(ROOT / "docs" / page)[anchor]
        missing += [f"{doc}: {n}" for n in names if n not in section]
    assert not missing, missing


def test_the_bound_is_the_documented_one():
    """The bound the checks use is the one docs/reliability.md promises."""
    text = (ROOT / "docs" / "reliability.md").read_text(encoding="utf-8")
    assert MAX_ERROR_LINE == 200 and "200 characters" in text
