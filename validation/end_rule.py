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
    out["stretching_at_end"] = stretching(sorted(HERE.glob("*/records")))
    (HERE / "paper_protocol" / "end_rule.json").write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
