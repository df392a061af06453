"""Figures of the flown single-spacecraft missions against their published results
(docs/closed-loop-validation.md; written by ``python tools/flown_figures.py``): LISA Pathfinder's Delta g, its
six-DOF stability and in-loop coordinates, TianQin-1's residual acceleration.

matplotlib is imported lazily (:func:`tqdyn.analysis.figures._pyplot`); each function writes ``<stem>.<fmt>``
for every format of ``formats`` into ``out_dir`` and returns the paths.  Frequencies in Hz on log axes; ASDs
one-sided per Hz^1/2.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .figures import FIGURE_FORMATS, _pyplot

__all__ = ["plot_delta_g", "plot_in_loop", "plot_residual_single_tm", "plot_stability"]

_DPI = 130


def _finish(fig, out_dir: Path, stem: str, formats) -> list[Path]:
    plt = _pyplot()
    fig.tight_layout()
    paths = []
    for ext in formats:
        p = Path(out_dir) / f"{stem}.{ext}"
        fig.savefig(p, dpi=_DPI)
        paths.append(p)
    plt.close(fig)
    return paths


def _top_sources(budget, sources, n=4):
    """Indices of the ``n`` sources with the largest contribution anywhere (budget (n_source, n_f))."""
    return [int(j) for j in np.argsort(-np.max(budget, axis=1))[:n] if np.max(budget[j]) > 0]


def plot_delta_g(f, budget, sources: Sequence[str], published, points, out_dir: Path, stem: str,
                 band=(1e-3, 3e-2), formats=FIGURE_FORMATS) -> list[Path]:
    """Delta g: the model's total and largest sources (budget (n_source, n_f) [m s^-2/Hz^1/2]), the published
    curve ``published`` (n_f,) and published points ``points`` [(f, value, label)]; lower panel the ratio
    model / published; the acceptance band shaded."""
    plt = _pyplot()
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(6.4, 5.6), sharex=True, gridspec_kw={"height_ratios": [3, 1.2]})
    total = np.sqrt(np.sum(np.asarray(budget) ** 2, axis=0))
    for j in _top_sources(budget, sources):
        ax.loglog(f, budget[j], lw=0.9, ls="--", label=f"model: {sources[j]}")
    ax.loglog(f, total, color="k", lw=1.8, label="model: total (six-DOF loop)")
    ax.loglog(f, published, color="tab:red", lw=1.2, ls=":", label="published (PRL 2016/2018, 2024 tail)")
    for fp, v, lab in points:
        ax.plot(fp, v, "o", color="tab:red", ms=5, mfc="none", label=lab)
    for a in (ax, ax2):
        a.axvspan(*band, color="0.9", zorder=0)
        a.grid(True, which="both", alpha=0.3)
    ax.set_ylim(total.min() * 0.2, total.max() * 3)
    ax.set_ylabel(r"$\Delta g$ ASD [m s$^{-2}$/Hz$^{1/2}$]")
    ax.legend(fontsize=7, loc="upper right")
    ax.set_title("LISA Pathfinder: differential acceleration", fontsize=10)
    ax2.semilogx(f, total / np.asarray(published), color="k")
    ax2.axhline(1.0, color="tab:red", ls=":")
    ax2.set_ylim(0.9, 1.1)
    ax2.set_ylabel("model / published")
    ax2.set_xlabel("frequency [Hz]")
    return _finish(fig, out_dir, stem, formats)


def plot_stability(f, budgets: dict, sources: Sequence[str], published: dict, f_pub: float, out_dir: Path,
                   stem: str, formats=FIGURE_FORMATS) -> list[Path]:
    """The spacecraft's stability in six DOF: per DOF (``budgets`` {dof: (n_source, n_f)}) the total and largest
    sources, the published value near ``f_pub`` (``published`` {dof: value}) with its factor-2 bar; the band
    below 1 mHz (star tracker) shaded."""
    plt = _pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(11.5, 6.4))
    for ax, (dof, b) in zip(axes.flat, budgets.items()):
        total = np.sqrt(np.sum(b ** 2, axis=0))
        for j in _top_sources(b, sources, 3):
            ax.loglog(f, b[j], lw=0.9, ls="--", label=sources[j])
        ax.loglog(f, total, color="k", lw=1.6, label="model total")
        v = published[dof]
        ax.errorbar([f_pub], [v], yerr=[[v / 2], [v]], fmt="o", color="tab:red", ms=5, mfc="none", capsize=3,
                    label="published (x/2, x2)")
        ax.axvspan(f[0], 1e-3, color="0.93", zorder=0)
        unit = "rad s$^{-2}$" if dof in ("Theta", "Eta", "Phi") else "m s$^{-2}$"
        ax.set_title(dof, fontsize=9)
        ax.set_ylabel(f"ASD [{unit}/Hz$^{{1/2}}$]", fontsize=8)
        ax.set_xlabel("frequency [Hz]", fontsize=8)
        ax.set_ylim(total.min() * 0.3, total.max() * 3)
        ax.tick_params(labelsize=7)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6, loc="upper left")
    fig.suptitle("LISA Pathfinder: the spacecraft's acceleration w.r.t. its geodesic (shaded: below 1 mHz)",
                 fontsize=10)
    return _finish(fig, out_dir, stem, formats)


def plot_in_loop(f, asd: dict, units: dict, out_dir: Path, stem: str, formats=FIGURE_FORMATS) -> list[Path]:
    """In-loop coordinates (the controllers' inputs): ``asd`` {name: (n_f,)} in ``units`` {name: unit}, one
    panel for lengths and one for angles."""
    plt = _pyplot()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10.5, 4.0))
    for name, y in asd.items():
        (a1 if units[name] == "m" else a2).loglog(f, y, lw=1.1, label=name)
    a1.set_ylabel("ASD [m/Hz$^{1/2}$]")
    a2.set_ylabel("ASD [rad/Hz$^{1/2}$]")
    for a in (a1, a2):
        a.set_xlabel("frequency [Hz]")
        a.grid(True, which="both", alpha=0.3)
        a.legend(fontsize=7)
    fig.suptitle("LISA Pathfinder: in-loop coordinates (model)", fontsize=10)
    return _finish(fig, out_dir, stem, formats)


def plot_residual_single_tm(f, curves: dict, points, thruster, out_dir: Path, stem: str,
                            formats=FIGURE_FORMATS) -> list[Path]:
    """TianQin-1's residual acceleration: model curves ``curves`` {label: (n_f,)}, the thruster noise
    ``thruster`` (n_f,) and published points [(f, value, label)]."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.loglog(f, thruster, color="0.5", lw=1.0, ls="--", label="thruster noise (acceleration, published)")
    for k, (lab, y) in enumerate(curves.items()):
        ax.loglog(f, y, lw=1.6 if k == 0 else 1.1, color="k" if k == 0 else None, ls="-" if k == 0 else "-.",
                  label=lab)
    for fp, v, lab in points:
        ax.plot(fp, v, "o", ms=6, mfc="none", label=lab)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("residual acceleration ASD [m s$^{-2}$/Hz$^{1/2}$]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("TianQin-1: residual acceleration under drag-free control", fontsize=10)
    return _finish(fig, out_dir, stem, formats)
