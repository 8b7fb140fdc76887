"""Analysis of one run directory, written by ``jkrdt setup`` + ``jkrdt run``, the deck
``inputs/collision.lmp``, or ``jkrdt.session.Session``. It composes the reading
(analysis.dumps), the per-frame measures (analysis.outcome.CollisionOutcome, an
MDAnalysis AnalysisBase), the log (jkrdt.rundir: thermo, status) and the writers
(analysis.tables, analysis.plots):

    collision.json, log.lammps, checks.csv, atoms.dump.gz, contacts.dump.gz   ->
    frames.csv     the outcome metrics and the energy partition at every settle check
                   (from the settle rule's table checks.csv), or, for a run without
                   one, at every dumped frame
    outcome.json   the final outcome, the run's parameters, N_cum, the energy scalings
    outcome.png/pdf, energy.png/pdf   a snapshot of the outcome and the energy partition
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from jkrdt import rundir
from jkrdt.protocol import offset_label
from jkrdt.rundir import IN_PROGRESS, read_thermo, run_status
from jkrdt.ledger import CHANNELS, contact_events, energy_budget, energy_error
from jkrdt.stopping import ENERGY_WARN, STOP_WORDS

from .dumps import atoms_universe
from .outcome import CollisionOutcome, energy_scalings, from_checks, stretching
from .plots import energy_partition, outcome, timeline
from .summary import diagnostics
from .tables import read_csv, write_csv


class RunNotComplete(ValueError):
    """A run that failed or was cut off, analysed without ``partial=True``."""


def flown(x: np.ndarray, measured, t_end: float) -> np.ndarray:
    """Positions at ``t_end`` with each departed fragment moved on from where it stopped at
    the velocity of its centre of mass (equal grains) since its departure: it flies on
    as a rigid body, and its spin, which turns it about that centre, is left out."""
    departed = measured.departed_at > 0
    if not departed.any() or measured.velocities is None:
        return x
    labels = measured.labels
    count = np.bincount(labels)
    centre_v = np.stack([np.bincount(labels, measured.velocities[:, k]) / count
                         for k in range(3)], axis=1)
    x = x.copy()
    x[departed] += centre_v[labels[departed]] * (t_end - measured.departed_at[departed])[:, None]
    return x


def analyse_run(run, tolerance: float | None = None, plots: bool = True,
                partial: bool = False) -> dict:
    """Analyse ``run``; returns what ``outcome.json`` holds. ``tolerance`` (m, default
    delta_c) is used only when the run has no contact dump. A run that failed or was
    cut off (``jkrdt.rundir.run_status``) raises ``RunNotComplete`` unless ``partial``,
    which analyses the frames there are and records the stop reason."""
    run = Path(run)
    if not (run / rundir.META).exists():
        raise FileNotFoundError(f"{run} has no collision.json: analyse a directory written by "
                                "'jkrdt setup' (jkrdt.rundir.write) and run there")
    meta = rundir.read_metadata(run)
    scene = rundir.from_metadata(meta)
    log = run / rundir.LOG          # read once: the status, the thermo, the status again
    text = log.read_text(errors="replace") if log.exists() else None
    status = run_status(run, text=text)
    if status.stop_reason in ("error", IN_PROGRESS) and not partial:
        raise RunNotComplete(f"{run}: {status.problem}; analyse what is there with --partial")
    s = scene.scales
    tolerance = s.delta_c if tolerance is None else tolerance
    n_tar, n_pro = scene.n_tar, scene.n_pro
    budget, thermo = None, None
    if text is not None:
        thermo = read_thermo(log, text=text)
        budget = energy_budget(thermo)
    atoms, contacts, checks = (run / name for name in (rundir.ATOMS,
                                                        rundir.CONTACTS,
                                                        rundir.CHECKS))
    if not atoms.exists():
        raise FileNotFoundError(f"{atoms} does not exist: run the scene first ('jkrdt run "
                                f"{run}')" + (f" ({status.problem})" if status.problem else ""))
    universe = atoms_universe(atoms)
    table = from_checks(read_csv(checks), n_tar, n_pro) if checks.exists() else []
    # with the table, the dumps give only the start and the end
    every = sorted({0, len(universe.trajectory) - 1}) if table else None
    measured = CollisionOutcome(universe, n_tar, n_pro,
                                contacts=contacts if contacts.exists() else None,
                                tolerance=tolerance).run(frames=every).results
    dumped = [{name: measured[name][k].item() for name in CollisionOutcome.MEASURES}
              for k in range(len(measured.step))]
    if not dumped:
        raise ValueError(f"{atoms} has no frames"
                         + (f" ({status.problem})" if status.problem else ""))
    last_frame = dumped[-1]["step"]
    # the timeline is the table's (every check, also past the last atom frame of a run
    # cut off or under way), or the frames' for a run without the settle rule
    rows = [r for r in table if partial or r["step"] <= last_frame] or dumped
    for row in rows:
        if budget is not None:
            at = np.flatnonzero(thermo["Step"] == row["step"])
            if at.size:
                row["time"] = float(thermo["Time"][at[0]])
                row.update({name: float(budget[name][at[0]]) for name in
                            ["kinetic", "potential", "dissipated", *CHANNELS]})
                events = contact_events(thermo, int(at[0]))
                if events is not None:            # N_con, N_cut so far (App. C.2)
                    row.update(N_con=events["N_con"], N_cut=events["N_cut"])
    # the outcome: at the last atom frame, or at the last check after it (a partial one)
    last_step = max(last_frame, int(rows[-1]["step"]))
    final = {name: (dumped[-1] if last_step == last_frame else rows[-1])[name]
             for name in CollisionOutcome.MEASURES}
    if status.stop_reason != IN_PROGRESS:
        status = run_status(run, last_dump_step=last_frame, text=text)
    if status.problem and not partial:
        raise RunNotComplete(f"{run}: {status.problem}; analyse what is there with --partial")
    n_k = n_tar + n_pro - 2
    sizes, cumulative = measured.fragment_sizes, measured.N_cum
    out = dict(rundir.parameters(run, meta), E_imp=meta["E_imp"], n_k=n_k, E_roll=s.E_roll, E_break=s.E_break,
               **energy_scalings(meta["E_imp"], n_k, s.E_roll, s.E_break),
               **final, fragment_sizes=sizes.tolist(), N_cum=cumulative.tolist(),
               contacts_source="contact list" if measured.has_contacts else
               f"positions, r_i + r_j + {tolerance:.3e} m")
    out.update(stop_reason=status.stop_reason, stop_step=status.stop_step,
               last_step=last_step, last_frame_step=last_frame,
               outcome_from="atom frame" if last_step == last_frame else "settle check",
               settled=status.stop_reason == "settled", problem=status.problem)
    rule = rundir.settle_window(text) if text is not None else None
    if status.stop_reason == "settled" and rule:    # the largest's shape over the last window
        out["shape_at_end"] = stretching(table, *rule)
    if budget is not None:
        out.update(energies_at(budget, thermo, last_step, meta["E_imp"], s.t_c))
    write_csv(run / rundir.FRAMES, rows)
    if plots:
        out["pictures"] = pictures(run, scene, meta, out, rows, measured, thermo, budget)
    out["diagnostics"] = diagnostics(out)
    rundir.write_outcome(run, out)
    return out


def energies_at(budget: dict, thermo: dict, step: int, e_imp: float, t_c: float) -> dict:
    """The energy partition at ``step`` (or the last thermo line before it), over E_imp,
    with the energy error over the run and N_con, N_cut so far."""
    upto = thermo["Step"] <= step
    at = np.flatnonzero(thermo["Step"] == step)
    end = int(at[0]) if at.size else int(np.flatnonzero(upto)[-1])
    t_end = float(thermo["Time"][end])
    error = energy_error(budget, e_imp)
    # the partition of the energy at the start, at the end: kinetic_start = kinetic_left
    # + potential_change + dissipated_fraction - energy_drift (all / E_imp)
    out = dict(time_end=t_end, time_end_over_tc=t_end / t_c,
               kinetic_start=float(budget["kinetic"][0] / e_imp),
               kinetic_left=float(budget["kinetic"][end] / e_imp),
               kinetic_departed=float(budget["departed"][end] / e_imp),
               potential_change=float((budget["potential"][end] - budget["potential"][0])
                                      / e_imp),
               energy_drift=float((budget["total"][end] - budget["total"][0]) / e_imp),
               energy_error=error, energy_warning=error > ENERGY_WARN,
               dissipated_fraction=float(budget["dissipated"][end] / e_imp),
               dissipated_by_channel={name: float(budget[name][end] / e_imp)
                                      for name in CHANNELS})
    # N_con, N_cut (3D BPCA paper, App. C.2) at the analysed end; the bonded contacts
    # then less those at the start are N_con - N_cut exactly
    events = contact_events(thermo, end)
    if events is not None:
        out.update(events)
    return out


def pictures(run: Path, scene, meta: dict, out: dict, rows: list[dict], measured, thermo,
             budget) -> list[str]:
    """outcome.png (the start and the last atom frame), timeline.png (every row, with the
    last atom frame marked when the outcome is a later check's) and energy.png."""
    mat, s = scene.material, scene.scales
    n_total = scene.n_tar + scene.n_pro
    title = (f"{mat.name} {scene.kind.upper()} {scene.n_tar}+{scene.n_pro}, "
             f"v = {scene.v_col:g} m/s, {offset_label(scene.b_off)}, {scene.model}"
             + (f", T_vis = {mat.tvis * 1e12:g} ps" if mat.tvis > 0 else ""))
    when = f"{out['stop_reason']} at step {out['last_step']}"
    if "time_end" in out:
        when += (f", t = {out['time_end'] * 1e9:.0f} ns = {out['time_end_over_tc']:.0f} t_c; "
                 f"max |dE|/E_imp = {out['energy_error']:.1e}")
    frame = out["last_frame_step"]
    later = frame != out["last_step"]      # the outcome is a check's after the last frame
    step_s = scene.time_step()[0] * s.t_c          # the time of a frame without a log
    frame_row = next((r for r in rows if r["step"] == frame), None)
    frame_time = frame_row.get("time", frame * step_s) if frame_row else frame * step_s
    moments = [(rows[0]["step"], rows[0].get("time", rows[0]["step"] * step_s)),
               (frame, frame_time)]
    if later:
        when += f"\natoms drawn at step {frame}, the last atom frame"
    made = outcome(run / "outcome", measured.first_positions,
                   flown(measured.positions, measured, frame_time), measured.types,
                   measured.labels, scene.radius, scene.dim, moments, s.t_c, b=meta.get("b"),
                   title=f"{title}\n{when}", departed=measured.departed_at > 0,
                   end_label="last atom frame" if later else "end")
    made += timeline(run / "timeline", rows, n_total, meta["E_imp"], s.t_c, title,
                     last_frame=frame_time if later else None)
    if budget is not None:
        made += energy_partition(run / "energy", thermo["Time"], budget, meta["E_imp"], title)
    return [str(p) for p in made]


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
        + (f" = {out['E_imp_over_nk_Ebreak']:.3g} n_k E_break" if out['E_imp_over_nk_Ebreak']
           else ""),
    ]
    ended = STOP_WORDS[out["stop_reason"]]
    lines.append(f"the run                     {ended} at step {out['stop_step']}"
                 + (f" (analysed up to step {out['last_step']})"
                    if out["last_step"] != out["stop_step"] else "")
                 + (f", t = {out['time_end'] * 1e9:.0f} ns = {out['time_end_over_tc']:.0f} t_c"
                    if "time_end" in out else ""))
    frame = out.get("last_frame_step", out["last_step"])
    if frame != out["last_step"]:
        lines.append(f"outcome from                the settle check at step {out['last_step']} "
                     f"(checks.csv, log.lammps); the last atom frame is at step {frame}, "
                     "where N_cum and the picture are")
    if out.get("problem"):
        lines.append(f"  WARNING                   {out['problem']}; partial outcome")
    shape = out.get("shape_at_end")
    if shape and shape["stretching"]:
        lines.append(f"  WARNING                   the largest body's r_g grew "
                     f"{100 * shape['r_g_growth']:.1f} % over the settle rule's last "
                     f"{shape['window']} checks: a neck may still part it and lower f_gro; "
                     "read the outcome at a later, fixed time (the manual's fix "
                     "jkr/dt/settle, 'What the rule does not watch')")
    if "kinetic_left" in out:
        lines.append(f"kinetic energy left / E_imp {out['kinetic_left']:.3f}"
                     + (f"  ({out['kinetic_departed']:.3f} in departed fragments)"
                        if out.get("kinetic_departed") else ""))
    if "dissipated_fraction" in out:
        lines.append(f"dissipated / E_imp          {out['dissipated_fraction']:.3f}  ("
                     + ", ".join(f"{k} {v:.3f}" for k, v in out["dissipated_by_channel"].items())
                     + ")")
    if out.get("N_con") is not None:
        lines.append(f"contacts made / cut         N_con {out['N_con']:.0f}, N_cut "
                     f"{out['N_cut']:.0f}  ({out['N_con'] / out['n_total']:.2f} and "
                     f"{out['N_cut'] / out['n_total']:.2f} N_tot; bonded "
                     f"{out['contacts_start']:.0f} -> {out['contacts_end']:.0f})")
    if "potential_change" in out:
        lines.append(f"energy partition / E_imp    kinetic {out['kinetic_left']:.3f} + potential "
                     f"change {out['potential_change']:+.3f} + dissipated "
                     f"{out['dissipated_fraction']:.3f} = {out['kinetic_start']:.3f} (kinetic "
                     f"at the start) {out['energy_drift']:+.1e} (drift)")
        lines.append(f"max |dE| / E_imp            {out['energy_error']:.2e}"
                     + (f"  WARNING: above {ENERGY_WARN:g}; use a smaller --dt"
                        if out["energy_warning"] else ""))
    for p in out.get("pictures", []):
        if p.endswith(".png"):
            lines.append(f"picture                     {p}")
    return "\n".join(lines)
