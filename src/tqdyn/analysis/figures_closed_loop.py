"""Figures of the closed loop (``tqdyn report --closed-loop``): budget stacks, loop gains with margins,
the residual TM acceleration against the mission's requirement, the single-link displacement budget
(TTL per link, readout, TM acceleration, total) and one link's TTL by source.

matplotlib is imported lazily (:func:`tqdyn.analysis.figures._pyplot`); every figure is written as PNG
and PDF (:data:`tqdyn.analysis.figures.FIGURE_FORMATS`) into ``out_dir`` as ``<stem>.png`` /
``<stem>.pdf``; the functions return the paths.  Frequencies in Hz on log axes; ASDs one-sided in
(output unit)/Hz^1/2 (:mod:`tqdyn.closedloop.noise`); phases in deg.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .figures import _pyplot, _save

__all__ = ["plot_budget_stack", "plot_link_budget", "plot_loop_gains", "plot_residual_acceleration",
           "plot_ttl_sources"]

_SOURCE_STYLES = ("-", "--", ":", "-.")


def _unit_tex(unit: str) -> str:
    return unit.replace("m/s^2", "m s$^{-2}$").replace("rad/s^2", "rad s$^{-2}$")


def plot_budget_stack(f, budget, sources: Sequence[str], outputs: Sequence[str], units: Sequence[str], out_dir: Path,
                      stem: str, title: str, requirement=None, floor: float = 1e-6) -> list[Path]:
    """One panel per output: the ASD contribution of every source and the total (power sum) against
    frequency, log-log; the requirement (an array over ``f``) on the panels whose unit is m/s^2.

    f (n_f,) [Hz]; budget (n_out, n_source, n_f) [output unit/Hz^1/2]; sources, outputs, units: names
    of its axes; a source below ``floor`` x the output's total everywhere is left out of the panel."""
    plt = _pyplot()
    n = len(outputs)
    ncol = 2 if n > 1 else 1
    nrow = math.ceil(n / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(5.2 * ncol, 3.6 * nrow + 0.6), squeeze=False)
    colors = plt.cm.tab20(np.linspace(0, 1, 20))
    for k, (ax, out, unit) in enumerate(zip(axes.flat, outputs, units)):
        total = np.sqrt(np.sum(budget[k] ** 2, axis=0))
        for j, s in enumerate(sources):
            y = budget[k, j]
            if not np.any(y > floor * total):
                continue
            ax.loglog(f, np.where(y > 0, y, np.nan), color=colors[j % 20], ls=_SOURCE_STYLES[(j // 10) % 4], lw=0.9,
                      label=s)
        ax.loglog(f, total, color="k", lw=1.6, label="total")
        if requirement is not None and unit == "m/s^2":
            ax.loglog(f, requirement, color="k", ls="--", lw=1.2, label="requirement")
        ax.set_ylim(max(total.max() * 1e-7, np.nanmin(total) * 1e-2), total.max() * 5)
        ax.set_title(out, fontsize=9)
        ax.set_ylabel(f"ASD [{_unit_tex(unit)}/Hz$^{{1/2}}$]", fontsize=8)
        ax.set_xlabel("frequency [Hz]", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6, ncol=2)
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    fig.suptitle(title, fontsize=9.5)
    return _save(fig, out_dir, stem)


def plot_loop_gains(f, gains: Sequence[tuple], out_dir: Path, stem: str, title: str) -> list[Path]:
    """Bode magnitude and phase of loop-at-a-time gains L, with the unity-gain crossover (phase margin)
    and the gain-margin frequency marked.

    f (n_f,) [Hz]; gains: (label, L (n_f,) complex, margins) with margins a
    :class:`tqdyn.closedloop.budget.LoopMargins` (crossover ``f_phase_margin`` [Hz], ``phase_margin``
    [deg], ``gain_margin`` (factor), ``f_gain_margin`` [Hz])."""
    plt = _pyplot()
    fig, (am, ap) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    for k, (label, L, m) in enumerate(gains):
        c = f"C{k % 10}"
        mag = np.abs(L)
        ph = np.degrees(np.unwrap(np.angle(L)))
        ph -= 360.0 * np.round(ph[np.argmin(np.abs(f - m.f_phase_margin))] / 360.0) if math.isfinite(
            m.f_phase_margin) else 0.0
        gm_db = 20 * math.log10(m.gain_margin) if m.gain_margin > 0 and math.isfinite(m.gain_margin) else float("nan")
        am.loglog(f, mag, color=c, lw=1.1, label=f"{label}: f$_c$ {m.f_phase_margin * 1e3:.3g} mHz, "
                                                   f"PM {m.phase_margin:.1f} deg, GM {gm_db:.1f} dB "
                                                   f"at {m.f_gain_margin * 1e3:.3g} mHz")
        ap.semilogx(f, ph, color=c, lw=1.1)
        if math.isfinite(m.f_phase_margin):
            am.plot(m.f_phase_margin, 1.0, "o", color=c, ms=5)
            ap.plot(m.f_phase_margin, -180.0 + m.phase_margin, "o", color=c, ms=5)
            ap.vlines(m.f_phase_margin, -180.0, -180.0 + m.phase_margin, color=c, lw=2.0, alpha=0.6)
        if math.isfinite(m.f_gain_margin) and m.f_gain_margin > 0:
            ap.plot(m.f_gain_margin, -180.0, "s", color=c, ms=4)
            am.vlines(m.f_gain_margin, 1.0, 1.0 / m.gain_margin if m.gain_margin > 0 else 1.0, color=c, lw=2.0,
                      alpha=0.6)
            am.plot(m.f_gain_margin, 1.0 / m.gain_margin, "s", color=c, ms=4)
    am.axhline(1.0, color="k", lw=0.8, ls="--")
    ap.axhline(-180.0, color="k", lw=0.8, ls="--")
    am.set_ylim(1e-4, 1e8)
    ap.set_ylim(-360, 0)
    am.set_ylabel("|L|", fontsize=9)
    ap.set_ylabel("phase of L [deg]", fontsize=9)
    ap.set_xlabel("frequency [Hz]", fontsize=9)
    for ax in (am, ap):
        ax.grid(True, which="both", alpha=0.3)
        ax.tick_params(labelsize=8)
    am.legend(fontsize=6.5)
    fig.suptitle(f"{title}\ndots: unity-gain crossover and phase margin (bar above -180 deg); squares: phase "
                 "crossover and the (lower) gain margin 1/|L|", fontsize=9)
    return _save(fig, out_dir, stem)


def plot_residual_acceleration(f, curves: Sequence[tuple], requirement, out_dir: Path, stem: str, title: str,
                               requirement_label: str, tm_force=None, band=None) -> list[Path]:
    """The residual TM acceleration along the sensitive axes [m/s^2/Hz^1/2] against the requirement.

    f (n_f,) [Hz]; curves: (label, ASD (n_f,)); requirement (n_f,) and its legend label; tm_force
    (n_f,): the TM force-noise input (dotted); band: (f_lo, f_hi) [Hz] of the mission's band (shaded
    outside)."""
    plt = _pyplot()
    fig, (ax, ar) = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True, gridspec_kw={"height_ratios": (2.2, 1)})
    for k, (label, y) in enumerate(curves):
        ax.loglog(f, y, color=f"C{k}", lw=1.3 if k == 0 else 1.0, ls="-" if k == 0 else "--", label=label)
        ar.loglog(f, y / requirement, color=f"C{k}", lw=1.3 if k == 0 else 1.0, ls="-" if k == 0 else "--")
    if tm_force is not None:
        ax.loglog(f, tm_force, color="0.4", ls=":", lw=1.2, label="TM force-noise input (tm_force)")
    ax.loglog(f, requirement, color="k", ls="--", lw=1.4, label=requirement_label)
    ar.axhline(1.0, color="k", ls="--", lw=1.0)
    if band is not None:
        for a in (ax, ar):
            a.axvspan(f[0], band[0], color="0.85", alpha=0.5, lw=0)
            if band[1] < f[-1]:
                a.axvspan(band[1], f[-1], color="0.85", alpha=0.5, lw=0)
    ax.set_ylabel("residual TM acceleration [m s$^{-2}$/Hz$^{1/2}$]", fontsize=9)
    ar.set_ylabel("/ requirement", fontsize=9)
    ar.set_xlabel("frequency [Hz]", fontsize=9)
    for a in (ax, ar):
        a.grid(True, which="both", alpha=0.3)
        a.tick_params(labelsize=8)
    ax.legend(fontsize=7.5)
    ax.set_title(title, fontsize=9.5)
    return _save(fig, out_dir, stem)


def _shade_outside(axes, f, band) -> None:
    if band is None:
        return
    for a in axes:
        if band[0] > f[0]:
            a.axvspan(f[0], band[0], color="0.85", alpha=0.5, lw=0)
        if band[1] < f[-1]:
            a.axvspan(band[1], f[-1], color="0.85", alpha=0.5, lw=0)


def plot_link_budget(f, links: Sequence[str], ttl, readout, tm_acceleration, total, requirement, out_dir: Path,
                     stem: str, title: str, requirement_label: str, allocation=None, band=None) -> list[Path]:
    """The single-link displacement budget of every link: upper panel the TTL ASD per link (colours), the
    total per link (thin, dashed, same colours), the readout noise, the TM acceleration as displacement
    (the largest over the links), the requirement and (optional) a flat TTL ``allocation`` [m/Hz^1/2];
    lower panel total / requirement per link.

    f (n_f,) [Hz]; ttl, tm_acceleration, total (n_link, n_f) and readout (n_f,) [m/Hz^1/2]; requirement
    (n_f,) [m/Hz^1/2] and its legend label; band: (f_lo, f_hi) [Hz] (shaded outside)."""
    plt = _pyplot()
    fig, (ax, ar) = plt.subplots(2, 1, figsize=(8, 6.8), sharex=True, gridspec_kw={"height_ratios": (2.4, 1)})
    for n, link in enumerate(links):
        c = f"C{n % 10}"
        ax.loglog(f, ttl[n], color=c, lw=1.2, label=f"TTL, link {link}")
        ax.loglog(f, total[n], color=c, lw=0.8, ls="--")
        ar.loglog(f, total[n] / requirement, color=c, lw=1.0, label=f"link {link}")
    ax.loglog(f, readout, color="0.45", lw=1.4, label="readout (science interferometer)")
    ax.loglog(f, np.max(tm_acceleration, axis=0), color="0.45", ls=":", lw=1.4,
              label="TM acceleration / $(2\\pi f)^2$ (two TMs)")
    ax.loglog(f, requirement, color="k", ls="--", lw=1.5, label=requirement_label)
    if allocation is not None:
        ax.axhline(allocation, color="k", ls="-.", lw=1.0,
                   label=f"TTL allocation after subtraction {allocation * 1e12:g} pm/Hz$^{{1/2}}$")
    ax.plot([], [], color="0.3", lw=0.8, ls="--", label="total per link (dashed)")
    ar.axhline(1.0, color="k", ls="--", lw=1.0)
    _shade_outside((ax, ar), f, band)
    ax.set_ylabel("single-link ASD [m/Hz$^{1/2}$]", fontsize=9)
    ar.set_ylabel("total / requirement", fontsize=9)
    ar.set_xlabel("frequency [Hz]", fontsize=9)
    for a in (ax, ar):
        a.grid(True, which="both", alpha=0.3)
        a.tick_params(labelsize=8)
    ax.legend(fontsize=6.5, ncol=2)
    ax.set_title(title, fontsize=9)
    return _save(fig, out_dir, stem)


def plot_ttl_sources(f, ttl, sources: Sequence[str], readout, requirement, out_dir: Path, stem: str, title: str,
                     requirement_label: str, allocation=None, band=None, floor: float = 1e-3) -> list[Path]:
    """One link's TTL ASD by noise source and its total (power sum), with the readout noise, the
    requirement and (optional) a flat TTL ``allocation``; a source below ``floor`` x the TTL total
    everywhere is left out.

    f (n_f,) [Hz]; ttl (n_source, n_f), readout (n_f,), requirement (n_f,) [m/Hz^1/2]; band: (f_lo, f_hi) [Hz]
    (shaded outside)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 5.2))
    total = np.sqrt(np.sum(np.asarray(ttl) ** 2, axis=0))
    shown = [j for j in range(len(sources)) if np.any(ttl[j] > floor * total)]
    for k, j in enumerate(shown):
        y = ttl[j]
        ax.loglog(f, np.where(y > 0, y, np.nan), color=f"C{k % 10}", lw=1.1, ls=_SOURCE_STYLES[(k // 10) % 4],
                  label=sources[j])
    ax.loglog(f, total, color="k", lw=1.8, label="TTL total")
    ax.loglog(f, readout, color="0.45", lw=1.4, label="readout")
    ax.loglog(f, requirement, color="k", ls="--", lw=1.4, label=requirement_label)
    if allocation is not None:
        ax.axhline(allocation, color="k", ls="-.", lw=1.0,
                   label=f"TTL allocation after subtraction {allocation * 1e12:g} pm/Hz$^{{1/2}}$")
    _shade_outside((ax,), f, band)
    ax.set_ylim(max(total.max() * 1e-5, np.nanmin(np.minimum(total, readout)) * 1e-1), total.max() * 5)
    ax.set_ylabel("TTL ASD [m/Hz$^{1/2}$]", fontsize=9)
    ax.set_xlabel("frequency [Hz]", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.tick_params(labelsize=8)
    ax.legend(fontsize=6.5, ncol=2)
    ax.set_title(title, fontsize=9)
    return _save(fig, out_dir, stem)
