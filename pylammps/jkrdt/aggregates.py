"""Aggregate builders: ballistic particle-cluster (BPCA) and cluster-cluster
(BCCA) aggregation, in 2D and 3D, and the fractal fit of their structure.

Every bond sits at the JKR equilibrium separation r_i + r_j - delta0, so a
relaxed aggregate starts with zero force, and no two unbonded grains are
closer than contact (2r): the contact graph is a tree with N - 1 bonds.
Reproducible from a ``numpy.random.Generator``.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def _check(dim: int, radius: float, delta0: float) -> None:
    if dim not in (2, 3):
        raise ValueError("dim must be 2 or 3")
    if not 0 <= delta0 < radius:
        raise ValueError("delta0 must lie in [0, radius)")


def random_directions(rng: np.random.Generator, n: int, dim: int) -> np.ndarray:
    """``n`` unit vectors uniform on the circle (dim 2, z = 0) or sphere (dim 3)."""
    v = rng.normal(size=(n, 3))
    if dim == 2:
        v[:, 2] = 0.0
    return v / np.linalg.norm(v, axis=1, keepdims=True)


#: BPCA size from which neighbour queries go through a kd-tree (below, all grains are tested)
KD_TREE_FROM = 2048


class _GrowingSet:
    """Positions of a growing cluster with neighbour queries: a kd-tree rebuilt
    every 256 grains, plus the grains added since."""

    def __init__(self, capacity: int):
        self.x = np.zeros((capacity, 3))
        self.n = 0
        self.tree, self.n_tree = None, 0

    def add(self, p):
        self.x[self.n] = p
        self.n += 1
        if self.n >= self.n_tree + 256:
            self.tree, self.n_tree = cKDTree(self.x[:self.n]), self.n

    def near(self, points: np.ndarray, distance: float) -> np.ndarray:
        """Indices of the grains within ``distance`` of any of ``points``; while the
        cluster is small, all of them (the caller tests exactly)."""
        if self.n < KD_TREE_FROM:
            return np.arange(self.n)
        found = []
        if self.tree is not None:
            hits = self.tree.query_ball_point(points, distance)
            found = [np.concatenate([np.asarray(h, dtype=int) for h in hits])]
        recent = self.x[self.n_tree:self.n]
        d2 = ((recent[None, :, :] - points[:, None, :]) ** 2).sum(axis=2)
        found.append(self.n_tree + np.flatnonzero((d2 < distance ** 2).any(axis=0)))
        return np.unique(np.concatenate(found))


def bpca(n: int, radius: float, delta0: float, rng: np.random.Generator, dim: int = 3,
         max_tries: int = 10000) -> np.ndarray:
    """Positions (n, 3) of a BPCA of ``n`` grains of ``radius``, centred on its centre of mass.

    Each new grain comes from a random direction along a straight line with a
    random offset inside a disc (3D) or segment (2D) that covers the cluster,
    and sticks where it first touches; it is then pulled onto the bond length
    2 r - delta0. A grain that would touch a second one there is thrown again.
    Beyond 2048 grains, grains near the line are found with a kd-tree, so a
    grain costs about O(log N) plus its path through the cluster, not O(N).
    """
    if n < 1:
        raise ValueError("an aggregate needs n >= 1 grains")
    _check(dim, radius, delta0)
    contact = 2.0 * radius
    bond = contact - delta0
    grains = _GrowingSet(n)
    grains.add(np.zeros(3))
    total = np.zeros(3)          # sum of positions, for the centre of mass
    reach = 0.0                  # bound on the distance of any grain from the centre
    for k in range(1, n):
        centre = total / k
        span = reach + contact
        for _ in range(max_tries):
            u = random_directions(rng, 1, dim)[0]
            w = random_directions(rng, 1, dim)[0]
            w -= (w @ u) * u
            w /= np.linalg.norm(w)
            spread = span * (np.sqrt(rng.random()) if dim == 3 else 2 * rng.random() - 1)
            start = centre - span * u + spread * w
            # grains within 2r of the path: near samples every 2r along it (cover 2.24 r)
            samples = start + np.outer(np.arange(0.0, 2 * span + contact, contact), u)
            cand = grains.near(samples, 1.125 * contact)
            if cand.size == 0:
                continue
            rel = start - grains.x[cand]
            b = rel @ u
            disc = b * b - ((rel ** 2).sum(axis=1) - contact ** 2)
            hit = disc >= 0
            if not hit.any():
                continue
            t = -b[hit] - np.sqrt(disc[hit])
            target = cand[hit][np.argmin(t)]
            touch = start + t.min() * u
            new = grains.x[target] + (touch - grains.x[target]) * (bond / contact)
            near = grains.near(new[None, :], contact)
            gaps = np.linalg.norm(grains.x[near] - new, axis=1)
            if np.array_equal(near[gaps <= contact], [target]):
                break
        else:
            raise RuntimeError(f"BPCA: could not place grain {k} in {max_tries} tries")
        grains.add(new)
        total += new
        moved = total / (k + 1)
        # the old grains are at most reach + |shift of the centre| from the new centre
        reach = max(reach + np.linalg.norm(moved - centre), np.linalg.norm(new - moved))
        if k % 256 == 0:
            reach = float(np.sqrt(((grains.x[:k + 1] - moved) ** 2).sum(axis=1).max()))
    x = grains.x[:n]
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


def _pairs_within(a: np.ndarray, b: np.ndarray, distance: float):
    """Index arrays (i, j) and distances of the pairs a[i], b[j] closer than ``distance``."""
    if len(a) * len(b) <= 4096:
        d = np.sqrt(((a[:, None, :] - b[None, :, :]) ** 2).sum(axis=2))
        i, j = np.nonzero(d < distance)
        return i, j, d[i, j]
    m = cKDTree(a).sparse_distance_matrix(cKDTree(b), distance, output_type="coo_matrix")
    keep = m.data < distance
    return m.row[keep], m.col[keep], m.data[keep]


def stick_head_on(a: np.ndarray, b: np.ndarray, radius: float, delta0: float,
                  rng: np.random.Generator, dim: int = 3, max_tries: int = 1000) -> np.ndarray:
    """Stick cluster ``b`` onto cluster ``a``, head-on (Wada et al. 2007, sec. 4).

    Both are turned at random about their centres of mass, put on the x axis
    and ``b`` comes in along -x until a grain of ``b`` first touches one of
    ``a``. That pair is pulled onto the bond length 2 r - delta0; an orientation
    that would bring any other pair within contact is drawn again. Returns the
    merged positions centred on their centre of mass.
    """
    contact = 2.0 * radius
    for _ in range(max_tries):
        pa = (a - a.mean(axis=0)) @ random_rotation(rng, dim).T
        pb = (b - b.mean(axis=0)) @ random_rotation(rng, dim).T
        # grains whose paths cross: projections on the plane normal to x closer than 2r
        i, j, rho = _pairs_within(pa[:, 1:], pb[:, 1:], contact)
        if i.size == 0:
            continue
        # b shifted by +L touches pair (i, j) at L_ij; coming from +infinity the first is the largest
        reach = pa[i, 0] - pb[j, 0] + np.sqrt(contact ** 2 - rho ** 2)
        k = int(np.argmax(reach))
        pb[:, 0] += reach[k]
        normal = (pb[j[k]] - pa[i[k]]) / contact
        pb -= delta0 * normal                   # the bond sits at 2 r - delta0
        if cKDTree(pa).count_neighbors(cKDTree(pb), contact) == 1:
            merged = np.vstack([pa, pb])
            return merged - merged.mean(axis=0)
    raise RuntimeError(f"head-on sticking failed in {max_tries} orientations")


def bcca(n: int, radius: float, delta0: float, rng: np.random.Generator, dim: int = 3) -> np.ndarray:
    """Positions (n, 3) of a BCCA of ``n`` = 2^k grains, centred on its centre of mass.

    Ballistic cluster-cluster aggregation: at each level, pairs of clusters of
    equal size, built independently, stick head-on in random orientations
    (Wada et al. 2007, sec. 4): n - 1 bonds at 2 r - delta0, no other contact.
    The work is O(N log N) kd-tree queries.
    """
    if n < 1 or n & (n - 1):
        raise ValueError(f"BCCA needs a power of two grains (got {n})")
    _check(dim, radius, delta0)
    clusters = [np.zeros((1, 3)) for _ in range(n)]
    while len(clusters) > 1:
        clusters = [stick_head_on(clusters[k], clusters[k + 1], radius, delta0, rng, dim)
                    for k in range(0, len(clusters), 2)]
    return clusters[0]


def bonds(x: np.ndarray, radius: float, delta0: float) -> np.ndarray:
    """Pairs (i < j) of an aggregate closer than contact 2r: its bonds."""
    pairs = cKDTree(x).query_pairs(2.0 * radius, output_type="ndarray")
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


def fractal_fit(n: np.ndarray, rg_over_r: np.ndarray) -> tuple[float, float]:
    """Least-squares fit of N = k0 (r_g / r_1)^D_f in log space (eq. 52-53 of
    Wada et al. 2007); returns (D_f, k0)."""
    slope, intercept = np.polyfit(np.log(rg_over_r), np.log(n), 1)
    return float(slope), float(np.exp(intercept))


#: the aggregate builders by the name a scene gives them (``kind``)
BUILDERS = {"bpca": bpca, "bcca": bcca}
