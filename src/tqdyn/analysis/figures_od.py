"""Figures of an orbit-determination fit (``tqdyn od fit --figure``; docs/orbit-determination.md).

:func:`plot_od_residuals` draws, from the contents of an estimate file
(:func:`tqdyn.formats.od_estimate.read_estimate_file`), the normalised post-fit residuals of every row
of the fit against time -- one panel per measurement type, one colour per satellite, the rows left
out by the outlier editing as crosses, the +-3 lines -- and the histogram of the kept rows'
normalised residuals with the unit normal density, titled with chi^2/dof and its p-value.

The normalised residual of a row is its residual over its post-fit standard deviation (dimensionless;
:mod:`tqdyn.od.estimator`); the rows are the fit's: one per measurement, except the GNSS pseudoranges,
whose receiver clock is eliminated per (epoch, satellite) -- n_k pseudoranges give n_k - 1
clock-free rows, each placed at its epoch and satellite (``residual_row`` of the file).  Time in
hours since the scenario epoch (days for arcs over three days) in the file's time scale.

matplotlib is imported lazily (:func:`tqdyn.analysis.figures._pyplot`); the figure is written
atomically (:func:`tqdyn.analysis.figures._savefig_atomic`) as PNG or PDF by the path's suffix.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..od.registry import TYPES
from .figures import _DPI, SAT_COLORS, _pyplot, _savefig_atomic, check_figure_path

__all__ = ["FIGURE_SUFFIXES", "HIST_LIMIT", "ResidualFigure", "check_residual_figure_path", "plot_od_residuals",
           "residual_table"]

#: The formats of the residuals' figure (the path's suffix).
FIGURE_SUFFIXES = ("pdf", "png")
#: Normalised residuals beyond +-HIST_LIMIT are counted in the histogram's outer bins.
HIST_LIMIT = 5.0
_BIN = 0.25


@dataclass(frozen=True)
class ResidualFigure:
    """What :func:`plot_od_residuals` drew, read back from the figure's artists.

    path: the file written; time_unit: "h" or "d"; points: {type: {satellite index: (x, z)}} of the
    kept rows (x in time_unit since the epoch, z normalised); edited: {type: (x, z)} of the rows
    left out; hist_counts (n_bins,) and hist_edges (n_bins + 1,) of the kept rows' z (clipped to
    +-:data:`HIST_LIMIT`); kept: the number of kept rows."""

    path: Path
    time_unit: str
    points: dict
    edited: dict
    hist_counts: np.ndarray
    hist_edges: np.ndarray
    kept: int


def check_residual_figure_path(path) -> str:
    """Check before any work that the residuals' figure can be written at ``path`` (a ``.png`` or
    ``.pdf`` file in an existing, writable directory); returns the format.  ValueError (one line,
    naming ``--figure``) otherwise."""
    return check_figure_path(path, "--figure", FIGURE_SUFFIXES)


def residual_table(est) -> dict:
    """The fit's rows of an estimate file's contents: {t [s since the epoch], type, sat, residual
    [m or m/s], z (normalised, 1), edited (bool)}, each (m',).  ValueError (one line) when the file
    does not say which measurement each row belongs to."""
    m = est.measurements
    name = est.path.name if est.path is not None else "estimate"
    if "residual_row" not in m:
        raise ValueError(f"{name}: {len(m['residual'])} residual rows for {len(m['t'])} measurements and no "
                         "/measurements/residual_row; allowed: a file written by this tqdyn (re-run tqdyn od fit)")
    rows = np.asarray(m["residual_row"], dtype=np.int64)
    return {"t": np.asarray(m["t"], np.float64)[rows], "type": np.asarray(m["type"]).astype(str)[rows],
            "sat": np.asarray(m["sat"], np.int64)[rows], "residual": np.asarray(m["residual"], np.float64),
            "z": np.asarray(m["normalised_residual"], np.float64), "edited": np.asarray(m["edited"], bool)}


def _satellite_names(est, n: int) -> list[str]:
    try:
        sats = tomllib.loads(str(est.attrs.get("scenario", "")))["satellites"]
        names = [str(s["name"]) for s in sats]
    except (tomllib.TOMLDecodeError, KeyError, TypeError):
        names = []
    return names + [f"satellite {k}" for k in range(len(names), n)]


def plot_od_residuals(est, path, title: str | None = None) -> ResidualFigure:
    """Draw the normalised post-fit residuals of the estimate file contents ``est`` (an
    :class:`tqdyn.formats.od_estimate.EstimateFile`) into ``path`` (``.png`` or ``.pdf``; checked
    first by :func:`check_residual_figure_path`); returns what was drawn (:class:`ResidualFigure`).
    title: the figure's first line (default: the scenario and measurement file)."""
    path = Path(path)
    fmt = check_residual_figure_path(path)
    rows = residual_table(est)
    attrs = est.attrs
    plt = _pyplot()
    types = list(dict.fromkeys(rows["type"].tolist()))
    n_sat = int(rows["sat"].max()) + 1 if rows["sat"].size else 0
    sat_names = _satellite_names(est, n_sat)
    span = float(np.max(rows["t"])) if rows["t"].size else 0.0
    unit, scale = ("d", 86400.0) if span > 3 * 86400.0 else ("h", 3600.0)
    x = rows["t"] / scale
    kept = ~rows["edited"]
    fig = plt.figure(figsize=(11.5, 2.3 * max(len(types), 2) + 1.0))
    gs = fig.add_gridspec(max(len(types), 1), 2, width_ratios=(3.0, 1.25))
    points, edited = {}, {}
    axes = []
    for k, typ in enumerate(types):
        ax = fig.add_subplot(gs[k, 0], sharex=axes[0] if axes else None)
        axes.append(ax)
        sel = rows["type"] == typ
        points[typ] = {}
        for s in range(n_sat):
            on = sel & kept & (rows["sat"] == s)
            if on.any():
                coll = ax.scatter(x[on], rows["z"][on], s=7, color=SAT_COLORS[s] if s < len(SAT_COLORS) else f"C{s}",
                                  lw=0, label=sat_names[s])
                points[typ][s] = tuple(np.asarray(coll.get_offsets(), np.float64).T)
        off = sel & ~kept
        if off.any():
            coll = ax.scatter(x[off], rows["z"][off], s=18, marker="x", color="k", lw=0.8, label="edited")
            edited[typ] = tuple(np.asarray(coll.get_offsets(), np.float64).T)
        for level in (-3.0, 3.0):
            ax.axhline(level, color="0.3", ls="--", lw=0.8)
        ax.axhline(0.0, color="0.6", lw=0.6)
        zk = rows["z"][sel & kept]
        top = max(4.0, float(np.max(np.abs(rows["z"][sel]))) * 1.1) if sel.any() else 4.0
        ax.set_ylim(-top, 1.45 * top)  # room for the legend
        mtype = TYPES.get(typ)
        res_unit = mtype.unit if mtype else "m"
        rms_z = float(np.sqrt(np.mean(zk ** 2))) if zk.size else math.nan
        rms_r = float(np.sqrt(np.mean(rows["residual"][sel & kept] ** 2))) if zk.size else math.nan
        what = " (clock-free combinations)" if mtype and mtype.receiver_clock else ""
        ax.set_title(f"{typ}{what}: {int((sel & kept).sum())} kept, {int((sel & ~kept).sum())} edited; "
                     f"rms {rms_r:.3g} {res_unit}, normalised rms {rms_z:.3f}", fontsize=8.5)
        ax.set_ylabel("normalised residual [1]", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=6.5, loc="upper right", ncol=n_sat + 1, markerscale=1.5, framealpha=0.9)
    if axes:
        axes[-1].set_xlabel(f"time since epoch [{unit}, {attrs.get('time_scale', 'TT')}]", fontsize=8)
    ah = fig.add_subplot(gs[:, 1])
    zk = np.clip(rows["z"][kept], -HIST_LIMIT, HIST_LIMIT)
    edges = np.arange(-HIST_LIMIT, HIST_LIMIT + _BIN / 2, _BIN)
    counts, edges, _ = ah.hist(zk, bins=edges, color="0.55", edgecolor="white", lw=0.4,
                               label=f"{zk.size} kept rows")
    grid = np.linspace(-HIST_LIMIT, HIST_LIMIT, 401)
    ah.plot(grid, zk.size * _BIN * np.exp(-0.5 * grid ** 2) / math.sqrt(2 * math.pi), color="k", lw=1.2,
            label="unit normal")
    ah.set_ylim(0, 1.3 * max(float(np.max(counts)) if counts.size else 0.0, zk.size * _BIN / math.sqrt(2 * math.pi)))
    ah.set_xlabel(f"normalised residual [1] (beyond +-{HIST_LIMIT:g}: outer bins)", fontsize=8)
    ah.set_ylabel(f"rows per {_BIN:g} bin", fontsize=8)
    ah.tick_params(labelsize=7)
    ah.grid(True, alpha=0.3)
    chi2, dof, p = float(attrs.get("chi2", math.nan)), int(attrs.get("chi2_dof", 0)), \
        float(attrs.get("chi2_pvalue", math.nan))
    ah.legend(fontsize=7, title=f"chi$^2$/dof = {chi2:.1f}/{dof} = {chi2 / max(dof, 1):.3f}\np = {p:.3g}",
              title_fontsize=7.5, loc="upper left")
    first = title or (f"{attrs.get('scenario_name', '')}: post-fit residuals of {attrs.get('tdm_file', '')}").strip()
    fig.suptitle(f"{first}\nchi$^2$/dof = {chi2:.1f}/{dof} = {chi2 / max(dof, 1):.3f}, p = {p:.3g}; dashed: +-3",
                 fontsize=9.5)
    fig.tight_layout()
    try:
        _savefig_atomic(fig, path, fmt, dpi=_DPI)
    finally:
        plt.close(fig)
    return ResidualFigure(path, unit, points, edited, np.asarray(counts), np.asarray(edges), int(zk.size))
