"""The speed/accuracy trade of the time step, measured on ensembles of collisions.

Scenes (ice, 0.1 micron grains), each an ensemble of seeds (new aggregates and a new
orientation per seed), each run to the settle rule (jkrdt.stopping) at every dt:

  bcca2d       2D BCCA head-on, 64 + 64 grains, 10 m/s, xi_crit 2 A (Wada et al. 2007, sec. 5)
  bpca3d_fric  3D BPCA, 128 + 128, 20 m/s, B_off 0.5, frictional (xi_crit 8 A)
  bpca3d_free  3D BPCA, 128 + 128, 40 m/s, B_off 0.5, frictionless

For each scene and dt/t_c: wall time per atom-step and per collision, max |dE|/E_imp,
and the ensemble means with standard errors of f_gro, N_lar/N, n_con, the dissipation
shares by channel and N_cum(<= N) at N = 1, 4, 16, compared with the smallest dt: an
observable is "within scatter" when its difference from the reference is below twice
the standard error of that difference. Aggregate collisions are chaotic, so only
ensembles can show how an outcome depends on dt.

A second part (``--models-only``, merged into tradeoff.json) measures what each switch
of the model costs and changes: the same 3D scene at dt = 0.014 t_c for a fixed number
of steps with the full model, the full model with viscoelastic damping, frictionless,
and frictionless with damping, interleaved (A B C D A B C D ...) in one process so that
the machine's load hits all alike, with the doubles each stores per contact; and the
same scene's ensemble run to the settle rule with each model (model_outcomes.csv).

Writes benchmarks/tradeoff/{runs.csv, summary.csv, models.csv, model_outcomes.csv, tradeoff.json,
tradeoff.png/pdf} and the fit of the energy error that ``jkrdt setup --dt auto`` uses
(pylammps/jkrdt/timestep_fit.json).

    python benchmarks/tradeoff.py                 # the full study (about 40 min on 2 cores)
    python benchmarks/tradeoff.py --models-only   # then the models part (about 10 min)
    python benchmarks/tradeoff.py --quick --out /tmp/t   # 2 seeds, 3 dt, small scenes
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
FIT_FILE = HERE.parent / "pylammps" / "jkrdt" / "timestep_fit.json"
SCENES = {
    "bcca2d": dict(kind="bcca", dim=2, n=64, v=10.0, b_off=0.0, model="frictional",
                   xi_crit=2e-10),
    "bpca3d_fric": dict(kind="bpca", dim=3, n=128, v=20.0, b_off=0.5, model="frictional",
                        xi_crit=8e-10),
    "bpca3d_free": dict(kind="bpca", dim=3, n=128, v=40.0, b_off=0.5, model="frictionless",
                        xi_crit=8e-10),
}
DTS = [0.005, 0.01, 0.014, 0.03, 0.05, 0.1, 0.2]
SEEDS = list(range(1, 9))
N_CUM_AT = [1, 4, 16]
OBSERVABLES = ["growth_efficiency", "N_lar_over_N", "contacts_per_particle",
               "share_events", "share_damping", "share_sliding", "share_rolling",
               "share_twisting"] + [f"N_cum_{n}" for n in N_CUM_AT]
MODELS = {"frictional": dict(model="frictional", tvis=0.0),
          "frictional+damping": dict(model="frictional", tvis=6e-12),
          "frictionless": dict(model="frictionless", tvis=0.0),
          "frictionless+damping": dict(model="frictionless", tvis=6e-12)}


def write_scene(directory: Path, scene: dict, seed: int, n: int | None = None,
                model: str | None = None, tvis: float = 0.0) -> Path:
    from jkrdt import rundir
    from jkrdt import scene as scene_module
    from jkrdt.materials import material

    n = n or scene["n"]
    return rundir.write(directory, scene_module.Scene(
        material("ice", xi_crit=scene["xi_crit"], tvis=tvis), n, n, v_col=scene["v"],
        b_off=scene["b_off"], seed=seed, kind=scene["kind"], dim=scene["dim"],
        model=model or scene["model"]))


def one_run(job: dict) -> dict:
    """Set up, run to the settle rule and analyse one collision (in a worker process)."""
    from mpi4py import MPI

    from jkrdt.analysis.run import analyse_run
    from jkrdt.session import Session
    from jkrdt.stopping import DEFAULT_RULE

    d = Path(job["dir"])
    d.mkdir(parents=True, exist_ok=True)
    write_scene(d, SCENES[job["scene"]], job["seed"], n=job.get("n"), model=job.get("model"),
                tvis=job.get("tvis", 0.0))
    t0 = time.perf_counter()
    with Session(d, d, dt=job["dt"], every=1, settle=DEFAULT_RULE, comm=MPI.COMM_SELF) as s:
        s.run_until_settled(progress=False)
    seconds = time.perf_counter() - t0
    out = analyse_run(d, plots=False)
    n_tot = out["n_total"]
    sizes, n_cum = np.array(out["fragment_sizes"]), np.array(out["N_cum"])
    row = dict(scene=job["scene"], model=job.get("model") or SCENES[job["scene"]]["model"],
               tvis=job.get("tvis", 0.0), dt_over_tc=job["dt"], seed=job["seed"], N=n_tot,
               steps=out["stop_step"], seconds=seconds,
               us_per_atom_step=1e6 * seconds / (n_tot * max(out["stop_step"], 1)),
               stop_reason=out["stop_reason"], energy_error=out["energy_error"],
               kinetic_left=out["kinetic_left"], growth_efficiency=out["growth_efficiency"],
               N_lar_over_N=out["n_largest"] / n_tot,
               contacts_per_particle=out["contacts_per_particle"],
               load=os.getloadavg()[0])
    for name, share in out["dissipated_by_channel"].items():
        row[f"share_{name}"] = share
    for n in N_CUM_AT:
        at = np.searchsorted(sizes, n, side="right") - 1
        row[f"N_cum_{n}"] = float(n_cum[at]) if at >= 0 else 0.0
    return row


def model_costs(workdir: Path, steps: int, repeats: int, n: int) -> list[dict]:
    """µs per atom-step of each model on one 3D scene, interleaved in one process."""
    from jkrdt.session import Session

    scene = SCENES["bpca3d_fric"]
    dirs = {}
    for name, m in MODELS.items():
        dirs[name] = write_scene(workdir / "models" / name.replace("+", "_"), scene, seed=1,
                                 n=n, model=m["model"], tvis=m["tvis"])
    times = {name: [] for name in MODELS}
    doubles = {}
    for _ in range(repeats):
        for name, d in dirs.items():
            with Session(d, d, dt=0.014) as s:
                t0 = time.perf_counter()
                s.lmp.command(f"run {steps} pre yes post no")
                times[name].append(time.perf_counter() - t0)
                doubles[name] = int(s.lmp.extract_fix("JKR_DT_CONTACTS", 0, 0))
    rows = []
    reference = np.median(times["frictional"])
    for name in MODELS:
        t = np.array(times[name])
        rows.append(dict(model=name, N=2 * n, steps=steps, repeats=repeats,
                         us_per_atom_step=float(1e6 * np.median(t) / (2 * n * steps)),
                         spread=float((t.max() - t.min()) / np.median(t)),
                         ratio_to_frictional=float(np.median(t) / reference),
                         doubles_per_contact=doubles[name], load=os.getloadavg()[0]))
    return rows


def model_outcomes(work: Path, seeds, n, workers: int) -> list[dict]:
    """What each model changes: the 3D scene of 'bpca3d_fric' (20 m/s, B_off 0.5) with
    every model at dt = 0.014 t_c, an ensemble of seeds each; means and standard errors."""
    jobs = [dict(scene="bpca3d_fric", dt=0.014, seed=seed, n=n, model=m["model"], tvis=m["tvis"],
                 name=name, dir=str(work / "models_outcome" / name.replace("+", "_") /
                                    f"seed{seed}"))
            for seed in seeds for name, m in MODELS.items()]
    with multiprocessing.get_context("spawn").Pool(workers) as pool:
        rows = pool.map(one_run, jobs)
    out = []
    for name, m in MODELS.items():
        mine = [r for r in rows if r["model"] == m["model"] and r["tvis"] == m["tvis"]]
        line = dict(model=name, runs=len(mine),
                    settled=sum(r["stop_reason"] == "settled" for r in mine),
                    seconds_per_collision=float(np.mean([r["seconds"] for r in mine])),
                    energy_error_max=float(max(r["energy_error"] for r in mine)))
        for key in OBSERVABLES + ["kinetic_left"]:
            a = np.array([r[key] for r in mine])
            line[f"{key}_mean"] = float(a.mean())
            line[f"{key}_stderr"] = float(a.std(ddof=1) / np.sqrt(len(a))) if len(a) > 1 else 0.0
        out.append(line)
    return out


def summarise(rows: list[dict]) -> list[dict]:
    """Ensemble mean and standard error per scene and dt, against the smallest dt."""
    out = []
    for scene in sorted({r["scene"] for r in rows}):
        mine = [r for r in rows if r["scene"] == scene]
        dts = sorted({r["dt_over_tc"] for r in mine})
        stats = {}
        for dt in dts:
            runs = [r for r in mine if r["dt_over_tc"] == dt and r["stop_reason"] == "settled"]
            stats[dt] = runs
        ref = stats[dts[0]]
        for dt in dts:
            runs = stats[dt]
            every = [r for r in mine if r["dt_over_tc"] == dt]
            line = dict(scene=scene, dt_over_tc=dt, runs=len(every), settled=len(runs),
                        us_per_atom_step=float(np.median([r["us_per_atom_step"] for r in every])),
                        seconds_per_collision=float(np.mean([r["seconds"] for r in every])),
                        steps_per_collision=float(np.mean([r["steps"] for r in every])),
                        energy_error_mean=float(np.mean([r["energy_error"] for r in every])),
                        energy_error_max=float(np.max([r["energy_error"] for r in every])))
            within = []
            for name in OBSERVABLES:
                a = np.array([r[name] for r in runs])
                b = np.array([r[name] for r in ref])
                if len(a) < 2 or len(b) < 2:
                    continue
                mean, err = a.mean(), a.std(ddof=1) / np.sqrt(len(a))
                diff_err = np.hypot(err, b.std(ddof=1) / np.sqrt(len(b)))
                line[f"{name}_mean"] = float(mean)
                line[f"{name}_stderr"] = float(err)
                line[f"{name}_diff"] = float(mean - b.mean())
                ok = abs(mean - b.mean()) <= 2 * diff_err or diff_err == 0 and mean == b.mean()
                line[f"{name}_within"] = bool(ok)
                within.append(ok)
            line["all_within_scatter"] = bool(all(within))
            out.append(line)
    return out


def fit_energy_error(rows: list[dict]) -> dict:
    """log10 max|dE|/E_imp = a + p log10(dt/t_c) + q log10(v_col/v0), least squares over
    the worst run of each scene and dt (so that the fit bounds the ensembles)."""
    from jkrdt.materials import material, scales

    v0 = scales(material("ice"), 1e-7).v0
    keys = sorted({(r["scene"], r["dt_over_tc"]) for r in rows})
    X, y = [], []
    for scene, dt in keys:
        worst = max(r["energy_error"] for r in rows if r["scene"] == scene
                    and r["dt_over_tc"] == dt)
        X.append([1.0, np.log10(dt), np.log10(SCENES[scene]["v"] / v0)])
        y.append(np.log10(worst))
    X, y = np.array(X), np.array(y)
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    residual = y - X @ coef
    # shift the fit up by its largest residual: it then bounds every scene's worst run
    margin = float(residual.max())
    return dict(log10_C=float(coef[0] + margin), p=float(coef[1]), q=float(coef[2]),
                margin_dex=margin, points=len(y),
                speeds_m_s=sorted({SCENES[s]["v"] for s, _ in keys}),
                dt_range=[min(d for _, d in keys), max(d for _, d in keys)],
                source="benchmarks/tradeoff.py (benchmarks/tradeoff/tradeoff.json)")


def plot(summary: list[dict], path: Path) -> list[Path]:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    markers = dict(bcca2d="o", bpca3d_fric="s", bpca3d_free="^")
    names = dict(bcca2d="2D BCCA 64+64, 10 m/s, frictional",
                 bpca3d_fric="3D BPCA 128+128, 20 m/s, frictional",
                 bpca3d_free="3D BPCA 128+128, 40 m/s, frictionless")
    for scene in sorted({s["scene"] for s in summary}):
        mine = [s for s in summary if s["scene"] == scene]
        dt = np.array([s["dt_over_tc"] for s in mine])
        cost = np.array([s["seconds_per_collision"] for s in mine])
        err = np.array([s["energy_error_max"] for s in mine])
        axes[0].loglog(cost, err, marker=markers[scene], label=names[scene])
        for s, c, e in zip(mine, cost, err):
            axes[0].annotate(f"{s['dt_over_tc']:g}", (c, e), textcoords="offset points",
                             xytext=(4, 3), fontsize=7)
        for ax, key in ((axes[1], "growth_efficiency"), (axes[2], "contacts_per_particle")):
            m = np.array([s.get(f"{key}_mean", np.nan) for s in mine])
            e = np.array([s.get(f"{key}_stderr", np.nan) for s in mine])
            ax.errorbar(dt, m, yerr=e, marker=markers[scene], capsize=3, label=names[scene])
    axes[0].axhline(1e-3, color="grey", ls=":")
    axes[0].axhline(1e-4, color="grey", ls=":")
    axes[0].set_xlabel("wall time per collision (s, 1 core)")
    axes[0].set_ylabel("max |dE| / E_imp (worst of the ensemble)")
    axes[0].set_title("cost against energy error; labels: dt / t_c")
    dts = sorted({s["dt_over_tc"] for s in summary})
    for ax in axes[1:]:
        ax.set_xscale("log")
        ax.set_xticks(dts, [f"{d:g}" for d in dts], fontsize=7)
        ax.minorticks_off()
    axes[1].set_xlabel("dt / t_c")
    axes[1].set_ylabel("<f_gro> (mean and standard error over seeds)")
    axes[1].set_title("growth efficiency against dt")
    axes[2].set_xlabel("dt / t_c")
    axes[2].set_ylabel("n_con of the largest fragment")
    axes[2].set_title("contacts per grain against dt")
    for ax in axes:
        ax.grid(alpha=0.3)
    axes[1].legend(fontsize=8, loc="center")    # the empty band between growth and disruption
    fig.text(0.01, 0.005, "Ensembles of 8 seeds per scene and dt, each run to the settle rule. "
             "The disruptive frictionless scene's cost hardly falls with dt: LAMMPS's neighbor "
             "binning of the box the fragments spread over dominates late in the run.",
             fontsize=8, color="dimgray")
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    out = []
    for suffix in (".png", ".pdf"):
        p = path.with_suffix(suffix)
        fig.savefig(p, dpi=120)
        out.append(p)
    plt.close(fig)
    return out


def markdown(study: dict) -> str:
    """The tables of docs/timestep.md from tradeoff.json (``--table``)."""
    names = dict(bcca2d="2D BCCA 64+64, 10 m/s", bpca3d_fric="3D BPCA 128+128, 20 m/s, frictional",
                 bpca3d_free="3D BPCA 128+128, 40 m/s, frictionless")
    lines = ["| scene | dt / t_c | steps to settle | s / collision | µs / atom-step | max \\|dE\\|/E_imp "
             "(worst, mean) | <f_gro> | n_con | outcomes off the reference |",
             "|---|---|---|---|---|---|---|---|---|"]
    for row in study["summary"]:
        off = [k[:-len("_within")] for k, v in row.items() if k.endswith("_within") and not v]
        lines.append(
            f"| {names[row['scene']]} | {row['dt_over_tc']:g} | {row['steps_per_collision']:.0f} | "
            f"{row['seconds_per_collision']:.1f} | {row['us_per_atom_step']:.2f} | "
            f"{row['energy_error_max']:.1e}, {row['energy_error_mean']:.1e} | "
            f"{row.get('growth_efficiency_mean', float('nan')):+.3f} ± "
            f"{row.get('growth_efficiency_stderr', float('nan')):.3f} | "
            f"{row.get('contacts_per_particle_mean', float('nan')):.3f} ± "
            f"{row.get('contacts_per_particle_stderr', float('nan')):.3f} | "
            f"{', '.join(off) if off else 'none'} |")
    lines += ["", "| scene | largest dt with max \\|dE\\|/E_imp < 1e-4 | < 1e-3 |", "|---|---|---|"]
    for scene in names:
        rows = [r for r in study["summary"] if r["scene"] == scene]
        best = {}
        for tol in (1e-4, 1e-3):
            ok = [r["dt_over_tc"] for r in sorted(rows, key=lambda r: r["dt_over_tc"])]
            good = 0.0
            for r in sorted(rows, key=lambda r: r["dt_over_tc"]):
                if r["energy_error_max"] >= tol:
                    break
                good = r["dt_over_tc"]
            best[tol] = f"{good:g} t_c" if good else f"< {ok[0]:g} t_c"
        lines.append(f"| {names[scene]} | {best[1e-4]} | {best[1e-3]} |")
    if study.get("models"):
        outcome = {m["model"]: m for m in study.get("model_outcomes", [])}
        lines += ["", "| model (3D BPCA 128+128, 20 m/s, B_off 0.5) | doubles / contact | "
                  "µs / atom-step | vs frictional | <f_gro> | N_lar/N | N_cum(<=4) | "
                  "dissipated by rolling |", "|---|---|---|---|---|---|---|---|"]
        for m in study["models"]:
            o = outcome.get(m["model"], {})
            lines.append(
                f"| {m['model']} | {m.get('doubles_per_contact', '')} | "
                f"{m['us_per_atom_step']:.3f} | {m['ratio_to_frictional']:.2f} | "
                f"{o.get('growth_efficiency_mean', float('nan')):+.3f} ± "
                f"{o.get('growth_efficiency_stderr', float('nan')):.3f} | "
                f"{o.get('N_lar_over_N_mean', float('nan')):.3f} | "
                f"{o.get('N_cum_4_mean', float('nan')):.1f} ± {o.get('N_cum_4_stderr', float('nan')):.1f} | "
                f"{o.get('share_rolling_mean', float('nan')):.3f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="2 seeds, 3 dt, 16-grain aggregates")
    p.add_argument("--out", default=str(HERE / "tradeoff"))
    p.add_argument("--work", default="runs/tradeoff", help="run directories (not kept)")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--models-only", action="store_true",
                   help="only the cost of each model; merged into an existing tradeoff.json")
    p.add_argument("--table", action="store_true",
                   help="print the tables of docs/timestep.md from an existing tradeoff.json")
    p.add_argument("--plot", action="store_true",
                   help="redraw tradeoff.png/pdf from an existing tradeoff.json")
    args = p.parse_args(argv)
    from jkrdt.analysis.tables import write_csv
    from jkrdt.rundir import write_json

    if args.table:
        print(markdown(json.loads((Path(args.out) / "tradeoff.json").read_text())))
        return 0
    if args.plot:
        study = json.loads((Path(args.out) / "tradeoff.json").read_text())
        print(plot(study["summary"], Path(args.out) / "tradeoff"))
        return 0
    out, work = Path(args.out), Path(args.work).resolve()
    out.mkdir(parents=True, exist_ok=True)
    steps, repeats, n = (500, 2, 16) if args.quick else (5000, 4, 128)
    if args.models_only:
        models = model_costs(work, steps=steps, repeats=repeats, n=n)
        outcomes = model_outcomes(work, SEEDS[:2] if args.quick else SEEDS, 16 if args.quick
                                  else None, args.workers)
        write_csv(out / "models.csv", models)
        write_csv(out / "model_outcomes.csv", outcomes)
        study = json.loads((out / "tradeoff.json").read_text())
        study.update(models=models, model_outcomes=outcomes)
        write_json(out / "tradeoff.json", study)
        print(f"wrote {out}/models.csv, model_outcomes.csv")
        return 0
    seeds, dts = (SEEDS[:2], [0.005, 0.014, 0.05]) if args.quick else (SEEDS, DTS)
    n = 16 if args.quick else None
    jobs = [dict(scene=scene, dt=dt, seed=seed, n=n,
                 dir=str(work / scene / f"dt{dt:g}" / f"seed{seed}"))
            for seed in seeds for scene in SCENES for dt in dts]
    t0 = time.time()
    with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
        rows = []
        for k, row in enumerate(pool.imap_unordered(one_run, jobs), 1):
            rows.append(row)
            print(f"[{k}/{len(jobs)}] {row['scene']} dt {row['dt_over_tc']:g} seed "
                  f"{row['seed']}: {row['stop_reason']} at {row['steps']} steps, "
                  f"{row['seconds']:.1f} s, |dE|/E_imp {row['energy_error']:.1e}, "
                  f"f_gro {row['growth_efficiency']:+.3f}", flush=True)
    rows.sort(key=lambda r: (r["scene"], r["dt_over_tc"], r["seed"]))
    summary = summarise(rows)
    models = model_costs(work, steps=steps, repeats=repeats, n=n)
    fit = fit_energy_error(rows)
    write_csv(out / "runs.csv", rows)
    write_csv(out / "summary.csv", summary)
    write_csv(out / "models.csv", models)
    write_json(out / "tradeoff.json", dict(scenes=SCENES, dts=dts, seeds=seeds,
                                           quick=args.quick, summary=summary, models=models,
                                           fit=fit, wall_seconds=time.time() - t0,
                                           workers=args.workers, cpus=os.cpu_count()))
    if not args.quick:
        write_json(FIT_FILE, fit)
    pictures = plot(summary, out / "tradeoff")
    print(f"wrote {out}/runs.csv, summary.csv, models.csv, tradeoff.json, "
          f"{', '.join(p.name for p in pictures)}; fit {fit}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
