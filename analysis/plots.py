"""Pictures of collision outcomes and campaigns (matplotlib, each as PNG and PDF).

outcome             the collision's first and last frame: target and projectile, the impact
                    direction and offset, the largest fragments
timeline            N_lar, fragments, n_con and the energy shares against time
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


#: colours of the largest fragments, largest first; smaller fragments are drawn faint grey
FRAGMENT_COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"]
#: colours of the two bodies at the start, target and projectile
BODY_COLOURS = {1: "#4c72b0", 2: "#dd8452"}


#: the smallest drawn grain, as a fraction of the view: fragments spread far apart stay visible
MIN_DISC = 1.0 / 150
#: from this many grains a picture is drawn as pixels, not as vector shapes (a PDF of 10^5
#: outlined discs takes minutes to write and tens of MB), and the grains lose their outlines
RASTER_FROM = 5000
#: fragments of at most this many grains are also marked at their centre, by a ring of
#: fixed size (by a dot where there are more than RINGS_UP_TO of them), so that they stay
#: visible however far the fragments have spread
MARK_UP_TO = 16
RINGS_UP_TO = 200


def _discs(ax, x, i, j, diameter, colours, alpha=1.0, zorder=1):
    """Grains as circles of ``diameter`` (micron) in the (i, j) projection, in micron,
    the nearest to the viewer (along e_i x e_j) drawn last and brightest, so that a
    body's depth shows."""
    from matplotlib.collections import EllipseCollection
    from matplotlib.colors import to_rgba_array

    if len(x) == 0:
        return
    um = x * 1e6
    depth = um @ np.cross(np.eye(3)[i], np.eye(3)[j])
    order = np.argsort(depth, kind="stable")
    near = (depth - depth.min()) / np.ptp(depth) if np.ptp(depth) > 0 else np.ones(len(x))
    rgba = to_rgba_array(colours, alpha)
    if len(rgba) == 1:
        rgba = np.repeat(rgba, len(x), axis=0)
    rgba[:, :3] *= (0.6 + 0.4 * near)[:, None]
    many = len(x) >= RASTER_FROM
    d = np.full(len(x), diameter)
    ax.add_collection(EllipseCollection(d, d, np.zeros(len(x)), units="xy",
                                        offsets=um[order][:, [i, j]],
                                        offset_transform=ax.transData,
                                        facecolors=rgba[order], edgecolors="k",
                                        linewidths=0.0 if many else 0.3, zorder=zorder,
                                        rasterized=many))


def _mark_small(ax, x, labels, i, j, zorder=1.5) -> int:
    """Rings (dots, when many) of fixed size at the centres of the fragments of at most
    ``MARK_UP_TO`` grains, under the largest fragments; returns how many."""
    sizes = np.bincount(labels)
    small = np.flatnonzero((sizes > 0) & (sizes <= MARK_UP_TO))
    if len(small) == 0:
        return 0
    centre = np.stack([np.bincount(labels, x[:, k] * 1e6, minlength=len(sizes))
                       for k in range(3)], axis=1)[small] / sizes[small, None]
    if len(small) <= RINGS_UP_TO:
        ax.scatter(centre[:, i], centre[:, j], s=18, facecolors="none", edgecolors="k",
                   linewidths=0.6, zorder=zorder)
    else:
        ax.scatter(centre[:, i], centre[:, j], s=2, c="0.2", linewidths=0, zorder=zorder,
                   rasterized=True)
    return len(small)


def _frame_axes(ax, x, i, j, radius, names) -> float:
    """Limits around the grains, equal aspect; returns the diameter to draw them with
    (micron): their own, or MIN_DISC of the view when they spread much farther."""
    um = x * 1e6
    span = max(np.ptp(um[:, i]), np.ptp(um[:, j]))
    diameter = max(2 * radius * 1e6, MIN_DISC * span)
    pad = 0.75 * diameter
    ax.set_xlim(um[:, i].min() - pad, um[:, i].max() + pad)
    ax.set_ylim(um[:, j].min() - pad, um[:, j].max() + pad)
    ax.set_aspect("equal")
    ax.set_xlabel(f"{names[i]} (micron)")
    ax.set_ylabel(f"{names[j]} (micron)")
    if diameter > 2 * radius * 1e6:
        ax.text(0.01, 0.01, f"grains drawn {diameter / (2 * radius * 1e6):.2g}x enlarged",
                transform=ax.transAxes, fontsize=7, color="0.4")
    return diameter


def _when(step, time, t_c) -> str:
    return f"step {step}: t = {time * 1e9:.3g} ns = {time / t_c:.0f} t_c"


def outcome(path, start: np.ndarray, end: np.ndarray, body: np.ndarray, labels: np.ndarray,
            radius: float, dim: int, when: tuple, t_c: float, b: float | None = None,
            title: str = "", departed: np.ndarray | None = None,
            end_label: str = "end") -> list[Path]:
    """The collision at its first and last frame (columns), in x-y and, in 3D, x-z
    (rows), grains to scale. At the start the target and the projectile have their own
    colours, with the impact direction (the projectile moves along -x) and the offset b
    drawn; at the end the five largest fragments have their own colours (grains from the
    projectile in a lighter shade of it) and the others are faint.
    ``when`` = ((step, time in s) of the start, (step, time) of the end); ``departed``
    marks the grains of fragments that departed (drawn where they fly at the end)."""
    plt = _pyplot()
    from matplotlib.colors import to_rgb
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    views = [(0, 1)] if dim == 2 else [(0, 1), (0, 2)]
    fig, axes = plt.subplots(len(views), 2, figsize=(13, 4.6 * len(views)), squeeze=False,
                             constrained_layout=True)
    names = "xyz"
    sizes = np.bincount(labels)
    rank = np.empty_like(sizes)
    rank[np.argsort(sizes, kind="stable")[::-1]] = np.arange(len(sizes))
    grain_rank = rank[labels]
    big = grain_rank < len(FRAGMENT_COLOURS)

    def shade(r, k):           # the fragment's colour; lighter for grains of the projectile
        rgb = np.array(to_rgb(FRAGMENT_COLOURS[r] if r < len(FRAGMENT_COLOURS) else "0.7"))
        return tuple(rgb + 0.5 * (1 - rgb)) if k == 2 else tuple(rgb)
    colours = np.array([shade(r, k) for r, k in zip(grain_rank, body)])
    start = start - start.mean(axis=0)
    end = end - end.mean(axis=0)
    tar, pro = body == 1, body == 2
    for row, (i, j) in enumerate(views):
        a, e = axes[row]
        d = _frame_axes(a, start, i, j, radius, names)
        _discs(a, start, i, j, d, [BODY_COLOURS.get(k, "0.6") for k in body])
        if j == 1:                      # the impact direction and the offset, in x-y
            c_tar, c_pro = start[tar].mean(axis=0) * 1e6, start[pro].mean(axis=0) * 1e6
            span = np.ptp(start[:, 0]) * 1e6
            a.annotate("", xy=(c_pro[0] - 0.3 * span, c_pro[1]), xytext=(c_pro[0], c_pro[1]),
                       arrowprops=dict(arrowstyle="-|>", lw=2, color="k"), zorder=5)
            for c in (c_tar, c_pro):
                a.axhline(c[1], color="k", ls=":", lw=0.8, zorder=4)
            if b is not None and b > 0:
                x_b = a.get_xlim()[0] + 0.05 * np.ptp(a.get_xlim())
                a.annotate("", xy=(x_b, c_tar[1]), xytext=(x_b, c_pro[1]),
                           arrowprops=dict(arrowstyle="<->", lw=1), zorder=5)
                a.text(x_b, 0.5 * (c_tar[1] + c_pro[1]), f" b = {b * 1e6:.2f} micron",
                       va="center", fontsize=8, zorder=6,
                       bbox=dict(facecolor="w", edgecolor="none", alpha=0.8, pad=1))
        d = _frame_axes(e, end, i, j, radius, names)
        _discs(e, end[~big], i, j, d, colours[~big], alpha=0.35)
        _discs(e, end[big], i, j, d, colours[big], zorder=2)
        marked = _mark_small(e, end, labels, i, j)
    axes[0, 0].set_title("start, " + _when(*when[0], t_c), fontsize=10)
    axes[0, 1].set_title(f"{end_label}, " + _when(*when[1], t_c), fontsize=10)
    axes[0, 0].legend(handles=[Patch(color=BODY_COLOURS[1], label=f"target ({tar.sum()})"),
                               Patch(color=BODY_COLOURS[2], label=f"projectile ({pro.sum()})"),
                               Line2D([], [], color="k", marker=">", label="projectile's motion")],
                      fontsize=8, loc="upper right")
    order = np.argsort(sizes, kind="stable")[::-1]
    def grains(n):
        return f"{n} grain" + ("s" if n != 1 else "")
    handles = []
    for k, f in enumerate(order[:len(FRAGMENT_COLOURS)]):
        from_pro = int(np.sum((labels == f) & pro))
        handles.append(Patch(color=FRAGMENT_COLOURS[k], label=f"{grains(sizes[f])} "
                             f"({from_pro} from the projectile, light)"))
    rest = order[len(FRAGMENT_COLOURS):]
    if len(rest):
        handles.append(Patch(color="0.75", label=f"{len(rest)} more, of at most "
                             f"{grains(sizes[rest].max())}"))
    if marked:
        ringed = marked <= RINGS_UP_TO
        handles.append(Line2D([], [], ls="none", marker="o", markersize=5 if ringed else 2,
                              markerfacecolor="none" if ringed else "0.2",
                              markeredgecolor="k" if ringed else "0.2",
                              label=f"{marked} fragment(s) of at most {MARK_UP_TO} grains, "
                              + ("ringed" if ringed else "a dot at each centre")))
    if departed is not None and departed.any():
        n_gone = len(np.unique(labels[departed]))
        handles.append(Patch(color="none", label=f"{n_gone} fragment(s), {grains(departed.sum())}"
                             ", departed:\ndrawn where they fly at the end"))
    axes[0, 1].legend(handles=handles, fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1),
                      title=f"{len(sizes)} fragment(s)", title_fontsize=8)
    fig.suptitle(title, fontsize=10)
    return _save(fig, path)


def timeline(path, rows: list[dict], n_total: int, e_imp: float, t_c: float,
             title: str = "", last_frame: float | None = None) -> list[Path]:
    """N_lar and the second largest, the number of fragments, n_con and the energy shares
    against time, from the per-frame rows of ``frames.csv`` (the energies and the time
    come from the run's log; without one, against the step). ``last_frame`` (s): the time
    of the last atom frame, marked when the rows go on past it (a partial analysis)."""
    plt = _pyplot()
    has_time = all("time" in r for r in rows)
    x = np.array([r["time"] * 1e9 if has_time else r["step"] for r in rows], dtype=float)
    energies = all("kinetic" in r for r in rows)
    fig, axes = plt.subplots(4 if energies else 3, 1, figsize=(7, 9 if energies else 7),
                             sharex=True, constrained_layout=True)

    def get(name):
        return np.array([r[name] for r in rows], dtype=float)

    axes[0].plot(x, get("n_largest") / n_total, "o-", ms=3, label="N_lar / N_total")
    axes[0].plot(x, get("n_second") / n_total, "s-", ms=3, label="second largest / N_total")
    axes[0].set_ylim(0, 1.05)
    axes[0].legend(fontsize=8)
    axes[1].plot(x, get("n_fragments"), "o-", ms=3, color="C2")
    axes[1].set_ylabel("fragments")
    axes[2].plot(x, get("contacts_per_particle"), "o-", ms=3, color="C3")
    axes[2].set_ylabel("n_con (largest)")
    if energies:
        axes[3].plot(x, get("kinetic") / e_imp, label="kinetic (with rotation)")
        axes[3].plot(x, get("dissipated") / e_imp, label="dissipated")
        axes[3].plot(x, (get("potential") - rows[0]["potential"]) / e_imp,
                     label="potential - U(0)")
        axes[3].set_ylabel("energy / E_imp")
        axes[3].legend(fontsize=8)
    if last_frame is not None and has_time:
        for ax in axes:
            ax.axvline(last_frame * 1e9, color="0.4", ls="--", lw=1)
        axes[0].annotate("last atom frame", (last_frame * 1e9, 0.02), fontsize=8,
                         color="0.3", ha="right", rotation=90, va="bottom")
    axes[-1].set_xlabel("time (ns)" if has_time else "step")
    if has_time:
        top = axes[0].secondary_xaxis("top", functions=(lambda ns: ns * 1e-9 / t_c,
                                                        lambda tc: tc * t_c * 1e9))
        top.set_xlabel("time (t_c)")
    fig.suptitle(title, fontsize=10)
    return _save(fig, path)


def energy_partition(path, time: np.ndarray, budget: dict, e_imp: float, title: str = ""):
    """Energies over E_imp: kinetic, potential change, dissipation by channel, and the sum."""
    from jkrdt.ledger import CHANNELS

    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
    t = np.asarray(time) * 1e9
    ax.plot(t, budget["kinetic"] / e_imp, label="kinetic (with rotation)", lw=2)
    if np.any(budget.get("departed", 0) != 0):
        ax.plot(t, budget["departed"] / e_imp, color="C0", ls="--",
                label="of it, carried by departed fragments")
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


def _two_d_bcca(rows: list[dict]) -> bool:
    """Whether every run is a 2D BCCA collision, the scene of Wada et al. (2007)'s fits."""
    return all(r.get("dimension") == 2 and r.get("kind") == "bcca" for r in rows)


def _by_speed(rows: list[dict]):
    """(v_col, the rows at it, its colour) for each speed, slowest first."""
    speeds = sorted({r["v_col"] for r in rows})
    for k, v in enumerate(speeds):
        yield v, [r for r in rows if r["v_col"] == v], f"C{k % 10}"


def _by_offset(ax, x, y, rows, marker):
    """The runs of one speed (one x: E_imp does not depend on B_off) spread a little
    along x in order of B_off^2 and coloured by it, so that 4 or 12 offsets stay apart;
    returns the colour scale for a colour bar."""
    b2 = np.array([r["B_off"] ** 2 for r in rows], dtype=float)
    rank = np.searchsorted(np.unique(b2), b2)
    # within +-7 % of the speed's value, well inside the 58 % step of the paper's speed grid
    spread = np.exp(0.14 * (rank / max(rank.max(), 1) - 0.5)) if len(rank) else rank
    return ax.scatter(np.asarray(x, dtype=float) * spread, y, c=b2, cmap="viridis", vmin=0.0,
                      vmax=1.0, marker=marker, s=28, edgecolors="0.2", linewidths=0.4)


def _speed_ticks(ax, x):
    """Ticks on a log axis at each speed's value only (its offsets spread about it)."""
    from matplotlib.ticker import FixedLocator, NullFormatter, NullLocator

    values = sorted({float(v) for v in x})
    if not values:
        return
    ax.xaxis.set_major_locator(FixedLocator(values))
    ax.set_xticklabels([f"{v:.3g}" for v in values])
    ax.xaxis.set_minor_locator(NullLocator())
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlim(values[0] / 1.25, values[-1] * 1.25)


#: a marker per speed, slowest first
SPEED_MARKERS = "osD^v<>pXh"


def _offset_colour_bar(fig, ax, mappable):
    bar = fig.colorbar(mappable, ax=ax, pad=0.01)
    bar.set_label("B_off^2")
    bar.set_ticks([k / 12 for k in range(0, 13, 3)], labels=["0", "3/12", "6/12", "9/12", "1"])


def compression(path, rows: list[dict]):
    """r_g / (r_1 sqrt(N_lar)) and n_con against E_imp / (n_k E_roll), one point per run,
    coloured by v_col and labelled with B_off; eqs. (51) and (56) only for 2D BCCAs."""
    plt = _pyplot()
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4.5), constrained_layout=True)
    x_all = np.array([r["E_imp_over_nk_Eroll"] for r in rows], dtype=float)
    shown = None
    for k, (v, mine, _) in enumerate(_by_speed(rows)):
        marker = SPEED_MARKERS[k % len(SPEED_MARKERS)]
        x = np.array([r["E_imp_over_nk_Eroll"] for r in mine], dtype=float)
        rg = np.array([r["gyration_radius_largest"] / (r["radius"] * np.sqrt(r["n_largest"]))
                       for r in mine])
        ncon = np.array([r["contacts_per_particle"] for r in mine])
        shown = _by_offset(a, x, rg, mine, marker)
        _by_offset(b, x, np.where(ncon > 1, ncon - 1, np.nan), mine, marker)
        for ax in (a, b):
            ax.scatter([], [], marker=marker, c="0.5", label=f"v = {v:g} m/s")
    for ax in (a, b):
        ax.set_xscale("log")
        y = np.concatenate([np.asarray(c.get_offsets())[:, 1] for c in ax.collections
                            if len(c.get_offsets())] or [np.array([])])
        if np.any(np.isfinite(y) & (y > 0)):       # n_con - 1 may be 0 for every run
            ax.set_yscale("log")
        _speed_ticks(ax, x_all)
    if shown is not None:
        _offset_colour_bar(fig, b, shown)
    fig.suptitle("one point per run; a speed's offsets spread about it, coloured by B_off^2",
                 fontsize=9)
    if _two_d_bcca(rows):
        e = np.logspace(np.log10(max(x_all.min(), 1e-3)) - 0.5, np.log10(x_all.max()) + 0.5, 50)
        a.loglog(e, 0.84 * e ** -0.12, "0.6", label="eq. (51), 2D BCCA")
        b.loglog(e, e ** 0.75, "0.6", label="eq. (56), 2D BCCA")
    a.set_ylabel("r_g / (r_1 N_lar^1/2)")
    b.set_ylabel("n_con - 1")
    for ax in (a, b):
        ax.set_xlabel("E_imp / (n_k E_roll)")
        ax.legend(fontsize=8)
    return _save(fig, path)


def disruption(path, rows: list[dict]):
    """Left: N_lar / N_total against E_imp / (n_k E_break), a marker per v_col, coloured by
    B_off^2; for 2D BCCAs the marks of Wada et al. (2007) at 3 and 10 n_k E_break. Right:
    f_gro against B_off^2, a line per v_col (seeds averaged: the 3D paper's Fig. B.1)."""
    plt = _pyplot()
    fig, (ax, right) = plt.subplots(1, 2, figsize=(11, 4.5), constrained_layout=True,
                                    gridspec_kw=dict(width_ratios=[1.15, 1]))
    for k, (v, mine, colour) in enumerate(_by_speed(rows)):
        b2 = np.array([r["B_off"] ** 2 for r in mine])
        f = np.array([r["growth_efficiency"] for r in mine])
        grid = np.unique(np.round(b2, 9))
        mean = [f[np.isclose(b2, g)].mean() for g in grid]
        right.plot(grid, mean, "-", color=colour, marker=SPEED_MARKERS[k % len(SPEED_MARKERS)],
                   ms=4, label=f"v = {v:g} m/s")
        right.plot(b2, f, ".", color=colour, alpha=0.35, ms=3)
    right.axhline(0, color="0.6", lw=0.8)
    right.set_xlim(0, 1)
    right.set_xticks([k / 12 for k in range(0, 13, 3)], labels=["0", "3/12", "6/12", "9/12", "1"])
    right.set_xlabel("B_off^2   (dots: each seed)")
    right.set_ylabel("f_gro = (N_lar - N_tar) / N_pro")
    right.legend(fontsize=8)
    shown = None
    for k, (v, mine, _) in enumerate(_by_speed(rows)):
        x = [r["E_imp_over_nk_Ebreak"] for r in mine]
        y = [r["n_largest"] / r["n_total"] for r in mine]
        shown = _by_offset(ax, x, y, mine, SPEED_MARKERS[k % len(SPEED_MARKERS)])
        ax.scatter([], [], marker=SPEED_MARKERS[k % len(SPEED_MARKERS)], c="0.5",
                   label=f"v = {v:g} m/s")
    ax.set_xscale("log")
    _speed_ticks(ax, [r["E_imp_over_nk_Ebreak"] for r in rows])
    if shown is not None:
        _offset_colour_bar(fig, ax, shown)
    if _two_d_bcca(rows):
        for mark, text in [(3, "loss of one grain"), (10, "catastrophic")]:
            ax.axvline(mark, color="0.6", ls=":")
            ax.text(mark, 0.02, text + " (2D BCCA)", rotation=90, fontsize=8)
    ax.set_xlabel("E_imp / (n_k E_break)   (a speed's offsets spread about it)")
    ax.set_ylabel("N_lar / N_total")
    ax.set_ylim(0, 1.05)
    ax.legend(fontsize=8)
    return _save(fig, path)


def growth_efficiency(path, curves: dict, thresholds: dict, runs: dict | None = None):
    """<f_gro> against v_col for each model; ``curves[model] = (v, mean f_gro)``, each point
    labelled with its number of runs (``runs[model]``, one count per point)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 4.5), constrained_layout=True)
    for model, (v, f) in curves.items():
        line, = ax.semilogx(v, f, "o-", label=model)
        for k, (vi, fi) in enumerate(zip(v, f)):
            if runs and model in runs:
                ax.annotate(f"{runs[model][k]} runs", (vi, fi), textcoords="offset points",
                            xytext=(4, 4), fontsize=7, color=line.get_color())
        if thresholds.get(model):
            ax.axvline(thresholds[model], color=line.get_color(), ls=":",
                       label=f"v_fra = {thresholds[model]:.3g} m/s")
    from matplotlib.ticker import NullFormatter, ScalarFormatter

    ax.set_xticks(sorted({vi for v, _ in curves.values() for vi in v}))   # the grid's speeds
    ax.xaxis.set_major_formatter(ScalarFormatter())
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.axhline(0, color="0.6", lw=0.8)
    ax.set_xlabel("v_col (m/s)")
    ax.set_ylabel("<f_gro>")
    ax.legend(fontsize=8)
    return _save(fig, path)


def cumulative(path, curves: dict):
    """<N_cum(<= N)> against N; ``curves[label] = (N, mean N_cum)``. Each curve is drawn as
    steps with a marker at every rise, so that a run whose grains all sit in one remnant
    (a single rise at N = N_total) shows too."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 4.5), constrained_layout=True)
    for k, (label, (n, c)) in enumerate(curves.items()):
        n, c = np.asarray(n, dtype=float), np.asarray(c, dtype=float)
        rise = np.flatnonzero(np.diff(np.r_[0.0, c]) > 0)
        line, = ax.loglog(n, np.where(c > 0, c, np.nan), drawstyle="steps-post")
        ax.loglog(n[rise], c[rise], "osD^v<>"[k % 7], ms=5, color=line.get_color(),
                  mfc="none", label=label)
    ax.set_xlabel("N")
    ax.set_ylabel("<N_cum(<= N)>")
    ax.legend(fontsize=8)
    return _save(fig, path)
