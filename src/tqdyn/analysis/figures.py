"""Figures of analysis results (matplotlib, imported lazily: an optional
dependency, `pip install tqdyn[plot]`).

The force budget, and the figures of ``tqdyn report``
(:mod:`tqdyn.workflows.report`): pointing-law errors, control, actuation
per axis, arm lengths, breathing angles, range ASDs, orbit deviations.
Every report figure is written as PNG and PDF (:data:`FIGURE_FORMATS`);
time axes in days since the epoch in the file's time scale (``time_scale``:
"TT" geocentric, the default, "TDB" heliocentric).
matplotlib is imported only inside the plotting functions (Agg backend).
"""

from __future__ import annotations

import os
import secrets
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .._choices import MAX_LISTED, allowed as allowed_names, did_you_mean
from ..constellation.indices import Sat
from . import spectra
from .metrics import BREATHING_BAND_DEG, AsdResult, common_rows, times_s
from .pointing_study import PointingStudy

__all__ = [
    "FIGURE_FORMATS",
    "SAT_COLORS",
    "check_figure_path",
    "figure_extensions",
    "plot_actuation",
    "plot_arms",
    "plot_asd",
    "plot_breathing",
    "plot_common_self_gravity",
    "plot_control",
    "plot_deviations",
    "plot_extreme",
    "plot_force_budget",
    "plot_pointing",
]

#: File formats every figure is written in.
FIGURE_FORMATS = ("png", "pdf")
_DPI = 130


def _pyplot():
    try:
        import matplotlib
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise ImportError("plotting needs matplotlib: pip install 'tqdyn[plot]'") from exc
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_force_budget(budget, t_s, path, title: str = "") -> None:
    """|a| of every term along the orbit (max over satellites) against time.

    budget: list of TermBudget (series (n_t, n_sat) [m/s^2]); t_s: (n_t,)
    seconds since the epoch; path: a file name whose extension is one of
    :func:`figure_extensions` (checked first by :func:`check_figure_path`).
    The figure is written atomically: to a temporary file next to ``path``,
    then renamed over it, so a failure leaves no partial file and an existing
    ``path`` untouched.
    """
    path = Path(path)
    ext = check_figure_path(path)
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(10, 5.5))
    days = np.asarray(t_s) / 86400.0
    colors = plt.cm.tab20(np.linspace(0, 1, 20))
    for k, term in enumerate(sorted(budget, key=lambda b: -b.max)):
        ax.semilogy(days, term.series.max(axis=1), label=term.name, color=colors[k % 20],
                    linestyle=("-", "--")[(k // 20) % 2])
    ax.set_xlabel("time since epoch [days]")
    ax.set_ylabel("|acceleration| [m/s$^2$]")
    if title:
        ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    fig.tight_layout()
    try:
        _savefig_atomic(fig, path, ext, dpi=120)
    finally:
        plt.close(fig)


def figure_extensions() -> tuple[str, ...]:
    """File extensions matplotlib can write (``png``, ``pdf``, ``svg``, ...), sorted."""
    _pyplot()
    from matplotlib.backend_bases import FigureCanvasBase

    return tuple(sorted(FigureCanvasBase.get_supported_filetypes()))


def check_figure_path(path, option: str = "--plot", formats: Sequence[str] | None = None) -> str:
    """Check, before any work, that a figure can be written at ``path``; returns
    its format (the extension, lower case).

    Raises ValueError ``"<option>: <path> <problem>; allowed: <what>"`` when the
    extension is missing or not one of ``formats`` (default :func:`figure_extensions`), the path is a
    directory, or its directory is missing, not a directory or not writable
    (tried by creating and removing a temporary file in it); ImportError when
    matplotlib is missing.
    """
    shown = repr(str(path))
    path = Path(path)
    allowed = tuple(formats) if formats is not None else figure_extensions()
    ext = path.suffix[1:].lower()
    exts = sorted(allowed)
    if len(", ".join(f".{e}" for e in exts)) > MAX_LISTED:  # too many to give whole: the usual ones first
        common = ("png", "pdf", "svg")
        exts.sort(key=lambda e: (e not in common, common.index(e) if e in common else 0, e))
    endings = allowed_names([f".{e}" for e in exts], noun="extensions")
    if str(path) in ("", ".") or path.is_dir():
        raise ValueError(f"{option}: {shown} is a directory, not a file name; allowed: a file name ending in {endings}")
    if ext not in allowed:
        problem = "has no file extension" if not ext else (f"has an unsupported extension .{path.suffix[1:]}"
                                                            + did_you_mean(ext, allowed, quote=lambda e: f"'.{e}'"))
        raise ValueError(f"{option}: {shown} {problem}; allowed: a file name ending in {endings}")
    parent = path.parent
    if not parent.exists():
        raise ValueError(f"{option}: {shown} is in a directory that does not exist ({str(parent)!r}); "
                         "allowed: a file in an existing, writable directory")
    if not parent.is_dir():
        raise ValueError(f"{option}: {shown} is in {str(parent)!r}, which is not a directory; "
                         "allowed: a file in an existing, writable directory")
    try:
        fd, probe = _open_temporary(path)
    except OSError as exc:
        raise ValueError(f"{option}: {shown} cannot be written in {str(parent)!r} ({exc.strerror or exc}); "
                         "allowed: a file in an existing, writable directory") from None
    os.close(fd)
    os.unlink(probe)
    return ext


def _open_temporary(path: Path) -> tuple[int, Path]:
    """A new hidden temporary file next to ``path`` (mode 0o666 less the umask): (fd, its path)."""
    for _ in range(100):
        tmp = path.with_name(f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp")
        try:
            return os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666), tmp
        except FileExistsError:
            continue
    raise FileExistsError(f"no free temporary file name next to {path}")  # pragma: no cover


def _savefig_atomic(fig, path: Path, fmt: str, **kwargs) -> None:
    """``fig.savefig`` to a temporary file next to ``path``, then rename it over ``path``
    (:func:`tqdyn.formats.atomic.replacing`); on any failure the temporary file is removed and
    ``path`` left as it was; a failed write (a full disk) raises
    :class:`tqdyn.formats.trajectory.OutputIOError` (one line)."""
    from ..formats.atomic import replacing

    with replacing(Path(path), "the figure") as tmp:
        fig.savefig(tmp, format=fmt, **kwargs)


def _save(fig, out_dir: Path, stem: str) -> list[Path]:
    plt = _pyplot()
    paths = []
    fig.tight_layout()
    for ext in FIGURE_FORMATS:
        p = out_dir / f"{stem}.{ext}"
        fig.savefig(p, dpi=_DPI)
        paths.append(p)
    plt.close(fig)
    return paths


def _stride(n: int, target: int = 4000) -> int:
    return max(1, n // target)


def _days(t):
    return np.asarray(t) / 86400.0


def _time_label(time_scale: str = "TT") -> str:
    return f"time since epoch [days, {time_scale}]"


def _time_scale_of(traj) -> str:
    ref = getattr(traj, "reference", None)
    return ref.time_scale if ref is not None else str(traj.attrs.get("time_scale", "TT"))


#: Line colour of Sat1, Sat2, Sat3 in every figure (matplotlib names).
SAT_COLORS = ("tab:blue", "tab:orange", "tab:green")


def plot_pointing(study: PointingStudy, out_dir: Path, stem: str, title: str, time_scale: str = "TT") -> list[Path]:
    """Fig. 5: per-beam, X_S and theta errors [rad] of each approximate law vs the iterative law
    against time (days since the epoch in ``time_scale``)."""
    plt = _pyplot()
    laws = list(study.laws)
    fig, axes = plt.subplots(len(laws), 1, figsize=(8, 2.6 * len(laws) + 0.6), sharex=True, squeeze=False)
    k = _stride(study.t.size)
    d = _days(study.t)[::k]
    for ax, law in zip(axes[:, 0], laws):
        c = study.laws[law]
        for s in Sat:
            for m, what in ((0, f"<-{int(s.k)}"), (1, f"<-{int(s.j)}")):
                ax.semilogy(d, np.maximum(c.per_beam[::k, s.index, m], 1e-30), lw=0.7, color=SAT_COLORS[s.index],
                            ls="-" if m == 0 else "--", label=f"beam Sat{int(s)} {what}")
        ax.semilogy(d, np.maximum(c.x_s[::k].max(axis=1), 1e-30), color="k", lw=0.9, ls=":", label="X_S (max over sats)")
        ax.semilogy(d, np.maximum(c.theta[::k].max(axis=1), 1e-30), color="0.45", lw=0.9, ls="-.",
                    label="theta (max over sats)")
        ax.set_ylabel("error vs iterative [rad]")
        ax.set_title(f"{law}: max per beam {c.max_per_beam:.2e} rad, X_S {c.max_x_s:.1e}, theta {c.max_theta:.1e}",
                     fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    axes[0, 0].legend(fontsize=6.5, ncol=4, loc="center right")
    axes[-1, 0].set_xlabel(_time_label(time_scale))
    fig.suptitle(title, fontsize=10)
    return _save(fig, out_dir, stem)


def plot_control(traj, out_dir: Path, stem: str, title: str, sat: Sat = Sat.S1) -> list[Path]:
    """Figs. 7/8: TM suspension acceleration [m/s^2] and angular acceleration
    [rad/s^2] (components in OA_l) of both TMs of ``sat``, and |A|, |G| of
    every satellite, against time (days since the epoch in the file's time scale)."""
    plt = _pyplot()
    t = times_s(traj)
    k = _stride(t.size)
    d = _days(t)[::k]
    A = traj["tm/a_suspension"][::k]
    W = traj["tm/alpha_suspension"][::k]
    G = np.linalg.norm(traj["sat/a_dragfree"][::k], axis=-1)
    fig, axes = plt.subplots(3, 1, figsize=(8, 8.4), sharex=True)
    comp = ("x", "y", "z")
    for tm, ls in ((0, "-"), (1, "--")):
        for q in range(3):
            axes[0].plot(d, A[:, sat.index, tm, q], ls=ls, lw=0.8, color=f"C{q}", label=f"TM{tm + 1} {comp[q]}")
            axes[1].plot(d, W[:, sat.index, tm, q], ls=ls, lw=0.8, color=f"C{q}", label=f"TM{tm + 1} {comp[q]}")
    axes[0].set_ylabel(f"Sat{int(sat)} suspension\nacceleration [m/s$^2$], OA$_l$")
    axes[1].set_ylabel(f"Sat{int(sat)} TM angular\nacceleration [rad/s$^2$], OA$_l$")
    for s in Sat:
        axes[2].semilogy(d, np.linalg.norm(A[:, s.index], axis=-1).max(axis=-1), color=SAT_COLORS[s.index], lw=0.8,
                         label=f"max$_l$ |A| Sat{int(s)}")
        axes[2].semilogy(d, G[:, s.index], color=SAT_COLORS[s.index], lw=0.8, ls="--", label=f"|G| Sat{int(s)}")
    axes[2].set_ylabel("[m/s$^2$]")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, ncol=3, loc="best")
    axes[-1].set_xlabel(_time_label(_time_scale_of(traj)))
    fig.suptitle(title, fontsize=10)
    return _save(fig, out_dir, stem)


def plot_breathing(series: Sequence[tuple[str, np.ndarray, np.ndarray, str]], out_dir: Path, stem: str, title: str,
                   band: bool = True, band_deg: tuple | None = BREATHING_BAND_DEG, band_label: str = "",
                   time_scale: str = "TT") -> list[Path]:
    """Fig. 9: breathing angles [deg] against time (days since the epoch in
    ``time_scale``); ``series`` of (label, t [s], alpha (N, 3) [rad], line
    style); the band ``band_deg`` (min, max) [deg] (default 60 +- 0.1 deg,
    TianQin's) if ``band``, labelled ``band_label`` after its values."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.4))
    for label, t, alpha, ls in series:
        k = _stride(t.size)
        for s in Sat:
            ax.plot(_days(t)[::k], np.degrees(alpha[::k, s.index]), ls=ls, lw=0.9, color=SAT_COLORS[s.index],
                    label=f"alpha_{int(s)} {label}")
    if band and band_deg is not None:
        mid, half = 0.5 * (band_deg[0] + band_deg[1]), 0.5 * (band_deg[1] - band_deg[0])
        for y in band_deg:
            ax.axhline(y, color="red", lw=0.8, ls=":")
        ax.axhspan(*band_deg, color="red", alpha=0.04, label=f"{mid:g} +- {half:g} deg" + (f" ({band_label})"
                                                                                         if band_label else ""))
    ax.set_xlabel(_time_label(time_scale))
    ax.set_ylabel("breathing angle [deg]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    ax.set_title(title, fontsize=10)
    return _save(fig, out_dir, stem)


def _length_unit(length_m: float) -> tuple[float, str]:
    """(scale [m], name) of a readable unit for lengths of about ``length_m``."""
    return (1e9, "10$^9$ m") if length_m >= 1e9 else (1e3, "km")


def plot_arms(t, length, rate, out_dir: Path, stem: str, title: str, nominal: tuple[float, str] | None = None,
              band: tuple | None = None, rate_max: float | None = None, time_scale: str = "TT") -> list[Path]:
    """Arm lengths and their rates against time (days since the epoch in
    ``time_scale``): t (N,) [s]; length (N, 3) [m] of the arms L_12, L_23,
    L_31; rate (N, 3) [m/s] or None.  ``nominal`` (length [m], label) draws
    the design arm, ``band`` (min, max) [m] the allowed range, ``rate_max``
    [m/s] the allowed |dL/dt|.  Lengths in 10^9 m for arms >= 1e9 m (LISA,
    Taiji), else in km (TianQin); rates in m/s."""
    plt = _pyplot()
    t = np.asarray(t)
    rows = 2 if rate is not None else 1
    fig, axes = plt.subplots(rows, 1, figsize=(8, 3.4 * rows + 0.6), sharex=True, squeeze=False)
    axes = axes[:, 0]
    k = _stride(t.size)
    d = _days(t)[::k]
    scale, unit = _length_unit(float(np.nanmean(length)))
    names = ("L$_{12}$", "L$_{23}$", "L$_{31}$")
    for a in range(3):
        axes[0].plot(d, length[::k, a] / scale, color=SAT_COLORS[a], lw=1.0, label=names[a])
    if nominal is not None:
        axes[0].axhline(nominal[0] / scale, color="k", lw=0.9, ls="--", label=nominal[1])
    if band is not None:
        for y in band:
            axes[0].axhline(y / scale, color="red", lw=0.8, ls=":")
    axes[0].set_ylabel(f"arm length [{unit}]")
    axes[0].ticklabel_format(axis="y", useOffset=False)
    if rate is not None:
        for a in range(3):
            axes[1].plot(d, rate[::k, a], color=SAT_COLORS[a], lw=1.0, label=f"d{names[a]}/dt")
        if rate_max is not None:
            for y in (-rate_max, rate_max):
                axes[1].axhline(y, color="red", lw=0.8, ls=":")
            axes[1].plot([], [], color="red", lw=0.8, ls=":", label=f"+- {rate_max:g} m/s")
        axes[1].set_ylabel("arm-length rate [m/s]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7.5, ncol=4, loc="best")
    axes[-1].set_xlabel(_time_label(time_scale))
    fig.suptitle(title, fontsize=10)
    return _save(fig, out_dir, stem)


def plot_actuation(traj, out_dir: Path, stem: str, title: str) -> list[Path]:
    """The actuation of a coupled run per satellite and axis against time
    (days since the epoch in the file's time scale): left, the TM suspension
    acceleration A_l [m/s^2] of TM 1 (solid) and TM 2 (dashed), components
    in OA_l (x = X_OA_l, the optical axis; the TMs' sensitive axes from
    :attr:`Trajectory.spacecraft` are named in the legend); right, the
    drag-free acceleration G [m/s^2] of the satellite, components in its body
    frame S (x = X_S towards the incentre, z = Z_S the constellation normal),
    and |G|."""
    plt = _pyplot()
    t = times_s(traj)
    k = _stride(t.size)
    d = _days(t)[::k]
    A = traj["tm/a_suspension"][::k]
    G = traj["sat/a_dragfree"][::k]
    G_S = np.einsum("nsij,nsj->nsi", traj["sat/T_S_I"][::k], G)
    craft = traj.spacecraft
    sens = craft.sensitive_axes if craft is not None else np.eye(3)[[0, 0]]
    n_sat = A.shape[1]
    fig, axes = plt.subplots(n_sat, 2, figsize=(11, 2.6 * n_sat + 0.9), sharex=True, squeeze=False)
    comp = ("x", "y", "z")
    for s in range(n_sat):
        ax = axes[s, 0]
        for tm, ls in ((0, "-"), (1, "--")):
            for q in range(3):
                tag = " (sensitive)" if np.array_equal(sens[tm], np.eye(3)[q]) else ""
                ax.plot(d, A[:, s, tm, q], ls=ls, lw=0.9, color=f"C{q}", label=f"TM{tm + 1} {comp[q]}{tag}")
        ax.set_ylabel(f"Sat{s + 1}: A$_l$ [m/s$^2$]\nin OA$_l$")
        ax = axes[s, 1]
        for q, name in enumerate(("X$_S$", "Y$_S$", "Z$_S$")):
            ax.plot(d, G_S[:, s, q], lw=0.9, color=f"C{q}", label=f"G . {name}")
        ax.plot(d, np.linalg.norm(G[:, s], axis=-1), lw=0.8, color="k", ls=":", label="|G|")
        ax.set_ylabel(f"Sat{s + 1}: G [m/s$^2$]\nin S")
    for ax in axes.ravel():
        ax.grid(True, alpha=0.3)
    for ax in axes[0]:  # the same styles in every row: one legend per column, above it
        ax.legend(fontsize=7, ncol=3, loc="lower center", bbox_to_anchor=(0.5, 1.02), frameon=False)
    for ax in axes[-1]:
        ax.set_xlabel(_time_label(_time_scale_of(traj)))
    fig.suptitle(f"{title}\nleft: TM suspension in OA$_l$ (TM1 solid, TM2 dashed; x = X$_{{OA_l}}$, the optical axis); "
                 "right: drag-free acceleration of the satellite in S", fontsize=9.5)
    return _save(fig, out_dir, stem)


def plot_asd(curves: Sequence[tuple[str, AsdResult, dict]], out_dir: Path, stem: str, title: str) -> list[Path]:
    """Figs. 6/10/11: range ASDs [m/Hz^1/2] with the requirement, the band
    [0.1 mHz, Nyquist] and the lowest reliable frequency marked."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 5))
    f_all = np.concatenate([c[1].f for c in curves])
    f_rel = max(c[1].f_reliable for c in curves)
    for label, res, style in curves:
        ax.loglog(res.f, res.asd, label=label, **{"lw": 1.0, **style})
    fr = np.geomspace(f_all.min(), f_all.max(), 400)
    ax.loglog(fr, spectra.requirement_asd(fr), color="k", ls="--", lw=1.2,
              label="requirement 0.3 pm/Hz$^{1/2}$ $\\sqrt{1+(7\\,\\mathrm{mHz}/f)^4}$")
    ax.axvspan(fr[0], 1e-4, color="0.85", alpha=0.5, lw=0)
    if f_rel > 1e-4:
        ax.axvline(f_rel, color="0.4", ls=":", lw=0.8)
        ax.text(f_rel, ax.get_ylim()[0], " lowest reliable bin", rotation=90, fontsize=7, va="bottom", color="0.3")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("range ASD [m/Hz$^{1/2}$]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7.5)
    ax.set_title(title, fontsize=10)
    return _save(fig, out_dir, stem)


def plot_deviations(series: Sequence[tuple[str, np.ndarray, np.ndarray, str, str]], out_dir: Path, stem: str,
                    title: str, ylabel: str = "|r - r$_{ref}$| [m]", log: bool = False,
                    hline: tuple[float, str] | None = None, ymin: float | None = None,
                    time_scale: str = "TT") -> list[Path]:
    """Deviation-type curves against time (days since the epoch in
    ``time_scale``): ``series`` of (label, t [s], y (N,), color, line style);
    ``hline`` (value, label) draws a reference level; ``ymin`` the lower y
    limit."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.6))
    for label, t, y, color, ls in series:
        k = _stride(t.size)
        (ax.semilogy if log else ax.plot)(_days(t)[::k], y[::k], color=color, ls=ls, lw=1.0, label=label)
    if hline is not None:
        ax.axhline(hline[0], color="red", lw=1.0, ls="-.", label=hline[1])
    if ymin is not None:
        ax.set_ylim(bottom=ymin)
    ax.set_xlabel(_time_label(time_scale))
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    ax.set_title(title, fontsize=10)
    return _save(fig, out_dir, stem)


def plot_common_self_gravity(curves: Sequence[tuple[str, str, np.ndarray, np.ndarray, np.ndarray]],
                             out_dir: Path) -> list[Path]:
    """Sec. V.B.2 (``common-self-gravity``): per common self-gravity direction
    the orbit deviation from the gravity orbit [m] and the breathing-angle
    change [deg], both the maximum over the satellites, against time;
    ``curves`` of (direction label, e.g. "+x", legend tag, t [s], deviation
    (N,) [m], angle change (N,) [deg]), in the order of
    :data:`tqdyn.workflows.studies.SG_DIRECTIONS`."""
    plt = _pyplot()
    fig, axes = plt.subplots(2, 1, figsize=(8, 7.5), sharex=True)
    for k, (label, tag, t, dev_max, dalpha_max) in enumerate(curves):
        kk = _stride(t.size)
        style = {"color": f"C{k // 2}", "ls": "-" if label[0] == "+" else "--", "lw": 1.2}
        axes[0].semilogy(_days(t)[::kk], np.maximum(dev_max[::kk], 1e-3), label=f"{label}{tag}", **style)
        axes[1].plot(_days(t)[::kk], dalpha_max[::kk], label=f"{label}{tag}", **style)
    axes[0].set_ylabel("max over satellites |r - r$_{gravity}$| [m]")
    axes[1].set_ylabel("max over satellites\n|alpha - alpha$_{gravity}$| [deg]")
    axes[1].set_xlabel("time since epoch [days, TT]")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8, ncol=3, title="common self-gravity 1e-9 m/s$^2$ along (S frame)", title_fontsize=8)
    fig.suptitle("Common self-gravity: orbit deviation and breathing-angle change vs the gravity orbit", fontsize=10)
    return _save(fig, out_dir, "common-self-gravity")


def plot_extreme(te, ae, tg, ag, out_dir):
    """Fig. 9: breathing angles of the extreme case and of the gravity orbit
    vs the 60 +- 0.1 deg band, and their difference [deg]."""
    plt = _pyplot()
    fig, axes = plt.subplots(2, 1, figsize=(8, 7), sharex=True, gridspec_kw={"height_ratios": [3, 2]})
    _, ia, ib = common_rows(te, tg)
    k = _stride(te.size)
    for s in Sat:
        c = SAT_COLORS[s.index]
        axes[0].plot(_days(te)[::k], np.degrees(ae[::k, s.index]), color=c, lw=0.9, label=f"alpha_{int(s)} extreme")
        axes[0].plot(_days(tg)[::k], np.degrees(ag[::k, s.index]), color=c, lw=0.7, ls=":",
                     label=f"alpha_{int(s)} gravity orbit")
        axes[1].plot(_days(te[ia])[::k], np.degrees(ae[ia, s.index] - ag[ib, s.index])[::k], color=c, lw=1.0,
                     label=f"alpha_{int(s)}")
    for y in BREATHING_BAND_DEG:
        axes[0].axhline(y, color="red", lw=1.0, ls="-.")
    axes[0].axhspan(*BREATHING_BAND_DEG, color="red", alpha=0.04, label="60 +- 0.1 deg")
    axes[0].set_ylabel("breathing angle [deg]")
    axes[1].set_ylabel("extreme - gravity orbit [deg]")
    axes[1].set_xlabel("time since epoch [days, TT]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=7, ncol=4, loc="upper left")
    axes[1].legend(fontsize=7, ncol=3, loc="upper left")
    fig.suptitle("Fig. 9: breathing angles, extreme self-gravity 1e-9 m/s$^2$ (Sat1 +flight, Sat2 -flight, "
                 "Sat3 +flight)", fontsize=10)
    return _save(fig, out_dir, "fig9-extreme-breathing")
