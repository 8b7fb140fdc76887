"""The 3D BPCA paper's collision protocol (Arakawa et al. 2023, Fig. 2 and App. B), by name.

    B_off^2 = k/12, k = 0 ... 12          v_col = 10^(0.1 i) m/s, i = 10 ... 20

B_off^2 = 12/12 grazes: the two aggregates' characteristic radii just touch, and the
outcome is taken as no collision (f_gro 0) rather than run, so a campaign runs k = 0 ... 11
(``B_OFF2``). <A> of eq. (1) is the trapezoid over the whole grid with the grazing point
at its no-collision value (``GRAZING``): the head-on run weighs 1/24, each inner offset
1/12, 11/12 weighs 1/24 and grazing 1/24 (analysis.summary.b_off_average). A grid of
other offsets is averaged without the grazing point, each end value held to the end of
[0, 1].

In a campaign spec, ``"v_col": "paper"`` and ``"b_off2": "paper"`` stand for these lists
(``jkrdt.campaign``).
"""

from __future__ import annotations

#: the name a campaign spec gives the paper's grids
PAPER = "paper"
#: the offsets a campaign of the paper's protocol runs: B_off^2 = k/12, k = 0 ... 11
B_OFF2 = [k / 12 for k in range(12)]
#: the paper's speeds, 10^(0.1 i) m/s for i = 10 ... 20 (10 to 100 m/s)
V_COL = [round(10 ** (0.1 * i), 1) for i in range(10, 21)]
#: at B_off^2 = 1 the aggregates graze: what a collision that does not happen gives (f_gro
#: 0, the target alone the largest of two equal aggregates); nothing is made, cut or
#: dissipated there (0), and N_cum is ``grazing_cumulative``
GRAZING = dict(growth_efficiency=0.0, N_lar_over_N_total=0.5)


def grazing_cumulative(n, n_tar: int, n_pro: int):
    """N_cum(<= n) of a collision that does not happen: the two aggregates whole."""
    import numpy as np

    n = np.asarray(n)
    return n_tar * (n >= n_tar) + n_pro * (n >= n_pro)


def twelfths(b_off2: float, tolerance: float = 1e-6) -> str | None:
    """B_off^2 as the paper writes it, "k/12", where it is a twelfth (within
    ``tolerance`` of k; 1e-3 for a value written with 4 decimals); else None."""
    k = 12 * b_off2
    return f"{round(k)}/12" if abs(k - round(k)) < tolerance else None


def offset_label(b_off: float) -> str:
    """B_off as the paper names it: "B_off^2 = k/12" on its grid, else "B_off = x"."""
    k = twelfths(b_off ** 2)
    return f"B_off^2 = {k}" if k else f"B_off = {b_off:g}"


def is_paper_grid(b_off2) -> bool:
    """Whether ``b_off2`` (the B_off^2 values of runs) is the paper's grid less its grazing
    end: then eq. (1) adds the grazing point."""
    return sorted({round(float(b), 9) for b in b_off2}) == [round(b, 9) for b in B_OFF2]
