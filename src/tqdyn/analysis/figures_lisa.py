"""Figures of the LISA / Taiji studies (``tqdyn report --studies --mission lisa``).

matplotlib is imported lazily (:func:`tqdyn.analysis.figures._pyplot`); every
figure is written as PNG and PDF (:data:`tqdyn.analysis.figures.FIGURE_FORMATS`)
into ``out_dir`` as ``<stem>.png`` / ``<stem>.pdf``; the functions return the
paths.  Time axes in days (TDB, the heliocentric runs' time scale) since the
scenario's epoch; units as labelled (SI, angles in deg where marked).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..constellation.indices import Sat
from .figures import SAT_COLORS, _days, _pyplot, _save, _stride

__all__ = ["plot_arm_response", "plot_deviation", "plot_esa_ramp", "plot_estimate"]


def plot_estimate(panels: Sequence[tuple], out_dir: Path, stem: str, title: str) -> list[Path]:
    """Nominal control against the analytic estimate, one row of two panels per run.

    ``panels``: (label, t (N,) [s], |G| (N, 3) [m/s^2], max suspension
    component (N, 3) [m/s^2], estimate of |G| (N, 3) or None, estimate of
    the suspension (N, 3) or None[, markers]) with the optional ``markers``
    = (t (M,) [s], |G| (M, 3), suspension (M, 3)) drawn as dots (e.g. the
    identity evaluated on ESA's file records); measured solid, estimate
    dashed, per satellite."""
    plt = _pyplot()
    fig, axes = plt.subplots(len(panels), 2, figsize=(9, 2.25 * len(panels) + 0.5), sharex=True, squeeze=False)
    for row, panel in zip(axes, panels):
        label, t, G, A, Ge, Ae = panel[:6]
        markers = panel[6] if len(panel) > 6 else None
        k = _stride(t.size)
        d = _days(t)[::k]
        for col, (ax, meas, est, what) in enumerate(((row[0], G, Ge, "|G|"), (row[1], A, Ae, "max |A| comp."))):
            for s in Sat:
                c = SAT_COLORS[s.index]
                ax.plot(d, meas[::k, s.index], color=c, lw=0.9, label=f"Sat{int(s)} run")
                if est is not None:
                    ax.plot(d, est[::k, s.index], color=c, lw=0.9, ls="--", label=f"Sat{int(s)} formula")
                if markers is not None:
                    ax.plot(_days(markers[0]), markers[1 + col][:, s.index], ".", color=c, ms=3,
                            label=f"Sat{int(s)} identity on ESA's files")
            ax.set_ylabel(f"{what} [m/s$^2$]", fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(True, alpha=0.3)
        row[0].set_title(label, fontsize=8, loc="left")
        row[0].legend(fontsize=6, ncol=2)
    for ax in axes[-1]:
        ax.set_xlabel("time since epoch [days, TDB]", fontsize=8)
    fig.suptitle(title, fontsize=9)
    return _save(fig, out_dir, stem)


def plot_deviation(series: Sequence[tuple[str, np.ndarray, np.ndarray, str, str]], out_dir: Path, stem: str,
                   title: str, ymin: float | None = None) -> list[Path]:
    """Orbit deviations [m] (log scale) against time (days, TDB); ``series`` of
    (label, t [s], y (N,) [m], colour, line style)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.6))
    for label, t, y, color, ls in series:
        k = _stride(t.size)
        ax.semilogy(_days(t)[::k], np.maximum(y[::k], 1e-30), color=color, ls=ls, lw=1.0, label=label)
    if ymin is not None:
        ax.set_ylim(bottom=ymin)
    ax.set_xlabel("time since epoch [days, TDB]")
    ax.set_ylabel("|r - r$_{gravity}$| [m]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    ax.set_title(title, fontsize=9)
    return _save(fig, out_dir, stem)


def plot_arm_response(curves: Sequence[tuple[str, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                             np.ndarray, np.ndarray]], out_dir: Path, stem: str,
                      title: str) -> list[Path]:
    """Arm lengths, arm-length rates and corner angles of a perturbed run minus the reference.

    ``curves``: (label, t (N,) [s], dL (N, 3) [m], dLdot (N, 3) [m/s],
    dalpha (N, 3) [rad], and the same three estimated); plotted: the
    largest |.| over arms / corners, measured solid, estimate dashed (same
    colour)."""
    plt = _pyplot()
    fig, axes = plt.subplots(3, 1, figsize=(8, 8.6), sharex=True)
    for k, (label, t, dL, dLd, dal, eL, eLd, eal) in enumerate(curves):
        kk = _stride(t.size)
        d = _days(t)[::kk]
        c = f"C{k}"
        for ax, m, e, scale in ((axes[0], dL, eL, 1e-3), (axes[1], dLd, eLd, 1e3), (axes[2], dal, eal, np.degrees(1.0))):
            ax.plot(d, np.abs(m[::kk]).max(axis=1) * scale, color=c, lw=1.2, label=f"{label} run")
            ax.plot(d, np.abs(e[::kk]).max(axis=1) * scale, color=c, lw=1.0, ls="--", label=f"{label} Hill estimate")
    axes[0].set_ylabel("max over arms |L - L$_{ref}$| [km]")
    axes[1].set_ylabel("max over arms |dL/dt - dL$_{ref}$/dt| [mm/s]")
    axes[2].set_ylabel("max over corners |alpha - alpha$_{ref}$| [deg]")
    axes[2].set_xlabel("time since epoch [days, TDB]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=7, ncol=2)
    fig.suptitle(title, fontsize=10)
    return _save(fig, out_dir, stem)


def plot_esa_ramp(t, along, along_pred, angle_deg, angle_est_deg, vs_files: Sequence[tuple[str, np.ndarray,
                  np.ndarray, str]], out_dir: Path, stem: str, title: str) -> list[Path]:
    """ESA's ramp through the TMs vs toward the centroid.

    t (N,) [s]; along, along_pred (N, 3) [m]: along-track difference of the
    coupled run from the point-mass run, measured and first-order (CW)
    prediction; angle_deg, angle_est_deg (N, 3) [deg]: angle between X_S and
    the centroid direction, measured and first-order; vs_files: (label, t
    (M,) [s], |r - r_ESA| (M, 3) [m], line style) against ESA's files."""
    plt = _pyplot()
    fig, axes = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    k = _stride(t.size)
    d = _days(t)[::k]
    for s in Sat:
        c = SAT_COLORS[s.index]
        axes[0].plot(d, along[::k, s.index] / 1e3, color=c, lw=1.2, label=f"Sat{int(s)} coupled - point mass")
        axes[0].plot(d, along_pred[::k, s.index] / 1e3, color=c, lw=1.0, ls="--", label=f"Sat{int(s)} CW prediction")
        axes[1].plot(d, angle_deg[::k, s.index], color=c, lw=1.2, label=f"Sat{int(s)} X_S vs centroid")
        axes[1].plot(d, angle_est_deg[::k, s.index], color=c, lw=1.0, ls="--",
                     label=f"Sat{int(s)} (L_ik - L_ij)/(2 sqrt3 L)")
    for label, tf, dr, ls in vs_files:
        kk = _stride(tf.size)
        for s in Sat:
            axes[2].semilogy(_days(tf)[::kk], np.maximum(dr[::kk, s.index], 1e-3), color=SAT_COLORS[s.index], ls=ls,
                             lw=1.0, label=f"Sat{int(s)} {label}")
    axes[0].set_ylabel("along-track difference [km]")
    axes[1].set_ylabel("angle X_S to centroid [deg]")
    axes[2].set_ylabel("|r - r$_{ESA\\ files}$| [m]")
    axes[2].set_xlabel("time since epoch [days, TDB]")
    axes[2].set_ylim(bottom=1.0)
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6.5, ncol=2)
    fig.suptitle(title, fontsize=10)
    return _save(fig, out_dir, stem)
