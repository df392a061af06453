"""The fault-classes table of docs/reliability.md, walked cell by cell (issue 34, items 1, 2 and 5).

Reference: the table itself (parsed from docs/reliability.md, "Fault classes"): for every command and
every fault it gives the exit status; the promise around it (docs/reliability.md) is exactly one
`tqdyn: error:` line on stderr, the last one, no traceback, no file left behind (no output, no hidden
temporary file) and the inputs unchanged.  Each cell runs the command in a real child process
(tests/fault_server.py: a fork server that has imported the command line, so a child costs its work,
not the imports) under the fault:

* bad input: one representative refusal of the command;
* SIGINT / SIGTERM: sent while the command is at work (SIGINT to the child's process group, as Ctrl-C
  in a terminal; SIGTERM to the child, as kill) -- the child waits inside the command (the rename
  of its output into place, with the temporary file written; the run's first block of rows; the
  closed loop's budget, its temporary file open; the report's first figure) until the signal is sent;
* full disk: a file-size limit of 1 kB (RLIMIT_FSIZE, SIGXFSZ ignored: writes fail with EFBIG, as on a
  full disk); a real small file system (a 64 kB tmpfs) in :func:`test_full_small_file_system`;
* corrupted input: the input cut to half its length;
* output = input: the output path is a hard link or a symbolic link to an input.

The commands on a local Dask cluster (`od campaign`, `closed-loop --monte-carlo`, one worker) get their
signals once their tasks are submitted; the worker processes alive then (psutil) must have ended with
the command, and a stopped campaign keeps only the result files of its finished members.

The inputs are built once per module: a 3 h tianqin-kepler run, a 2 h coupled tianqin run, its
closed-loop file (60 s at 4 Hz), a TDM, a sweep with its member done; the campaign's member is run
once in this process (the workers load its kernels from the cache) and the fork server runs the Monte
Carlo's H-infinity synthesis once (its children inherit it).
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SRC = str(ROOT / "src")
SERVER = str(Path(__file__).resolve().parent / "fault_server.py")
FAULTS = ("bad input", "SIGINT", "SIGTERM", "full disk", "corrupted input", "output = input")
#: the file-size limit of the full-disk cells [bytes]
LIMIT = 1024
#: the campaign of the `od campaign` cells: one seed, on one worker (tqdyn.workflows.od_campaign.plan_campaign)
CAMPAIGN = {"tracking": ["isr,slr"], "arc": ["3h"], "interval": "1800", "seeds": "1", "estimate": "state",
            "a_priori": ["state=1000,0.1"]}


def fault_table() -> dict:
    """{command: {fault: status or None ("-": does not apply)}} of docs/reliability.md, "Fault classes"."""
    text = (ROOT / "docs" / "reliability.md").read_text(encoding="utf-8")
    section = text.split("## Fault classes", 1)[1]
    start = section.index("\n|") + 1
    rows = section[start:section.index("\n\n", start)].splitlines()  # the first table of the section
    head = [c.strip() for c in rows[0].strip("|").split("|")]
    assert tuple(head[1:]) == FAULTS, head
    table = {}
    for ln in rows[2:]:
        cells = [c.strip() for c in ln.strip("|").split("|")]
        command = cells[0].strip("`").removeprefix("tqdyn ").strip()
        table[command] = {f: (int(c) if c.isdigit() else None) for f, c in zip(FAULTS, cells[1:])}
    return table


TABLE = fault_table()


# --------------------------------------------------------------------------- the fork server


class Server:
    """The client of tests/fault_server.py: one child at a time."""

    def __init__(self):
        self.children = []
        env = dict(os.environ, PYTHONPATH=SRC, MPLBACKEND="Agg")
        self.p = subprocess.Popen([sys.executable, SERVER], stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=env,
                                  bufsize=0)
        self.fd = self.p.stdout.fileno()
        assert self._line() == {"ready": True}

    def _line(self, wait=None):
        """The server's next answer (None if none within ``wait`` seconds)."""
        buf = b""
        while not buf.endswith(b"\n"):
            if wait is not None and not buf and not select.select([self.fd], [], [], wait)[0]:
                return None
            chunk = os.read(self.fd, 1)
            assert chunk, "the fault server ended"
            buf += chunk
        return json.loads(buf)

    def run(self, argv, cwd, *, limit=None, block=None, sig=None):
        """Run ``tqdyn ARGV`` in ``cwd``; with ``block`` (target, only under ``cwd``) send ``sig`` once
        the child waits there (SIGINT to its process group, as Ctrl-C; another signal to the child).
        Returns (status, stdout, stderr); stdout is not kept under a limit (the
        limit is for the command's files).  ``self.children``: the child's own child processes (a local
        Dask cluster's workers) when the signal was sent."""
        side = Path(cwd).parent / Path(cwd).name
        out, err = Path(f"{side}.out"), Path(f"{side}.err")
        req = {"argv": [str(a) for a in argv], "cwd": str(cwd), "stderr": str(err), "limit": limit, "block": None,
               "stdout": os.devnull if limit is not None else str(out)}
        if block is not None:
            ready, go = Path(f"{side}.ready"), Path(f"{side}.go")
            req["block"] = {"target": block[0], "under": str(cwd) if block[1] else None, "ready": str(ready),
                            "go": str(go)}
        os.write(self.p.stdin.fileno(), (json.dumps(req) + "\n").encode())
        pid = self._line()["pid"]
        answer = None
        if block is not None:
            t0 = time.monotonic()
            while not ready.exists():
                answer = self._line(wait=0.01)
                if answer is not None:  # the child ended before it got there
                    break
                assert time.monotonic() - t0 < 300, f"{argv}: never reached {block[0]}"
            else:
                self.children = _descendants(pid)
                # Ctrl-C in a terminal reaches the whole foreground process group (the child and its own
                # children, e.g. Dask workers); SIGTERM (kill, a batch scheduler) the process
                (os.killpg if sig == signal.SIGINT else os.kill)(pid, sig)
                go.touch()
        status = (answer or self._line())["status"]
        return status, out.read_text() if out.exists() else "", err.read_text()

    def close(self):
        self.p.stdin.close()
        self.p.wait(timeout=60)


# --------------------------------------------------------------------------- inputs


@pytest.fixture(scope="module")
def fx(tmp_path_factory):
    """The inputs (built in this process, which also fills the kernel cache) and the server."""
    import contextlib
    import io

    import tqdyn
    from tqdyn import cli
    from tqdyn.scenario import load_scenario
    from tqdyn.workflows import od_campaign
    from tqdyn.workflows.run import run_scenario_text
    from tqdyn.workflows.sweep import plan_sweep

    d = tmp_path_factory.mktemp("fault-inputs")

    def tqdyn_cli(*argv):
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()) as err:
            try:
                status = cli.main([str(a) for a in argv])
            except SystemExit as exc:
                status = exc.code
        assert status in (0, None), err.getvalue()

    tqdyn.run("tianqin-kepler", {"run.duration": "3h", "integrator.step": 600}, output=str(d / "kep.h5"))
    tqdyn.run("tianqin", {"run.duration": "2h", "integrator.step": 600}, output=str(d / "tq.h5"))
    tqdyn_cli("closed-loop", d / "tq.h5", "-o", d / "cl.h5", "--duration", "60", "--fs", "4", "--set",
              "closed_loop.n_freq=8", "-q")
    tqdyn_cli("od", "simulate", d / "kep.h5", "--tracking", "isr,slr", "--arc", "3h", "--interval", "1800", "-o",
              d / "m.tdm", "-q")
    (d / "scen.toml").write_text(load_scenario("tianqin-kepler").to_toml(), encoding="utf-8")
    # the campaign's member, run here once: its kernels are in the cache the cells' Dask workers load
    spec = od_campaign.plan_campaign("recovery", "tianqin-kepler", output=tmp_path_factory.mktemp("warm") / "c.nc",
                                     **CAMPAIGN)
    spec.parts.mkdir()
    assert od_campaign.run_member(json.dumps({"job": spec.members[0].job, "path": str(spec.members[0].path)}))["ok"]
    (d / "sw").mkdir()
    sweep = ('[sweep]\nname = "one"\nscenario = "tianqin-kepler"\noutput_dir = "sw"\n'
             'set = ["run.duration=1h", "integrator.step=600"]\n\n'
             '[[sweep.parameter]]\nkey = "satellites.1.a_km"\nvalues = [100000.0]\n')
    (d / "sw.toml").write_text(sweep, encoding="utf-8")
    member = plan_sweep(d / "sw.toml").members[0]
    run_scenario_text(member.scenario_toml, source="test")
    (d / "rec.json").write_text(json.dumps({"written_by": "tqdyn bench", "models": {}}, indent=1))
    for name in ("kep.h5", "tq.h5", "cl.h5", "m.tdm", "scen.toml", "sw.toml", "rec.json"):
        data = (d / name).read_bytes()
        stem, ext = name.split(".")
        (d / f"{stem}-cut.{ext}").write_bytes(data[: len(data) // 2])
    server = Server()
    fx = {"dir": d, "server": server, "member": member.path.name, "sweep": sweep,
          **{p.name.replace(".", "_").replace("-", "_"): p for p in d.iterdir()}}
    before = _digests(d)
    yield fx
    server.close()
    assert _digests(d) == before, "an input changed"


def _descendants(pid: int) -> list:
    """The processes started by ``pid`` and by them (psutil)."""
    import psutil

    try:
        return psutil.Process(pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []


def _survivors(procs, wait: float = 5.0) -> list:
    """Those of ``procs`` (psutil processes) still running (not zombies) ``wait`` seconds on."""
    import psutil

    t0 = time.monotonic()
    while True:
        alive = []
        for p in procs:
            try:
                if p.is_running() and p.status() != psutil.STATUS_ZOMBIE:
                    alive.append(p)
            except psutil.NoSuchProcess:
                pass
        if not alive or time.monotonic() - t0 > wait:
            return alive
        time.sleep(0.1)


def _digests(d: Path) -> dict:
    return {str(p.relative_to(d)): hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(d.rglob("*"))
            if p.is_file()}


def _link(src: Path, dst: Path, symbolic: bool = False) -> Path:
    (os.symlink if symbolic else os.link)(src, dst)
    return dst


# --------------------------------------------------------------------------- the commands


def _sweep_cell(fx, cell, text=None):
    """A sweep file in ``cell`` whose member is done (a hard link to the fixture's member file)."""
    (cell / "sw").mkdir()
    _link(fx["dir"] / "sw" / fx["member"], cell / "sw" / fx["member"])
    (cell / "sw.toml").write_text(text or fx["sweep"], encoding="utf-8")
    return cell / "sw.toml"


def _case(command: str, fx, cell: Path) -> dict:
    """The arguments of ``command`` in the cell directory ``cell``: "good" (the command at work,
    its outputs in ``cell``), "bad", "corrupt", "same" (output = input), and "block": where a
    signal finds it at work ((target, only under the cell), as tests/fault_server.py takes it)."""
    kep, tq, cl, tdm, scen = fx["kep_h5"], fx["tq_h5"], fx["cl_h5"], fx["m_tdm"], fx["scen_toml"]
    replace = ("os:replace", True)
    if command == "run":
        good = ["run", "tianqin-kepler", "--duration", "1d", "--step", "600", "--checkpoint-every", "0", "-q",
                "-o", cell / "r.h5"]
        return {"good": good, "bad": good[:3] + ["-1d"] + good[4:], "corrupt": ["run", fx["scen_cut_toml"], "-o",
                cell / "r.h5"], "same": lambda: ["run", scen, "-q", "-o", _link(scen, cell / "s.h5")],
                "block": ("tqdyn.formats.trajectory.writer:TrajectoryWriter.append", False)}
    if command == "forces --plot":
        good = ["forces", "tianqin-kepler", "--duration", "1h", "--plot", cell / "f.png"]
        return {"good": good, "bad": good + ["--every", "nan"],
                "corrupt": ["forces", fx["scen_cut_toml"], "--plot", cell / "f.png"],
                "same": lambda: ["forces", scen, "--duration", "1h", "--plot",
                                 _link(scen, cell / "f.png", symbolic=True)],
                "block": replace}
    if command.startswith("export --format "):
        fmt = command.split()[-1]
        src, out = (cl, cell / "x.h5") if fmt in ("ttl", "lisa-injection") else (kep, cell / "x.h5")
        extra = ["--run", tq] if fmt == "lisa-injection" else []
        if fmt == "oem":
            out = cell / "x.oem"
        good = ["export", src, "--format", fmt, out, *extra]
        cut = fx["cl_cut_h5"] if src == cl else fx["kep_cut_h5"]
        bad = {"lisa": good + ["--step", "1"], "oem": good[:3] + [fmt, cell / "x.txt"],
               "ttl": good + ["--drift", "nan"], "lisa-injection": good[:5]}[fmt]

        def same():
            link = (_link(kep, cell / "x-Sat1.oem") if fmt == "oem" else
                    _link(tq, cell / "run.h5") if fmt == "lisa-injection" else _link(src, cell / "in.h5"))
            return good[:4] + [cell / "x.oem" if fmt == "oem" else link, *extra]

        return {"good": good, "bad": bad, "corrupt": [good[0], cut] + good[2:], "same": same, "block": replace}
    if command == "closed-loop":
        good = ["closed-loop", tq, "-o", cell / "c.h5", "--duration", "60", "--fs", "4", "--set",
                "closed_loop.n_freq=8", "-q"]
        return {"good": good, "bad": good + ["--fs", "0"], "corrupt": [good[0], fx["tq_cut_h5"]] + good[2:],
                "same": lambda: good[:3] + [_link(tq, cell / "run.h5")] + good[4:],
                "block": ("tqdyn.analysis.closed_loop:closed_loop_budget", False)}
    if command == "od simulate":
        good = ["od", "simulate", kep, "--tracking", "isr,slr", "--arc", "3h", "--interval", "1800", "-q", "-o",
                cell / "m.tdm"]
        return {"good": good, "bad": good[:4] + ["radar"] + good[5:],
                "corrupt": good[:2] + [fx["kep_cut_h5"]] + good[3:],
                "same": lambda: good[:-1] + [_link(kep, cell / "run.h5")], "block": replace}
    if command == "od fit":
        good = ["od", "fit", kep, tdm, "--estimate", "state", "--a-priori", "state=1000,0.1", "-q", "-o", cell / "e.h5"]
        return {"good": good, "bad": good + ["--edit-sigma", "-1"], "corrupt": good[:3] + [fx["m_cut_tdm"]] + good[4:],
                "same": lambda: good[:-1] + [_link(tdm, cell / "m.h5")], "block": replace}
    if command == "od covariance --json":
        good = ["od", "covariance", kep, "--tracking", "slr,isr", "--arc", "3h", "--interval", "1800", "--estimate",
                "state", "--a-priori", "state=1000,0.1", "-q", "--json", cell / "c.json"]
        return {"good": good, "bad": good[:6] + ["0"] + good[7:], "corrupt": good[:2] + [fx["kep_cut_h5"]] + good[3:],
                "same": lambda: good[:-1] + [_link(kep, cell / "c.json")], "block": replace}
    if command == "report":
        good = ["report", kep, "--out", cell / "rep", "-q"]
        return {"good": good, "bad": ["report", "--out", cell / "rep"], "corrupt": ["report", fx["kep_cut_h5"], "--out",
                cell / "rep"], "same": lambda: ["report", _link(kep, cell / "summary.json"), "--out", cell],
                "block": ("matplotlib.figure:Figure.savefig", False)}
    if command == "sweep":
        sweep = ["sweep", _sweep_cell(fx, cell), "--dashboard", "off", "-q"]

        def bad():
            (cell / "bad.toml").write_text(fx["sweep"].replace("[sweep]\n", "[sweep]\nworkers = 2\n"))
            return ["sweep", cell / "bad.toml"]

        def corrupt():
            (cell / "cut.toml").write_bytes(fx["sw_cut_toml"].read_bytes())
            return ["sweep", cell / "cut.toml"]

        def same():  # the sweep file is <output_dir>/<name>.nc
            (cell / "sw" / "one.nc").write_text(fx["sweep"].replace('output_dir = "sw"', 'output_dir = "."'))
            return ["sweep", cell / "sw" / "one.nc"]

        return {"good": sweep, "bad": bad, "corrupt": corrupt, "same": same, "block": replace}
    if command == "bench --json":
        good = ["bench", "--model", "kepler", "--duration", "1h", "--step", "600", "--no-heyoka", "--json",
                cell / "rec.json"]
        return {"good": good, "bad": good[:3] + ["--duration", "-1"] + good[5:],
                "corrupt": good[:-1] + [fx["rec_cut_json"]], "same": None, "block": replace}
    if command == "od campaign":
        good = ["od", "campaign", "recovery", "tianqin-kepler", "--tracking", CAMPAIGN["tracking"][0], "--arc",
                CAMPAIGN["arc"][0], "--interval", CAMPAIGN["interval"], "--seeds", CAMPAIGN["seeds"], "--estimate",
                CAMPAIGN["estimate"], "--a-priori", CAMPAIGN["a_priori"][0], "--workers", "1", "-q", "-o",
                cell / "c.nc"]
        return {"good": good, "bad": good[:11] + ["0"] + good[12:],
                "corrupt": good[:3] + [fx["scen_cut_toml"]] + good[4:],
                "same": lambda: good[:3] + [scen] + good[4:-1] + [_link(scen, cell / "c.nc")],
                "block": ("distributed:as_completed", False)}
    if command == "closed-loop --monte-carlo":
        good = ["closed-loop", "--mission", "tianqin", "--monte-carlo", "1", "--workers", "1", "-q", "-o",
                cell / "mc.nc"]
        return {"good": good, "bad": good[:4] + ["0"] + good[5:], "corrupt": None, "same": None,
                "block": ("distributed:as_completed", False)}
    raise AssertionError(f"no case for {command!r}")


CELLS = [(c, f) for c in TABLE for f in FAULTS]
#: the rows whose command runs on a local Dask cluster: a signal must also end its worker processes
DASK = ("od campaign", "closed-loop --monte-carlo")
_SIGNALS = {"SIGINT": signal.SIGINT, "SIGTERM": signal.SIGTERM}


def _listing(d: Path) -> dict:
    return {str(p.relative_to(d)): (p.is_symlink() or p.stat().st_ino) for p in sorted(d.rglob("*"))}


@pytest.mark.parametrize("command, fault", CELLS, ids=[f"{c}|{f}" for c, f in CELLS])
def test_fault_table_cell(fx, tmp_path, command, fault):
    """One cell: the status of the table, one `tqdyn: error:` line (the last), no traceback, the cell's
    directory as before (no output, no temporary file), the inputs unchanged (checked at the end)."""
    expected = TABLE[command][fault]
    cell = tmp_path / "cell"
    cell.mkdir()
    case = _case(command, fx, cell)
    key = {"bad input": "bad", "corrupted input": "corrupt", "output = input": "same"}.get(fault, "good")
    if expected is None:
        assert case[key] is None, f"{command}: {fault} applies but the table says '-'"
        return
    argv = case[key]() if callable(case[key]) else case[key]
    before = _listing(cell)
    server = fx["server"]
    if fault in _SIGNALS:
        status, out, err = server.run(case["good"], cell, block=case["block"], sig=_SIGNALS[fault])
    elif fault == "full disk":
        status, out, err = server.run(case["good"], cell, limit=LIMIT)
    else:
        status, out, err = server.run(argv, cell)
    lines = err.splitlines()
    assert status == expected, f"{command} under {fault}: status {status}\n{err}"
    assert "Traceback" not in err and "Exception ignored" not in err, err
    errors = [ln for ln in lines if ln.startswith("tqdyn: error:")]
    assert len(errors) == 1 and lines[-1] == errors[0] and len(errors[0]) <= 400, err
    if fault in _SIGNALS:
        assert ("interrupted" if fault == "SIGINT" else "stopped by SIGTERM") in errors[0], errors[0]
        if command in DASK:  # the signal found the local cluster's workers at work; none outlives the command
            assert server.children, f"{command}: no worker process when the signal was sent"
            assert not _survivors(server.children), _survivors(server.children)
    if fault == "full disk":
        assert re.search(r"File too large|needs at least", errors[0]), errors[0]
    if fault == "output = input":
        assert "is the input" in errors[0] or "would replace the input" in errors[0] or "which is the" in errors[0]
    after = _listing(cell)
    if command == "od campaign" and fault in _SIGNALS:  # kept on purpose: the members that finished
        after = {k: v for k, v in after.items() if k not in _finished_members(cell)}
    assert after == before, f"left behind: {set(after) - set(before)}"


def _finished_members(cell: Path, seeds: str = CAMPAIGN["seeds"]) -> set:
    """What a stopped `od campaign` of the cell keeps on purpose (docs/reliability.md): the result files of
    its finished members, each holding its member's job (CampaignSpec.done), and their directory."""
    from tqdyn.workflows import od_campaign

    spec = od_campaign.plan_campaign("recovery", "tianqin-kepler", output=cell / "c.nc", **dict(CAMPAIGN, seeds=seeds))
    done = {str(m.path.relative_to(cell)) for m in spec.members if spec.done(m)}
    return done | ({"c.nc.parts"} if done else set())


def test_commands_md_gives_the_same_table():
    """docs/commands.md ("Exit status and errors") holds the same table as docs/reliability.md."""
    def table(name):
        text = (ROOT / "docs" / name).read_text(encoding="utf-8")
        i = text.index("| command | bad input |")
        return text[i:text.index("\n\n", i)]

    assert table("commands.md") == table("reliability.md")


def test_the_table_lists_every_writing_command():
    """Every command that writes a file is a row (tqdyn info writes nothing)."""
    from tqdyn.cli import cli
    from tqdyn.cli.export import FORMATS

    commands = set(cli.commands) - {"info", "export", "od", "forces", "bench"}
    rows = set(TABLE)
    assert {f"export --format {f}" for f in FORMATS} <= rows
    assert {"od simulate", "od fit", "od covariance --json", "od campaign", "forces --plot", "bench --json",
            "closed-loop --monte-carlo"} <= rows
    assert commands <= rows, commands - rows


# --------------------------------------------------------------------------- a real small file system


@pytest.fixture
def small_fs(tmp_path):
    """A 64 kB tmpfs mounted on a fresh directory (root only; skipped where mounting is not allowed)."""
    mnt = tmp_path / "small"
    mnt.mkdir()
    try:
        subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(mnt)], check=True,
                       capture_output=True, timeout=30)
    except (OSError, subprocess.SubprocessError) as exc:
        pytest.skip(f"cannot mount a tmpfs here ({exc})")
    yield mnt
    subprocess.run(["umount", str(mnt)], check=False, capture_output=True, timeout=30)


def test_full_small_file_system(fx, small_fs):
    """On a 64 kB file system the outputs larger than it (a trajectory, a closed-loop file, a TTL
    file, an estimate file, a report) end with status 3 and one line naming the cause
    (ENOSPC, or the closed loop's size refused before its work), and the file system is left empty."""
    kep, tq, cl = fx["kep_h5"], fx["tq_h5"], fx["cl_h5"]
    cases = [["run", "tianqin-kepler", "--duration", "1d", "--step", "600", "-q", "-o", small_fs / "r.h5"],
             ["closed-loop", tq, "-o", small_fs / "c.h5", "--duration", "60", "--fs", "4", "-q"],
             ["export", cl, "--format", "ttl", small_fs / "t.h5", "--step", "0.01", "--drift", "lpf"],
             ["od", "fit", kep, fx["m_tdm"], "--estimate", "state", "--a-priori", "state=1000,0.1", "-q", "-o",
              small_fs / "e.h5"],
             ["report", kep, "--out", small_fs / "rep", "-q"]]
    work = small_fs.parent / "work"
    work.mkdir()
    for argv in cases:
        status, _, err = fx["server"].run(argv, work)
        lines = err.splitlines()
        assert status == 3, f"{argv[0]}: {err}"
        assert lines[-1].startswith("tqdyn: error:") and sum(ln.startswith("tqdyn: error:") for ln in lines) == 1
        assert "No space left on device" in lines[-1] or "are free there" in lines[-1], lines[-1]
        assert "Traceback" not in err
        assert sorted(os.listdir(small_fs)) == [], os.listdir(small_fs)


# --------------------------------------------------------------------------- item 5: memory and size


@pytest.mark.parametrize("argv, field", [
    (["export", "{cl}", "--format", "ttl", "{cell}/t.h5", "--step", "1e-9"], "--step >= "),
    (["closed-loop", "{tq}", "-o", "{cell}/c.h5", "--set", "closed_loop.n_freq=1000000000", "-q"],
     "closed_loop.n_freq <= "),
], ids=["ttl-step", "closed-loop-n_freq"])
def test_memory_refused_before_work(fx, tmp_path, argv, field):
    """An export or a closed loop that would not fit in memory is refused at once: status 2, one line
    naming the size (the estimate: samples x bytes per sample measured, module docstrings) and the
    option that bounds it with its bound; nothing written."""
    argv = [a.format(cl=fx["cl_h5"], tq=fx["tq_h5"], cell=tmp_path) for a in argv]
    status, _, err = fx["server"].run(argv, tmp_path)
    line = err.splitlines()[-1]
    assert status == 2 and line.startswith("tqdyn: error:") and "of memory, over 50% of the" in line, err
    assert field in line, line
    assert os.listdir(tmp_path) == []


def test_injection_memory_and_closed_loop_disk_refused(fx, tmp_path, monkeypatch, capsys):
    """The injection export estimates its memory from the closed-loop file's samples (1 kB each,
    export_injection.BYTES_PER_SAMPLE; in process, with the available memory made 400 kB: the 240
    samples need 246 kB, more than half of it) and names the closed loop's --duration / --fs; a closed
    loop whose time series would not fit on the disk is refused before its work with status 3, naming
    --duration and --fs."""
    from cli_support import run_cli
    from tqdyn.workflows import memory

    monkeypatch.setattr(memory, "available_memory", lambda: 400_000)
    status, _, err = run_cli(["export", str(fx["cl_h5"]), "--format", "lisa-injection", str(tmp_path / "i.h5"),
                              "--run", str(fx["tq_h5"])], capsys)
    assert status == 2 and err.count("\n") == 1, err
    assert "240 samples needs ~246 kB of memory" in err and "(closed-loop --duration, --fs)" in err, err
    monkeypatch.undo()
    status, _, err = fx["server"].run(["closed-loop", fx["tq_h5"], "-o", tmp_path / "c.h5", "--duration", "1e9",
                                       "-q"], tmp_path)
    line = err.splitlines()[-1]
    assert status == 3 and "needs at least" in line and "--duration" in line and "--fs" in line, err
    assert os.listdir(tmp_path) == []


# --------------------------------------------------------------------------- a stopped campaign resumes


@pytest.mark.slow
def test_campaign_resumes_after_sigterm(fx, tmp_path):
    """`tqdyn od campaign` of two seeds on one worker gets SIGTERM once the first member's result is back
    (the worker is then at the second): exit 143, one line, the result files of the finished members kept
    in c.nc.parts -- the first, and the second if it finished while the cluster closed -- and nothing else
    (no c.nc, no temporary file), no worker process left.  The same command
    again runs the second member only and writes the dataset of the same campaign run uninterrupted (the
    reference: that run in another directory): every variable but the members' wall times equal, bit for
    bit, and the same attributes."""
    from tqdyn.workflows.sweep import read_sweep_netcdf

    server = fx["server"]
    cells = {}
    for name in ("stopped", "reference"):
        cells[name] = tmp_path / name
        cells[name].mkdir()
    argv = {k: _case("od campaign", fx, c)["good"] for k, c in cells.items()}
    for a in argv.values():
        a[a.index("--seeds") + 1] = "2"
    cell = cells["stopped"]
    status, _, err = server.run(argv["stopped"], cell, block=("tqdyn.workflows.sweep.execute:_lost_counts", False),
                                sig=signal.SIGTERM)
    lines = err.splitlines()
    assert status == 143 and lines[-1].startswith("tqdyn: error: stopped by SIGTERM"), err
    assert sum(ln.startswith("tqdyn: error:") for ln in lines) == 1 and "Traceback" not in err, err
    assert server.children and not _survivors(server.children)
    kept = set(_listing(cell))
    assert kept == _finished_members(cell, "2") and len(kept) >= 2, kept  # the first member at least
    done = len(kept) - 1
    status, out, err = server.run(argv["stopped"], cell)
    assert status == 0 and f"2 members: {done} already done, {2 - done} ran, 0 failed" in out, err
    status, _, err = server.run(argv["reference"], cells["reference"])
    assert status == 0, err
    resumed, ref = (read_sweep_netcdf(c / "c.nc") for c in (cell, cells["reference"]))
    assert set(resumed.data_vars) == set(ref.data_vars) and resumed.attrs == ref.attrs
    for var in set(ref.data_vars) - {"wall_s"}:
        assert resumed[var].equals(ref[var]), var
