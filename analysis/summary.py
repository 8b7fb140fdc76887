"""Campaign statistics over runs analysed by ``analysis.run`` (one outcome.json each).

    <A> = int_0^1 dB_off 2 B_off A = int_0^1 A d(B_off^2)      (3D BPCA paper, eq. 1)

is integrated with the trapezoid rule over the grid of B_off^2 values the campaign ran
(the paper's grid is 0, 1/12, ..., 1, on which the rule is exact for A linear in
B_off^2); A is held at its end values outside the grid, except on the paper's grid less
its grazing end (``jkrdt.protocol``), where B_off^2 = 1 takes A's no-collision value.
v_fra is where <f_gro> crosses 0, interpolated linearly in log v_col between the grid
velocities. With two or more seeds, each seed's <f_gro> and v_fra are taken on their own
too, and their mean and standard error are the scatter the campaign reports.
"""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path

import numpy as np

from jkrdt import ledger, protocol, rundir
from jkrdt.rundir import write_json
from jkrdt.stopping import COMPLETE

from . import plots
from .tables import write_csv

#: N of the paper's N_cum(<= N) that every run's diagnostics carry (3D BPCA paper, Fig. 3)
N_CUM_AT = (1, 10, 100, 1000)
#: the 3D BPCA paper's diagnostics of one collision (its App. C and Fig. 3), as
#: ``diagnostics`` names them: contacts made and cut (Figs. C.3, C.4), the energy
#: dissipated in all, by making and breaking contacts, by damping (Figs. C.1, C.2) and by
#: the tangential channels, all over E_imp; N_cum(<= N) at N_CUM_AT
#: the paper's name of a channel's dissipation (the others: E_dis_<channel>)
PAPER_CHANNEL = {"events": "E_dis_c", "damping": "E_dis_v"}
CHANNEL_DIAGNOSTICS = [PAPER_CHANNEL.get(c, f"E_dis_{c}") for c in ledger.CHANNELS]
DIAGNOSTICS = ["N_con", "N_cut", "E_dis_tot", *CHANNEL_DIAGNOSTICS,
               *(f"N_cum_{n}" for n in N_CUM_AT)]
SCALARS = ["model", "material", "xi_crit", "tvis", "kind", "dimension", "N_tar", "N_pro",
           "v_col", "B_off", "B_off2", "seed", "radius", "E_imp", "n_k", "E_imp_over_nk_Eroll",
           "E_imp_over_nk_Ebreak", "step", "n_total", "n_largest", "n_second", "n_fragments",
           "growth_efficiency", "gyration_radius_largest", "contacts_per_particle",
           "dissipated_fraction", "energy_error", "energy_warning", "stop_reason", "stop_step",
           "kinetic_left", "r_g_growth_at_end", "stretching_at_end", *DIAGNOSTICS, "problem",
           "run"]


def b_off_average(b_off2, values, grazing=None) -> np.ndarray:
    """<A> of eq. (1) from values of A (along axis 0) at the given B_off^2; ``grazing``:
    A at B_off^2 = 1 where the grid stops short of it (else the last value is held)."""
    b2 = np.asarray(b_off2, dtype=float)
    a = np.asarray(values, dtype=float)
    if b2.ndim != 1 or len(b2) != len(a) or len(b2) == 0:
        raise ValueError("one value of A per B_off^2 is needed")
    if b2.min() < 0 or b2.max() > 1:
        raise ValueError("B_off^2 must lie in [0, 1]")
    if len(np.unique(b2)) != len(b2):
        raise ValueError("repeated B_off^2 values: average the runs of one B_off^2 first")
    if grazing is not None and b2.max() < 1:
        b2 = np.append(b2, 1.0)
        a = np.concatenate([a, np.full((1, *a.shape[1:]), grazing, dtype=float)])
    order = np.argsort(b2)
    b2, a = b2[order], a[order]
    grid = np.concatenate([[0.0], b2, [1.0]])
    a = np.concatenate([a[:1], a, a[-1:]])
    widths = np.diff(grid).reshape(-1, *([1] * (a.ndim - 1)))
    return (0.5 * widths * (a[1:] + a[:-1])).sum(axis=0)


def b_off_groups(runs, value) -> tuple[np.ndarray, np.ndarray]:
    """The B_off^2 values of ``runs`` (ascending) and value(run) averaged over the runs
    (seeds) of each."""
    by_b2 = defaultdict(list)
    for o in runs:
        by_b2[round(o["B_off"] ** 2, 12)].append(value(o))
    b2 = np.array(sorted(by_b2))
    return b2, np.array([np.mean(by_b2[b], axis=0) for b in b2])


def b_off_mean(runs, value, grazing=None) -> np.ndarray:
    """<A> of eq. (1) over ``runs`` (outcomes at one v_col): A = value(run) averaged over
    the runs (seeds) of each B_off^2 first (``b_off_groups``), then over B_off^2 by
    ``b_off_average``; on the paper's grid less its grazing end (``jkrdt.protocol``)
    B_off^2 = 1 takes ``grazing``, A of a collision that does not happen."""
    b2, a = b_off_groups(runs, value)
    return b_off_average(b2, a, grazing if protocol.is_paper_grid(b2) else None)


def seed_scatter(runs, value, grazing=None) -> dict:
    """<A> of eq. (1) for each seed whose runs cover every B_off^2 of ``runs``, and their
    mean and standard error over seeds (NaN for fewer than two seeds)."""
    grid = {round(o["B_off"] ** 2, 12) for o in runs}
    seeds = sorted({o["seed"] for o in runs})
    per = {}
    for k in seeds:
        mine = [o for o in runs if o["seed"] == k]
        if {round(o["B_off"] ** 2, 12) for o in mine} == grid:
            per[k] = float(b_off_mean(mine, value, grazing))
    x = np.array(list(per.values()))
    se = float(x.std(ddof=1) / np.sqrt(len(x))) if len(x) > 1 else float("nan")
    return dict(per_seed=per, mean=float(x.mean()) if len(x) else float("nan"), se=se)


def offset_table(groups) -> dict:
    """The 3D BPCA paper's Fig. B.1 for each model: f_gro (seeds averaged) per B_off^2
    (rows) and v_col (columns), from ``groups[(model, v_col)] = runs``."""
    table = defaultdict(dict)
    for (name, v), runs in sorted(groups.items()):
        b2, f = b_off_groups(runs, lambda o: o["growth_efficiency"])
        for b, value in zip(b2, f):
            table[name].setdefault(f"{b:.4f}", {})[f"{v:g}"] = float(value)
    return {name: dict(sorted(rows.items())) for name, rows in table.items()}


def offset_rows(table: dict) -> list[dict]:
    """``offset_table`` as rows of f_gro_by_offset.csv: model, B_off^2 (and as k/12),
    then f_gro at each v_col (m/s)."""
    rows = []
    for name, by_b2 in table.items():
        speeds = sorted({v for row in by_b2.values() for v in row}, key=float)
        for b, row in by_b2.items():
            rows.append(dict(model=name, B_off2=float(b),
                             B_off2_twelfths=protocol.twelfths(float(b), 1e-3) or "",
                             **{f"f_gro_{v}": row.get(v) for v in speeds}))
    return rows


def offset_table_text(table: dict) -> str:
    """``offset_table`` as the text ``jkrdt summarise`` prints: B_off^2 as k/12 where it
    is one, a column per v_col."""
    lines = []
    for name, rows in table.items():
        speeds = sorted({v for row in rows.values() for v in row}, key=float)
        lines.append(f"f_gro by B_off^2 and v_col (m/s), {name} (the paper's Fig. B.1):")
        lines.append("B_off^2 " + "".join(f"{v:>8}" for v in speeds))
        for b, row in rows.items():
            lines.append(f"{protocol.twelfths(float(b), 1e-3) or b:<8}" + "".join(
                f"{row[v]:+8.3f}" if v in row else f"{'':>8}" for v in speeds))
    return "\n".join(lines)


def threshold_velocity(v_col, mean_f_gro) -> float | None:
    """The first v_col at which <f_gro> falls from > 0 to <= 0 (log-linear interpolation)."""
    v = np.asarray(v_col, dtype=float)
    f = np.asarray(mean_f_gro, dtype=float)
    order = np.argsort(v)
    v, f = v[order], f[order]
    for k in range(len(v) - 1):
        if f[k] > 0 >= f[k + 1]:
            w = f[k] / (f[k] - f[k + 1])
            return float(np.exp(np.log(v[k]) + w * (np.log(v[k + 1]) - np.log(v[k]))))
    return None


def cumulative_on(n_grid: np.ndarray, sizes, n_cum) -> np.ndarray:
    """N_cum(<= N) of one run on ``n_grid`` (a step function of N)."""
    sizes = np.asarray(sizes)
    n_cum = np.asarray(n_cum)
    at = np.searchsorted(sizes, n_grid, side="right") - 1
    return np.where(at >= 0, n_cum[np.maximum(at, 0)], 0.0)


def diagnostics(out: dict) -> dict:
    """The paper's diagnostics (``DIAGNOSTICS``) of one run's outcome (outcome.json as
    ``analysis.run`` writes it): None where the run's record lacks them (no log, or a log
    of a plugin that did not count contacts made and cut)."""
    by = out.get("dissipated_by_channel") or {}
    at = cumulative_on(np.array(N_CUM_AT), out["fragment_sizes"], out["N_cum"]) \
        if out.get("fragment_sizes") else [None] * len(N_CUM_AT)
    return dict(N_con=out.get("N_con"), N_cut=out.get("N_cut"),
                E_dis_tot=out.get("dissipated_fraction"),
                **{name: by.get(c) for c, name in zip(ledger.CHANNELS, CHANNEL_DIAGNOSTICS)},
                **{f"N_cum_{n}": None if c is None else int(c) for n, c in zip(N_CUM_AT, at)})


def mean_diagnostics(runs) -> dict[str, float | None]:
    """<A> of eq. (1) of each of the paper's diagnostics (``DIAGNOSTICS``) over ``runs``
    (each run's diagnostics taken once); at the grazing offset nothing is made, cut or
    dissipated and N_cum is the two aggregates whole. None where a run lacks one."""
    each = [dict(B_off=o["B_off"], **diagnostics(o)) for o in runs]
    out = {}
    for name in DIAGNOSTICS:
        if any(d[name] is None for d in each):
            out[name] = None
            continue
        grazing = (protocol.grazing_cumulative(int(name.split("_")[-1]), runs[0]["N_tar"],
                                               runs[0]["N_pro"])
                   if name.startswith("N_cum_") else 0.0)
        out[name] = float(b_off_mean(each, lambda d: d[name], grazing))
    return out


def scalars(out: dict) -> dict:
    """One run's row of runs.csv: the outcome's ``SCALARS``, its diagnostics among them."""
    shape = out.get("shape_at_end") or {}     # a settled run's largest body over the window
    row = dict(out, **diagnostics(out), B_off2=round(out["B_off"] ** 2, 12),
               r_g_growth_at_end=shape.get("r_g_growth"),
               stretching_at_end=shape.get("stretching"))
    return {k: row.get(k, "steps" if k == "stop_reason" else None) for k in SCALARS}


def label(run: dict) -> str:
    tvis = run.get("tvis") or 0.0
    return f"{run.get('material')} {run.get('model')}, T_vis = {tvis * 1e12:g} ps"


def load_outcomes(campaign) -> list[dict]:
    return [json.loads(p.read_text()) for p in sorted(Path(campaign).rglob(rundir.OUTCOME))]


def summarise(campaign, plot: bool = True, include_cap: bool = False) -> dict:
    """Collect every run under ``campaign`` into runs.csv, and write summary.csv (one row
    per model and v_col: <f_gro>, <N_lar/N_total>, ...), summary.json (with v_fra) and
    the campaign plots.

    Only complete runs (settled, or of a fixed number of steps) enter the averages; runs
    that hit the settle cap enter with ``include_cap``, failed runs never. Each row of
    the table counts the runs left out, and summary.json lists them."""
    campaign = Path(campaign)
    every = load_outcomes(campaign)
    if not every:
        raise ValueError(f"{campaign}: no outcome.json below it; run 'jkrdt analyse' on its runs")
    rows = [scalars(o) for o in every]
    write_csv(campaign / "runs.csv", rows)
    allowed = set(COMPLETE) | ({"cap"} if include_cap else set())
    outcomes, left_out = [], []
    capped, dropped = defaultdict(int), defaultdict(int)
    for o in every:
        reason, key = o.get("stop_reason", "steps"), (label(o), o["v_col"])
        capped[key] += reason == "cap"
        if reason in allowed:
            outcomes.append(o)
        else:
            dropped[key] += 1
            left_out.append(dict(run=o["run"], stop_reason=o.get("stop_reason"),
                                 problem=o.get("problem")))
    if not outcomes:
        raise ValueError(f"{campaign}: none of its {len(every)} runs is complete "
                         f"({sorted({d['stop_reason'] for d in left_out})}); see runs.csv")
    rows = [scalars(o) for o in outcomes]

    groups = defaultdict(list)
    for o in outcomes:
        groups[(label(o), o["v_col"])].append(o)
    table, curves, cumulative = [], defaultdict(lambda: ([], [])), {}
    counts = defaultdict(list)
    g = protocol.GRAZING
    per_seed = defaultdict(dict)
    for (name, v), runs in sorted(groups.items()):
        n_grid = np.arange(1, runs[0]["n_total"] + 1)
        f_gro = lambda o: o["growth_efficiency"]    # noqa: E731
        mean_f = float(b_off_mean(runs, f_gro, g["growth_efficiency"]))
        scatter = seed_scatter(runs, f_gro, g["growth_efficiency"])
        for k, f in scatter["per_seed"].items():
            per_seed[name].setdefault(k, ([], []))
            per_seed[name][k][0].append(v)
            per_seed[name][k][1].append(f)
        table.append(dict(model=name, v_col=v, runs=len(runs), left_out=dropped[(name, v)],
                          capped=capped[(name, v)],
                          B_off2_values=len({round(o["B_off"] ** 2, 12) for o in runs}),
                          paper_grid=protocol.is_paper_grid([o["B_off"] ** 2 for o in runs]),
                          mean_f_gro=mean_f, seeds=len(scatter["per_seed"]),
                          mean_f_gro_se=scatter["se"],
                          mean_N_lar_over_N_total=float(b_off_mean(
                              runs, lambda o: o["n_largest"] / o["n_total"],
                              g["N_lar_over_N_total"])),
                          **{f"mean_{k}": m for k, m in mean_diagnostics(runs).items()},
                          E_imp_over_nk_Ebreak=runs[0]["E_imp_over_nk_Ebreak"]))
        curves[name][0].append(v)
        curves[name][1].append(mean_f)
        counts[name].append(len(runs))
        cumulative[f"{name}, {v:g} m/s"] = (n_grid, b_off_mean(
            runs, lambda o: cumulative_on(n_grid, o["fragment_sizes"], o["N_cum"]),
            protocol.grazing_cumulative(n_grid, runs[0]["N_tar"], runs[0]["N_pro"])))
    thresholds = {name: threshold_velocity(v, f) for name, (v, f) in curves.items()}
    seed_thresholds = {name: {k: threshold_velocity(v, f) for k, (v, f) in seeds.items()}
                       for name, seeds in per_seed.items()}
    write_csv(campaign / "summary.csv", table)
    by_offset = offset_table(groups)
    write_csv(campaign / "f_gro_by_offset.csv", offset_rows(by_offset))
    # settled while a neck still stretched their largest body: counted, but flagged
    stretching = [dict(run=o["run"], growth_efficiency=o["growth_efficiency"],
                       r_g_growth=o["shape_at_end"]["r_g_growth"]) for o in outcomes
                  if (o.get("shape_at_end") or {}).get("stretching")]
    summary = dict(runs=len(outcomes), left_out=left_out, stretching_at_end=stretching,
                   include_cap=include_cap, table=table,
                   v_fra=thresholds, v_fra_per_seed=seed_thresholds,
                   f_gro_by_offset=by_offset)
    if plot:
        pictures = plots.growth_efficiency(campaign / "growth_efficiency", dict(curves), thresholds,
                                          dict(counts))
        pictures += plots.cumulative(campaign / "cumulative", cumulative)
        pictures += plots.disruption(campaign / "disruption", rows)
        if all(r["E_imp_over_nk_Eroll"] for r in rows):
            pictures += plots.compression(campaign / "compression", rows)
        summary["pictures"] = [str(p) for p in pictures]
    write_json(campaign / "summary.json", summary)
    return summary
