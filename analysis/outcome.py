"""Collision outcome from the final state: fragments, largest remnant, growth efficiency.

A fragment is a connected component of the bonded-contact graph (the plugin's
contact list). Growth efficiency f_gro = (N_lar - N_tar) / N_pro, 3D BPCA paper sec. 3.1.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components


def fragments(n_atoms: int, pairs: np.ndarray) -> np.ndarray:
    """Fragment label of each atom (0-based index = atom ID - 1) from contact pairs of atom IDs."""
    pairs = np.asarray(pairs, dtype=int).reshape(-1, 2) - 1
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n_atoms, n_atoms))
    return connected_components(graph, directed=False)[1]


@dataclasses.dataclass
class Outcome:
    n_total: int
    n_largest: int
    n_second: int
    n_fragments: int
    growth_efficiency: float
    gyration_radius_largest: float    # m, eq. (50) of Wada et al. (2007)
    contacts_per_particle: float      # n_con = 2 n_contacts / N

    def summary(self) -> str:
        return "\n".join([
            f"grains                      {self.n_total}",
            f"largest remnant N_lar       {self.n_largest}",
            f"second largest              {self.n_second}",
            f"fragments                   {self.n_fragments}",
            f"growth efficiency f_gro     {self.growth_efficiency:+.3f}",
            f"r_g of largest              {self.gyration_radius_largest * 1e6:.3f} micron",
            f"contacts per grain n_con    {self.contacts_per_particle:.3f}",
        ])


def outcome(x: np.ndarray, pairs: np.ndarray, n_target: int, n_projectile: int) -> Outcome:
    """Outcome metrics for positions ``x`` (rows ordered by atom ID) and contact ``pairs``."""
    labels = fragments(len(x), pairs)
    sizes = np.bincount(labels)
    order = np.argsort(sizes)[::-1]
    largest = labels == order[0]
    xl = x[largest]
    rg = float(np.sqrt(((xl - xl.mean(axis=0)) ** 2).sum(axis=1).mean()))
    return Outcome(
        n_total=len(x), n_largest=int(sizes[order[0]]),
        n_second=int(sizes[order[1]]) if len(sizes) > 1 else 0,
        n_fragments=len(sizes),
        growth_efficiency=(sizes[order[0]] - n_target) / n_projectile,
        gyration_radius_largest=rg,
        contacts_per_particle=2.0 * len(pairs) / len(x))
