"""Analysis of one run directory (written by ``jkrdt setup`` + ``jkrdt run``, the deck
``inputs/collision.lmp``, or ``jkrdt.session.Session``):

    collision.json, log.lammps, atoms.dump, contacts.dump   ->
    frames.csv     the outcome metrics and the energy partition at every dumped frame
    outcome.json   the final outcome, the run's parameters, N_cum, the energy scalings
    outcome.png/pdf, energy.png/pdf   a snapshot of the outcome and the energy partition
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from jkrdt.materials import from_dict, scales

from . import fragments as frag
from .dumps import frames
from .outcome import energy_scalings, measure_frame
from .plots import energy_partition, snapshot
from .tables import write_csv, write_json
from .thermo import CHANNELS, energy_budget, read_thermo


def analyse_run(run, tolerance: float | None = None, plots: bool = True) -> dict:
    """Analyse ``run``; returns what ``outcome.json`` holds. ``tolerance`` (m, default
    delta_c) is used only when the run has no contact dump."""
    run = Path(run)
    meta = json.loads((run / "collision.json").read_text())
    mat = from_dict(meta["material"])
    s = scales(mat, meta["radius"])
    tolerance = s.delta_c if tolerance is None else tolerance
    n_tar, n_pro = meta["N_tar"], meta["N_pro"]
    budget, thermo = None, None
    if (run / "log.lammps").exists():
        thermo = read_thermo(run / "log.lammps")
        budget = energy_budget(thermo)
    rows, last = [], None
    for frame in frames(run):
        labels, result = measure_frame(frame, n_tar, n_pro, tolerance)
        row = dict(result.__dict__)
        if budget is not None:
            at = np.flatnonzero(thermo["Step"] == frame.step)
            if at.size:
                row["time"] = float(thermo["Time"][at[0]])
                row.update({name: float(budget[name][at[0]]) for name in
                            ["kinetic", "potential", "dissipated", *CHANNELS]})
        rows.append(row)
        last = frame, labels, result
    if last is None:
        raise ValueError(f"{run / 'atoms.dump'} has no frames")
    frame, labels, final = last
    n_k = n_tar + n_pro - 2
    sizes, cumulative = frag.cumulative_number(labels)
    out = dict(run=str(run), N_tar=n_tar, N_pro=n_pro, v_col=meta["v_col"],
               B_off=meta["B_off"], seed=meta.get("seed"), model=meta.get("model"),
               kind=meta.get("kind"), dimension=meta["dimension"],
               material=mat.name, xi_crit=mat.xi_crit, tvis=mat.tvis, radius=meta["radius"],
               E_imp=meta["E_imp"], n_k=n_k, E_roll=s.E_roll, E_break=s.E_break,
               **energy_scalings(meta["E_imp"], n_k, s.E_roll, s.E_break),
               **final.__dict__, fragment_sizes=sizes.tolist(), N_cum=cumulative.tolist(),
               contacts_source="contact list" if frame.pairs is not None else
               f"positions, r_i + r_j + {tolerance:.3e} m")
    if budget is not None:
        e_imp = meta["E_imp"]
        out.update(energy_error=float(np.abs(budget["total"] - budget["total"][0]).max() / e_imp),
                   dissipated_fraction=float(budget["dissipated"][-1] / e_imp),
                   dissipated_by_channel={name: float(budget[name][-1] / e_imp)
                                          for name in CHANNELS})
    write_csv(run / "frames.csv", rows)
    if plots:
        title = (f"{mat.name} {(meta.get('kind') or '').upper()} {n_tar}+{n_pro}, "
                 f"v = {meta['v_col']:g} m/s, B_off = {meta['B_off']:g}, {meta.get('model', '')}")
        out["pictures"] = [str(p) for p in snapshot(run / "outcome", frame.x, labels, title,
                                                           radius=meta["radius"])]
        if budget is not None:
            out["pictures"] += [str(p) for p in energy_partition(run / "energy", thermo["Time"],
                                                                 budget, meta["E_imp"], title)]
    write_json(run / "outcome.json", out)
    return out


def summary_text(out: dict) -> str:
    """The outcome summary printed by ``jkrdt analyse`` and ``jkrdt demo``."""
    lines = [
        f"grains                      {out['n_total']}  ({out['N_tar']} + {out['N_pro']})",
        f"largest remnant N_lar       {out['n_largest']}",
        f"second largest              {out['n_second']}",
        f"fragments                   {out['n_fragments']}",
        f"growth efficiency f_gro     {out['growth_efficiency']:+.3f}",
        f"r_g of largest              {out['gyration_radius_largest'] * 1e6:.4f} micron",
        f"contacts per grain n_con    {out['contacts_per_particle']:.3f}  (largest fragment)",
        f"impact energy E_imp         {out['E_imp']:.3e} J"
        + (f" = {out['E_imp_over_nk_Eroll']:.3g} n_k E_roll" if out['E_imp_over_nk_Eroll'] else "")
        + f" = {out['E_imp_over_nk_Ebreak']:.3g} n_k E_break",
    ]
    if "dissipated_fraction" in out:
        lines.append(f"dissipated / E_imp          {out['dissipated_fraction']:.3f}  ("
                     + ", ".join(f"{k} {v:.3f}" for k, v in out["dissipated_by_channel"].items())
                     + ")")
        lines.append(f"max |dE| / E_imp            {out['energy_error']:.2e}")
    for p in out.get("pictures", []):
        if p.endswith(".png"):
            lines.append(f"picture                     {p}")
    return "\n".join(lines)
