"""Calibrating self-gravity from tracking: a covariance study (docs/orbit-determination.md).

For TianQin (tianqin-gravity) and LISA (lisa-gravity), the formal 1-sigma of each satellite's
DC self-gravity per S axis (the S-frame constant acceleration, estimated together with the
initial states, no a priori) against the arc length, for each tracking plan, by covariance
analysis (tqdyn.od.problem.covariance: measurement noise only, no data; for TianQin also with
constant measurement biases considered, :data:`TIANQIN_BIAS_SIGMA`).  One propagation with
partials over the longest arc is shared by every plan and arc of a mission.

Usage:
    python tools/od_study.py                    # writes docs/data/od-study.json, docs/figures/od-study.png
    python tools/od_study.py --quick --out /tmp/od-study.json --figure /tmp/od-study.png   # short arcs

Then ``python tools/render_docs.py`` (the section's numbers are markers into the record).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from tqdyn.od import problem as odp
from tqdyn.od.variational import propagate_with_partials
from tqdyn.workflows.numbers import provenance, write_record

ROOT = Path(__file__).resolve().parent.parent
DAY = 86400.0
#: The paper: 1e-9 m/s^2 of common self-gravity along the flight direction moves TianQin's orbit
#: by ~100 km in 90 days (along-track drift 3/2 a t^2 = 91 km at t = 90 d).
PAPER_ACC = 1e-9
PAPER_SHIFT_KM = 100.0
#: Condition-number limit of the study (the estimator's default is 1e10): plans up to it are
#: reported with their sigmas, beyond it as unobservable.
MAX_CONDITION = 1e12

#: Measurement biases considered in the plan "combined_biases" (one per SLR station, one per one-way
#: inter-satellite link; tqdyn.od.problem's group "bias") [m]: SLR 1 cm, the order of the ILRS
#: stations' systematic range errors (mm to cm: Luceri et al. 2019, J. Geod. 93, 2357); ISR 0.5 m,
#: the absolute-ranging sigma itself (an assumption).
TIANQIN_BIAS_SIGMA = {"slr_range": 0.01, "isr_range": 0.5}

MISSIONS = {
    "tianqin": {"scenario": "tianqin-gravity", "interval_s": 1800.0, "arcs_days": [1, 2, 4, 7, 14, 30],
                "plans": {"gnss": ("gnss",), "slr": ("slr",), "isr": ("isr",),
                          "combined": ("gnss", "slr", "isr"), "combined_biases": ("gnss", "slr", "isr")},
                "bias_sigma": {"combined_biases": TIANQIN_BIAS_SIGMA}},
    "lisa": {"scenario": "lisa-gravity", "interval_s": 21600.0, "arcs_days": [1, 2, 4, 7, 14, 30, 90],
             "plans": {"dsn": ("dsn",), "isr": ("isr",), "combined": ("dsn", "isr")}},
}


def _study(mission: str, cfg: dict, quick: bool) -> dict:
    arcs = cfg["arcs_days"][:3] if quick else cfg["arcs_days"]
    grid = np.arange(0.0, max(arcs) * DAY + 1.0, cfg["interval_s"])
    t0 = time.perf_counter()
    p = propagate_with_partials(cfg["scenario"], None, grid,
                                step=min(cfg["interval_s"], 600.0) if mission == "tianqin" else None)
    out = {"scenario": cfg["scenario"], "interval_s": cfg["interval_s"], "arcs_days": arcs,
           "propagation_wall_s": time.perf_counter() - t0, "plans": {}}
    for plan, kinds in cfg["plans"].items():
        bias = cfg.get("bias_sigma", {}).get(plan)
        res = {"kinds": list(kinds), "sigma": [], "sigma_x_max": [], "sigma_y_max": [], "sigma_z_max": [],
               "common_y": [], "orbit_90d_m": [], "condition_number": [], "status": []}
        if bias:
            res["consider_bias_sigma"] = dict(bias)
        for arc in arcs:
            extra = {"consider": ("bias",), "a_priori_sigma": {"bias": bias}} if bias else {}
            tr = odp.Tracking(kinds, arc * DAY, cfg["interval_s"], estimate=("state", "s_frame"), **extra)
            try:
                c = odp.covariance(cfg["scenario"], tr, partials=p, max_condition=MAX_CONDITION)
            except ValueError as exc:
                if "unobservable" not in str(exc):
                    raise
                for k in ("sigma", "sigma_x_max", "sigma_y_max", "sigma_z_max", "common_y", "orbit_90d_m",
                          "condition_number"):
                    res[k].append(None)
                res["status"].append("unobservable")
                continue
            sats = sorted({n.split("/")[0] for n in c.names}, key=lambda s: c.names.index(f"{s}/x"))
            idx = np.array([[c.names.index(f"{s}/{a}") for a in ("s_x", "s_y", "s_z")] for s in sats])
            # with biases considered: their consider sigma and covariance (noise and biases)
            sigma, cov = (c.consider_sigma, c.consider_covariance) if bias else (c.sigma, c.covariance)
            sig = sigma[idx]                                         # (3 sats, 3 axes) m/s^2
            iy = idx[:, 1]
            common_y = float(np.sqrt(cov[np.ix_(iy, iy)].sum()) / len(iy))
            res["sigma"].append(sig.tolist())
            for a, key in enumerate(("sigma_x_max", "sigma_y_max", "sigma_z_max")):
                res[key].append(float(sig[:, a].max()))
            res["common_y"].append(common_y)
            res["orbit_90d_m"].append(PAPER_SHIFT_KM * 1e3 * common_y / PAPER_ACC)
            res["condition_number"].append(float(c.condition_number))
            res["status"].append("ok")
            print(f"{mission:8s} {plan:9s} {arc:3d} d  sigma_y max {sig[:, 1].max():.2e}  common_y {common_y:.2e}  "
                  f"kappa {c.condition_number:.1e}", flush=True)
        out["plans"][plan] = res
    out["wall_s"] = time.perf_counter() - t0
    return out


def _figure(data: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    for ax, (mission, title) in zip(axes, (("tianqin", "TianQin (tianqin-gravity; Y_S = flight direction)"),
                                                   ("lisa", "LISA (lisa-gravity)"))):
        m = data["missions"][mission]
        for k, (plan, res) in enumerate(m["plans"].items()):
            arcs = np.array(m["arcs_days"], float)
            for key, ls in (("sigma_y_max", "-"), ("sigma_x_max", ":")):
                v = np.array([np.nan if x is None else x for x in res[key]])
                ax.loglog(arcs, v, ls, marker="o", ms=3, color=f"C{k}",
                          label=f"{plan.replace('_biases', ' + biases')} ({'Y_S' if key == 'sigma_y_max' else 'X_S'})")
        ax.axhline(PAPER_ACC, color="k", lw=0.8, ls="--")
        ax.text(arcs[0], PAPER_ACC * 1.4, "1e-9 m/s$^2$: ~100 km in 90 d (TianQin)", fontsize=7)
        ax.set_title(title)
        ax.set_xlabel("arc [days]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, ncol=2, loc="lower left")
    axes[0].set_ylabel("1-sigma of the DC self-gravity [m/s$^2$]\n(largest of the three satellites)")
    fig.suptitle("Calibrating self-gravity from tracking: formal 1-sigma (covariance analysis, state + S-frame "
                 "constants estimated; + biases: SLR station and link biases considered)", fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs" / "data" / "od-study.json"))
    ap.add_argument("--figure", default=str(ROOT / "docs" / "figures" / "od-study.png"))
    ap.add_argument("--quick", action="store_true", help="the first three arcs only")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    data = {**provenance("tools/od_study.py"),
            "description": "Formal 1-sigma [m/s^2] of each satellite's DC self-gravity per S axis (X_S toward "
                           "the incentre, Y_S the flight direction, Z_S normal), state and S-frame constants "
                           "estimated without a priori, by covariance analysis (tqdyn.od.problem.covariance; "
                           "plan combined_biases: the consider sigma with the measurement biases of "
                           "consider_bias_sigma [m] considered); "
                           "common_y: the mean of the three Y_S constants; orbit_90d_m: the along-track shift "
                           "of 90 days it leaves (100 km per 1e-9 m/s^2, the paper).",
            "max_condition": MAX_CONDITION, "sigma": dict(odp.DEFAULT_SIGMA), "missions": {}}
    for mission, cfg in MISSIONS.items():
        data["missions"][mission] = _study(mission, cfg, args.quick)
    data["wall_s"] = time.perf_counter() - t0
    write_record(args.out, data)
    _figure(data, Path(args.figure))
    print(f"wrote {args.out} and {args.figure} in {data['wall_s']:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
