"""The 3D BPCA paper's own protocol where this tool and the paper disagree (issue 46).

At the paper's size (2 x 50000) two of three models disagree with it over four offsets
(``vfra_size --paper-size``). This study asks each disagreement as the paper would, on
its grid of offsets (``jkrdt.protocol``: B_off^2 = k/12, eq. 1 with the grazing 12/12 as
no collision), with its diagnostics (N_con, N_cut, E_dis by channel, N_cum: every run's
``outcome.json["diagnostics"]``):

  a   frictionless, undamped, head-on, 100 m/s: the paper's sharpest case, f_gro about -1
      with E_dis,tot well below E_imp (App. C.1)
  c   damped frictional (T_vis 6 ps), 63.1 m/s, B_off^2 3/12, where one seed at 2 x 50000
      kept the projectile (f_gro +0.53) though the paper's v_fra is 50 m/s
  b   frictionless, undamped, 39.8 m/s, on the paper's twelve offsets: <f_gro> should be
      clearly negative (v_fra 30 m/s); four offsets gave +0.06 at 2 x 50000
  d   frictionless, undamped, 31.6 m/s, the paper's twelve offsets: the next speed down
  e   the frictional, damped frictional and damped frictionless models, head-on, 100 m/s:
      f_gro about 1 with E_dis,tot about E_imp (App. C.1), one campaign per model
  f   all four models at 10 m/s on four offsets (seed 1): N_con < N_tot for the frictional
      models, N_cut well below N_tot for all but the undamped frictionless (App. C.2)
  g   frictional, undamped, 63.1 m/s, the paper's twelve offsets: <f_gro> about 0 (v_fra
      60 m/s), where four offsets ended by the settle rule without shape gave +0.12 at
      2 x 5000 (``vfra_size``: v_fra 82 m/s); asked at 2 x 5000, where that rise with N is
      seen, it tells the grid of offsets from the end of the run (``mean_f_gro_four_offsets``
      reads the same runs on the four offsets)

e and f are there for the paper's statements (``statements``: every statement of App. C
that gives a number or a sign, one row each, read at each speed at the largest size that
ran it, the models compared on the same scenes), drawn in fig_statements.

Each question is placed first at 2 x 5000 with seeds 1 and 2 (``--stage place``, about
ten times cheaper, two collisions side by side on the two ranks), then asked at the
paper's 2 x 50000 where the placement says it decides something (``--stage paper``: seed
1, each collision on all ranks; seed 2 for c). One campaign per question, size and offset
(``RUNS/n<N>_<question>_b2_<B_off^2>``), in the order of QUESTIONS; a second call resumes
them, and a campaign whose runs all have their records kept is not run again, on this
machine or a new one (``--again K`` runs the offset K/12 anew, bit for bit on the same
build and ranks, for ``fixed_end`` to continue; on another build it is another run of the
same collision, which ``fixed_end --anew`` continues and reads on its own). Every run ends by the settle rule, its
dt chosen by ``--dt auto`` for max |dE| / E_imp <= 1e-3 (vfra_size.TOLERANCE); at the
paper's size a run that has not settled by PAPER_CAP_TC ends there and is averaged at
its end (``summary.json``'s ``ended_at_cap`` lists each with how far its f_gro moved over
its last 1.6 us; ``end_rule.py`` measures the cap against the runs' real ends), and a run
that failed or was cut off is left out (``left_out``).

The small record of every finished run (``jkrdt.rundir.RECORD``: outcome.json,
checks.csv, collision.json, frames.csv, the outcome and timeline pictures) is copied to
RESULTS/records/<campaign>/v<v_col>/b2_<B_off^2>/seed<k>/ as its campaign ends, and the
results are made from those records alone:
runs.csv (every run, its diagnostics among the columns), summary.json (per question: f_gro
per offset and seed, <f_gro> by eq. 1 with its seed scatter where the twelve offsets ran,
the diagnostics' eq. 1 means, and f_gro at the paper's snapshot times 0.4-1.6 us read
from each run's settle checks, to show whether where a run ends moves it; the paper's
statements of App. C against the runs, one row each) and fig_protocol (f_gro, N_con / N_tot and N_cut / N_tot against B_off^2).
Each run is also read where its outcome is decided (``readings.py``; its continuation's
record from ``fixed_end``, ``--continued``): summary.json's ``read`` per question and
size, with eq. (1)'s <f_gro> so read, or what the offsets not yet read must average.

    ./run validate paper_protocol                   # --stage place: 2 x 5000, hours
    ./run validate paper_protocol --questions a c
    ./run validate paper_protocol --stage paper --questions a
    ./run validate paper_protocol --summary-only    # the results of the records committed
    ./run validate paper_protocol --quick           # 2 x 24 grains (tests)
"""

from __future__ import annotations

import json
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from b_off_grid import FOUR, one_of_four
from bpca3d_models import MODELS, model_spec
from common import (HERE, all_kept, campaign_study_parser, run_campaigns, save, study_paths,
                    write_summary)
from jkrdt import protocol, rundir
from jkrdt.analysis.outcome import from_checks
from jkrdt.analysis.summary import (b_off_average, b_off_groups, mean_diagnostics, scalars,
                                   seed_scatter)
from jkrdt.analysis.tables import read_csv, write_csv
from jkrdt.stopping import COMPLETE
from readings import OPEN, read
from vfra_size import TOLERANCE

#: the paper's twelve offsets in the order they are run where they decide a sign: the two
#: nearest head-on first (where f_gro falls from the head-on run's to below 0), then three
#: of the four of the other studies, then the rest, and 9/12 last: at 2 x 50000 its outcome
#: was fixed from 0.5 us on (f_gro -0.04 to -0.03) while it ran on toward its cap
TWELFTHS_FIRST = [protocol.B_OFF2[k] for k in (1, 2, 0, 3, 6, 4, 5, 7, 8, 10, 11, 9)]
#: the questions, in the order they run: the model (or models, a campaign each), its speed,
#: the offsets, what the paper says; the seeds where a question sets its own at the
#: placement. e and f are the runs that the paper's other statements of App. C bear on
#: (``statements``): the other three models head-on at 100 m/s, all four at 10 m/s
QUESTIONS = {
    "a": dict(model="frictionless", v_col=100.0, b_off2=[0.0],
              paper="f_gro about -1, E_dis,tot well below E_imp (App. C.1, Fig. B.1c)"),
    "c": dict(model="frictional, T_vis 6 ps", v_col=63.1, b_off2=[0.25],
              paper="<f_gro> below 0 above v_fra = 50 m/s (Fig. 2)"),
    "b": dict(model="frictionless", v_col=39.8, b_off2=TWELFTHS_FIRST,
              paper="<f_gro> below 0 above v_fra = 30 m/s (Fig. 2)"),
    "d": dict(model="frictionless", v_col=31.6, b_off2=TWELFTHS_FIRST,
              paper="<f_gro> about 0 at v_fra = 30 m/s (Fig. 2)"),
    "e": dict(model=("frictional", "frictional, T_vis 6 ps", "frictionless, T_vis 6 ps"),
              v_col=100.0, b_off2=[0.0],
              paper="f_gro about 1 with E_dis,tot about E_imp (App. C.1, Figs. C.1a, b, d)"),
    "f": dict(model=tuple(MODELS), v_col=10.0, b_off2=[0.0, 0.25, 0.5, 0.75], seeds=[1],
              paper="frictional: N_con < N_tot; all but the undamped frictionless: N_cut "
                    "well below N_tot (App. C.2, Figs. C.3, C.4)"),
    "g": dict(model="frictional", v_col=63.1, b_off2=TWELFTHS_FIRST,
              paper="<f_gro> about 0 at v_fra = 60 m/s, below 0 above it (Sect. 3.1, Fig. 2)"),
}


def models_of(question: str) -> tuple[str, ...]:
    """The models (``bpca3d_models.MODELS`` names) a question asks, one or several."""
    model = QUESTIONS[question]["model"]
    return (model,) if isinstance(model, str) else tuple(model)


def model_name(outcome: dict) -> str:
    """The MODELS name of a run's model, from its outcome (its kind and T_vis)."""
    return next(name for name, (kind, tvis, _) in MODELS.items()
                if kind == outcome["model"] and tvis == (outcome.get("tvis") or 0.0))


#: the paper stage's cap, t_c (4.4 us for 0.1 um ice): a run that has not settled by then
#: ends there and is counted at its end, as the paper's runs end at a time it does not
#: state. Twice the latest any paper-size run settled (8302 t_c, b at 6/12) and 2.7 times
#: the paper's last snapshot (1.6 us); at 10^5 grains N_lar can drift by tens of grains a
#: check for microseconds after the outcome is fixed (b at 9/12), which the settle rule's
#: counts (10 grains) never let settle. Measured against the runs' real ends: end_rule.py
PAPER_CAP_TC = 16000.0
#: the quick variant's fixed end (t_c), to which ``fixed_end --quick`` continues its runs:
#: the quick head-on 2 x 24 runs settle by about 400 t_c
QUICK_CAP_TC = 1200.0
#: the paper-size campaigns started with the default cap (SettleRule.cap_tc) before the
#: paper stage's was lowered: they keep it, so that they resume (or run again, --again)
#: under the spec they began. 9/12 began so too, but its run directory was lost with its
#: machine at 4.72 us, before it ended, so it starts anew under the paper stage's cap
STARTED_WITH_DEFAULT_CAP = {"b": (0.0, 1 / 12, 2 / 12, 3 / 12, 6 / 12)}
#: the campaigns begun before the settle rule watched shape (``SettleRule.stretch``), per
#: stage: they keep the rule they ran with (stretch 0), so that they resume, or run again
#: (--again) to the same end, under the spec they began; every other campaign watches it
STARTED_WITHOUT_SHAPE = {
    "place": {"a": (0.0,), "b": tuple(TWELFTHS_FIRST), "c": (0.25,)},
    "paper": {"a": (0.0,), "c": (0.25,),
              "b": (0.0, 1 / 12, 2 / 12, 3 / 12, 4 / 12, 6 / 12)}}
#: the sizes a question is asked at: its seeds, and the ranks one collision shares
STAGES = {"place": dict(n=5000, seeds=[1, 2], ranks_per_run=1,
                        no_shape=STARTED_WITHOUT_SHAPE["place"]),
          "paper": dict(n=50000, seeds=[1], ranks_per_run=2, more_seeds={"c": [1, 2]},
                        cap_tc=PAPER_CAP_TC, default_cap=STARTED_WITH_DEFAULT_CAP,
                        no_shape=STARTED_WITHOUT_SHAPE["paper"])}
#: how a run may end and be averaged here: settled, or at the cap of its stage
COUNTED = COMPLETE + ("cap",)
#: the span (us) before a capped run's end over which its f_gro range is reported
CAP_SPAN_US = 1.6
#: the tests' variant: every offset of a question in one campaign
QUICK = dict(n=24, seeds=[1, 2], ranks_per_run=1, one_campaign=True)


def campaign_specs(question: str, stage: dict) -> dict[str, dict]:
    """The campaigns of one question at one stage: one per model and offset (or one per
    model in all), each with all its seeds."""
    q = QUESTIONS[question]
    seeds = stage.get("more_seeds", {}).get(question, q.get("seeds", stage["seeds"]))
    groups = [q["b_off2"]] if stage.get("one_campaign") else [[b2] for b2 in q["b_off2"]]
    kept = stage.get("default_cap", {}).get(question, ())
    models = models_of(question)

    def began(b2, of):    # whether the campaign of offset b2[0] is among ``of``'s
        return any(abs(b2[0] - k) < 1e-9 for k in of)

    def settle(b2):    # the stage's cap, unless the campaign began with the default one;
        rule = {}      # shape not watched where the campaign began without it
        if "cap_tc" in stage and not began(b2, kept):
            rule["cap_tc"] = stage["cap_tc"]
        if began(b2, stage.get("no_shape", {}).get(question, ())):
            rule["stretch"] = 0.0
        return dict(settle=rule) if rule else {}

    return {f"n{stage['n']}/{question}/b2_{b2[0]:.4f}" + ("_all" if len(b2) > 1 else "")
            + (f"/{model}" if len(models) > 1 else ""):
            model_spec(model, stage["n"], v_col=[q["v_col"]], b_off2=b2, seeds=seeds,
                       dt="auto", tolerance=TOLERANCE, **settle(b2))
            for model in models for b2 in groups}


def run_question(question: str, stage: dict, runs: Path, ranks: int,
                 again: tuple[int, ...] = ()) -> None:
    """Every campaign of ``question`` at ``stage``, each one's records kept as its runs
    end; a campaign whose every run has its record kept is not run again (the results
    come from the records), unless its offset B_off^2 = k/12 has its k in ``again``."""
    for name, spec in campaign_specs(question, stage).items():
        k = [round(12 * b2) for b2 in spec["b_off2"]]
        if all_kept(name, spec, runs) and not set(k) & set(again):
            print(f"{name}: every run's record is kept, not run again (--again "
                  f"{' '.join(map(str, k))} runs it anew)", flush=True)
            continue
        run_campaigns({name: spec}, runs, ranks, stage["ranks_per_run"])


def question_of(record: Path, records: Path) -> tuple[int, str]:
    """(N per aggregate, question) of a record below its campaign's records,
    RESULTS/records/n<N>_<question>_b2_<B_off^2>/."""
    size, question = record.relative_to(records).parts[0].split("_")[:2]
    return int(size[1:]), question


#: the times (us from the start) at which f_gro is read from each run's checks as well as at
#: its end: the paper's snapshots are 0.4 us apart (its Fig. 1), and its runs' end is not
#: stated, so these show whether when a run ends moves f_gro
SNAPSHOTS_US = (0.4, 0.8, 1.2, 1.6)


def f_gro_at(record: Path, n_tar: int, n_pro: int) -> dict[str, float | None]:
    """f_gro = (N_lar - N_tar) / N_pro at SNAPSHOTS_US from the run's settle checks (the
    last check at or before each time; the settled value after the run's end)."""
    rows = from_checks(read_csv(record / rundir.CHECKS), n_tar, n_pro)
    out = {}
    for t in SNAPSHOTS_US:
        before = [r for r in rows if r["time"] <= t * 1e-6 * (1 + 1e-9)]
        out[f"{t:g}"] = before[-1]["growth_efficiency"] if before else None
    return out


def f_gro_range_before_end(record: Path, n_tar: int, n_pro: int) -> list[float]:
    """[min, max] of f_gro over the run's settle checks in its last CAP_SPAN_US: for a run
    counted at its cap, how far its outcome still moved."""
    rows = from_checks(read_csv(record / rundir.CHECKS), n_tar, n_pro)
    since = rows[-1]["time"] - CAP_SPAN_US * 1e-6
    f = [r["growth_efficiency"] for r in rows if r["time"] >= since]
    return [min(f), max(f)]


def load(records: Path, continued: Path | None = None,
         fixed_tc: float = PAPER_CAP_TC) -> list[dict]:
    """Every kept record's outcome, with its size, question, f_gro at SNAPSHOTS_US and,
    for a run that ended as this study counts it, where its outcome is read
    (``readings.read``: ``continued`` holds the continuations' records, ``fixed_end``'s,
    made to the fixed end ``fixed_tc``)."""
    out = []
    for path in sorted(records.rglob(rundir.OUTCOME)):
        o = json.loads(path.read_text())
        o["n"], o["question"] = question_of(path.parent, records)
        o["f_gro_at_us"] = f_gro_at(path.parent, o["N_tar"], o["N_pro"])
        o["record"] = path.parent
        if o.get("stop_reason") in COUNTED:
            where = path.parent.relative_to(records)
            o["read"] = read(o, path.parent, continued and continued / where, fixed_tc)
        out.append(o)
    return out


def what_the_rest_needs(b2, f) -> dict | None:
    """Where only some of the paper's twelve offsets have run: those still to run, the part
    of eq. (1)'s <f_gro> the others make, and the average f_gro of the rest below which
    <f_gro> is negative (the grazing 12/12 at 0). None off the paper's grid or on all of it."""
    k = [round(12 * b) for b in b2]
    if len(k) == 12 or any(abs(12 * b - j) > 1e-6 for b, j in zip(b2, k)):
        return None
    f_of = dict(zip(k, f))
    grid = protocol.B_OFF2
    part = float(b_off_average(grid, [f_of.get(j, 0.0) for j in range(12)], grazing=0.0))
    weight = float(b_off_average(grid, [float(j not in f_of) for j in range(12)],
                                 grazing=0.0))
    return dict(to_run=[f"{j}/12" for j in range(12) if j not in f_of], part_run=part,
                weight_to_run=weight, rest_must_average_below=-part / weight)


def question_summary(runs: list[dict], twelve: bool) -> dict:
    """One question at one size: f_gro per offset (by seed and seeds averaged), N_con and
    N_cut per offset over N_tot, and where the twelve offsets ran, eq. (1)'s <f_gro> with
    its seed scatter and the diagnostics' eq. (1) means; for a question asked on the
    ``twelve`` offsets while some are still to run, what they must average for <f_gro> < 0."""
    f_gro = lambda o: o["growth_efficiency"]    # noqa: E731
    b2, f = b_off_groups(runs, f_gro)
    n_tot = runs[0]["n_total"]
    per_seed = defaultdict(dict)
    for o in runs:
        per_seed[f"{o['B_off'] ** 2:.4f}"][o["seed"]] = o["growth_efficiency"]
    def per_grain(name):    # NaN for a record without the count, 0 for a collision that missed
        return lambda o: (np.nan if o.get(name) is None else o[name]) / n_tot

    _, con = b_off_groups(runs, per_grain("N_con"))
    _, cut = b_off_groups(runs, per_grain("N_cut"))
    out = dict(runs=len(runs), N_tar=runs[0]["N_tar"], model=model_name(runs[0]),
               B_off2=[float(b) for b in b2], f_gro=[float(x) for x in f],
               f_gro_per_seed=dict(per_seed), N_con_over_N_tot=[float(x) for x in con],
               N_cut_over_N_tot=[float(x) for x in cut],
               paper_grid=protocol.is_paper_grid(b2))
    at = {t: b_off_groups(runs, lambda o: o["f_gro_at_us"][t])[1]
          for t in runs[0]["f_gro_at_us"]
          if all(o["f_gro_at_us"][t] is not None for o in runs)}
    out["f_gro_at_us"] = {t: [float(x) for x in f] for t, f in at.items()}
    if twelve:
        out["sign_open"] = what_the_rest_needs(b2, f)
    out["read"] = read_summary(runs, twelve)
    if out["paper_grid"]:
        out["mean_f_gro"] = seed_scatter(runs, f_gro, protocol.GRAZING["growth_efficiency"])
        # the same runs on the other studies' four offsets, by their quadrature (the last
        # value held to B_off^2 = 1): what the offsets' grid alone moves <f_gro> by
        out["mean_f_gro_four_offsets"] = seed_scatter(
            [o for o in runs if one_of_four(o["B_off"] ** 2)], f_gro)
        out["means"] = mean_diagnostics(runs)
        out["mean_f_gro_at_us"] = {
            t: seed_scatter(runs, lambda o: o["f_gro_at_us"][t],
                            protocol.GRAZING["growth_efficiency"])["mean"] for t in at}
    return out


def read_summary(runs: list[dict], twelve: bool) -> dict:
    """The question's runs as ``readings.read`` reads them: per offset and seed, f_gro, the
    end it is read at and when; f_gro per offset (seeds averaged over the runs read, an
    offset whose every run is open left out); and eq. (1)'s <f_gro> with its seed scatter
    where the twelve offsets are read, else (``twelve``) what the offsets not read yet
    must average for <f_gro> < 0."""
    per_seed = defaultdict(dict)
    for o in runs:
        per_seed[f"{o['B_off'] ** 2:.4f}"][o["seed"]] = o["read"]
    known = [o for o in runs if o["read"]["read_at"] != OPEN]
    out = dict(per_seed=dict(per_seed),
               open=sorted({round(o["B_off"] ** 2, 4) for o in runs} -
                           {round(o["B_off"] ** 2, 4) for o in known}))
    if not known:
        return out
    f_read = lambda o: o["read"]["f_gro"]    # noqa: E731
    b2, f = b_off_groups(known, f_read)
    out.update(B_off2=[float(b) for b in b2], f_gro=[float(x) for x in f])
    if twelve:
        out["sign_open"] = what_the_rest_needs(b2, f)
    if protocol.is_paper_grid(b2):
        out["mean_f_gro"] = seed_scatter(known, f_read, protocol.GRAZING["growth_efficiency"])
    return out


#: the questions whose runs are there for the paper's statements (``statements``), drawn in
#: ``statements_figure`` rather than as offsets in fig_protocol
STATEMENT_QUESTIONS = ("e", "f")
#: the frictional and the frictionless models (MODELS names)
FRICTIONAL = ("frictional", "frictional, T_vis 6 ps")
FRICTIONLESS = ("frictionless", "frictionless, T_vis 6 ps")


#: the runs of ``vfra_size`` (four offsets, the settle rule of their time, shape not
#: watched); c and g ask some of its 2 x 5000 scenes again: the same aggregates, dt and rule
EARLIER = HERE / "vfra_size" / "runs.csv"


def same_scenes_earlier(rows: list[dict], earlier: Path = EARLIER) -> dict:
    """Each run here whose collision ``vfra_size`` ran too (the same model, size, speed,
    offset and seed), with both runs' ends; and per question, size and seed where
    ``vfra_size`` has all four of its offsets, eq. (1)'s trapezoid over them (the last value
    held to 1) of its runs (``earlier``), of this study's where it ran all four (``here``),
    and of its runs with this study's readings where it decided an offset (``read``, those
    offsets in ``read_here``): where a run here ends later than the earlier one, at another
    f_gro, the end of the run moved it (here the rule watches shape unless the campaign
    began without it)."""
    if not earlier.exists():
        return dict(pairs=[], four_offsets={})
    before = {(r["model"], int(r["size"]), r["v_col"], round(r["B_off"], 9), int(r["seed"])): r
              for r in read_csv(earlier)}
    pairs, groups = [], defaultdict(dict)
    for r in rows:
        e = before.get((r["model_name"], r["N_tar"], r["v_col"], round(r["B_off"], 9),
                        r["seed"]))
        if e is None:
            continue
        pairs.append(dict(question=r["question"], N_tar=r["N_tar"], v_col=r["v_col"],
                          B_off2=round(r["B_off"] ** 2, 4), seed=r["seed"],
                          earlier=dict(f_gro=e["growth_efficiency"], stop_step=int(e["stop_step"])),
                          here=dict(f_gro=r["growth_efficiency"], stop_step=r["stop_step"],
                                    read_at=r["read_at"], f_gro_read=r["f_gro_read"])))
        groups[(r["question"], str(cell(r)), r["seed"])][round(r["B_off"] ** 2, 6)] = r
    four, b2s = {}, list(FOUR)
    for (question, size, seed), mine in sorted(groups.items()):
        r = next(iter(mine.values()))
        first = [before.get((r["model_name"], r["N_tar"], r["v_col"], round(float(np.sqrt(b2)), 9),
                             seed))
                 for b2 in b2s]
        if any(e is None for e in first):
            continue
        here = [mine.get(round(b2, 6)) for b2 in b2s]
        decided = [h is not None and h["f_gro_read"] is not None for h in here]
        entry = dict(earlier=float(b_off_average(b2s, [e["growth_efficiency"] for e in first])),
                     read=float(b_off_average(b2s, [h["f_gro_read"] if d else e["growth_efficiency"]
                                                    for h, d, e in zip(here, decided, first)])),
                     read_here=[protocol.twelfths(b2) for b2, d in zip(b2s, decided) if d])
        if all(h is not None for h in here):
            entry["here"] = float(b_off_average(b2s, [h["growth_efficiency"] for h in here]))
        four.setdefault(question, {}).setdefault(size, {})[str(seed)] = entry
    return dict(pairs=pairs, four_offsets=four)


def pick(rows: list[dict], model=None, v=None, b2=None) -> list[dict]:
    """The runs of ``model`` (a MODELS name or several) at ``v`` and ``b2`` (None: any), at
    each speed those of the largest size that ran it."""
    models = (model,) if isinstance(model, str) else model
    sel = [r for r in rows if (model is None or r["model_name"] in models)
           and (v is None or abs(r["v_col"] - v) < 0.05)
           and (b2 is None or abs(r["B_off"] ** 2 - b2) < 1e-6)]
    top = defaultdict(int)
    for r in sel:
        top[r["v_col"]] = max(top[r["v_col"]], r["N_tar"])
    return [r for r in sel if r["N_tar"] == top[r["v_col"]]]


def collided(run: dict) -> bool:
    """Whether the aggregates touched (a grazing offset can miss: nothing dissipated but
    rounding)."""
    return run["E_dis_tot"] > 1e-9


def same_scenes(rows: list[dict], v=None) -> list[tuple[dict, dict]]:
    """(frictionless run, frictional run) pairs of one scene (speed, offset, seed, size),
    each frictionless model against each frictional one."""
    scene = lambda r: (r["v_col"], round(r["B_off"], 6), r["seed"], r["N_tar"])  # noqa: E731
    less = [r for r in pick(rows, FRICTIONLESS, v) if collided(r)]
    more = defaultdict(list)
    for r in rows:
        if r["model_name"] in FRICTIONAL and (v is None or abs(r["v_col"] - v) < 0.05) \
                and collided(r):
            more[scene(r)].append(r)
    return [(a, b) for a in less for b in more[scene(a)]]


def statements(rows: list[dict]) -> list[dict]:
    """The paper's statements of App. C and Sect. 3 that give a number or a sign, each
    against the runs that bear on it (at each speed, the largest size that has them)."""
    def row(paper, runs, measured, holds):
        sizes = sorted({r["N_tar"] for r in runs}, reverse=True)
        return dict(paper=paper, runs=len(runs),
                    size=", ".join(f"2 x {n}" for n in sizes) if runs else None,
                    measured=measured if runs else "not run", holds=holds if runs else None)

    def per_grain(runs, name):
        x = [r[name] / r["n_total"] for r in runs]
        return f"{name} / N_tot {min(x):.2f} to {max(x):.2f}" if runs else None

    def below(runs, name):    # the runs where a count the paper puts above N_tot is not
        low = [r for r in runs if r[name] <= r["n_total"]]
        return "; at or below N_tot at " + ", ".join(
            f"{r['v_col']:g} m/s, B_off^2 {round(12 * r['B_off'] ** 2)}/12 "
            f"(2 x {r['N_tar']}, seed {r['seed']})" for r in low) if low else ""

    def speeds(runs):
        return " at " + ", ".join(f"{v:g}" for v in sorted({r["v_col"] for r in runs})) + \
            " m/s" if runs else ""

    out = []
    for name, fig in (("frictionless", "c"), ("frictionless, T_vis 6 ps", "d")):
        fl = [r for r in pick(rows, name) if collided(r)]
        what = "undamped" if name == "frictionless" else "damped"
        out.append(row(f"frictionless, {what}: N_con > N_tot for 10 <= v_col <= 100 m/s "
                       f"(App. C.2, Fig. C.3{fig})", fl,
                       (per_grain(fl, "N_con") or "") + speeds(fl) + below(fl, "N_con"),
                       all(r["N_con"] > r["n_total"] for r in fl)))
    fl = [r for r in pick(rows, "frictionless") if collided(r)]
    out.append(row("frictionless, undamped: N_cut > N_tot for 10 <= v_col <= 100 m/s "
                   "(App. C.2, Fig. C.4c)", fl,
                   (per_grain(fl, "N_cut") or "") + speeds(fl) + below(fl, "N_cut"),
                   all(r["N_cut"] > r["n_total"] for r in fl)))
    out.append(row("frictionless, undamped: E_dis,c = E_dis,tot (App. C.1, Fig. C.2c)", fl,
                   f"E_dis,c / E_dis,tot {min(r['E_dis_c'] / r['E_dis_tot'] for r in fl):.4f}"
                   if fl else None,
                   all(abs(r["E_dis_c"] / r["E_dis_tot"] - 1) < 1e-9 for r in fl)))
    a = pick(rows, "frictionless", 100.0, 0.0)
    out.append(row("frictionless, undamped, head-on, 100 m/s: f_gro about -1 (App. C.1, "
                   "Fig. B.1c)", a,
                   ", ".join(f"{r['growth_efficiency']:+.3f}" for r in a),
                   all(r["growth_efficiency"] < -0.5 for r in a)))
    out.append(row("frictionless, undamped, head-on, 100 m/s: E_dis,tot significantly below "
                   "E_imp (App. C.1, Fig. C.1c)", a,
                   "E_dis,tot / E_imp " + ", ".join(f"{r['E_dis_tot']:.3f}" for r in a),
                   all(r["E_dis_tot"] < 0.5 for r in a)))
    h = pick(rows, FRICTIONAL + FRICTIONLESS[1:], 100.0, 0.0)
    out.append(row("frictional, damped frictional and damped frictionless, head-on, 100 m/s: "
                   "f_gro about 1 with E_dis,tot about E_imp (App. C.1)", h,
                   "; ".join(f"{r['model_name']} (seed {r['seed']}): f_gro "
                             f"{r['growth_efficiency']:+.3f}, E_dis,tot {r['E_dis_tot']:.3f}"
                             for r in h),
                   all(r["growth_efficiency"] > 0.5 and r["E_dis_tot"] > 0.8 for r in h)))
    fr = [r for r in pick(rows, FRICTIONAL) if collided(r)]
    out.append(row("frictional models: E_dis,c / E_dis,tot << 1 (App. C.1)", fr,
                   (f"E_dis,c / E_dis,tot {min(r['E_dis_c'] / r['E_dis_tot'] for r in fr):.3f}"
                    f" to {max(r['E_dis_c'] / r['E_dis_tot'] for r in fr):.3f}" + speeds(fr))
                   if fr else None,
                   all(r["E_dis_c"] / r["E_dis_tot"] < 0.1 for r in fr)))
    pairs = same_scenes(rows)
    out.append(row("E_dis,c of the frictionless models above that of the frictional models "
                   "for 10 <= v_col <= 100 m/s (App. C.1, Fig. C.2)", [a for a, _ in pairs],
                   f"frictionless less frictional E_dis,c on the same scene "
                   f"{min(a['E_dis_c'] - b['E_dis_c'] for a, b in pairs):+.3f} E_imp at "
                   f"least, {len(pairs)} pairs" + speeds([a for a, _ in pairs])
                   if pairs else None,
                   all(a["E_dis_c"] > b["E_dis_c"] for a, b in pairs)))
    pairs = same_scenes(rows, 10.0)
    out.append(row("at about 10 m/s, E_dis,tot of the frictionless models above that of the "
                   "frictional models (App. C.1, Fig. C.1)", [a for a, _ in pairs],
                   f"frictionless less frictional E_dis,tot on the same scene "
                   f"{min(a['E_dis_tot'] - b['E_dis_tot'] for a, b in pairs):+.3f} to "
                   f"{max(a['E_dis_tot'] - b['E_dis_tot'] for a, b in pairs):+.3f} E_imp, "
                   f"{len(pairs)} pairs" if pairs else None,
                   all(a["E_dis_tot"] > b["E_dis_tot"] for a, b in pairs)))
    slow = [r for r in pick(rows, FRICTIONAL, 10.0) if collided(r)]
    out.append(row("frictional models at about 10 m/s: N_con < N_tot (App. C.2, Figs. C.3a, "
                   "b)", slow, per_grain(slow, "N_con"),
                   all(r["N_con"] < r["n_total"] for r in slow)))
    slow = [r for r in pick(rows, FRICTIONAL + FRICTIONLESS[1:], 10.0) if collided(r)]
    out.append(row("all but the undamped frictionless model at about 10 m/s: N_cut "
                   "significantly below N_tot (App. C.2, Figs. C.4a, b, d)", slow,
                   per_grain(slow, "N_cut"),
                   all(r["N_cut"] < 0.5 * r["n_total"] for r in slow)))
    return out


def statements_figure(rows: list[dict], results: Path) -> list[Path]:
    """The runs of the paper's statements as its Figs. C.1-C.4 show them: at 10 m/s, N_con
    and N_cut over N_tot against B_off^2, each model; head-on at 100 m/s, f_gro and
    E_dis,tot / E_imp of each model (the four, at the size all of them ran)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(10.5, 4.2))
    colors = {name: f"C{j}" for j, name in enumerate(MODELS)}
    slow = pick(rows, None, 10.0)
    for name in MODELS:
        runs = sorted((r for r in slow if r["model_name"] == name and collided(r)),
                      key=lambda r: r["B_off"])
        if not runs:
            continue
        b2 = [r["B_off"] ** 2 for r in runs]
        left.plot(b2, [r["N_con"] / r["n_total"] for r in runs], "o-", color=colors[name],
                  label=f"{name}: N_con")
        left.plot(b2, [r["N_cut"] / r["n_total"] for r in runs], "s--", color=colors[name],
                  mfc="none", label=f"{name}: N_cut")
    left.axhline(1, color="0.5", lw=0.8)
    left.text(0.0, 1.0, " N_tot", fontsize=7, va="bottom", color="0.4")
    left.set_yscale("symlog", linthresh=0.1)      # a collision that cut nothing shows
    left.set_xlabel("B_off^2")
    left.set_ylabel("contacts made (N_con), cut (N_cut) / N_tot")
    sizes = sorted({r["N_tar"] for r in slow})
    left.set_ylim(bottom=0)
    left.set_title("10 m/s" + (f", 2 x {sizes[0]}" if len(sizes) == 1 else "")
                   + "; paper: N_con < N_tot for the frictional models,\nN_cut << N_tot "
                   "for all but the undamped frictionless", fontsize=8)
    left.legend(fontsize=6, ncol=2)
    fast = [r for r in rows if abs(r["v_col"] - 100.0) < 0.05 and r["B_off"] == 0.0]
    common = [n for n in sorted({r["N_tar"] for r in fast}, reverse=True)
              if {r["model_name"] for r in fast if r["N_tar"] == n} >= set(MODELS)]
    n = common[0] if common else max((r["N_tar"] for r in fast), default=None)
    for j, name in enumerate(MODELS):
        runs = [r for r in fast if r["model_name"] == name and r["N_tar"] == n]
        for k, (key, marker) in enumerate((("growth_efficiency", "o"), ("E_dis_tot", "D"))):
            right.plot([j + 0.15 * (2 * k - 1)] * len(runs), [r[key] for r in runs], marker,
                       color=colors[name], mfc="none" if k else colors[name], ms=7)
    right.axhline(0, color="0.8", lw=0.8)
    right.set_xticks(range(len(MODELS)), [m.replace(", ", ",\n") for m in MODELS], fontsize=7)
    right.set_ylim(-1.1, 1.1)
    right.set_ylabel("filled circles: f_gro; open diamonds: E_dis,tot / E_imp")
    right.set_title(f"head-on, 100 m/s, 2 x {n} (each seed); paper: f_gro about 1 and "
                    "E_dis,tot about E_imp,\nbut f_gro about -1, E_dis,tot << E_imp for the "
                    "undamped frictionless", fontsize=8)
    fig.tight_layout()
    return save(fig, results, "fig_statements")


def figure(summary: dict, results: Path) -> list[Path]:
    """Per question and size: f_gro per B_off^2 (each seed, and seeds averaged) over
    N_con / N_tot and N_cut / N_tot."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cells = [(k, s) for k, by in summary.items() if k not in STATEMENT_QUESTIONS for s in by]
    fig, axes = plt.subplots(2, len(cells), figsize=(3.6 * len(cells), 5.6), squeeze=False,
                             sharex="col")
    for col, (k, size) in enumerate(cells):
        s, q = summary[k][size], QUESTIONS[k]
        ax = axes[0, col]
        for b, by_seed in s["f_gro_per_seed"].items():
            ax.plot([float(b)] * len(by_seed), list(by_seed.values()), "o", color="0.6", ms=4)
        ax.plot(s["B_off2"], s["f_gro"], "k-o", ms=4, label="seeds averaged, where they ended")
        r = s["read"]
        if r.get("B_off2") and r["f_gro"] != [f for b, f in zip(s["B_off2"], s["f_gro"])
                                              if b in r["B_off2"]]:
            ax.plot(r["B_off2"], r["f_gro"], "s", color="C3", mfc="none", ms=7,
                    label="read where decided (readings.py)")
            if r.get("mean_f_gro"):
                ax.axhline(r["mean_f_gro"]["mean"], color="C3", ls=":",
                           label=f"<f_gro> so read {r['mean_f_gro']['mean']:+.3f}")
            for b in r["open"]:
                ax.annotate("open", (b, -0.95), fontsize=6, ha="center", color="C3")
            need = r.get("sign_open")
            if need:
                ax.annotate(f"so read, <f_gro> < 0 needs {', '.join(need['to_run'])}\n"
                            f"to {'average' if len(need['to_run']) > 1 else 'read'} below "
                            f"{need['rest_must_average_below']:+.3f}",
                            (0.98, 0.4), fontsize=6, ha="right", color="C3")
        if s.get("mean_f_gro"):
            ax.plot([1.0], [protocol.GRAZING["growth_efficiency"]], "o", mfc="none",
                    color="k", ms=5, label="12/12 grazes: taken as 0")
            m = s["mean_f_gro"]
            scatter = f" +- {m['se']:.3f}" if np.isfinite(m["se"]) else ", one seed"
            ax.axhline(m["mean"], color="k", ls="--",
                       label=f"<f_gro> (eq. 1) where they ended {m['mean']:+.3f}{scatter}")
        ax.axhline(0, color="0.8", lw=0.8)
        ax.set_ylim(-1.05, 1.05)
        ax.set_xlim(-0.03, 1.03)
        ax.set_xticks([k / 12 for k in range(0, 13, 3)], ["0", "3/12", "6/12", "9/12", "1"])
        ax.set_title(f"{k}: {s['model']}, {q['v_col']:g} m/s, 2 x {s['N_tar']}\npaper: "
                     f"{q['paper'].split(' (')[0]}", fontsize=8)
        ax.legend(fontsize=7)
        ax = axes[1, col]
        ax.plot(s["B_off2"], s["N_con_over_N_tot"], "o-", ms=4, label="N_con / N_tot")
        ax.plot(s["B_off2"], s["N_cut_over_N_tot"], "s--", ms=4, label="N_cut / N_tot")
        ax.axhline(1, color="0.8", lw=0.8)
        ax.set_xlabel("B_off^2")
        ax.legend(fontsize=7)
    axes[0, 0].set_ylabel("f_gro (grey: one seed)")
    axes[1, 0].set_ylabel("contacts made, cut / N_tot")
    fig.tight_layout()
    return save(fig, results, "fig_protocol")


def listed(o: dict) -> dict:
    """What a record holds, for the lists of records not settled: its question, size,
    B_off^2, seed, how it ended, when, and f_gro there and at the paper's snapshots."""
    return dict(question=o["question"], N_tar=o["N_tar"], B_off2=round(o["B_off"] ** 2, 4),
                seed=o.get("seed"), stop_reason=o.get("stop_reason"),
                time_end_over_tc=o.get("time_end_over_tc"),
                growth_efficiency=o.get("growth_efficiency"),
                f_gro_at_us=o["f_gro_at_us"], problem=o.get("problem"))


def ended_at_cap(outcomes: list[dict]) -> list[dict]:
    """The records averaged at their cap, each with the range of its f_gro over its last
    CAP_SPAN_US, so that how far a capped outcome still moved is seen."""
    return [dict(listed(o), f_gro_last_span=f_gro_range_before_end(
                 o["record"], o["N_tar"], o["N_pro"]), span_us=CAP_SPAN_US)
            for o in outcomes if o.get("stop_reason") == "cap"]


def left_out(outcomes: list[dict]) -> list[dict]:
    """The records not averaged (a run that failed or is cut off), so that leaving each
    out is seen."""
    return [listed(o) for o in outcomes if o.get("stop_reason") not in COUNTED]


def cell(outcome: dict):
    """Where a run goes in its question's summary: by its size (N per aggregate), and for a
    question of several models, by "N, model" as well."""
    if len(models_of(outcome["question"])) == 1:
        return outcome["N_tar"]
    return f"{outcome['N_tar']}, {model_name(outcome)}"


def summarise(records: Path, results: Path, plot: bool = True,
              continued: Path | None = None, fixed_tc: float = PAPER_CAP_TC) -> dict:
    loaded = load(records, continued, fixed_tc)
    outcomes = [o for o in loaded if o.get("stop_reason") in COUNTED]
    rows = []
    for o in outcomes:
        r = scalars(o)
        r.update(time_end_over_tc=o.get("time_end_over_tc"),
                 **{f"f_gro_at_{t}_us": f for t, f in o["f_gro_at_us"].items()})
        r.update(question=o["question"], model_name=model_name(o), read_at=o["read"]["read_at"],
                 f_gro_read=o["read"]["f_gro"], read_time_us=o["read"]["time_us"])
        rows.append(r)
    write_csv(results / "runs.csv", [{k: v for k, v in r.items() if k != "run"} for r in rows])
    by = defaultdict(lambda: defaultdict(list))
    for o in outcomes:
        by[o["question"]][cell(o)].append(o)
    order = {name: j for j, name in enumerate(MODELS)}
    summary = {k: {c: question_summary(runs, len(QUESTIONS[k]["b_off2"]) == 12)
                   for c, runs in sorted(by[k].items(), key=lambda item: (
                       item[1][0]["N_tar"], order[model_name(item[1][0])]))}
               for k in QUESTIONS if k in by}
    done = dict(study="paper_protocol", protocol="the paper's offsets B_off^2 = k/12 "
                "(k = 0 ... 11, 12/12 grazing taken as f_gro 0) for b and d; one offset for "
                "a and c", questions={k: dict(QUESTIONS[k], b_off2=[round(b, 4) for b in
                                                                     QUESTIONS[k]["b_off2"]])
                                      for k in QUESTIONS},
                records=str(records.relative_to(results)) if records.is_relative_to(results)
                else str(records),
                results=dict(by_question=summary, statements=statements(rows),
                             same_scenes_in_vfra_size=same_scenes_earlier(rows)),
                ended_at_cap=ended_at_cap(outcomes), left_out=left_out(loaded))
    if plot and summary:
        done["figures"] = [p.name for p in figure(summary, results)]
        if any(k in summary for k in STATEMENT_QUESTIONS):
            done["figures"] += [p.name for p in statements_figure(rows, results)]
    return done


def table(by_question: dict) -> list[str]:
    """The paper's Fig. B.1 as lines, per question and size: f_gro of each offset and seed,
    N_con and N_cut over N_tot; then <f_gro> of eq. (1), or what the offsets still to run
    must average for it to be negative."""
    lines = []
    for k, sizes in by_question.items():
        q = QUESTIONS[k]
        for size, s in sizes.items():
            lines.append(f"{k}: {s['model']}, {q['v_col']:g} m/s, 2 x {s['N_tar']}; paper: "
                         f"{q['paper']}")
            lines.append("  B_off^2  f_gro by seed           N_con/N_tot  N_cut/N_tot")
            for b, con, cut in zip(s["B_off2"], s["N_con_over_N_tot"], s["N_cut_over_N_tot"]):
                seeds = s["f_gro_per_seed"][f"{b:.4f}"]
                f = "  ".join(f"{v:+.3f} ({seed})" for seed, v in sorted(seeds.items()))
                lines.append(f"  {protocol.twelfths(b, 1e-3) or f'{b:.4f}':7s}  {f:22s} "
                             f"{con:11.2f}  {cut:11.2f}")
            lines += mean_lines(s, "where each run ended")
            r = s["read"]
            if any(x["read_at"] != "settle end" for seeds in r["per_seed"].values()
                   for x in seeds.values()):
                lines.append("  read where its outcome is decided (readings.py):")
                for b, seeds in sorted(r["per_seed"].items()):
                    f = "  ".join(("open" if x["f_gro"] is None else f"{x['f_gro']:+.3f}")
                                  + f" ({seed}: {x['read_at']}, {x['time_us']:.2f} us)"
                                  for seed, x in sorted(seeds.items()))
                    lines.append(f"  {protocol.twelfths(float(b), 1e-3) or b:7s}  {f}")
                lines += mean_lines(r, "so read")
    return lines


def mean_lines(s: dict, how: str) -> list[str]:
    """eq. (1)'s <f_gro> of a summary (``question_summary`` or its ``read``), or what the
    offsets still to run or read must average for it to be negative."""
    if s.get("mean_f_gro"):
        m = s["mean_f_gro"]
        return [f"  <f_gro> (eq. 1), {how}: {m['mean']:+.3f} +- {m['se']:.3f}"]
    if s.get("sign_open"):
        o = s["sign_open"]
        return [f"  {how}: {' '.join(o['to_run'])} to come; <f_gro> < 0 needs them to "
                f"average below {o['rest_must_average_below']:+.3f}"]
    return []


def main(argv=None) -> int:
    p = campaign_study_parser(__doc__)
    p.add_argument("--stage", choices=sorted(STAGES), default="place")
    p.add_argument("--questions", nargs="+", choices=sorted(QUESTIONS), default=None)
    p.add_argument("--summary-only", action="store_true",
                   help="run nothing: the results from the records kept so far")
    p.add_argument("--again", type=int, nargs="+", default=(), metavar="K",
                   help="run the offsets B_off^2 = K/12 again though their records are kept "
                        "(for fixed_end, which continues a run from its run directory)")
    p.add_argument("--continued", type=Path, default=None,
                   help="the records of the runs' continuations, where each run is read "
                        "(default: fixed_end's, validation/fixed_end[_quick]/records, "
                        "unless --results is given)")
    args = p.parse_args(argv)
    runs, results = study_paths(args, "paper_protocol")
    records = results / "records"
    continued = args.continued or (None if args.results else
                                   HERE / ("fixed_end" + "_quick" * args.quick) / "records")
    stage = QUICK if args.quick else STAGES[args.stage]
    if not args.summary_only:
        for k in args.questions or list(QUESTIONS):
            run_question(k, stage, runs, args.np, tuple(args.again))
    done = summarise(records, results, continued=continued,
                     fixed_tc=QUICK_CAP_TC if args.quick else PAPER_CAP_TC)
    print("\n".join(table(done["results"]["by_question"])))
    for o in done["ended_at_cap"]:
        low, high = o["f_gro_last_span"]
        print(f"averaged at its cap: {o['question']} 2 x {o['N_tar']} B_off^2 {o['B_off2']} "
              f"seed {o['seed']}, f_gro {o['growth_efficiency']:+.3f} at "
              f"{o['time_end_over_tc']:.0f} t_c ({low:+.3f} to {high:+.3f} over the last "
              f"{o['span_us']:g} us)")
    for o in done["left_out"]:
        print(f"left out of the averages: {o['question']} 2 x {o['N_tar']} B_off^2 "
              f"{o['B_off2']} seed {o['seed']}, {o['stop_reason']}, f_gro "
              f"{o['growth_efficiency']} (at 1.6 us {o['f_gro_at_us'].get('1.6')})")
    return write_summary(results, done)


if __name__ == "__main__":
    sys.exit(main())
