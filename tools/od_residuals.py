"""The worked example of docs/orbit-determination.md: tracking of TianQin with injected self-gravity,
fitted, and the residuals' figure.

Runs the documented command chain in a temporary directory (this Python's tqdyn):

    tqdyn run tianqin-gravity --duration 2d -q -o tg.h5 --set 'accelerations.s_frame=[[0,1e-10,0],...]'
    tqdyn od simulate tg.h5 --tracking gnss,slr,isr --arc 1d --seed 1 --interval 1800 --output meas.tdm
    tqdyn od fit tianqin-gravity meas.tdm --output est.h5 --estimate state,s_frame --figure od-residuals.png

and records, from the estimate file, chi^2/dof with its p-value, the measurement and fit-row counts
per type and each satellite's recovered S-frame constants against the injected ones, in sigmas
(about a minute, most of it the first compilation).

Usage:
    python tools/od_residuals.py     # writes docs/data/od-residuals.json, docs/figures/od-residuals.png

Then ``python tools/render_docs.py`` (the example's numbers are markers into the record).
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from tqdyn.formats.od_estimate import read_estimate_file
from tqdyn.workflows.numbers import provenance, write_record

ROOT = Path(__file__).resolve().parent.parent
_CLI = "import sys; from tqdyn.cli import main; sys.exit(main(sys.argv[1:]))"
#: The injected DC self-gravity [m/s^2] per satellite (X_S, Y_S, Z_S): 1e-10 along the flight direction.
INJECTED = ((0.0, 1e-10, 0.0),) * 3
COMMANDS = (
    ("run", "tianqin-gravity", "--duration", "2d", "-q", "-o", "tg.h5", "--set",
     "accelerations.s_frame=[[0,1e-10,0],[0,1e-10,0],[0,1e-10,0]]"),
    ("od", "simulate", "tg.h5", "--tracking", "gnss,slr,isr", "--arc", "1d", "--seed", "1", "--interval", "1800",
     "--output", "meas.tdm", "-q"),
    ("od", "fit", "tianqin-gravity", "meas.tdm", "--output", "est.h5", "--estimate", "state,s_frame",
     "--figure", "od-residuals.png", "-q"),
)


def _tqdyn(argv, cwd) -> str:
    p = subprocess.run([sys.executable, "-c", _CLI, *argv], cwd=cwd, check=True, capture_output=True, text=True)
    return p.stdout


def record(est) -> dict:
    """The example's numbers from the estimate file contents ``est``."""
    a, m = est.attrs, est.measurements
    names = list(est.parameters["names"])
    sats = []
    for k, inj in enumerate(INJECTED):
        sat = {}
        for j, axis in enumerate("xyz"):
            i = names.index(f"Sat{k + 1}/s_{axis}")
            v, s = float(est.parameters["values"][i]), float(est.parameters["sigma"][i])
            sat[f"s_{axis}"] = {"injected": inj[j], "value": v, "sigma": s, "error_sigmas": (v - inj[j]) / s}
        sats.append(sat)
    types = list(dict.fromkeys(m["type"].tolist()))
    fit_types = m["type"][m["residual_row"]]
    return {"commands": ["tqdyn " + " ".join(c) for c in COMMANDS], "scenario": a["scenario_name"],
            "chi2": a["chi2"], "chi2_dof": a["chi2_dof"], "chi2_per_dof": a["chi2"] / a["chi2_dof"],
            "chi2_pvalue": a["chi2_pvalue"], "measurements": int(len(m["t"])), "fit_rows": int(len(m["residual"])),
            "edited": int(np.sum(m["edited"])),
            "per_type": {t: {"measurements": int(np.sum(m["type"] == t)), "fit_rows": int(np.sum(fit_types == t))}
                         for t in types},
            "satellites": sats}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs" / "data" / "od-residuals.json"))
    ap.add_argument("--figure", default=str(ROOT / "docs" / "figures" / "od-residuals.png"))
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="tqdyn-od-residuals-") as d:
        for argv_ in COMMANDS:
            _tqdyn(argv_, d)
        data = {**provenance("tools/od_residuals.py"),
                "description": "The worked example of docs/orbit-determination.md: 1 day of GNSS, SLR and "
                               "inter-satellite ranging of tianqin-gravity with 1e-10 m/s^2 of DC self-gravity "
                               "along Y_S injected on each satellite, fitted for the initial states and the "
                               "S-frame constants; values in SI units, error_sigmas = (value - injected) / sigma.",
                **record(read_estimate_file(Path(d) / "est.h5"))}
        Path(args.figure).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(Path(d) / "od-residuals.png", args.figure)
    data["wall_s"] = time.perf_counter() - t0
    write_record(args.out, data)
    print(f"wrote {args.out} and {args.figure} in {data['wall_s']:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
