"""The closed loop's tilt-to-length through LISA Instrument 2.3 and PyTDI 2.2 (docs/lisa-ttl.md).

:func:`make_files` runs the command chain (``tqdyn run`` -> ``tqdyn closed-loop`` -> ``tqdyn export
--format lisa`` -> ``tqdyn export --format lisa-injection``) on a short TianQin run; :func:`simulate`
runs LISA Instrument on the orbit file with or without the injection file and forms X2 with PyTDI.
Shared by the recipe of docs/lisa-ttl.md and tests/test_lisa_injection.py.
"""

from __future__ import annotations

import pathlib
import subprocess
import sys
import warnings

import numpy as np

LINKS = ("12", "23", "31", "13", "32", "21")
LTT = 0.578          # s: TianQin's light travel time (delay_isc_min/max = 0.5, 1.5 times it)
_CLI = "import sys; from tqdyn.cli import main; sys.exit(main(sys.argv[1:]))"


def tqdyn_cli(*argv, cwd="."):
    """Run ``tqdyn ARGV`` (this Python's tqdyn) in ``cwd``; returns its stdout."""
    p = subprocess.run([sys.executable, "-c", _CLI, *map(str, argv)], cwd=cwd, check=True, capture_output=True,
                       text=True)
    return p.stdout


def make_files(directory, duration: float = 1800.0, fs: float = 4.0, coefficients: str = "worst-case",
               seed: int | None = None) -> dict:
    """The four files of the chain in ``directory``: {"run", "closed_loop", "orbits", "injection"}."""
    d = pathlib.Path(directory)
    tqdyn_cli("run", "tianqin", "--duration", "2h", "--step", "600", "-q", "-o", "tq.h5", cwd=d)
    tqdyn_cli("closed-loop", "tq.h5", "-o", "cl.h5", "--duration", duration, "--fs", fs, "--seed", "1",
              "--set", "closed_loop.n_freq=8", "-q", cwd=d)
    tqdyn_cli("export", "tq.h5", "--format", "lisa", "orbits.h5", cwd=d)
    tqdyn_cli("export", "cl.h5", "--format", "lisa-injection", "ttl.h5", "--run", "tq.h5",
              "--coefficients", coefficients, *(("--seed", seed) if seed is not None else ()), cwd=d)
    return {"run": d / "tq.h5", "closed_loop": d / "cl.h5", "orbits": d / "orbits.h5", "injection": d / "ttl.h5"}


def simulate(orbits, injection=None, size: int = 3000, laser: bool = False, seed: int = 1):
    """LISA Instrument (dt = 0.25 s, six lasers locked to their cavities, every noise off but the laser's
    if ``laser``) on ``orbits`` with the glitch file ``injection`` (or none), and PyTDI's X2.
    Returns (t, sci, x2, group_delay): measurement times [s], {link: sci carrier fluctuations [Hz]},
    X2 [Hz] and the anti-aliasing filter's group delay [s]."""
    from lisainstrument import Instrument

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        instru = Instrument(orbits=str(orbits), glitches=None if injection is None else str(injection), size=size,
                            dt=0.25, lock="six", seed=seed, telemetry_downsampling=100,
                            delay_isc_min=0.5 * LTT, delay_isc_max=1.5 * LTT)
        instru.disable_all_noises(excluding="laser" if laser else None)
        res = instru.export_numpy_full()
        meas = {f"{kind}_{ln}": np.asarray(getattr(res.mosa_data, f"{kind}_carrier_fluctuations")[ln])
                for kind in ("sci", "ref", "tmi") for ln in LINKS}
        x2 = x2_of(orbits, meas, res.t[0] - instru.aafilter_group_delay)
    sci = {ln: meas[f"sci_{ln}"] for ln in LINKS}
    return np.asarray(res.t), sci, x2, float(instru.aafilter_group_delay)


def x2_of(orbits, meas: dict, t0: float):
    """PyTDI's X2 [Hz] of the measurements ``meas`` (sci_ij, ref_ij, tmi_ij carrier fluctuations, 4 Hz
    from t0 [s]), delays from the orbit file's proper pseudoranges."""
    from pytdi import Data
    from pytdi.michelson import X2

    data = Data.from_orbits(str(orbits), fs=4.0, t0=t0, dataset="tps/ppr", **meas)
    return np.asarray(X2.build(**data.args)(data.measurements))
