"""Figures of analysis results (matplotlib, imported lazily: an optional
dependency, `pip install tqdyn[plot]`)."""

from __future__ import annotations

import numpy as np

__all__ = ["plot_force_budget"]


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
    seconds since the epoch; path: PNG or PDF file name.
    """
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
    fig.savefig(path, dpi=120)
    plt.close(fig)
