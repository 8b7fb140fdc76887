"""Pictures of a collision outcome (matplotlib, PNG and PDF)."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def snapshot(path, x: np.ndarray, labels: np.ndarray, title: str = "") -> list[Path]:
    """Projections x-y and x-z of the grains, the largest fragment dark, others by fragment."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sizes = np.bincount(labels)
    rank = np.empty_like(sizes)
    rank[np.argsort(sizes)[::-1]] = np.arange(len(sizes))
    colour = rank[labels]
    fig, axes = plt.subplots(1, 2, figsize=(10, 5), constrained_layout=True)
    um = x * 1e6
    for ax, (i, j, name) in zip(axes, [(0, 1, "y"), (0, 2, "z")]):
        ax.scatter(um[:, i], um[:, j], c=np.minimum(colour, 10), cmap="tab10", s=4, vmin=0, vmax=10)
        ax.set_xlabel("x (micron)")
        ax.set_ylabel(f"{name} (micron)")
        ax.set_aspect("equal")
    fig.suptitle(title)
    out = []
    for suffix in (".png", ".pdf"):
        p = Path(path).with_suffix(suffix)
        fig.savefig(p, dpi=120)
        out.append(p)
    plt.close(fig)
    return out
