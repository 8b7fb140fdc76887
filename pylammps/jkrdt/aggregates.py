"""Aggregate builders: ballistic particle-cluster (BPCA) and cluster-cluster
(BCCA) aggregation, in 2D and 3D, and the fractal fit of their structure.

Every bond sits at the JKR equilibrium separation r_i + r_j - delta0, so a
relaxed aggregate starts with zero force, and no two unbonded grains are
closer than contact (2r): the contact graph is a tree with N - 1 bonds.
Reproducible from a ``numpy.random.Generator``.
"""

from __future__ import annotations

import itertools
import math

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


class _RayGrid:
    """Positions of a growing cluster, binned for straight-line queries.

    Cells are cubes of side ``cell``. Each grain is listed in every cell that its
    sphere of radius ``reach`` (the contact distance plus half the ray sampling step)
    overlaps, so the grains within contact of a ray are all listed in the cells of
    the ray's sample points, and those within contact of a point in that point's
    cell. The grid doubles when the cluster reaches its edge; a cell's slots double
    when one fills.
    """

    def __init__(self, capacity: int, reach: float):
        self.x = np.zeros((capacity, 3))
        self.n = 0
        self.reach = reach
        self.cell = 2.0 * reach                 # a grain is then listed in at most 8 cells
        self._allocate(16, 8)

    def _allocate(self, side: int, slots: int) -> None:
        self.side = side
        self.low = -0.5 * side * self.cell      # the cluster grows about the origin
        self.slots = np.full((side ** 3, slots), -1, dtype=np.int64)
        self.count = np.zeros(side ** 3, dtype=np.int64)

    def _cells_of(self, p) -> list[int] | None:
        """The cells that a sphere of radius ``reach`` at ``p`` overlaps (None: off the grid)."""
        ranges = []
        for c in p:
            lo = math.floor((c - self.reach - self.low) / self.cell)
            hi = math.floor((c + self.reach - self.low) / self.cell)
            if lo < 0 or hi >= self.side:
                return None
            ranges.append(range(lo, hi + 1))
        return [(i * self.side + j) * self.side + k for i, j, k in itertools.product(*ranges)]

    def _list(self, k: int) -> bool:
        cells = self._cells_of(self.x[k])
        if cells is None:
            return False
        for c in cells:
            if self.count[c] == self.slots.shape[1]:
                self.slots = np.hstack([self.slots, np.full_like(self.slots, -1)])
            self.slots[c, self.count[c]] = k
            self.count[c] += 1
        return True

    def add(self, p) -> None:
        self.x[self.n] = p
        self.n += 1
        side = self.side
        while not self._list(self.n - 1):        # off the grid: a grid twice as wide
            side *= 2
            self._allocate(side, self.slots.shape[1])
            for k in range(self.n - 1):
                self._list(k)

    def near(self, p) -> np.ndarray:
        """The grains within ``reach`` of the point ``p``, and some farther."""
        i, j, k = (math.floor((c - self.low) / self.cell) for c in p)
        row = self.slots[(i * self.side + j) * self.side + k]
        return row[row >= 0]

    def listed(self, points: np.ndarray, groups: np.ndarray):
        """Grain indices listed in the cells of ``points`` (m, 3), with repeats, and the
        group (``groups``, (m,)) of the point each was found from."""
        idx = np.floor((points - self.low) / self.cell).astype(np.int64)
        inside = ((idx >= 0) & (idx < self.side)).all(axis=1)
        cells = (idx[inside, 0] * self.side + idx[inside, 1]) * self.side + idx[inside, 2]
        key = np.unique(groups[inside] * self.side ** 3 + cells)
        found = self.slots[key % self.side ** 3]
        keep = found >= 0
        return found[keep], np.broadcast_to((key // self.side ** 3)[:, None], found.shape)[keep]


#: lines thrown at once: their first touches are found together, then taken in turn
BPCA_LINES = 64


def _first_touch(rel: np.ndarray, u: np.ndarray, contact: float) -> np.ndarray:
    """For lines start + t u (unit u) and grains at start - ``rel``: the least t at which
    the line comes within ``contact`` of the grain, |rel + t u| = contact; inf where it
    misses. Rows of ``rel`` and ``u`` pair up (or broadcast)."""
    b = (rel * u).sum(axis=-1)
    disc = b * b - ((rel ** 2).sum(axis=-1) - contact ** 2)
    with np.errstate(invalid="ignore"):
        return np.where(disc >= 0, -b - np.sqrt(disc), np.inf)


def bpca(n: int, radius: float, delta0: float, rng: np.random.Generator, dim: int = 3,
         max_tries: int = 10000) -> np.ndarray:
    """Positions (n, 3) of a BPCA of ``n`` grains of ``radius``, centred on its centre of mass.

    Each new grain comes from a random direction along a straight line with a
    random offset inside a disc (3D) or segment (2D) that covers the cluster,
    and sticks where it first touches; it is then pulled onto the bond length
    2 r - delta0. A grain that would touch a second one there, and a line that
    misses, is thrown again. Since lines that miss are thrown again, the
    covering disc's size and centre do not change the aggregate's statistics,
    which lets ``BPCA_LINES`` lines be thrown at once from one disc: their first
    touches with the cluster are found together in a grid (``_RayGrid``), then
    the lines are taken in turn, each grain that sticks updating the first
    touches of the lines after it. A grain costs a few array operations, not O(N).
    """
    if n < 1:
        raise ValueError("an aggregate needs n >= 1 grains")
    _check(dim, radius, delta0)
    contact = 2.0 * radius
    bond = contact - delta0
    step = radius                                 # sampling step along a line
    grains = _RayGrid(n, contact + 0.5 * step)
    grains.add(np.zeros(3))
    total = np.zeros(3)          # sum of positions, for the centre of mass
    k, thrown = 1, 0
    while k < n:
        centre = total / k
        reach = float(np.sqrt(((grains.x[:k] - centre) ** 2).sum(axis=1).max()))
        span = reach + contact                    # the disc's radius: it covers the cluster
        u = random_directions(rng, 2 * BPCA_LINES, dim)
        u, w = u[:BPCA_LINES], u[BPCA_LINES:]
        w -= (w * u).sum(axis=1, keepdims=True) * u
        w /= np.linalg.norm(w, axis=1, keepdims=True)
        r = rng.random(BPCA_LINES)
        spread = span * (np.sqrt(r) if dim == 3 else 2 * r - 1)
        starts = centre - span * u + spread[:, None] * w
        # the first touch of each line with the cluster as it is: grains near the line
        # are those listed in the cells of its points, every ``step`` along it
        offsets = np.arange(0.0, 2 * span + contact, step)
        points = (starts[:, None, :] + offsets[None, :, None] * u[:, None, :]).reshape(-1, 3)
        cand, line = grains.listed(points, np.repeat(np.arange(BPCA_LINES), len(offsets)))
        along = _first_touch(starts[line] - grains.x[cand], u[line], contact)
        hit = np.isfinite(along)
        cand, line, along = cand[hit], line[hit], along[hit]
        t = np.full(BPCA_LINES, np.inf)
        target = np.zeros(BPCA_LINES, dtype=np.int64)
        order = np.lexsort((along, line))
        hitting, first = np.unique(line[order], return_index=True)
        t[hitting], target[hitting] = along[order[first]], cand[order[first]]
        for j in range(BPCA_LINES):
            thrown += 1
            if thrown > max_tries:
                raise RuntimeError(f"BPCA: could not place grain {k} in {max_tries} tries")
            if not np.isfinite(t[j]):
                continue
            x_t = grains.x[target[j]]
            new = x_t + (starts[j] + t[j] * u[j] - x_t) * (bond / contact)
            near = grains.near(new)
            gaps = ((grains.x[near] - new) ** 2).sum(axis=1)
            if np.count_nonzero(near[gaps <= contact ** 2] != target[j]):
                continue          # it would touch a second grain
            grains.add(new)
            total += new
            k, thrown = k + 1, 0
            if k == n or math.dist(new, centre) + contact > span:
                break             # done, or the disc no longer covers the cluster
            # the new grain may come first on the lines still to be taken
            t_new = _first_touch(starts[j + 1:] - new, u[j + 1:], contact)
            sooner = t_new < t[j + 1:]
            t[j + 1:][sooner] = t_new[sooner]
            target[j + 1:][sooner] = k - 1
    x = grains.x[:n]
    return x - x.mean(axis=0)


def bpca_plain(n: int, radius: float, delta0: float, rng: np.random.Generator,
               dim: int = 3) -> np.ndarray:
    """BPCA as the papers define it, in its plainest form: one line at a time from a
    disc covering the cluster, its first touch found against every grain, O(N^2).
    The reference that ``bpca`` is tested and timed against."""
    _check(dim, radius, delta0)
    contact, bond = 2.0 * radius, 2.0 * radius - delta0
    x = np.zeros((1, 3))
    while len(x) < n:
        centre = x.mean(axis=0)
        span = np.sqrt(((x - centre) ** 2).sum(axis=1).max()) + contact
        u, w = random_directions(rng, 2, dim)
        w -= (w @ u) * u
        w /= np.linalg.norm(w)
        r = rng.random()
        start = centre - span * u + span * (np.sqrt(r) if dim == 3 else 2 * r - 1) * w
        t = _first_touch(start - x, u, contact)
        if not np.isfinite(t).any():
            continue
        k = np.argmin(t)
        new = x[k] + (start + t[k] * u - x[k]) * (bond / contact)
        if np.count_nonzero(np.linalg.norm(x - new, axis=1) <= contact) == 1:
            x = np.vstack([x, new])
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


def first_touch_along_x(a: np.ndarray, b: np.ndarray, distance: float):
    """Cluster ``b`` coming in along -x from far away towards cluster ``a``: the shift
    L along x at which a grain of b (moved by +L) first comes within ``distance`` of
    a grain of a, and that pair (L, i, j); None if no path crosses."""
    # grains whose paths cross: projections on the plane normal to x closer than distance
    i, j, rho = _pairs_within(a[:, 1:], b[:, 1:], distance)
    if i.size == 0:
        return None
    # b shifted by +L is at distance from pair (i, j) at L_ij; from +infinity the first is the largest
    shift = a[i, 0] - b[j, 0] + np.sqrt(distance ** 2 - rho ** 2)
    k = int(np.argmax(shift))
    return float(shift[k]), int(i[k]), int(j[k])


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
        touch = first_touch_along_x(pa, pb, contact)
        if touch is None:
            continue
        shift, i, j = touch
        pb[:, 0] += shift
        normal = (pb[j] - pa[i]) / contact
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

#: peak memory of building and setting up grains, per grain: jkrdt setup of 2 x 50000 BPCA
#: grains peaked at 360 MB resident (docs/paper_size.md), rounded up
BYTES_PER_GRAIN = 4000


def check_fits(n: int) -> None:
    """Refuse ``n`` grains when building them would need more memory than the machine has."""
    import os

    need = n * BYTES_PER_GRAIN
    have = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    if need > have:
        raise ValueError(f"{n} grains need about {need / 2**30:.3g} GiB to build, and this "
                         f"machine has {have / 2**30:.3g} GiB: choose fewer grains (at most "
                         f"about {have // BYTES_PER_GRAIN})")
