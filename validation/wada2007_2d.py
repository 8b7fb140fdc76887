"""Wada et al. (2007), sec. 5: 2D head-on collisions of two BCCAs, reproduced.

The paper's four parameter sets (Table 3: quartz and ice, xi_crit 2 and 30 Angstrom),
two BCCAs of 128 grains each (N_total = 256, as in Fig. 14), head-on (B_off = 0), three
seeds (three initial structures, as in the paper), and impact speeds from 0.3 to 20 v0 on
a logarithmic grid, which spans E_imp / (n_k E_roll) from 3e-5 to 17 over the four sets.
Every run ends by the settle rule at the papers' dt = 0.014 t_c, and is run by ``jkrdt
campaign`` (one campaign per parameter set, side by side over the MPI ranks).

Measured against the paper:

* r_g / (r_1 N_large^1/2) against E_imp / (n_k E_roll), eq. (51), fitted by the paper over
  E_roll < E_imp < 0.1 n_k E_roll (Fig. 7a);
* n_con - 1 against E_imp / (n_k E_roll), eq. (56), for E_imp <= 0.1 n_k E_roll (Fig. 11b),
  and n_con's maximum against eq. (57), k - (k - 1) / sqrt(N) with k = 1.6 (ice) and
  1.3-1.4 (quartz) (Fig. 12, xi_crit = 2 Angstrom);
* N_large / N_total against E_imp / (n_k E_break) (Fig. 14): where disruption starts (the
  paper: ~3 n_k E_break) and where it becomes catastrophic, N_large / N_total <= 0.5 (~10);
* the shares of the dissipated energy by channel (Fig. 6: rolling takes almost all);
* every run's energy error.

Writes ``RESULTS`` (default validation/wada2007_2d/): runs.csv (one row per run),
summary.json (the comparisons) and the figures fig7_gyration, fig11_contacts,
fig14_largest and fig6_shares (PNG and PDF). The runs go to ``--runs`` (default
validation/runs/wada2007_2d, not committed); a second call resumes them.

    ./run validate wada2007_2d            # the study (about 20 min on 2 cores)
    ./run validate wada2007_2d --quick    # 2 x 32 grains, 2 sets, 5 speeds, 2 seeds (tests)
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

from common import campaign_study_parser, run_campaigns, save as save_figure, study_paths
from jkrdt.analysis.tables import write_csv
from jkrdt import ledger, rundir

#: Table 3 of the paper: (material preset, xi_crit)
SETS = {"quartz 2A": ("quartz", 2e-10), "quartz 30A": ("quartz", 30e-10),
        "ice 2A": ("ice", 2e-10), "ice 30A": ("ice", 30e-10)}
#: k of eq. (57), the mean contacts of an inner grain at maximum compression (sec. 5.3)
K_EQ57 = {"quartz": (1.3, 1.4), "ice": (1.6, 1.6)}
FULL = dict(n=128, seeds=[1, 2, 3], speeds=list(np.geomspace(0.3, 20.0, 10)), sets=list(SETS))
QUICK = dict(n=32, seeds=[1, 2], speeds=list(np.geomspace(1.0, 20.0, 5)),
             sets=["quartz 2A", "ice 2A"])


def eq51(x):
    """r_g / (r_1 N_large^1/2) at E_imp = x n_k E_roll."""
    return 0.84 * np.asarray(x, dtype=float) ** -0.12


def eq56(x):
    """n_con - 1 at E_imp = x n_k E_roll."""
    return np.asarray(x, dtype=float) ** 0.75


def eq57(k, n):
    """The largest n_con of a compact 2D aggregate of n grains, inner grains with k."""
    return k - (k - 1) / math.sqrt(n)


def spec(name: str, plan: dict) -> dict:
    """The campaign of one parameter set: its speeds in m/s from the grid in v0."""
    from jkrdt.materials import material, scales

    preset, xi = SETS[name]
    v0 = scales(material(preset, xi_crit=xi), 1.0e-7).v0
    return dict(kind="bcca", dim=2, n_tar=plan["n"], n_pro=plan["n"], material=preset,
                material_overrides=dict(xi_crit=xi), model="frictional",
                v_col=[float(f"{u * v0:.6g}") for u in plan["speeds"]], b_off2=[0.0],
                seeds=plan["seeds"], dt=0.014)


def collect(plan: dict, runs: Path) -> list[dict]:
    """One row per run: the scene, the paper's scalings and the outcome."""
    from jkrdt.materials import material, scales

    rows = []
    for name in plan["sets"]:
        preset, xi = SETS[name]
        s = scales(material(preset, xi_crit=xi), 1.0e-7)
        for path in sorted((runs / name.replace(" ", "_")).rglob(rundir.OUTCOME)):
            o = json.loads(path.read_text())
            if o.get("stop_reason") == "error":
                rows.append(dict(set=name, seed=o["seed"], v_over_v0=o["v_col"] / s.v0,
                                 stop_reason="error", problem=o.get("problem")))
                continue
            shares = o["dissipated_by_channel"]
            total = sum(shares.values())
            rows.append(dict(
                set=name, material=preset, xi_crit=xi, seed=o["seed"], N_total=o["n_total"],
                v_col=o["v_col"], v_over_v0=o["v_col"] / s.v0,
                x=o["E_imp_over_nk_Eroll"], y=o["E_imp_over_nk_Ebreak"],
                rg_over_r1_sqrt_Nlar=o["gyration_radius_largest"]
                / (o["radius"] * math.sqrt(o["n_largest"])),
                n_con=o["contacts_per_particle"], N_lar_over_N=o["n_largest"] / o["n_total"],
                n_fragments=o["n_fragments"], stop_reason=o["stop_reason"],
                stop_step=o["stop_step"], energy_error=o["energy_error"],
                **{f"share_{k}": v / total if total > 0 else 0.0 for k, v in shares.items()}))
    return rows


def power_fit(x, y) -> dict:
    """y = A x^b by least squares in log-log, with the rms scatter of log10 y about it."""
    lx, ly = np.log10(x), np.log10(y)
    b, a = np.polyfit(lx, ly, 1)
    return dict(A=float(10 ** a), b=float(b), points=int(len(x)),
                rms_dex=float(np.sqrt(np.mean((ly - (a + b * lx)) ** 2))))


def crossing(y, frac, level) -> float | None:
    """The first y (log-interpolated) at which the seed-mean N_lar/N falls to ``level``."""
    order = np.argsort(y)
    y, frac = np.asarray(y)[order], np.asarray(frac)[order]
    for k in range(1, len(y)):
        if frac[k - 1] > level >= frac[k]:
            w = (frac[k - 1] - level) / (frac[k - 1] - frac[k])
            return float(10 ** (np.log10(y[k - 1]) + w * (np.log10(y[k]) - np.log10(y[k - 1]))))
    return None


def by_speed(rows: list[dict], name: str):
    """(x, y, the seed-mean of each measure) per speed of one set, slowest first."""
    mine = [r for r in rows if r["set"] == name and r["stop_reason"] != "error"]
    speeds = sorted({round(r["v_over_v0"], 9) for r in mine})
    out = []
    for u in speeds:
        at = [r for r in mine if round(r["v_over_v0"], 9) == u]
        out.append({k: float(np.mean([r[k] for r in at])) for k in
                    ("x", "y", "rg_over_r1_sqrt_Nlar", "n_con", "N_lar_over_N",
                     *(f"share_{c}" for c in ledger.CHANNELS))}
                   | dict(v_over_v0=u, runs=len(at),
                          n_con_sd=float(np.std([r["n_con"] for r in at]))))
    return out


def relation(rows, n_k, key, law, shift, x_max, where="", paper=None) -> dict:
    """A measure (less ``shift``) against a law of x = E_imp / (n_k E_roll) over
    E_roll < E_imp <= x_max n_k E_roll: our power-law fit and the ratio to the law."""
    inside = [r for r in rows if 1.0 / n_k < r["x"] <= x_max and r[key] > shift]
    if len(inside) < 3:
        return dict(points=len(inside), ratio_mean=None)
    x = np.array([r["x"] for r in inside])
    y = np.array([r[key] - shift for r in inside])
    q = y / law(x)
    return dict(range=where, fit=power_fit(x, y), paper=paper, points=len(inside),
                ratio_mean=float(q.mean()), ratio_sd=float(q.std()))


def compare(plan: dict, rows: list[dict]) -> dict:
    """The paper's relations against the runs."""
    good = [r for r in rows if r["stop_reason"] != "error"]
    n_total = 2 * plan["n"]
    n_k = n_total - 2
    out = dict(runs=len(rows), failed=len(rows) - len(good),
               stop_reasons={k: sum(r["stop_reason"] == k for r in rows)
                             for k in sorted({r["stop_reason"] for r in rows})},
               energy_error_max=max(r["energy_error"] for r in good),
               energy_error_median=float(np.median([r["energy_error"] for r in good])))
    out["eq51"] = relation(good, n_k, "rg_over_r1_sqrt_Nlar", eq51, 0.0, 0.1,
                           "E_roll < E_imp < 0.1 n_k E_roll", dict(A=0.84, b=-0.12))
    out["eq56"] = relation(good, n_k, "n_con", eq56, 1.0, 0.1,
                           "E_roll < E_imp <= 0.1 n_k E_roll, n_con > 1", dict(A=1.0, b=0.75))
    sets = {}
    for name in plan["sets"]:
        curve = by_speed(rows, name)
        if not curve:
            continue
        preset = SETS[name][0]
        top = max(curve, key=lambda c: c["n_con"])
        k_lo, k_hi = K_EQ57[preset]
        y = [c["y"] for c in curve]
        frac = [c["N_lar_over_N"] for c in curve]
        sets[name] = dict(
            n_con_max=top["n_con"], n_con_max_sd=top["n_con_sd"], at_x=top["x"],
            eq57=[eq57(k_lo, n_total), eq57(k_hi, n_total)] if name.endswith("2A") else None,
            disruption_starts_at_y=crossing(y, frac, 0.98), paper_disruption_y=3.0,
            catastrophic_at_y=crossing(y, frac, 0.5), paper_catastrophic_y=10.0,
            eq51_ratio=relation([r for r in good if r["set"] == name], n_k,
                                "rg_over_r1_sqrt_Nlar", eq51, 0.0, 0.1)["ratio_mean"],
            eq56_ratio=relation([r for r in good if r["set"] == name], n_k, "n_con", eq56, 1.0,
                                0.1)["ratio_mean"],
            shares_at_maximum_compression={k: top[f"share_{k}"] for k in ledger.CHANNELS},
            largest_rolling_share=max(c["share_rolling"] for c in curve))
    out["sets"] = sets
    return out


def figures(plan: dict, rows: list[dict], results: Path) -> list[Path]:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    good = [r for r in rows if r["stop_reason"] != "error"]
    marks = {"quartz 2A": ("s", "C0", True), "quartz 30A": ("s", "C0", False),
             "ice 2A": ("o", "C3", True), "ice 30A": ("o", "C3", False)}
    n_total = 2 * plan["n"]
    saved = []

    def points(ax, key, shift=0.0, ylog=True):
        for name in plan["sets"]:
            mine = [r for r in good if r["set"] == name]
            m, c, filled = marks[name]
            xs = [r[key[0]] for r in mine]
            ys = [r[key[1]] - shift for r in mine]
            ax.plot(xs, ys, m, color=c, mfc=c if filled else "none", ms=5, label=name,
                    ls="none")
            capped = [r for r in mine if r["stop_reason"] == "cap"]
            if capped:
                ax.plot([r[key[0]] for r in capped], [r[key[1]] - shift for r in capped], "x",
                        color="k", ms=7, label=f"{name}: hit the cap")
        ax.set_xscale("log")
        if ylog:
            ax.set_yscale("log")

    def label(ax, x, y, heading):
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        ax.set_title(heading, fontsize=9)
        ax.legend(fontsize=7)

    def save(fig, stem):
        saved.extend(save_figure(fig, results, stem))

    title = f"2D BCCA head-on, N_total = {n_total}, seeds {plan['seeds']}, dt = 0.014 t_c"
    fig, ax = plt.subplots(figsize=(6.5, 4.8), constrained_layout=True)
    points(ax, ("x", "rg_over_r1_sqrt_Nlar"))
    e = np.geomspace(1.0 / (n_total - 2), 0.1, 20)
    ax.plot(e, eq51(e), "0.4", lw=2, label="eq. (51), its fit range")
    e = np.geomspace(min(r["x"] for r in good), max(r["x"] for r in good), 40)
    ax.plot(e, eq51(e), "0.7", lw=1, ls="--")
    label(ax, "E_imp / (n_k E_roll)", "r_g / (r_1 N_large^1/2)",
          "Wada et al. (2007) Fig. 7a\n" + title)
    save(fig, "fig7_gyration")

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.6), constrained_layout=True)
    points(a, ("x", "n_con"), ylog=False)
    for name in plan["sets"]:
        if name.endswith("2A"):
            k_lo, k_hi = K_EQ57[SETS[name][0]]
            a.axhspan(eq57(k_lo, n_total), eq57(k_hi, n_total) + 0.004,
                      color=marks[name][1], alpha=0.2, label=f"eq. (57), {SETS[name][0]}")
    label(a, "E_imp / (n_k E_roll)", "n_con (largest cluster)",
          "Fig. 11a, with eq. (57) for xi_crit = 2 A")
    points(b, ("x", "n_con"), shift=1.0)
    e = np.geomspace(1.0 / (n_total - 2), 0.1, 20)
    b.plot(e, eq56(e), "0.4", lw=2, label="eq. (56), its range")
    label(b, "E_imp / (n_k E_roll)", "n_con - 1", "Fig. 11b\n" + title)
    save(fig, "fig11_contacts")

    fig, ax = plt.subplots(figsize=(6.5, 4.8), constrained_layout=True)
    points(ax, ("y", "N_lar_over_N"), ylog=False)
    for mark, text in ((3, "disruption begins (paper)"), (10, "catastrophic (paper)")):
        ax.axvline(mark, color="0.5", ls=":")
        ax.text(mark * 1.05, 0.05, text, rotation=90, fontsize=8)
    ax.axhline(0.5, color="0.7", lw=0.8)
    ax.set_ylim(0, 1.05)
    label(ax, "E_imp / (n_k E_break)", "N_large / N_total", "Fig. 14\n" + title)
    save(fig, "fig14_largest")

    fig, axes = plt.subplots(1, len(plan["sets"]), figsize=(3.4 * len(plan["sets"]), 3.8),
                             sharey=True, constrained_layout=True, squeeze=False)
    for ax, name in zip(axes[0], plan["sets"]):
        curve = by_speed(rows, name)
        x = [c["x"] for c in curve]
        for k in ledger.CHANNELS:
            share = [c[f"share_{k}"] for c in curve]
            if max(share) > 0.005:
                ax.semilogx(x, share, "o-", ms=3, label=k)
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("E_imp / (n_k E_roll)")
        ax.axvline(1.0, color="0.7", ls=":")
    axes[0, 0].set_ylabel("share of the dissipated energy")
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("Fig. 6: where the energy goes (seed means); " + title, fontsize=9)
    save(fig, "fig6_shares")
    return saved


def main(argv=None) -> int:
    args = campaign_study_parser(__doc__).parse_args(argv)
    plan = QUICK if args.quick else FULL
    runs, results = study_paths(args, "wada2007_2d")
    t0 = time.time()
    run_campaigns({name: spec(name, plan) for name in plan["sets"]}, runs, args.np)
    rows = collect(plan, runs)
    write_csv(results / "runs.csv", rows)
    summary = dict(plan={k: v for k, v in plan.items()}, ranks=args.np,
                   seconds_this_call=time.time() - t0, load=os.getloadavg()[0],
                   **compare(plan, rows))
    (results / "summary.json").write_text(json.dumps(summary, indent=2, default=float) + "\n")
    figures(plan, rows, results)
    print(json.dumps({k: summary[k] for k in ("runs", "stop_reasons", "energy_error_max")
                      if k in summary}))
    for key in ("eq51", "eq56"):
        if key in summary:
            print(key, json.dumps(summary[key]))
    for name, s in summary["sets"].items():
        print(name, json.dumps(s, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
