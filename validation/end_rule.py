"""Could a paper-size collision stop earlier than the settle rule ends it? (issue 46)

    python validation/end_rule.py [--records validation/paper_protocol/records] [RUN_DIR ...]

A candidate end rule stops a run at the first settle check where the largest fragment
N_lar and the number of fragments have each varied by at most ``c`` N_tot over the last
``W`` checks: the settle rule's counts without its bonded contacts and dissipation (W = 5,
c = 1e-4 is that part of the rule every run here used). For each committed
2 x 50000 record (its checks.csv) and each (W, c), it gives the time the rule would have
stopped and f_gro there against f_gro at the run's real end. It does the same for a lower
cap (the paper stage's, ``paper_protocol.PAPER_CAP_TC``): a run stops at the first check
at or after it. The issue allows such a rule for its campaigns only if it moves no
committed paper-size f_gro by more than 0.02.

And a rule that stops later: the settle rule's counts and contacts (its dissipation is
not in the checks) with, as well, "not while the largest fragment, of at least a quarter
of the grains, grows in r_g by more than the tolerance over the window" (``stretching``
of the analysis, the warning's own test), replayed on every run that ``fixed_end``
continued to 16000 t_c (its record's checks and the continuation's), against f_gro at
that fixed end: whether watching shape gives the fixed end's outcome, and how much sooner.

The other way round, it lists every committed record (of every study that keeps them)
that the settle rule ended while the largest fragment's gyration radius r_g was still
growing by more than the rule's own tolerance (1 %) over its last window: a body being
pulled apart by a neck, which the rule does not watch (``fixed_end``), per study and
size. Reads the records only; writes validation/paper_protocol/end_rule.json.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

from jkrdt import rundir
from jkrdt.analysis.outcome import from_checks, stretching as stretching_at
from jkrdt.analysis.tables import read_csv
from jkrdt.stopping import SettleRule
from paper_protocol import PAPER_CAP_TC
from readings import ANEW, continued_run

HERE = Path(__file__).resolve().parent
#: the rules tried: (W checks, c of N_tot); (5, 1e-4) is the settle rule's own counts
RULES = [(5, 1e-4), (5, 2e-4), (10, 1e-3), (20, 1e-3)]
ALLOWED = 0.02


def series(run: Path) -> tuple[list[float], list[int], list[int], dict]:
    """Time (s), N_lar and the number of fragments at every settle check (``from_checks``:
    a step written twice counts once), and the run's collision.json with its t_c (s)."""
    meta = rundir.read_metadata(run)
    meta["t_c"] = rundir.from_metadata(meta).scales.t_c
    rows = from_checks(read_csv(run / rundir.CHECKS), meta["N_tar"], meta["N_pro"])
    return ([r["time"] for r in rows], [r["n_largest"] for r in rows],
            [r["n_fragments"] for r in rows], meta)


def capped(runs: list[Path], cap_tc: float) -> dict:
    """Each run stopped at the first check at or after ``cap_tc`` (its end if sooner)."""
    rule = dict(cap_tc=cap_tc, runs=[])
    for run in runs:
        t, n_lar, _, meta = series(run)
        k = next((i for i, x in enumerate(t) if x >= cap_tc * meta["t_c"] * (1 - 1e-9)),
                 len(t) - 1)
        f = [(n - meta["N_tar"]) / meta["N_pro"] for n in n_lar]
        rule["runs"].append(dict(run=named(run), B_off=meta["B_off"], end_ns=t[-1] * 1e9,
                                 end_tc=t[-1] / meta["t_c"], f_gro_end=f[-1],
                                 stop_ns=t[k] * 1e9, f_gro_stop=f[k]))
    rule["largest_move"] = max(abs(r["f_gro_stop"] - r["f_gro_end"]) for r in rule["runs"])
    rule["allowed"] = rule["largest_move"] <= ALLOWED
    print(f"a cap at {cap_tc:g} t_c: largest move of f_gro {rule['largest_move']:.3f} "
          f"({'allowed' if rule['allowed'] else 'refused'})")
    for r in rule["runs"]:
        print(f"  B_off^2 {r['B_off'] ** 2:.4f}: stops at {r['stop_ns']:.0f} ns with "
              f"{r['f_gro_stop']:+.3f}; the run ended at {r['end_ns']:.0f} ns "
              f"({r['end_tc']:.0f} t_c) with {r['f_gro_end']:+.3f}")
    return rule


def stretching(records: list[Path], rule: SettleRule = SettleRule()) -> dict:
    """Per campaign of each folder of ``records`` (a paper_protocol question and size
    with all its offsets): how many settled runs there are, and each whose largest
    fragment's r_g grew by more than ``rule.tolerance`` over the rule's last window
    (``rule.window`` checks) when the rule ended it."""
    out = {}
    for checks in sorted(c for top in records for c in top.glob("**/checks.csv")):
        o = rundir.read_outcome(checks.parent)     # None: a continuation's checks alone
        if o is None or o.get("stop_reason") != "settled":
            continue
        shape = stretching_at(from_checks(read_csv(checks), o["N_tar"], o["N_pro"]),
                              rule.window, rule.tolerance)
        grew = shape["r_g_growth"] if shape else 0.0    # 0: a largest of one grain
        campaign = re.sub(r"_b2_[0-9.]+$", "", named(checks.parent).split("/v")[0])
        folder = out.setdefault(campaign, dict(settled=0, stretching=[]))
        folder["settled"] += 1
        if grew > rule.tolerance:
            folder["stretching"].append(dict(
                run=named(checks.parent), B_off2=round(o["B_off"] ** 2, 4), seed=o["seed"],
                model=o["model"], f_gro=o["growth_efficiency"], n_largest=o["n_largest"],
                r_g_growth=grew))
    print(f"settled runs whose largest fragment's r_g grew by more than "
          f"{100 * rule.tolerance:g} % over the rule's last window:")
    for folder, v in out.items():
        print(f"  {folder}: {len(v['stretching'])} of {v['settled']}" + "".join(
            f"\n    B_off^2 {r['B_off2']:.4f} seed {r['seed']}: f_gro {r['f_gro']:+.3f}, "
            f"N_lar {r['n_largest']}, r_g {100 * r['r_g_growth']:+.1f} %"
            for r in v["stretching"]))
    return out


#: the runs fixed_end continued: (its records of the continuations, the records continued)
CONTINUED = [(HERE / "fixed_end" / "records", HERE / "paper_protocol" / "records"),
             (HERE / "fixed_end" / "size_trend" / "records", HERE / "size_trend" / "records")]


def settle_replay(rows: list[dict], rule: SettleRule, shape: bool) -> int | None:
    """The first check (index into ``rows``, ``from_checks`` with each row's ``contacts``)
    at which ``rule``'s counts and contacts have held over its window, and with ``shape``
    the largest fragment is not being stretched (``stretching_at``); None: never."""
    allowed = int(rule.counts * rows[0]["n_total"])
    for k in range(rule.window, len(rows)):
        span = rows[k - rule.window:k + 1]
        ranges = [max(r[key] for r in span) - min(r[key] for r in span)
                  for key in ("n_largest", "n_fragments", "contacts")]
        if ranges[0] > allowed or ranges[1] > allowed or \
                ranges[2] > rule.tolerance * max(r["contacts"] for r in span):
            continue
        if shape and (stretching_at(rows[:k + 1], rule.window, rule.tolerance) or {}).get(
                "stretching"):
            continue
        return k
    return None


def watched_shape(rule: SettleRule = SettleRule()) -> dict:
    """Each continued run's f_gro where the settle rule's counts and contacts would have
    ended it, and where they would have with its shape watched too, against f_gro at the
    fixed end (its last check): the largest move of each, and whether watching shape
    keeps every one within ALLOWED."""
    runs = []
    for kept, records in CONTINUED:
        for more in sorted(kept.rglob(rundir.CHECKS)):
            if more.parent.name == ANEW:     # the run made anew inside a continuation's
                continue
            record = records / more.parent.relative_to(kept)
            first = read_csv(continued_run(record, more.parent) / rundir.CHECKS)
            meta = rundir.read_metadata(record)
            t_c = rundir.from_metadata(meta).scales.t_c
            raw = first + read_csv(more)
            contacts = {int(r["step"]): int(r["contacts"]) for r in raw}    # last written
            rows = from_checks(raw, meta["N_tar"], meta["N_pro"])
            for r in rows:
                r["contacts"] = contacts[r["step"]]
            end = next(k for k, r in enumerate(rows)
                       if r["step"] == int(first[-1]["step"]))
            run = dict(run=named(record), N_tar=meta["N_tar"], B_off2=round(meta["B_off"] ** 2, 4),
                       seed=meta["seed"], settle_end_us=rows[end]["time"] * 1e6,
                       f_gro_settle_end=rows[end]["growth_efficiency"],
                       fixed_end_us=rows[-1]["time"] * 1e6,
                       f_gro_fixed_end=rows[-1]["growth_efficiency"])
            for name, shape in (("counts", False), ("shape", True)):
                k = settle_replay(rows, rule, shape)
                run[f"{name}_stop_us"] = None if k is None else rows[k]["time"] * 1e6
                run[f"{name}_stop_tc"] = None if k is None else rows[k]["time"] / t_c
                run[f"f_gro_{name}"] = None if k is None else rows[k]["growth_efficiency"]
            runs.append(run)
    out = dict(runs=runs)
    for name in ("counts", "shape"):
        moved = [abs(r[f"f_gro_{name}"] - r["f_gro_fixed_end"]) for r in runs
                 if r[f"f_gro_{name}"] is not None]
        out[f"largest_move_{name}"] = max(moved) if moved else None
        out[f"all_stop_{name}"] = all(r[f"f_gro_{name}"] is not None for r in runs)
    out["allowed"] = bool(out["all_stop_shape"] and out["largest_move_shape"] <= ALLOWED)
    print(f"the settle rule's counts and contacts, with and without shape watched, on the "
          f"{len(runs)} runs continued to the fixed end (f_gro there):")
    for r in runs:
        print(f"  {r['run']}: settle end {r['settle_end_us']:.2f} us {r['f_gro_settle_end']:+.3f};"
              f" counts {r['counts_stop_us']:.2f} us {r['f_gro_counts']:+.3f}; shape "
              f"{r['shape_stop_us']:.2f} us {r['f_gro_shape']:+.3f}; fixed end "
              f"{r['fixed_end_us']:.2f} us {r['f_gro_fixed_end']:+.3f}")
    print(f"  largest move against the fixed end: counts {out['largest_move_counts']:.3f}, "
          f"shape {out['largest_move_shape']:.3f} "
          f"({'allowed' if out['allowed'] else 'refused'})")
    return out


def named(run: Path) -> str:
    return str(run.relative_to(HERE.parent) if run.is_relative_to(HERE.parent) else run)


def first_stop(counts: list[list[int]], window: int, fraction: float, n_total: int):
    """The first check at which every one of ``counts`` has varied by at most
    ``fraction`` n_total over the last ``window`` checks, or None."""
    for k in range(window, len(counts[0])):
        if all(max(c[k - window:k + 1]) - min(c[k - window:k + 1]) <= fraction * n_total
               for c in counts):
            return k
    return None


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("runs", nargs="*", type=Path, help="more run directories (running ones too)")
    p.add_argument("--records", type=Path, default=HERE / "paper_protocol" / "records")
    args = p.parse_args(argv)
    runs = sorted(r.parent for r in args.records.glob("n50000_*/v*/*/seed*/checks.csv"))
    runs += args.runs
    out = dict(allowed=ALLOWED, rules=[])
    for window, fraction in RULES:
        rule = dict(window=window, fraction=fraction, runs=[])
        for run in runs:
            t, n_lar, n_frag, meta = series(run)
            n_tar, n_pro = meta["N_tar"], meta["N_pro"]
            final = (n_lar[-1] - n_tar) / n_pro
            k = first_stop([n_lar, n_frag], window, fraction, n_tar + n_pro)
            rule["runs"].append(dict(
                run=named(run), B_off=meta["B_off"], end_ns=t[-1] * 1e9, f_gro_end=final,
                stop_ns=None if k is None else t[k] * 1e9,
                f_gro_stop=None if k is None else (n_lar[k] - n_tar) / n_pro))
        moved = [abs(r["f_gro_stop"] - r["f_gro_end"]) for r in rule["runs"]
                 if r["f_gro_stop"] is not None]
        rule["largest_move"] = max(moved) if moved else None
        rule["allowed"] = bool(moved) and max(moved) <= ALLOWED
        out["rules"].append(rule)
        print(f"W = {window}, c = {fraction:g}: largest move of f_gro "
              f"{rule['largest_move']:.3f} ({'allowed' if rule['allowed'] else 'refused'})")
        for r in rule["runs"]:
            stop = "never" if r["stop_ns"] is None else \
                f"{r['stop_ns']:.0f} ns, f_gro {r['f_gro_stop']:+.3f}"
            print(f"  B_off^2 {r['B_off'] ** 2:.4f}: stops {stop}; the run ended at "
                  f"{r['end_ns']:.0f} ns with {r['f_gro_end']:+.3f}")
    out["caps"] = [capped(runs, PAPER_CAP_TC)]
    path = HERE / "paper_protocol" / "end_rule.json"
    if path.exists():
        keep_gone_rows(out, json.loads(path.read_text()))
    out["stretching_at_end"] = stretching(sorted(HERE.glob("*/records")))
    out["shape_watched"] = watched_shape()
    path.write_text(json.dumps(out, indent=1) + "\n")
    return 0


def keep_gone_rows(out: dict, before: dict) -> None:
    """Rows of the earlier end_rule.json for run directories that are gone (a running run
    given on the command line, lost with its machine: 9/12 at 3.9 us) are kept, so that a
    later call loses no measurement; each rule's largest move is taken over all its rows."""
    for now, then in zip(out["rules"] + out["caps"], before.get("rules", []) +
                         before.get("caps", [])):
        names = {r["run"] for r in now["runs"]}
        now["runs"] += [r for r in then["runs"] if r["run"] not in names
                        and not (HERE.parent / r["run"]).exists()]
        key = ("f_gro_stop", "f_gro_end")
        moved = [abs(r[key[0]] - r[key[1]]) for r in now["runs"] if r[key[0]] is not None]
        now["largest_move"] = max(moved) if moved else None
        now["allowed"] = bool(moved) and max(moved) <= ALLOWED


if __name__ == "__main__":
    sys.exit(main())
