"""The LISA tool chain on tqdyn orbit files: lisainstrument (laser noise only) -> pytdi X2.

Makes docs/figures/lisa-toolchain-x2.png (``python tools/lisa_toolchain_x2.py``;
about a minute): a TianQin run (tqdyn's built-in scenario, 4 hours, GCRS
export) and a LISA-like heliocentric run (3 days, BCRS/TCB export) through
lisainstrument (six lasers locked to their cavities, laser noise only) and
pytdi's second-generation Michelson X2; the figure shows the ASD of the raw
interferometer (sci_12, carrier) and of X2.  :func:`x2_chain` is also used
by tests/test_export_lisa_bcrs.py and mirrors the example of
docs/lisa-toolchain.md.

Parameters TianQin's short arms (light times ~0.58 s) need, found in the
sources of lisainstrument 2.3.0 and pytdi 2.2.1 and verified here:
``delay_isc_min`` / ``delay_isc_max`` (defaults 6 s and 12 s, LISA's ~8.3 s:
otherwise "RegularInterpLagrange: interpolation requires samples above provided
range"), ``telemetry_downsampling`` (default 86400 * 4 samples = one
telemetry sample a day: needs orbit data beyond a day; "Found x value not in
the domain" otherwise) and, for delays from the orbit file
(``Data.from_orbits``), the anti-aliasing filter's group delay
(``Instrument.aafilter_group_delay``, 4.5 s for the default Kaiser filter)
subtracted from t0.
"""

from __future__ import annotations

import pathlib
import subprocess
import sys
import tempfile
import warnings

import numpy as np

LINKS = ("12", "23", "31", "13", "32", "21")
BAND = (1e-2, 1.0)  # Hz: where the suppression factor is measured


def x2_chain(orbit_file, ltt_nominal: float, size: int = 20000, dt: float = 0.25, seed: int = 1,
             delays: str = "orbits"):
    """Simulate laser noise with lisainstrument on ``orbit_file`` and form X2 with pytdi.

    ltt_nominal [s]: the light time of the arms (delay_isc_min/max = 0.5, 1.5 times it); delays: "orbits"
    (Data.from_orbits with t0 moved back by the filter's group delay) or "mprs" (Data.from_instrument).
    Returns (f, asd_raw, asd_x2, factor): Welch ASDs [Hz/sqrt(Hz)] of sci_12 and X2 and the median ratio
    asd_raw / asd_x2 in BAND.
    """
    from lisainstrument import Instrument
    from pytdi import Data
    from pytdi.michelson import X2
    from scipy.signal import welch

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        instru = Instrument(orbits=str(orbit_file), size=size, dt=dt, lock="six", seed=seed,
                            telemetry_downsampling=100, delay_isc_min=0.5 * ltt_nominal,
                            delay_isc_max=1.5 * ltt_nominal)
        instru.disable_all_noises(excluding="laser")
        res = instru.export_numpy_full()
        if delays == "mprs":
            data = Data.from_instrument(res)
        else:
            meas = {f"{kind}_{ln}": getattr(res.mosa_data, f"{kind}_carrier_fluctuations")[ln]
                    for kind in ("sci", "ref", "tmi") for ln in LINKS}
            data = Data.from_orbits(str(orbit_file), fs=1 / dt, t0=res.t[0] - instru.aafilter_group_delay,
                                    dataset="tps/ppr", **meas)
        x2 = X2.build(**data.args)(data.measurements)
    raw = res.mosa_data.sci_carrier_fluctuations["12"]
    skip = int(np.ceil(8 * ltt_nominal / dt)) + 200  # X2 needs 8 light times of past data
    f, p_raw = welch(raw[skip:], 1 / dt, nperseg=4096)
    _, p_x2 = welch(x2[skip:], 1 / dt, nperseg=4096)
    band = (f > BAND[0]) & (f < BAND[1])
    return f, np.sqrt(p_raw), np.sqrt(p_x2), float(np.median(np.sqrt(p_raw[band] / p_x2[band])))


LISA_SCENARIO = """
[scenario]
name = "lisa-like"
central_body = "sun"
epoch_tdb = "2035-01-01T00:00:00"
[run]
duration = "3d"
output = "lisa.h5"
[integrator]
step = 600
[forces]
third_bodies = ["earth", "moon", "jupiter"]
third_bodies_extended = []
# lisaorbits' KeplerianOrbits at t = 0, turned 80 deg about the ecliptic pole (20 deg behind the Earth) and
# rotated to ICRF axes (erfa.ecm06 at J2000)
[[satellites]]
name = "S1"
r_km = [26131735.953486774, 134960941.3666237, 57159288.75073563]
v_kmps = [-29.463791778419207, 4.819882905956382, 2.0896707304787228]
[[satellites]]
name = "S2"
r_km = [27546990.850214314, 134991367.85147685, 59217321.48223371]
v_kmps = [-29.228465573677504, 4.982027831168125, 1.9266094114807382]
[[satellites]]
name = "S3"
r_km = [25096271.05719715, 135392272.88523775, 59391134.732700124]
v_kmps = [-29.271964856080714, 4.58786143291527, 2.2224369199901632]
"""

TIANQIN_SCENARIO = """
[scenario]
name = "tianqin-short"
extends = "tianqin"
[run]
duration = "4h"
output = "tianqin.h5"
[constellation]
pointing = "none"
control = "off"
"""


_CLI = "import sys; from tqdyn.cli import main; sys.exit(main(sys.argv[1:]))"


def make_orbit_files(directory) -> dict:
    """Run the two scenarios with ``tqdyn run`` and export them; returns {"TianQin": path, "LISA": path}."""
    d = pathlib.Path(directory)
    out = {}
    for name, text, run, frame in (("TianQin", TIANQIN_SCENARIO, "tianqin.h5", "gcrs"),
                                   ("LISA", LISA_SCENARIO, "lisa.h5", "bcrs")):
        (d / f"{run}.toml").write_text(text)
        for argv in (["run", f"{run}.toml"], ["export", run, "--format", "lisa", f"orbits-{run}", "--frame", frame]):
            subprocess.run([sys.executable, "-c", _CLI, *argv], cwd=d, check=True, capture_output=True)
        out[name] = d / f"orbits-{run}"
    return out


def main(path="docs/figures/lisa-toolchain-x2.png") -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with tempfile.TemporaryDirectory() as tmp:
        files = make_orbit_files(tmp)
        fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
        for ax, (name, ltt) in zip(axes, (("TianQin", 0.58), ("LISA", 8.3))):
            f, raw, x2, factor = x2_chain(files[name], ltt, size=40000)
            ax.loglog(f[1:], raw[1:], label="raw interferometer sci_12 (laser noise)")
            ax.loglog(f[1:], x2[1:], label=f"X2 (median suppression {factor:.1e} in 0.01-1 Hz)")
            ax.set_title(f"{name} orbits from tqdyn ({'GCRS/TT' if name == 'TianQin' else 'BCRS/TCB'})")
            ax.set_xlabel("frequency [Hz]")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8)
            print(f"{name}: X2 suppresses laser noise by {factor:.2e} (median ASD ratio, 0.01-1 Hz)")
        axes[0].set_ylabel("ASD [Hz/sqrt(Hz)]")
        fig.tight_layout()
        fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main(*sys.argv[1:])
