"""Does f_gro still move after the settle rule ends a paper-size run? (issue 46, item 5)

At 2 x 50000 the frictionless collisions at 39.8 m/s make one body that parts into two
(2/12 at 1.63 us, 3/12 at 1.37 us, 6/12 at 0.88 us), and 4/12 parted twice (1.23 and
1.70 us): the outcome moves on microsecond scales, while the settle rule watches 250 t_c
(68 ns). The paper's runs end at a time it does not state. This study puts every
paper-size run of a question on one clock: each run the settle rule ended before the
paper stage's cap (``paper_protocol.PAPER_CAP_TC``, 4.4 us) is continued from its
final.restart to that time with the settle checks written but the rule off, so that
f_gro is read at one fixed end for every offset (a run that hit the cap is there already).

    ./run validate fixed_end                 # continue each settled run (hours; resumable)
    ./run validate fixed_end --shape         # ... until it settles with shape watched;
                                             # a later call without --shape goes on from
                                             # there to the fixed end, the record extended
    ./run validate fixed_end --summary-only  # the results from the records kept so far
    ./run validate fixed_end --anew          # ... a run made anew that is not the one
                                             # recorded too, as another run of its collision

Continuations run one at a time over --np ranks, in the protocol's order of offsets
(``paper_protocol.TWELFTHS_FIRST``), each in RUNS/<campaign>/ (a second call resumes a cut-off one from its newer
restart file). As each ends, its checks.csv is kept below RESULTS/records/<campaign>/, and
the results come from the records alone: each offset's f_gro(t) from the original run's
checks and its continuation's, f_gro at the settle end and at the fixed end, <f_gro> of
eq. (1) at both ends where the twelve offsets are in (else what the open offsets must
average for <f_gro> < 0), and fig_fixed_end (f_gro against time, one line per run).
Question b at 2 x 50000 writes summary.json and fig_fixed_end; any other (``--question``,
``--size``) writes summary_<question>_n<size>.json and fig_fixed_end_<question>_n<size>.
Another study's settled runs are continued the same way with ``--campaigns GLOB`` (its
campaigns below ``--protocol-runs`` and ``--protocol-records``), named by the glob:

    ./run validate fixed_end --np 1 --campaigns frictional_63.1/dt_0.014 \
        --protocol-runs validation/runs/size_trend --protocol-records \
        validation/size_trend/records --results validation/fixed_end/size_trend
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

from common import BIN, campaign_study_parser, copy_record, save, study_paths, write_summary
from jkrdt import protocol, rundir
from jkrdt.analysis.outcome import stretching
from jkrdt.analysis.summary import b_off_average, b_off_groups
from jkrdt.stopping import SettleRule
from paper_protocol import (PAPER_CAP_TC, QUESTIONS, QUICK_CAP_TC, SNAPSHOTS_US,
                            TWELFTHS_FIRST, what_the_rest_needs)
from readings import ANEW, RULE, anew, checks_through, continued_run, first_at, fixed_end_us

HERE = Path(__file__).resolve().parent
#: a settle window no run reaches: the checks are written, the rule never ends the run
WATCH_ONLY = 10 ** 9
#: what each continued run's record holds
KEPT = (rundir.CHECKS, rundir.META)


def continue_run(run: Path, out: Path, cap_tc: float, shape: bool = False) -> None:
    """Continue ``run`` (ended by the settle rule) in ``out`` to ``cap_tc`` with the settle
    checks on and the rule off (``shape``: on, with shape watched, ``SettleRule()``), from
    its final.restart, or from ``out``'s newer restart file where an earlier call was cut
    off. Every rank of COMM_WORLD calls this."""
    from mpi4py import MPI

    from jkrdt.session import Session

    comm = MPI.COMM_WORLD
    rule = SettleRule(cap_tc=cap_tc) if shape else SettleRule(window=WATCH_ONLY, cap_tc=cap_tc)
    end = rule.cap_steps(rundir.read(run).time_step()[0])
    point = None
    if comm.rank == 0:
        if shape and "stretch ${settle_stretch}" not in rundir.deck(run).read_text():
            rundir.write_deck(run)     # a deck from before the keyword: the same but for it
        out.mkdir(parents=True, exist_ok=True)
        shutil.copy2(run / rundir.META, out / rundir.META)    # resume_point looks for it
        settled = None if shape else shape_end_step(out)
        if settled is not None:     # it settled with shape watched: on from there
            point = (out / rundir.FINAL_RESTART, settled)
        elif (out / rundir.LOG).exists():
            point = rundir.resume_point(out, end)
        if point is not None:
            rundir.cut_back(out, point[1])
        else:                       # cut off before its first restart file: anew
            rundir.clear_run(out)
    point = comm.bcast(point, root=0)
    if point is None:
        start = json.loads((run / rundir.OUTCOME).read_text())["stop_step"]
        restart, append = run / rundir.FINAL_RESTART, False
    else:
        (restart, start), append = point, True
    with Session(run, out, every=1, settle=rule, restart=restart, append=append,
                 variables=dict(steps=end - start)) as s:
        s.run_until_settled(progress=False)
        s.finish()


def shape_end_step(out: Path) -> int | None:
    """The step at which the continuation in ``out`` settled with shape watched (``--shape``),
    its final.restart at hand, so that it can go on to the fixed end; None otherwise."""
    if not (out / rundir.FINAL_RESTART).exists():
        return None
    status = rundir.run_status(out)
    return status.stop_step if status.stop_reason == "settled" else None


def keep(run: Path, record: Path) -> None:
    """A finished continuation's record (KEPT), copied whole: its checks.csv, the mark of a
    kept record, is renamed into place last."""
    record.mkdir(parents=True, exist_ok=True)
    for name in KEPT:
        shutil.copy2(run / name, record / f".{name}")
    for name in sorted(KEPT, key=lambda n: n == rundir.CHECKS):
        (record / f".{name}").rename(record / name)


def to_continue(runs: Path, campaigns: str, cap_tc: float, twelfths=None,
                seeds=None) -> list[Path]:
    """The runs of the ``campaigns`` (a glob below ``runs``) that the settle rule ended
    before ``cap_tc`` (their final.restart at hand), offsets in TWELFTHS_FIRST's order
    (others after, by B_off); ``twelfths``: only the offsets B_off^2 = k/12 of these k;
    ``seeds``: only these seeds."""
    order = {round(12 * b2): k for k, b2 in enumerate(TWELFTHS_FIRST)}
    out = []
    for run in runs.glob(f"{campaigns}/v*/b2_*/seed*"):
        o = rundir.read_outcome(run)
        if o is None or not (run / rundir.FINAL_RESTART).exists():
            continue
        k = 12 * o["B_off"] ** 2
        if twelfths is not None and not any(abs(k - j) < 1e-6 for j in twelfths):
            continue
        if seeds is not None and o["seed"] not in seeds:
            continue
        if o.get("stop_reason") == "settled" and o["time_end_over_tc"] < cap_tc:
            first = order.get(round(k), len(order)) if abs(k - round(k)) < 1e-6 else len(order)
            out.append(((first, o["B_off"], o["seed"]), run))
    return [run for _, run in sorted(out)]


#: what a run and its kept record must share to be the same collision (a run made anew
#: by ``paper_protocol --again``: bit for bit on the same build and ranks, else not)
SAME_RUN = ("stop_step", "n_largest", "n_fragments", "N_con", "N_cut", "dissipated_fraction")


def not_the_record(run: Path, record: Path) -> str | None:
    """How ``run``'s outcome differs from its kept record's (None: the same run, or no
    record kept)."""
    kept = rundir.read_outcome(record)
    if kept is None:
        return None
    o = rundir.read_outcome(run)
    return ", ".join(f"{k} {o.get(k)} against {kept.get(k)}" for k in SAME_RUN
                     if o.get(k) != kept.get(k)) or None


def not_at_hand(records: Path, kept: Path, runs: Path, campaigns: str,
                cap_tc: float) -> list[dict]:
    """The records of the ``campaigns`` that the settle rule ended before ``cap_tc`` whose
    continuation is neither kept nor possible here: their run directory (its
    final.restart) is gone with the machine that ran them. Each with its offset's k, for
    ``paper_protocol --again k``, which runs it anew."""
    out = []
    for outcome in sorted(records.glob(f"{campaigns}/v*/b2_*/seed*/{rundir.OUTCOME}")):
        o = json.loads(outcome.read_text())
        where = outcome.parent.relative_to(records)
        if o.get("stop_reason") != "settled" or o["time_end_over_tc"] >= cap_tc or \
                (kept / where / rundir.CHECKS).exists() or \
                (runs / where / rundir.FINAL_RESTART).exists():
            continue
        out.append(dict(record=str(where), seed=o["seed"], twelfths=round(12 * o["B_off"] ** 2),
                        settled_tc=o["time_end_over_tc"]))
    return out


def offsets(records: Path, kept: Path, campaigns: str, cap_tc: float) -> list[dict]:
    """Each record of the ``campaigns`` (a glob below ``records``): its f_gro(t), with the
    continuation's checks appended where one was kept; f_gro at its own end and at the
    fixed end ``cap_tc`` (the first check at or after it, as a cap ends a run: one capped
    later is read there too); how it ended, and how much the largest fragment's gyration
    radius grew over the settle rule's last window there (a body still being pulled apart
    by a neck, which the rule does not watch). Where the continuation is of a run made
    anew (``readings.anew``), the row is that run's: its own end, checks and continuation."""
    out = []
    for outcome in sorted(records.glob(f"{campaigns}/v*/b2_*/seed*/{rundir.OUTCOME}")):
        where = outcome.parent.relative_to(records)
        run = continued_run(outcome.parent, kept / where)
        o = json.loads((run / rundir.OUTCOME).read_text())
        own = checks_through(run, None, o["N_tar"], o["N_pro"])
        end_us = own[-1]["time"] * 1e6
        fixed_us = fixed_end_us(outcome.parent, cap_tc)
        shape = stretching(own, RULE.window, RULE.tolerance)     # None: one grain
        more = kept / where / rundir.CHECKS
        checks = checks_through(outcome.parent, kept / where, o["N_tar"], o["N_pro"])
        t = [r["time"] * 1e6 for r in checks]
        f = [r["growth_efficiency"] for r in checks]
        at = first_at(checks, fixed_us)
        reaches = at is not None
        at = len(t) - 1 if at is None else at
        out.append(dict(record=str(where), B_off=o["B_off"], B_off2=round(o["B_off"] ** 2, 4),
                        seed=o["seed"], model=o["model"], tvis=o["tvis"], v_col=o["v_col"],
                        N_tar=o["N_tar"], stop_reason=o["stop_reason"], end_us=end_us,
                        f_gro_end=o["growth_efficiency"],
                        r_g_change_at_end=shape and shape["r_g_growth"],
                        continued=more.exists(), anew=anew(kept / where),
                        fixed_us=fixed_us, fixed_end_us=t[at], f_gro_fixed_end=f[at],
                        reaches_fixed_end=reaches,
                        # continued with shape watched (--shape), settled before the end
                        shape_end=more.exists() and not reaches and t[-1] > end_us + 1e-9,
                        time_us=t, f_gro=f))
    return out


def mean_or_open(rows: list[dict], key: str) -> dict:
    """<f_gro> of eq. (1) from ``key`` of each offset (seeds averaged) if all twelve are
    in, else what the open ones must average for <f_gro> < 0 (none: nothing to say)."""
    if not rows:
        return {}
    b2, f = b_off_groups(rows, lambda r: r[key])
    if protocol.is_paper_grid(b2):
        return dict(mean_f_gro=float(b_off_average(b2, f, grazing=0.0)))
    return dict(sign_open=what_the_rest_needs(b2, f))


def figure(rows: list[dict], results: Path, cap_us: float, title: str,
           tag: str = "") -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.6))
    seeds = len({r["seed"] for r in rows}) > 1
    for k, r in enumerate(sorted(rows, key=lambda r: (r["B_off2"], r["seed"]))):
        color, style = plt.cm.tab10(k % 10), ("-", "--")[k // 10]
        label = f"B_off^2 {protocol.twelfths(r['B_off2'], 1e-3)}" + \
            (f", seed {r['seed']}" if seeds else "")
        ax.plot(r["time_us"], r["f_gro"], color=color, ls=style, lw=1.2, label=label)
        if r["continued"]:
            ax.plot([r["end_us"]], [r["f_gro_end"]], "o", color=color, ms=5, mfc="none")
        if r["shape_end"]:
            ax.plot([r["time_us"][-1]], [r["f_gro"][-1]], "s", color=color, ms=5)
    ax.axvline(cap_us, color="0.5", ls=":", lw=1)
    ax.text(cap_us, 1.0, "fixed end ", fontsize=7, va="top", ha="right", color="0.4")
    ax.set_xlim(0, cap_us * 1.02)
    for t in SNAPSHOTS_US:
        ax.axvline(t, color="0.9", lw=0.8, zorder=0)
    ax.axhline(0, color="0.7", lw=0.8)
    ax.set_xlabel("time (us); grey: the paper's snapshots; circle: where the settle rule "
                  "ended the run" + ("; square: settled with shape watched"
                                     if any(r["shape_end"] for r in rows) else ""), fontsize=8)
    ax.set_ylabel("f_gro = (N_lar - N_tar) / N_pro")
    ax.set_ylim(-1.05, 1.05)
    ax.legend(fontsize=7, ncol=2, loc="lower left")
    ax.set_title(f"{title}: f_gro against time, settled runs continued to the fixed end"
                 + ("\nor until settled with shape watched" if any(r["shape_end"] for r in rows)
                    else ""), fontsize=9)
    fig.tight_layout()
    return save(fig, results, "fig_fixed_end" + tag)


def table(rows: list[dict], done: dict) -> list[str]:
    """Each offset's f_gro where its run ended and at the fixed end, and <f_gro> at both."""
    lines = ["  B_off^2  ended             f_gro  r_g over its last window  f_gro at "
             f"{done['cap_tc']:g} t_c"]
    for r in sorted(rows, key=lambda r: r["B_off2"]):
        fixed = (f"{r['f_gro_fixed_end']:+.3f}" + ("" if r["continued"] or r["stop_reason"]
                                                   != "settled" else " (not continued)")
                 + (f" (settled with shape watched at {r['fixed_end_us']:.2f} us)"
                    if r["shape_end"] else "") + (" (a run made anew)" if r["anew"] else ""))
        stretch = ("      -" if r["r_g_change_at_end"] is None
                   else f"{100 * r['r_g_change_at_end']:+6.2f} %")
        lines.append(f"  {protocol.twelfths(r['B_off2'], 1e-3):7s}  {r['stop_reason']:8s} "
                     f"{r['end_us']:4.2f} us {r['f_gro_end']:+.3f}  {stretch}"
                     f"                  {fixed}")
    for end in ("settle_end", "fixed_end"):
        m = done["results"][end]
        if "mean_f_gro" in m:
            lines.append(f"  <f_gro> at the {end.replace('_', ' ')}: {m['mean_f_gro']:+.3f}")
        elif m.get("sign_open"):
            lines.append(f"  at the {end.replace('_', ' ')}, <f_gro> < 0 needs "
                         f"{' '.join(m['sign_open']['to_run'])} to average below "
                         f"{m['sign_open']['rest_must_average_below']:+.3f}")
    return lines


def results_tag(args) -> str:
    """What names the summary and figure: nothing for the study's own question (b at
    2 x 50000) and its quick variant, else the question and size, or the campaigns' glob."""
    if args.campaigns:
        return "_" + re.sub(r"[^A-Za-z0-9.]+", "_", args.campaigns).strip("_")
    if args.quick or (args.question, args.size) == ("b", 50000):
        return ""
    return f"_{args.question}_n{args.size}"


def main(argv=None) -> int:
    p = campaign_study_parser(__doc__)
    p.add_argument("--question", default=None, help="default b (--quick: a)")
    p.add_argument("--size", type=int, default=None, help="default 50000 (--quick: 24)")
    p.add_argument("--cap", type=float, default=None,
                   help=f"the fixed end, t_c (default {PAPER_CAP_TC:g}; --quick: {QUICK_CAP_TC:g})")
    p.add_argument("--seeds", type=int, nargs="+", default=None,
                   help="continue only the runs of these seeds")
    p.add_argument("--twelfths", type=int, nargs="+", default=None,
                   help="continue only the offsets B_off^2 = k/12 of these k")
    p.add_argument("--campaigns", default=None,
                   help="the campaigns to continue, a glob below --protocol-runs and "
                        "--protocol-records (default n<size>_<question>_b2_*; another "
                        "study's, e.g. --protocol-runs validation/runs/size_trend "
                        "--protocol-records validation/size_trend/records --campaigns "
                        "frictional_63.1/dt_0.014)")
    p.add_argument("--protocol-runs", type=Path, default=HERE / "runs" / "paper_protocol")
    p.add_argument("--protocol-records", type=Path,
                   default=HERE / "paper_protocol" / "records")
    p.add_argument("--shape", action="store_true",
                   help="continue under the settle rule with shape watched (the default "
                        "rule, SettleRule()) instead of to the fixed end: a run ends where "
                        "its largest body has stopped stretching and its counts hold, or at "
                        "the fixed end (validation/end_rule.py measured that end against "
                        "the fixed end on every run continued there)")
    p.add_argument("--anew", action="store_true",
                   help="continue a run made anew (paper_protocol --again) even where it is "
                        "not the recorded one (another build: chaos parts the two), as "
                        "another run of the same collision, read from its own checks")
    p.add_argument("--summary-only", action="store_true")
    p.add_argument("--one", nargs=2, type=Path, help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    for name, paper, quick in (("question", "b", "a"), ("size", 50000, 24),
                               ("cap", PAPER_CAP_TC, QUICK_CAP_TC)):
        if getattr(args, name) is None:
            setattr(args, name, quick if args.quick else paper)
    if args.one:                                 # one continuation, under mpirun
        continue_run(args.one[0], args.one[1], args.cap, args.shape)
        return 0
    runs, results = study_paths(args, "fixed_end")
    kept = results / "records"
    campaigns = args.campaigns or f"n{args.size}_{args.question}_b2_*"
    if not args.summary_only:
        for run in to_continue(args.protocol_runs, campaigns, args.cap, args.twelfths,
                               args.seeds):
            where = run.relative_to(args.protocol_runs)
            # a continuation that settled with shape watched goes on to the fixed end
            # (its record extended), unless --shape asks for that end again
            on = not args.shape and shape_end_step(runs / where) is not None
            if (kept / where / rundir.CHECKS).exists() and not on:
                continue
            if (runs / where / rundir.FINAL_RESTART).exists() and not on:    # ended, not kept
                keep(runs / where, kept / where)
                continue
            differs = not_the_record(run, args.protocol_records / where)
            if differs and not args.anew:
                print(f"{where}: not continued: this run is not the one recorded "
                      f"({differs}), so its continuation would not extend the record's "
                      "checks; --anew continues it as another run of the same collision, "
                      "read from its own checks", flush=True)
                continue
            if differs:     # its own small record in the continuation's, before the mark
                copy_record(run, kept / where / ANEW)
                print(f"{where}: not the run recorded ({differs}): continued as another "
                      "run of the same collision", flush=True)
            cmd = [str(BIN / "python"), __file__, "--one", str(run), str(runs / where),
                   "--cap", str(args.cap)] + (["--shape"] if args.shape else [])
            if args.np > 1:
                cmd = [str(BIN / "mpirun"), "-np", str(args.np)] + cmd
            print(f"{where}: continued to {args.cap:g} t_c", flush=True)
            if subprocess.run(cmd).returncode != 0:
                raise SystemExit(f"{where}: the continuation stopped; run again to resume")
            keep(runs / where, kept / where)
    missing = [] if args.campaigns else not_at_hand(args.protocol_records, kept,
                                                    args.protocol_runs, campaigns, args.cap)
    for m in missing:
        print(f"{m['record']}: settled at {m['settled_tc']:.0f} t_c, not continued, and its "
              f"run directory is not here: './run validate paper_protocol --stage paper "
              f"--questions {args.question} --again {m['twelfths']}' runs it anew, then "
              "this continues it", flush=True)
    rows = offsets(args.protocol_records, kept, campaigns, args.cap)
    cap_us = max((r["fixed_us"] for r in rows), default=None)
    # eq. (1) over the grid for a protocol question asked on the twelve offsets
    twelve = not args.campaigns and len(QUESTIONS[args.question]["b_off2"]) == 12
    tag = results_tag(args)
    done = dict(study="fixed_end", campaigns=campaigns, question=args.question, size=args.size,
                cap_tc=args.cap, cap_us=cap_us, results=dict(
                    offsets=[{k: v for k, v in r.items() if k not in ("time_us", "f_gro")}
                             for r in rows],
                    settle_end=mean_or_open(rows, "f_gro_end") if twelve else {},
                    fixed_end=mean_or_open([r for r in rows if r["reaches_fixed_end"]],
                                           "f_gro_fixed_end") if twelve else {},
                    not_at_hand=missing))
    print("\n".join(table(rows, done)))
    if rows:
        r = rows[0]
        model = r["model"] + (f", T_vis {r['tvis'] * 1e12:g} ps" if r["tvis"] else "")
        done["figures"] = [p.name for p in figure(
            rows, results, cap_us, f"{model}, {r['v_col']:g} m/s, 2 x {r['N_tar']}", tag)]
    return write_summary(results, done, f"summary{tag}.json")


if __name__ == "__main__":
    sys.exit(main())
