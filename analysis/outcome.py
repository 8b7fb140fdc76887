"""Outcome metrics of a collision, per frame and at the end.

    N_lar, N_second   sizes of the largest and second-largest fragment
    f_gro             growth efficiency (N_lar - N_tar) / N_pro   (3D BPCA paper, sec. 3.1)
    r_g               gyration radius of the largest fragment     (Wada et al. 2007, eq. 50)
    n_con             contacts per grain in the largest fragment, n_contacts / N_lar: about 1
                      for an aggregate that is a tree (N - 1 contacts), more once compressed
                      (Wada et al. 2007, sec. 5.3, Fig. 11, eqs. 56-57; half the mean
                      coordination number)
    n_fragments       number of fragments
    N_cum(<= N)       grains in fragments of at most N grains     (3D BPCA paper, sec. 3.2)

and the scalings of Wada et al. (2007): E_imp / (n_k E_roll) and E_imp / (n_k E_break),
with n_k = N_total - 2 the contacts of the two aggregates before impact (sec. 4).

``CollisionOutcome`` computes the per-frame measures the MDAnalysis way, as an
``AnalysisBase`` over a Universe of a run's atom dump.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from MDAnalysis.analysis.base import AnalysisBase

from jkrdt.aggregates import gyration_radius
from jkrdt.stopping import STRETCH

from . import fragments as frag


@dataclasses.dataclass
class Outcome:
    step: int
    n_total: int
    n_largest: int
    n_second: int
    n_fragments: int
    growth_efficiency: float
    gyration_radius_largest: float    # m
    contacts_per_particle: float      # n_con of the largest fragment


def growth_efficiency(n_largest: int, n_target: int, n_projectile: int) -> float:
    """f_gro = (N_lar - N_tar) / N_pro (3D BPCA paper, sec. 3.1)."""
    return (n_largest - n_target) / n_projectile


def from_checks(rows: list[dict], n_target: int, n_projectile: int) -> list[dict]:
    """The measures of ``Outcome`` at every check, from the rows of the settle rule's
    in-run table (``checks.csv``, fix_jkr_dt_settle_table.cpp); a step written twice (a
    run continued from a restart file) counts once, as written last."""
    latest = {int(row["step"]): row for row in rows}
    out = []
    for step in sorted(latest):
        row = latest[step]
        n_lar = int(row["n_largest"])
        out.append(dict(step=step, n_total=int(row["n_total"]), n_largest=n_lar,
                        n_second=int(row["n_second"]), n_fragments=int(row["n_fragments"]),
                        growth_efficiency=growth_efficiency(n_lar, n_target, n_projectile),
                        gyration_radius_largest=float(row["gyration_radius_largest"]),
                        contacts_per_particle=int(row["contacts_largest"]) / n_lar,
                        N_cum_1=int(row["N_cum_1"]), N_cum_4=int(row["N_cum_4"]),
                        N_cum_16=int(row["N_cum_16"]),
                        departed_grains=int(row["departed_grains"]),
                        time=float(row["time"]),
                        **{k: float(row[k]) for k in ("wall", "memory_mb") if k in row}))
    return out


#: a body of at least this share of all grains (f_gro >= -0.5 for equal aggregates) whose
#: r_g still grew when the settle rule ended the run may yet part (``stretching``): the
#: share from which the rule itself watches shape (``jkrdt.stopping.STRETCH``)
STRETCH_SHARE = STRETCH


def stretching(table: list[dict], window: int, tolerance: float) -> dict | None:
    """How much the largest fragment's gyration radius grew over the settle rule's last
    ``window`` checks of ``table`` (rows of ``from_checks``), and whether that is a body
    still being pulled apart: it grew by more than ``tolerance`` (the rule's relative
    tolerance) and holds at least STRETCH_SHARE of the grains. The rule watches counts,
    contacts and dissipation, not shape: a neck without rolling or sliding resistance
    stretches at constant N_lar and contacts, dissipating nothing, and parts later (at
    2 x 50000, 1/12 at 39.8 m/s: r_g +4.2 % over the window at the settle end, parted
    0.4 us on). None for a table shorter than the window or a largest of one grain."""
    if len(table) < window + 1:
        return None
    first, last = table[-1 - window], table[-1]
    if not first["gyration_radius_largest"] > 0:
        return None
    growth = last["gyration_radius_largest"] / first["gyration_radius_largest"] - 1
    return dict(r_g_growth=growth, window=window,
                stretching=bool(growth > tolerance
                                and last["n_largest"] >= STRETCH_SHARE * last["n_total"]))


def measure(x: np.ndarray, labels: np.ndarray, pairs: np.ndarray, n_target: int,
            n_projectile: int, step: int = 0) -> Outcome:
    """Metrics of one frame: positions ``x`` (N, 3), fragment ``labels``, and the bonded
    ``pairs`` as 0-based index pairs (those the labels were built from)."""
    if n_target + n_projectile != len(x):
        raise ValueError(f"N_tar + N_pro = {n_target + n_projectile} but the frame has "
                         f"{len(x)} grains: the metadata belong to another run")
    sizes = np.bincount(labels)
    # of fragments equally large, the one holding the first grain (labels count up from
    # the fragment of the first grain) ranks first, as in the settle rule's table
    first = int(np.argmax(sizes))
    largest = labels == first
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    inside = largest[pairs[:, 0]] & largest[pairs[:, 1]]
    n_lar = int(sizes[first])
    return Outcome(
        step=int(step), n_total=len(x), n_largest=n_lar,
        n_second=int(np.delete(sizes, first).max()) if len(sizes) > 1 else 0,
        n_fragments=len(sizes),
        growth_efficiency=growth_efficiency(n_lar, n_target, n_projectile),
        gyration_radius_largest=gyration_radius(x[largest]),
        contacts_per_particle=int(inside.sum()) / n_lar)


def measure_frame(frame, n_target: int, n_projectile: int, tolerance: float | None = None):
    """Fragments and metrics of a ``dumps.Frame``: from its contact list, or from positions
    with ``tolerance`` (normally delta_c) when the frame has none. Returns (labels, Outcome)."""
    if frame.pairs is not None:
        index = np.searchsorted(frame.ids, frame.pairs)
        labels = frag.from_contacts(frame.ids, frame.pairs)
    else:
        if tolerance is None:
            raise ValueError("no contact list in this run: give the position tolerance "
                             "(delta_c of the material)")
        index = frag.position_pairs(frame.x, frame.radius, tolerance)
        labels = frag.from_positions(frame.x, frame.radius, tolerance)
    return labels, measure(frame.x, labels, index, n_target, n_projectile, frame.step)


def energy_scalings(e_imp: float, n_k: int, e_roll: float | None, e_break: float) -> dict:
    """E_imp in units of n_k E_roll and of n_k E_break (Wada et al. 2007, Table 1); None
    where the unit is not defined (no rolling, or n_k = 0: two single grains)."""
    return dict(E_imp_over_nk_Eroll=None if e_roll is None or n_k == 0 else e_imp / (n_k * e_roll),
                E_imp_over_nk_Ebreak=None if n_k == 0 else e_imp / (n_k * e_break))


class CollisionOutcome(AnalysisBase):
    """Per-frame outcome of an aggregate collision over a Universe of its atom dump
    (``analysis.dumps.atoms_universe``: positions plus the per-atom ``radius`` column).

    Fragments come from ``contacts``, the run's contact dump (compute jkr/dt/contacts
    through ``dump local``, joined by timestep), or, without one, from positions within
    r_i + r_j + ``tolerance``. ``run(start, stop, step)`` as for any AnalysisBase; then
    ``results`` holds one entry per analysed frame in ``step``, ``n_largest``,
    ``n_second``, ``n_fragments``, ``growth_efficiency``, ``gyration_radius_largest``
    and ``contacts_per_particle`` (arrays), and for the last frame analysed its
    ``labels`` (fragment of each atom, by ascending ID), ``positions``, ``has_contacts``,
    ``fragment_sizes`` and ``N_cum`` (grains in fragments of at most N grains), its
    ``velocities`` (None where the dump has none) and ``departed_at`` (the time each
    grain's fragment departed, 0 if it did not or the dump does not say), with the
    atoms' ``types`` (1 target, 2 projectile) and the first analysed frame's
    ``first_positions``. A contact
    snapshot cut off by the end of its file (a run killed while dumping) ends the
    analysis at the frame before it; ``results.cut_off_at`` is then that frame's step."""

    MEASURES = [f.name for f in dataclasses.fields(Outcome)]
    #: each measure's array type: the results are allocated for every frame at the start,
    #: as MDAnalysis's own analyses do, and cut to the frames measured at the end
    DTYPES = {f.name: np.int64 if f.type == "int" else np.float64
              for f in dataclasses.fields(Outcome)}

    def __init__(self, universe, n_target: int, n_projectile: int, contacts=None,
                 tolerance: float | None = None, **kwargs):
        super().__init__(universe.trajectory, **kwargs)
        self._atoms = universe.atoms
        self._order = np.argsort(self._atoms.ids)
        self._ids = self._atoms.ids[self._order]
        from .dumps import ContactSnapshots
        self._contacts = ContactSnapshots(contacts) if contacts is not None else None
        self._n = (n_target, n_projectile)
        self._tolerance = tolerance
        if self._contacts is None and tolerance is None:
            raise ValueError("no contact dump given: give the position tolerance (delta_c "
                             "of the material)")

    def _prepare(self):
        for name in self.MEASURES:
            self.results[name] = np.zeros(self.n_frames, dtype=self.DTYPES[name])
        self._measured = 0    # frames measured: all but those after a cut-off snapshot
        self.results.cut_off_at = None
        self.results.types = self._atoms.types[self._order].astype(int)
        self._last = None

    def _single_frame(self):
        from .dumps import Frame, TruncatedDump
        ts = self._ts
        if self.results.cut_off_at is not None:
            return
        if "radius" not in ts.data:
            raise ValueError("the atom dump has no radius column; dump 'id type radius x y z'")
        step = int(ts.data["step"])
        try:
            pairs = self._contacts.pairs(step) if self._contacts else None
        except TruncatedDump:
            self.results.cut_off_at = step
            return
        frame = Frame(step=step, ids=self._ids,
                      x=self._atoms.positions[self._order].astype(np.float64),
                      radius=np.asarray(ts.data["radius"][self._order], dtype=np.float64),
                      pairs=pairs)
        labels, outcome = measure_frame(frame, *self._n, self._tolerance)
        for name in self.MEASURES:
            self.results[name][self._frame_index] = getattr(outcome, name)
        self._measured = self._frame_index + 1
        if self._last is None:
            self.results.first_positions = frame.x
        from .dumps import DEPARTED_AT
        departed_at = (np.asarray(ts.data[DEPARTED_AT][self._order], dtype=np.float64)
                       if DEPARTED_AT in ts.data else np.zeros(len(self._ids)))
        velocities = (self._atoms.velocities[self._order].astype(np.float64)
                      if ts.has_velocities else None)
        self._last = frame, labels, departed_at, velocities

    def _conclude(self):
        for name in self.MEASURES:
            self.results[name] = self.results[name][:self._measured]
        if self._last is not None:
            frame, labels, self.results.departed_at, self.results.velocities = self._last
            sizes, cumulative = frag.cumulative_number(labels)
            self.results.labels, self.results.positions = labels, frame.x
            self.results.has_contacts = frame.pairs is not None
            self.results.fragment_sizes, self.results.N_cum = sizes, cumulative
