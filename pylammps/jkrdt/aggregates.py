"""Aggregate builders: ballistic particle-cluster aggregation (BPCA).

Every bond sits at the JKR equilibrium separation r_i + r_j - delta0, so a
relaxed aggregate starts with zero force, and no two unbonded grains are
closer than contact (2r): the contact graph is a tree with N - 1 bonds.
Reproducible from a ``numpy.random.Generator``.
"""

from __future__ import annotations

import numpy as np


def random_directions(rng: np.random.Generator, n: int, dim: int) -> np.ndarray:
    """``n`` unit vectors uniform on the circle (dim 2, z = 0) or sphere (dim 3)."""
    v = rng.normal(size=(n, 3))
    if dim == 2:
        v[:, 2] = 0.0
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def bpca(n: int, radius: float, delta0: float, rng: np.random.Generator, dim: int = 3,
         max_tries: int = 10000) -> np.ndarray:
    """Positions (n, 3) of a BPCA of ``n`` grains of ``radius``, centred on its centre of mass.

    Each new grain comes from a random direction along a straight line with a
    random offset inside the cluster's cross-section and sticks where it first
    touches; it is then pulled onto the bond length 2 r - delta0.
    """
    if n < 1:
        raise ValueError("an aggregate needs n >= 1 grains")
    if dim not in (2, 3):
        raise ValueError("dim must be 2 or 3")
    if not 0 <= delta0 < radius:
        raise ValueError("delta0 must lie in [0, radius)")
    contact = 2.0 * radius
    bond = contact - delta0
    x = np.zeros((n, 3))
    for k in range(1, n):
        placed = False
        for _ in range(max_tries):
            centre = x[:k].mean(axis=0)
            reach = np.sqrt(((x[:k] - centre) ** 2).sum(axis=1).max()) + contact
            u = random_directions(rng, 1, dim)[0]
            # offset uniform over the disc (3D) or segment (2D) across the approach line
            w = random_directions(rng, 1, dim)[0]
            w -= (w @ u) * u
            w /= np.linalg.norm(w)
            spread = reach * (np.sqrt(rng.random()) if dim == 3 else 2 * rng.random() - 1)
            start = centre - 2.0 * reach * u + spread * w
            # first grain the ray start + t u touches: |start + t u - x_i| = 2r
            rel = start - x[:k]
            b = rel @ u
            disc = b * b - ((rel ** 2).sum(axis=1) - contact ** 2)
            hits = np.flatnonzero(disc >= 0)
            if hits.size == 0:
                continue
            t = -b[hits] - np.sqrt(disc[hits])
            target = hits[np.argmin(t)]
            touch = start + t.min() * u
            new = x[target] + (touch - x[target]) * (bond / contact)
            gaps = np.sqrt(((x[:k] - new) ** 2).sum(axis=1))
            gaps[target] = np.inf
            if gaps.min() > contact:
                x[k] = new
                placed = True
                break
        if not placed:
            raise RuntimeError(f"BPCA: could not place grain {k} in {max_tries} tries")
    return x - x.mean(axis=0)


def gyration_radius(x: np.ndarray) -> float:
    """r_g of equal grains, eq. (50) of Wada et al. (2007)."""
    return float(np.sqrt(((x - x.mean(axis=0)) ** 2).sum(axis=1).mean()))


def random_rotation(rng: np.random.Generator, dim: int = 3) -> np.ndarray:
    """A uniformly random rotation matrix (about z only in 2D)."""
    if dim == 2:
        a = rng.uniform(0, 2 * np.pi)
        c, s = np.cos(a), np.sin(a)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q
