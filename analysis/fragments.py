"""Fragments: connected components of the bonded-contact graph.

The graph comes from the plugin's contact list (``compute jkr/dt/contacts``) when a
run dumped it. Otherwise it is rebuilt from positions: grains i and j are taken as
bonded when

    |x_i - x_j| <= r_i + r_j + tolerance,    tolerance = delta_c by default,

because a JKR contact forms at |x_i - x_j| = r_i + r_j and breaks only beyond
r_i + r_j + delta_c (Wada et al. 2007, sec. 2.1): every bonded pair passes the test.
A pair that has not touched yet but approaches within delta_c also passes (for
example two aggregates set up delta_c/2 apart before impact), so the contact list
is the better source whenever it exists.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree


def _components(n: int, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    graph = coo_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
    return connected_components(graph, directed=False)[1]


def from_contacts(ids: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """Fragment label of each atom of ``ids`` from contact ``pairs`` of atom IDs."""
    ids = np.asarray(ids)
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    index = np.searchsorted(ids, pairs)
    if len(ids) and pairs.size and (index.max() >= len(ids) or
                                    not np.array_equal(ids[index], pairs)):
        raise ValueError("contact list names atoms that are not in the frame: check that "
                         "the atom and contact dumps belong to the same run")
    return _components(len(ids), index[:, 0], index[:, 1])


def position_pairs(x: np.ndarray, radius, tolerance: float) -> np.ndarray:
    """Index pairs (i < j) with |x_i - x_j| <= r_i + r_j + tolerance."""
    x = np.asarray(x, dtype=float)
    r = np.broadcast_to(np.asarray(radius, dtype=float), (len(x),))
    if tolerance < 0:
        raise ValueError("tolerance must be >= 0")
    pairs = cKDTree(x).query_pairs(2.0 * r.max() + tolerance, output_type="ndarray")
    d = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
    return pairs[d <= r[pairs[:, 0]] + r[pairs[:, 1]] + tolerance]


def from_positions(x: np.ndarray, radius, tolerance: float) -> np.ndarray:
    """Fragment label of each grain from positions (see the module text for ``tolerance``,
    normally delta_c of the material)."""
    pairs = position_pairs(x, radius, tolerance)
    return _components(len(x), pairs[:, 0], pairs[:, 1])


def sizes_by_rank(labels: np.ndarray) -> np.ndarray:
    """Fragment sizes, largest first."""
    return np.sort(np.bincount(labels))[::-1]


def cumulative_number(labels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """N_cum(<= N): the number of grains in fragments of at most N grains (3D BPCA paper
    sec. 3.2), at each distinct fragment size N; returns (N, N_cum)."""
    sizes = np.bincount(labels)
    n, count = np.unique(sizes, return_counts=True)
    return n, np.cumsum(n * count)


def same_partition(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two labellings group the grains into the same fragments."""
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape:
        return False
    pairs = np.unique(np.stack([a, b], axis=1), axis=0)
    return len(pairs) == len(np.unique(a)) == len(np.unique(b))
