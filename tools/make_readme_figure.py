"""Make docs/figures/kepler-error.png: position error of the three TianQin
satellites (tianqin-kepler scenario, Earth monopole) against the analytic
two-body solution (mpmath, 50 digits), dd vs float64 mode, 90 days at 50 s with DP87
(tests/test_propagation.py::test_tianqin_kepler_90_days records the same errors).

Run: python tools/make_readme_figure.py  (needs matplotlib)
"""

from __future__ import annotations

import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import mpmath  # noqa: E402
import numpy as np  # noqa: E402

from tqdyn import dynamics  # noqa: E402
from tqdyn.astro import elements  # noqa: E402
from tqdyn.scenario import load_scenario  # noqa: E402

OUT = pathlib.Path(__file__).resolve().parents[1] / "docs" / "figures" / "kepler-error.png"
EVERY = 864  # one output row every 12 h


def errors(scen, precision):
    blocks = []
    dynamics.propagate(scen, precision=precision, sink=blocks.append)
    rows = dynamics.Rows.concatenate(blocks)
    t = rows.t[0] + rows.t[1]
    r_hi, r_lo = rows.sat_r
    err = np.zeros((t.size, len(scen.satellites)))
    with mpmath.workdps(50):
        for k in range(t.size):
            for s, sat in enumerate(scen.satellites):
                ref, _ = elements.kepler_state_at(sat.a_m, sat.e, elements.deg(sat.i_deg), elements.deg(sat.raan_deg),
                                                  elements.deg(sat.argp_deg), elements.deg(sat.nu_deg),
                                                  scen.forces.gm_earth, mpmath.mpf(t[k]))
                d = [mpmath.mpf(r_hi[k, s, q]) + mpmath.mpf(r_lo[k, s, q]) - ref[q] for q in range(3)]
                err[k, s] = float(mpmath.sqrt(sum(x * x for x in d)))
    return t, err


def main():
    scen = load_scenario("tianqin-kepler", ["run.duration=90d", f"run.output_every={EVERY}", "integrator.method=dp87"])
    fig, ax = plt.subplots(figsize=(7, 4))
    for precision, style in (("float64", "--"), ("dd", "-")):
        t, err = errors(scen, precision)
        for s, sat in enumerate(scen.satellites):
            ax.semilogy(t[1:] / 86400, err[1:, s], style, label=f"{sat.name}, {precision}")
    ax.set_xlabel("time since 2004-06-06 00:00 UTC [days]")
    ax.set_ylabel("position error vs analytic [m]")
    ax.set_title("TianQin satellites, Earth monopole, DP87 at 50 s")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(ncol=2, fontsize=8)
    fig.tight_layout()
    OUT.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(OUT, dpi=120)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
