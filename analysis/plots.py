"""Pictures of collision outcomes and campaigns (matplotlib, each as PNG and PDF).

snapshot            grains of one outcome, coloured by fragment
energy_partition    kinetic, potential and dissipated energy by channel against time
                    (Wada et al. 2007, Fig. 6)
compression         r_g / (r_1 N_lar^1/2) and n_con against E_imp / (n_k E_roll), with
                    eqs. (51) and (56) (Wada et al. 2007, Figs. 7 and 11)
disruption          N_lar / N_total against E_imp / (n_k E_break) (Wada et al. 2007, Fig. 14)
growth_efficiency   <f_gro> against v_col, per model (3D BPCA paper, Fig. 2)
cumulative          <N_cum(<= N)> per model and v_col (3D BPCA paper, Fig. 3)
"""

from __future__ import annotations

from pathlib import Path

import numpy as np


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _save(fig, path) -> list[Path]:
    out = []
    for suffix in (".png", ".pdf"):
        p = Path(path).with_suffix(suffix)
        fig.savefig(p, dpi=120)
        out.append(p)
    _pyplot().close(fig)
    return out


def snapshot(path, x: np.ndarray, labels: np.ndarray, title: str = "",
             radius: float | None = None) -> list[Path]:
    """Projections x-y and x-z of the grains, drawn to scale when ``radius`` is given:
    the largest fragment blue, the next nine in their own colours, the rest grey."""
    plt = _pyplot()
    sizes = np.bincount(labels)
    rank = np.empty_like(sizes)
    rank[np.argsort(sizes)[::-1]] = np.arange(len(sizes))
    colour = np.minimum(rank[labels], 10)
    fig, axes = plt.subplots(1, 2, figsize=(10, 5), constrained_layout=True)
    order = np.argsort(colour, kind="stable")      # the largest first, fragments on top
    um = (x[order] - x.mean(axis=0)) * 1e6
    dots = []
    for ax, (i, j, name) in zip(axes, [(0, 1, "y"), (0, 2, "z")]):
        dots.append(ax.scatter(um[:, i], um[:, j], c=colour[order], cmap="tab10", s=4, vmin=0,
                               vmax=10, edgecolors="k", linewidths=0.2))
        ax.set_xlabel("x (micron)")
        ax.set_ylabel(f"{name} (micron)")
        ax.set_aspect("equal")
    fig.suptitle(title + f"\n{len(sizes)} fragments; largest {sizes.max()} grains (blue)")
    if radius:
        fig.canvas.draw()                      # final axes sizes, then grains at their size
        for ax, dot in zip(axes, dots):
            points_per_um = ax.get_window_extent().width * 72 / fig.dpi / np.ptp(ax.get_xlim())
            dot.set_sizes([(2 * radius * 1e6 * points_per_um) ** 2])
    return _save(fig, path)


def energy_partition(path, time: np.ndarray, budget: dict, e_imp: float, title: str = ""):
    """Energies over E_imp: kinetic, potential change, dissipation by channel, and the sum."""
    from .thermo import CHANNELS

    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
    t = np.asarray(time) * 1e9
    ax.plot(t, budget["kinetic"] / e_imp, label="kinetic (with rotation)", lw=2)
    ax.plot(t, (budget["potential"] - budget["potential"][0]) / e_imp, label="potential - U(0)")
    for name in CHANNELS:
        if np.any(budget[name] != 0):
            ax.plot(t, budget[name] / e_imp, label=f"dissipated: {name}")
    ax.plot(t, (budget["total"] - budget["total"][0]) / e_imp, "k:", label="total - E(0)")
    ax.set_xlabel("time (ns)")
    ax.set_ylabel("energy / E_imp")
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=9)
    return _save(fig, path)


def compression(path, rows: list[dict]):
    """r_g / (r_1 sqrt(N_lar)) and n_con against E_imp / (n_k E_roll), one point per run."""
    plt = _pyplot()
    x = np.array([r["E_imp_over_nk_Eroll"] for r in rows], dtype=float)
    rg = np.array([r["gyration_radius_largest"] / (r["radius"] * np.sqrt(r["n_largest"]))
                   for r in rows])
    ncon = np.array([r["contacts_per_particle"] for r in rows])
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4.5), constrained_layout=True)
    e = np.logspace(np.log10(max(x.min(), 1e-3)) - 0.5, np.log10(x.max()) + 0.5, 50)
    a.loglog(x, rg, "o")
    a.loglog(e, 0.84 * e ** -0.12, "0.6", label="eq. (51), 2D BCCA")
    a.set_ylabel("r_g / (r_1 N_lar^1/2)")
    b.loglog(x, ncon - 1, "o")
    b.loglog(e, e ** 0.75, "0.6", label="eq. (56), 2D BCCA")
    b.set_ylabel("n_con - 1")
    for ax in (a, b):
        ax.set_xlabel("E_imp / (n_k E_roll)")
        ax.legend()
    return _save(fig, path)


def disruption(path, rows: list[dict]):
    """N_lar / N_total against E_imp / (n_k E_break), with the DT recipe's 3 and 10."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 4.5), constrained_layout=True)
    x = [r["E_imp_over_nk_Ebreak"] for r in rows]
    y = [r["n_largest"] / r["n_total"] for r in rows]
    ax.semilogx(x, y, "o")
    for mark, text in [(3, "loss of one grain"), (10, "catastrophic")]:
        ax.axvline(mark, color="0.6", ls=":")
        ax.text(mark, 0.02, text, rotation=90, fontsize=8)
    ax.set_xlabel("E_imp / (n_k E_break)")
    ax.set_ylabel("N_lar / N_total")
    ax.set_ylim(0, 1.05)
    return _save(fig, path)


def growth_efficiency(path, curves: dict, thresholds: dict):
    """<f_gro> against v_col for each model; ``curves[model] = (v, mean f_gro)``."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 4.5), constrained_layout=True)
    for model, (v, f) in curves.items():
        line, = ax.semilogx(v, f, "o-", label=model)
        if thresholds.get(model):
            ax.axvline(thresholds[model], color=line.get_color(), ls=":")
    ax.axhline(0, color="0.6", lw=0.8)
    ax.set_xlabel("v_col (m/s)")
    ax.set_ylabel("<f_gro>")
    ax.legend()
    return _save(fig, path)


def cumulative(path, curves: dict):
    """<N_cum(<= N)> against N; ``curves[label] = (N, mean N_cum)``."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 4.5), constrained_layout=True)
    for label, (n, c) in curves.items():
        c = np.asarray(c, dtype=float)
        ax.loglog(n, np.where(c > 0, c, np.nan), drawstyle="steps-post", label=label)
    ax.set_xlabel("N")
    ax.set_ylabel("<N_cum(<= N)>")
    ax.legend(fontsize=8)
    return _save(fig, path)
