"""The 3D BPCA paper's four models at ten times the size: v_fra against N.

``validation/bpca3d_models.py`` placed each model's fragmentation threshold v_fra at
2 x 100, 2 x 250 and 2 x 1000 ice grains (its committed summary.json). This study adds
larger sizes (default 2 x 5000) on a grid of the paper's speeds, 10^(1 + 0.1 k) m/s, that
brackets each model's v_fra as the smaller sizes place it (GRIDS), at B_off^2 = 0, 3/12,
6/12, 9/12:

  phase 1   seed 1 at every speed of the model's grid;
  extend    if <f_gro> of seed 1 is <= 0 already at the grid's slowest speed, or > 0 at
            every speed (v_fra has moved out of the grid with N), seed 1 at the paper's
            next speed beyond the grid on that side, one speed at a time (at most EXTEND,
            within 10-125.9 m/s);
  phase 2   seed 2 at the two speeds on either side of seed 1's v_fra, then at the speeds
            on either side of both seeds' v_fra where it has not run yet;
  both      if both seeds' <f_gro> does not cross 0 on the speeds run (seed 1's alone did),
            both seeds at the paper's next speed on that side, as in extend.

Each model's phases are campaigns of their own (``RUNS/n<N>/<model>/seed<k>``, an added
speed ``seed<k>_v<speed>``), run one after the other, damped models first (their gap to
the paper is the open question), and a second call resumes them. ``--paper-size`` runs
instead the 12 collisions at the paper's 2 x 50000 grains (PAPER_SIZE), one campaign per
model and offset. Every run ends by the settle rule, its dt chosen by ``--dt auto`` for
max |dE| / E_imp <= 1e-3 (TOLERANCE): the trade study (benchmarks/tradeoff) found no
outcome moving beyond its scatter up to 0.2 t_c, where the worst run's error was 6.5e-3.

Writes RESULTS (default validation/vfra_size/), from every finished run below RUNS
whichever call ran it and every run the committed RESULTS/runs.csv already lists:
runs.csv (every run, with its loop time), summary.json (per size and model: <f_gro>
against v_col, v_fra with its bracket, the compute spent; the trend of v_fra against N;
the paper-size collisions; f_gro per offset against size, by_offset), fig_vfra_size,
fig_growth_size (<f_gro> against v_col per model, a line per size) and fig_offsets_size
(f_gro at each B_off^2 against N_total at one speed per model).

    ./run validate vfra_size                    # 2 x 5000, 2 ranks: 100 runs, hours of both cores
    ./run validate vfra_size --models "frictional, T_vis 6 ps"
    ./run validate vfra_size --paper-size 0 0.5  # 2 x 50000: B_off^2 0 and 6/12 of PAPER_SIZE
    ./run validate vfra_size --paper-size --models "frictional, T_vis 6 ps"
    ./run validate vfra_size --sizes 10000
    ./run validate vfra_size --quick            # 2 x 24 grains, two models (tests)
    ./run validate vfra_size --summary-only     # run nothing: the results of what finished

The committed runs.csv is the study's ledger: a campaign whose every run it lists is not
run again, and its rows stay in the results, so a machine that lost RUNS (a new checkout,
a wiped disk) goes on where the last committed results stopped instead of redoing hours of
runs; of a campaign that the ledger holds in part, only the speeds it lacks run again.
``--summary-only`` writes the results from the finished runs and runs nothing: the
finished part of a campaign still under way, to commit while the rest goes on.
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from bpca3d_models import FULL as SMALLER_PLAN, MODELS, model_spec
from common import (HERE, campaign_paths, campaign_study_parser, loop_ranks, loop_seconds,
                    read_committed, run_campaigns, save, study_paths)
from jkrdt import rundir
from jkrdt.analysis.summary import (DIAGNOSTICS, b_off_average, b_off_groups, b_off_mean,
                                    diagnostics, threshold_velocity)
from jkrdt.analysis.tables import read_csv, write_csv
from jkrdt.stopping import COMPLETE

#: max |dE| / E_imp that each run's dt is chosen for
TOLERANCE = 1e-3
#: each model's speeds (the paper's grid) around its v_fra at 2 x 1000 grains (frictional
#: 54, damped frictional 82, frictionless 22, damped frictionless above 100 m/s) and the
#: paper's at 10^5 (60, 50, 30, 45), in the order the models are run
GRIDS = {"frictionless, T_vis 6 ps": [50.1, 63.1, 79.4, 100.0, 125.9],
         "frictional, T_vis 6 ps": [50.1, 63.1, 79.4, 100.0],
         "frictional": [39.8, 50.1, 63.1, 79.4],
         "frictionless": [15.8, 20.0, 25.1, 31.6]}
#: at most this many speeds added beyond a grid that does not bracket v_fra
EXTEND = 3
QUICK = dict(sizes=[24], grids={"frictional": [10.0, 39.8, 100.0],
                                "frictionless": [10.0, 39.8, 100.0]}, b_off2=[0.0, 0.5],
             extend=0, follow=0)
FULL = dict(sizes=[5000], grids=GRIDS, b_off2=SMALLER_PLAN["b_off2"], extend=EXTEND, follow=2)
#: the 3D paper's size (issue 23, item 2): both damped models at 63.1 m/s, where the paper
#: has them fragmenting and 2 x 1000 grains still grow, and the undamped frictionless model
#: at 39.8 m/s (the paper's Fig. 1); seed 1, B_off^2 0 and 6/12 of every model first
PAPER_SIZE = dict(n=50000, speeds={"frictionless, T_vis 6 ps": 63.1,
                                   "frictional, T_vis 6 ps": 63.1, "frictionless": 39.8},
                  b_off2=[0.0, 0.5, 0.25, 0.75])
#: the paper's speeds are 10^(1 + 0.1 k) m/s, k = 0 ... 10; one step more each way at most
SLOWEST, FASTEST = 10.0, 125.9
SEEDS = (1, 2)              # phase 1, phase 2
#: the committed runs of the smaller sizes (validation/bpca3d_models.py)
SMALLER = HERE / "bpca3d_models" / "runs.csv"


def spec(model: str, n: int, speeds: list[float], b_off2: list[float], seed: int) -> dict:
    return model_spec(model, n, v_col=speeds, b_off2=b_off2, seeds=[seed], dt="auto",
                      tolerance=TOLERANCE)


def nearest_two(c: dict) -> list[float]:
    """The two speeds of curve ``c`` nearest its v_fra: the grid speeds on either side of
    it (the two slowest if the model fragments at every speed of the grid, the two fastest
    if at none)."""
    if c["bracket"] is not None:
        return c["bracket"]
    v, f = c["v_col"], c["mean_f_gro"]
    return v[:2] if f[0] <= 0 else v[-2:]


def next_speed(c: dict) -> float | None:
    """The paper's grid speed one step beyond curve ``c``'s speeds toward its v_fra, the
    first speed at which <f_gro> falls to <= 0: below the slowest if <f_gro> <= 0 there
    already (even if a later rise and fall brackets a crossing: a curve near 0 wanders
    with one seed), above the fastest if it is > 0 everywhere; None if the slowest speed
    grows and a crossing is bracketed, or the step would leave SLOWEST-FASTEST."""
    v, f = c["v_col"], c["mean_f_gro"]
    if f[0] <= 0:
        k = round(10 * np.log10(v[0])) - 1
    elif c["bracket"] is None:
        k = round(10 * np.log10(v[-1])) + 1
    else:
        return None
    speed = round(10 ** (k / 10), 1)
    return speed if SLOWEST <= speed <= FASTEST else None


def curve(rows: list[dict]) -> dict:
    """<f_gro>(v_col) and v_fra of the finished runs in ``rows`` (as ``jkrdt summarise``
    takes them: the seeds averaged per B_off^2, then the B_off-weighted average of eq. 1 of
    the 3D paper), with the two grid speeds that bracket v_fra."""
    done = [r for r in rows if r["stop_reason"] in COMPLETE]
    v = sorted({r["v_col"] for r in done})
    f = [float(b_off_mean([r for r in done if r["v_col"] == x],
                          lambda r: r["growth_efficiency"])) for x in v]
    bracket = next(([v[k], v[k + 1]] for k in range(len(v) - 1) if f[k] > 0 >= f[k + 1]),
                   None)
    return dict(v_col=v, mean_f_gro=f, runs=[sum(r["v_col"] == x for r in done) for x in v],
                v_fra=threshold_velocity(v, f) if len(v) > 1 else None, bracket=bracket)


def seed_spread(rows: list[dict]) -> list[float]:
    """v_fra of each seed's own curve, at the speeds that seed ran (the spread of v_fra
    from the seeds)."""
    found = [curve([r for r in rows if r["seed"] == seed])["v_fra"]
             for seed in sorted({r["seed"] for r in rows})]
    return [v for v in found if v is not None]


def outcome_rows(home: Path, n: int, model: str) -> list[dict]:
    """One row per finished run below ``home``, with its loop time, its dt and the paper's
    diagnostics (``analysis.summary.diagnostics``; rows of the ledger from before they
    were recorded leave them empty). A run is
    read where its outcome lies (the path an outcome records may be relative to where its
    campaign was started)."""
    return [dict(size=n, model=model, loop_seconds=loop_seconds(p.parent),
                 ranks=loop_ranks(p.parent),
                 dt_over_tc=rundir.read_metadata(p.parent)["dt_over_tc"],
                 **{k: o.get(k) for k in (
                     "v_col", "B_off", "seed", "n_total", "n_largest", "n_fragments",
                     "growth_efficiency", "stop_reason", "stop_step", "time_end_over_tc",
                     "energy_error", "kinetic_left")}, **diagnostics(o))
            for p in sorted(home.rglob(rundir.OUTCOME)) for o in [json.loads(p.read_text())]]


#: the columns of runs.csv that hold whole numbers
INTS = ("size", "seed", "n_total", "n_largest", "n_fragments", "stop_step", "ranks",
        *(k for k in DIAGNOSTICS if k.startswith("N_cum_")))


def core_hours(rows: list[dict]) -> float:
    """The compute the runs in ``rows`` took: loop time times the ranks each used (rows of
    the ledger from before ranks were recorded ran on one)."""
    return sum(r["loop_seconds"] * (r.get("ranks") or 1) for r in rows) / 3600


def row_key(r: dict) -> tuple:
    """What tells one run of the study from another: size, model, seed, v_col, B_off^2."""
    return (int(r["size"]), r["model"], int(r["seed"]), round(float(r["v_col"]), 4),
            round(float(r["B_off"]) ** 2, 4))


def finished(home: Path, n: int, model: str, ledger: list[dict], seed: int | None = None,
             speeds: list[float] | None = None) -> list[dict]:
    """The finished runs of ``model`` at 2 x ``n`` (of ``seed`` and at ``speeds`` if
    given): those below ``home`` and the ledger's that the disk does not hold."""
    at = None if speeds is None else {round(v, 4) for v in speeds}

    def wanted(r):
        return (r["size"] == n and r["model"] == model and seed in (None, r["seed"])
                and (at is None or round(r["v_col"], 4) in at))

    disk = [r for r in outcome_rows(home, n, model) if wanted(r)]
    seen = {row_key(r) for r in disk}
    return disk + [r for r in ledger if wanted(r) and row_key(r) not in seen]


def campaign(name: str, model: str, n: int, speeds: list[float], b_off2: list[float],
             seed: int, home: Path, ranks: int, ledger: list[dict],
             ranks_per_run: int = 1) -> list[dict]:
    """The campaign ``home/name`` of ``seed`` at ``speeds`` x ``b_off2``, unless its every
    run is finished; its finished runs. Where the ledger holds some of its speeds and the
    campaign is not on disk (a new machine), each speed it lacks runs as a campaign of its
    own (``name_v<speed>``). ``ranks_per_run``: the ranks that share one collision."""
    held = {row_key(r) for r in finished(home, n, model, ledger, seed, speeds)}
    missing = [v for v in speeds if any((n, model, seed, round(v, 4), round(b2, 4))
                                        not in held for b2 in b_off2)]
    if not missing:
        print(f"{name}: every run finished (on disk or in the committed runs.csv)", flush=True)
    elif campaign_paths({name: None}, home)[name].exists() or missing == speeds:
        run_campaigns({name: spec(model, n, speeds, b_off2, seed)}, home, ranks, ranks_per_run)
    else:
        for v in missing:
            run_campaigns({f"{name}_v{v:g}": spec(model, n, [v], b_off2, seed)}, home, ranks,
                          ranks_per_run)
    return finished(home, n, model, ledger, seed, speeds)


def size_trend(rows: list[dict]) -> dict:
    """Per model: v_fra at each size with the range of its seeds' own v_fra (or, where the
    speeds run do not place it, the bound they give: above the fastest or below the
    slowest), and the fit v_fra = a + b log10(N_total) over the largest sizes that all
    place it, with its value at the paper's N_total = 10^5 (None where fewer than two do)."""
    out = {}
    for model in MODELS:
        mine = [r for r in rows if r["model"] == model]
        points = []
        for size in sorted({r["size"] for r in mine}):
            at = [r for r in mine if r["size"] == size]
            c = curve(at)
            seeds = seed_spread(at)
            found = c["v_fra"] is not None
            points.append(dict(n_total=2 * size, v_fra=c["v_fra"], bracket=c["bracket"],
                               low=min(seeds + [c["v_fra"]]) if found else None,
                               high=max(seeds + [c["v_fra"]]) if found else None,
                               bound=None if found else (
                                   ("below", c["v_col"][0]) if c["mean_f_gro"][0] <= 0
                                   else ("above", c["v_col"][-1]))))
        # the fit takes the largest sizes that all place v_fra: a smaller size that places
        # it again below one that does not (damped frictionless: 2 x 100 does, 2 x 250 and
        # 2 x 1000 do not) would draw a line through a gap it cannot see
        placed = []
        for point in reversed(points):
            if point["v_fra"] is None:
                break
            placed.insert(0, point)
        fit = None
        if len(placed) >= 2:
            b, a = np.polyfit(np.log10([p["n_total"] for p in placed]),
                              [p["v_fra"] for p in placed], 1)
            fit = dict(a=float(a), b=float(b), at_1e5=float(a + 5 * b),
                       n_total=[p["n_total"] for p in placed])
        out[model] = dict(points=points, fit=fit, paper_v_fra=MODELS[model][2])
    return out


#: each damped model and its undamped twin (MODELS)
TWINS = {"frictional, T_vis 6 ps": "frictional", "frictionless, T_vis 6 ps": "frictionless"}


def damping_effect(rows: list[dict]) -> dict:
    """Per damped model and size: <f_gro> with damping minus without, at the speeds both
    ran, and the largest of these differences in size (with its sign). The paper has the
    frictional models within about 0.1 of each other over 10-100 m/s at 10^5 grains (its
    Sec. 3.1), the frictionless ones apart."""
    out = {}
    for damped, undamped in TWINS.items():
        by_size = {}
        for size in sorted({r["size"] for r in rows}):
            c = {m: curve([r for r in rows if r["size"] == size and r["model"] == m])
                 for m in (damped, undamped)}
            f = {m: dict(zip(c[m]["v_col"], c[m]["mean_f_gro"])) for m in c}
            common = sorted(set(f[damped]) & set(f[undamped]))
            if common:
                diff = [f[damped][v] - f[undamped][v] for v in common]
                by_size[str(int(2 * size))] = dict(
                    v_col=common, difference=diff, largest=max(diff, key=abs))
        out[damped] = by_size
    return out


#: the speed at which each model's offsets are followed in size (by_offset): the paper-size
#: collisions' speed, and for the undamped frictional model the paper's speed nearest its v_fra
OFFSET_SPEEDS = {"frictional": 63.1, **PAPER_SIZE["speeds"]}


def by_offset(rows: list[dict], offsets: int) -> dict:
    """Per model, at its OFFSET_SPEEDS speed: f_gro at each B_off^2 (seeds averaged) for
    every size that ran there, and their <f_gro> (eq. 1) where all ``offsets`` ran. It
    shows which collisions move <f_gro> with N: a head-on one that sticks more as the
    aggregates grow, or the offset ones."""
    out = {}
    for model, v in OFFSET_SPEEDS.items():
        sizes = {}
        for size in sorted({r["size"] for r in rows}):
            mine = [r for r in rows if r["model"] == model and r["size"] == size and
                    r["v_col"] == v and r["stop_reason"] in COMPLETE]
            if not mine:
                continue
            b2, f = b_off_groups(mine, lambda r: r["growth_efficiency"])
            sizes[str(int(2 * size))] = dict(
                f_gro={f"{b:.4f}": float(x) for b, x in zip(b2, f)},
                seeds=len({r["seed"] for r in mine}),
                mean_f_gro=float(b_off_average(b2, f)) if len(b2) == offsets else None)
        out[model] = dict(v_col=v, by_size=sizes)
    return out


def offset_figure(offsets: dict, results: Path) -> list[Path]:
    """fig_offsets_size: f_gro against N_total at each B_off^2, one panel per model at its
    OFFSET_SPEEDS speed, with <f_gro> of the four (eq. 1) where all four ran."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = model_panels()
    for ax, (model, o) in zip(axes.flat, offsets.items()):
        n = sorted(o["by_size"], key=int)
        for k, b in enumerate(f"{b:.4f}" for b in sorted(PAPER_SIZE["b_off2"])):
            at = [m for m in n if b in o["by_size"][m]["f_gro"]]
            ax.semilogx([int(m) for m in at], [o["by_size"][m]["f_gro"][b] for m in at],
                        "o-", color=plt.cm.viridis(k / 3.5), ms=4,
                        label=f"B_off^2 = {round(float(b) * 12)}/12")
        at = [m for m in n if o["by_size"][m]["mean_f_gro"] is not None]
        ax.semilogx([int(m) for m in at], [o["by_size"][m]["mean_f_gro"] for m in at],
                    "k--", lw=2, label="<f_gro> (eq. 1)")
        ax.axhline(0, color="0.7", lw=0.8)
        ax.set_title(f"{model}, {o['v_col']:g} m/s (paper's v_fra {MODELS[model][2]:g})",
                     fontsize=9)
        ax.legend(fontsize=7)
    label_panels(fig, axes, "N_total (grains in both aggregates)", "f_gro (seeds averaged)",
                 "Which collisions move <f_gro> with size: f_gro at each offset against "
                 "N_total (ice BPCA)")
    return save(fig, results, "fig_offsets_size")


def model_panels():
    """A figure of one panel per model (2 x 2), the panels sharing their axes."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt.subplots(2, 2, figsize=(11, 7.5), sharex=True, sharey=True,
                        constrained_layout=True)


def label_panels(fig, axes, xlabel: str, ylabel: str, title: str) -> None:
    """The x label under the bottom panels, the y label beside the left ones, the title."""
    for ax in axes[1]:
        ax.set_xlabel(xlabel)
    for ax in axes[:, 0]:
        ax.set_ylabel(ylabel)
    fig.suptitle(title, fontsize=10)


def figure(trend: dict, paper_size: dict, results: Path) -> list[Path]:
    """fig_vfra_size: v_fra against N_total per model, the seeds' range as error bars,
    sizes whose speeds place no v_fra as open triangles at the bound they give (up: above
    the fastest speed, down: below the slowest), the fits to 10^5 and the paper's values;
    at 10^5, where all four offsets of PAPER_SIZE ran, a bound: v_fra below its speed
    (<f_gro> <= 0 there, a triangle down) or above it (up)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = dict(zip(MODELS, ("C0", "C1", "C3", "C2")))
    fig, ax = plt.subplots(figsize=(11, 5), constrained_layout=True)
    for k, (model, t) in enumerate(trend.items()):
        c = colours[model]
        placed = [p for p in t["points"] if p["v_fra"] is not None]
        if placed:
            n = np.array([p["n_total"] for p in placed], dtype=float)
            v = np.array([p["v_fra"] for p in placed])
            err = [v - [p["low"] for p in placed], [p["high"] for p in placed] - v]
            ax.errorbar(n, v, yerr=err, fmt="o", color=c, capsize=3, label=model)
        for side, marker in (("above", "^"), ("below", "v")):
            bounds = [p for p in t["points"] if p["bound"] and p["bound"][0] == side]
            if bounds:
                ax.plot([p["n_total"] * 1.05 ** k for p in bounds],      # side by side
                        [p["bound"][1] for p in bounds], marker, color=c, mfc="none", ms=9,
                        label=f"{model}: {side} the {'fastest' if side == 'above' else 'slowest'}"
                              " speed run")
        if t["fit"]:
            x = np.logspace(np.log10(t["fit"]["n_total"][0]), 5, 50)
            ax.plot(x, t["fit"]["a"] + t["fit"]["b"] * np.log10(x), "--", color=c, lw=1)
        ax.plot([1e5], [t["paper_v_fra"]], "*", ms=12, color=c, mec="k", mew=0.5)
        large = paper_size.get(model, {})
        if large.get("mean_f_gro") is not None:
            below = large["mean_f_gro"] <= 0
            ax.plot([2 * PAPER_SIZE["n"] * 1.05 ** k], [large["v_col"]], "v" if below else "^",
                    color=c, ms=9, label=f"{model}, 2 x {PAPER_SIZE['n']}: <f_gro> "
                                         f"{large['mean_f_gro']:+.2f} at {large['v_col']:g} m/s")
    ax.set_xscale("log")
    ax.set_xlabel("N_total (grains in both aggregates)")
    ax.set_ylabel("v_fra (m/s)")
    ax.set_title("v_fra against size: points this study (error bars: the seeds), dashed "
                 "fits a + b log N, stars the paper at 10^5,\ntriangles: v_fra not placed, above "
                 "(up) or below (down) the speeds run; filled at 10^5: the paper-size runs' "
                 "bound", fontsize=8)
    ax.set_ylim(0, 1.1 * FASTEST)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1))     # beside, not over
    return save(fig, results, "fig_vfra_size")


def growth_figure(rows: list[dict], paper_size: dict, results: Path) -> list[Path]:
    """fig_growth_size: <f_gro> against v_col, one panel per model, one line per size
    (darker = larger), the 2 x 50000 <f_gro> where all four offsets ran, and the paper's
    v_fra: where each size's curve crosses 0, and how flat it is there."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter, ScalarFormatter

    sizes = sorted({r["size"] for r in rows})
    shade = {n: plt.cm.viridis(0.85 * (1 - k / max(1, len(sizes) - 1)))
             for k, n in enumerate(sizes)}
    fig, axes = model_panels()
    for ax, model in zip(axes.flat, MODELS):
        for n in sizes:
            at = [r for r in rows if r["model"] == model and r["size"] == n]
            if not at:
                continue
            c = curve(at)
            label = f"2 x {int(n)}: " + (f"v_fra {c['v_fra']:.3g} m/s" if c["v_fra"]
                                          else "no v_fra")
            ax.semilogx(c["v_col"], c["mean_f_gro"], "o-", ms=3, color=shade[n],
                        lw=1 + sizes.index(n) * 0.6, label=label)
        large = paper_size.get(model, {})
        if large.get("mean_f_gro") is not None:
            ax.plot([large["v_col"]], [large["mean_f_gro"]], "s", color="k", ms=7,
                    label=f"2 x {PAPER_SIZE['n']}: {large['mean_f_gro']:+.2f}")
        ax.plot([MODELS[model][2]], [0], "v", color="C3", ms=10,
                label=f"the paper's v_fra at 10^5: {MODELS[model][2]:g} m/s")
        ax.axhline(0, color="0.7", lw=0.8)
        ax.set_title(model, fontsize=9)
        ax.legend(fontsize=7)
    for ax in axes[1]:
        ax.set_xticks([10, 20, 40, 60, 100])
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_formatter(NullFormatter())
    label_panels(fig, axes, "v_col (m/s)", "<f_gro> (eq. 1, B_off^2 0-9/12)",
                 "3D BPCA paper Fig. 2 against size (ice): <f_gro> of each size, seeds "
                 "averaged per offset")
    return save(fig, results, "fig_growth_size")


def model_home(runs: Path, n: int, model: str) -> Path:
    """Where the campaigns of ``model`` at 2 x ``n`` grains go."""
    return runs / f"n{n}" / model.replace(", ", "_").replace(" ", "_")


def run_model(model: str, n: int, plan: dict, runs: Path, ranks: int,
              ledger: list[dict]) -> None:
    """Phase 1, its extension and phase 2 (with its follow-up) of one model at 2 x ``n``."""
    grid, offsets = plan["grids"][model], plan["b_off2"]
    home = model_home(runs, n, model)
    first = f"seed{SEEDS[0]}"
    rows = campaign(first, model, n, grid, offsets, SEEDS[0], home, ranks, ledger)
    for _ in range(plan["extend"]):
        speed = next_speed(curve(rows))
        if speed is None:
            break
        rows += campaign(f"{first}_v{speed:g}", model, n, [speed], offsets, SEEDS[0], home,
                         ranks, ledger)
    second = f"seed{SEEDS[1]}"
    campaign(second, model, n, nearest_two(curve(rows)), offsets, SEEDS[1], home, ranks,
             ledger)
    # seed 2 may move v_fra out of seed 1's bracket: seed 2 then runs at the new bracket's
    # speeds too, so that both seeds stand at the two speeds nearest v_fra
    for _ in range(plan["follow"]):
        missing = seed_2_missing(finished(home, n, model, ledger), len(offsets))
        if not missing:
            break
        for speed in missing:
            campaign(f"{second}_v{speed:g}", model, n, [speed], offsets, SEEDS[1], home,
                     ranks, ledger)
    # seed 1 alone may bracket v_fra where the two seeds together do not (2 x 5000
    # frictional: seed 1 fell to <= 0 at 79.4 m/s, both seeds' <f_gro> there was +0.004):
    # both seeds then run at the paper's next speed on that side, as far as EXTEND allows
    for _ in range(plan["extend"]):
        speed = next_speed(curve(finished(home, n, model, ledger)))
        if speed is None:
            break
        for seed in SEEDS:
            campaign(f"seed{seed}_v{speed:g}", model, n, [speed], offsets, seed, home, ranks,
                     ledger)


def seed_2_missing(rows: list[dict], offsets: int) -> list[float]:
    """The speeds nearest v_fra of the seeds' curve in ``rows`` at which seed 2 has not run
    at every offset."""
    return [v for v in nearest_two(curve(rows))
            if sum(r["seed"] == SEEDS[1] and r["v_col"] == v for r in rows) < offsets]


def run_paper_size(runs: Path, ranks: int, b_off2: list[float], ledger: list[dict],
                   models: list[str] | None = None) -> None:
    """The 12 collisions of PAPER_SIZE at 2 x 50000 grains, seed 1, the offsets ``b_off2``
    of each model before the next offsets of any (one campaign per model and offsets, its
    one collision across all ``ranks``); only ``models`` of them if given."""
    n = PAPER_SIZE["n"]
    for b2 in b_off2:
        for model, v in PAPER_SIZE["speeds"].items():
            if models and model not in models:
                continue
            campaign(f"v{v:g}_b2_{b2:.4f}", model, n, [v], [b2], SEEDS[0],
                     model_home(runs, n, model), ranks, ledger, ranks_per_run=ranks)


def size_summary(mine: list[dict], model: str) -> dict:
    """One model at one size: its curve, v_fra, the seeds' v_fra, where seed 2 ran, how the
    runs ended, their worst energy error and the compute they took."""
    c = curve(mine)
    c.update(seeds_v_fra=seed_spread(mine),
             seed_2_at=sorted({r["v_col"] for r in mine if r["seed"] == SEEDS[1]}),
             paper_v_fra=MODELS[model][2],
             stop_reasons={k: sum(r["stop_reason"] == k for r in mine)
                           for k in sorted({r["stop_reason"] for r in mine})},
             energy_error_max=max(r["energy_error"] for r in mine),
             core_hours=core_hours(mine))
    return c


def paper_size_summary(rows: list[dict]) -> dict:
    """Per model at 2 x 50000: f_gro per B_off^2 and, once all four offsets ran, <f_gro>
    (eq. 1), with the paper's v_fra it is read against."""
    out = {}
    for model, v in PAPER_SIZE["speeds"].items():
        mine = [r for r in rows if r["model"] == model and r["stop_reason"] in COMPLETE]
        if not mine:
            continue
        out[model] = dict(
            v_col=v, paper_v_fra=MODELS[model][2],
            f_gro={f"{r['B_off'] ** 2:.4f}": r["growth_efficiency"]
                   for r in sorted(mine, key=lambda r: r["B_off"])},
            mean_f_gro=(float(b_off_mean(mine, lambda r: r["growth_efficiency"]))
                        if len(mine) == len(PAPER_SIZE["b_off2"]) else None),
            energy_error_max=max(r["energy_error"] for r in mine),
            core_hours=core_hours(mine))
    return out


def main(argv=None) -> int:
    p = campaign_study_parser(__doc__)
    p.add_argument("--sizes", type=int, nargs="+", default=None,
                   help="grains per aggregate (default: 5000)")
    p.add_argument("--models", nargs="+", default=None, metavar="MODEL",
                   help="run only these models at the sizes or at --paper-size (default: "
                        "all, in GRIDS' order); the summary takes every model's finished runs")
    p.add_argument("--paper-size", nargs="*", type=float, default=None, metavar="B_OFF2",
                   help="run the 12 collisions at 2 x 50000 (PAPER_SIZE) instead of the "
                        "sizes, at these B_off^2 (default all four)")
    p.add_argument("--summary-only", action="store_true",
                   help="run nothing; write the results from the runs finished so far")
    args = p.parse_args(argv)
    plan = dict(QUICK if args.quick else FULL)
    if args.sizes:
        plan["sizes"] = args.sizes
    unknown = sorted(set(args.models or []) - set(plan["grids"]))
    if unknown:
        p.error(f"unknown model {unknown[0]!r}: give one of {list(plan['grids'])}")
    if args.paper_size is not None and not set(args.paper_size) <= set(PAPER_SIZE["b_off2"]):
        p.error(f"--paper-size takes B_off^2 of {PAPER_SIZE['b_off2']}")
    if args.paper_size is not None and not set(args.models or []) <= set(PAPER_SIZE["speeds"]):
        p.error(f"--paper-size runs the models {list(PAPER_SIZE['speeds'])}: give those "
                "to --models")
    runs, results = study_paths(args, "vfra_size")
    ledger = read_committed(results, INTS)
    t0 = time.time()
    if args.paper_size is not None and not args.summary_only:
        run_paper_size(runs, args.np, args.paper_size or PAPER_SIZE["b_off2"], ledger,
                       args.models)
    elif not args.summary_only:
        for n in plan["sizes"]:
            for model in args.models or plan["grids"]:
                run_model(model, n, plan, runs, args.np, ledger)
    # every finished run below RUNS or in the ledger goes into runs.csv, whichever call
    # ran it; a model enters the summary, the trend and the figures once its seed 2 has
    # run (before that its curve is phase 1's so far), and is listed as under way until then
    rows, sizes, under_way = [], {}, {}
    for n in plan["sizes"]:
        for model in plan["grids"]:
            mine = finished(model_home(runs, n, model), n, model, ledger)
            done = any(r["seed"] == SEEDS[1] for r in mine) and \
                not (plan["follow"] and seed_2_missing(mine, len(plan["b_off2"])))
            if done:
                rows += mine
                sizes.setdefault(str(n), {})[model] = size_summary(mine, model)
            elif mine:
                under_way.setdefault(str(n), {})[model] = mine
    big = PAPER_SIZE["n"]
    large = [r for model in PAPER_SIZE["speeds"]
             for r in finished(model_home(runs, big, model), big, model, ledger)]
    write_csv(results / "runs.csv", rows + [r for m in under_way.values() for x in m.values()
                                            for r in x] + large)
    # the size trend: the committed smaller sizes of bpca3d_models with these (not in the
    # quick variant, whose sizes are its own)
    before = [] if args.quick else [r for r in read_csv(SMALLER) if r["size"] not in
                                    plan["sizes"]]
    trend = size_trend(before + rows)
    paper_size = paper_size_summary(large)
    figure(trend, paper_size, results)
    growth_figure(before + rows, paper_size, results)
    offsets = by_offset(before + rows + large, len(plan["b_off2"]))
    offset_figure(offsets, results)
    summary = dict(plan=plan, tolerance=TOLERANCE, ranks=args.np,
                   seconds_this_call=time.time() - t0, load=os.getloadavg()[0], sizes=sizes,
                   trend=trend, damping_effect=damping_effect(before + rows),
                   paper_size=paper_size, by_offset=offsets,
                   under_way={n: {m: len(x) for m, x in by.items()}
                              for n, by in under_way.items()})
    (results / "summary.json").write_text(json.dumps(summary, indent=2, default=float) + "\n")
    print(json.dumps(dict(sizes=sizes, paper_size=paper_size), indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
