"""Cost, memory and output of a shattering collision as its fragments fly, before and
after bins that grow with the box; and how evenly the ranks share it.

Part 1, side by side: two worker processes (one rank each) run the same scene one check
interval (50 t_c) at a time, taking turns (A B A B ...), so both see the same load.
"before" is the scene's deck as it was: LAMMPS's bins, which tile the whole box
(``bins box``), and no load balancing; "after" is the deck's default (``bins bounded``,
``balance rcb``). Both depart fragments and write the deck's full record. Per chunk: us
per atom-step, box, resident memory, the run directory's size.

Part 2, the ranks: the deck on 2, 4 and 8 ranks, balancing (its default, rcb) and not
(``balance no``), over the first ``--balance-tc`` t_c (more ranks than cores is fine: the
numbers are counts, not times), one check interval per run command; per chunk, the
imbalance LAMMPS reports (the largest rank's grains over the mean, from the run's
"Nlocal" line) and fix balance's own weighted factor before its last rebalance.

    ./run bench-scale                               # 2 x 2500 and 2 x 25000
    ./run bench-scale --sizes 2500 --until-tc 1000  # shorter
    ./run bench-scale --quick                       # 2 x 300, 200 t_c (a look, not a result)

Writes JSON (default benchmarks/scale/scale.json): per size and variant the series and its
verdict (largest cost and memory against the first chunk's, the output's size), per rank
count the imbalance series and its largest value, the load average.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from side_by_side import alternate

HERE = Path(__file__).resolve().parent
BIN = Path(sys.executable).parent
# both write the deck's full record (its size is measured)
VARIANTS = {"before": dict(bins="box", balance="no", outputs="yes"),
            "after": dict(outputs="yes")}


# a check interval per run command, so that LAMMPS reports the ranks' grains after each
BALANCE_DECK = """variable run index no
include in.collision.lmp
variable k loop {chunks}
label chunk
run ${{every}} pre no post yes
if "${{balance}} != no" then 'print "jkrdt-bench balance $(step) $(f_balance) $(f_balance[3])"'
if "${{balance}} == no" then 'print "jkrdt-bench balance $(step) 0 0"'
next k
jump SELF chunk
"""


def imbalance(scene: Path, ranks: int, balance_tc: float, balance: str = "rcb") -> dict:
    from jkrdt import rundir
    from jkrdt.stopping import DEFAULT_RULE

    sc = rundir.read(scene)
    variables = dict(DEFAULT_RULE.deck_variables(sc.time_step(None)[0]), balance=balance)
    every = int(variables["every"])
    chunks = max(1, round(balance_tc / DEFAULT_RULE.check_tc))
    deck = scene / "in.bench_balance"
    deck.write_text(BALANCE_DECK.format(chunks=chunks))
    args = [str(BIN / "mpirun"), "-np", str(ranks), str(BIN / "lmp"), "-in", deck.name,
            "-log", f"log.balance{ranks}{balance}", "-screen", "none", "-var", "outputs", "no"]
    for name, value in variables.items():
        args += ["-var", name, str(value)]
    # ranks that sleep while they wait: MPICH's polling would otherwise make more ranks
    # than cores ~40x slower (8 ranks on 2 cores: 20 s against 0.5 s for 714 steps)
    env = dict(os.environ, MPIR_CVAR_CH4_PROGRESS_THROTTLE="true",
               MPIR_CVAR_CH4_PROGRESS_THROTTLE_NO_PROGRESS_COUNT="1")
    start = time.perf_counter()
    subprocess.run(args, cwd=scene, check=True, env=env)
    wall = time.perf_counter() - start
    log = (scene / f"log.balance{ranks}{balance}").read_text()
    nlocal = [(float(ave), float(mx)) for ave, mx in
              re.findall(r"^Nlocal:\s+(\S+) ave\s+(\S+) max", log, re.M)]
    fix = [tuple(map(float, m)) for m in
           re.findall(r"^jkrdt-bench balance (\S+) (\S+) (\S+)", log, re.M)]
    rows = [dict(t_tc=(k + 1) * DEFAULT_RULE.check_tc, grains_max_over_mean=mx / ave,
                 fix_after=f[1], fix_before=f[2])
            for k, ((ave, mx), f) in enumerate(zip(nlocal, fix))]
    return dict(ranks=ranks, balance=balance, every=every, wall=wall, series=rows,
                grains_max_over_mean_max=max(r["grains_max_over_mean"] for r in rows),
                fix_before_max=max(r["fix_before"] for r in rows))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--sizes", type=int, nargs="*", default=[2500, 25000],
                    help="grains per aggregate, each size side by side (none: skip part 1)")
    ap.add_argument("--v", type=float, default=39.8, help="v_col, m/s")
    ap.add_argument("--model", default="frictionless")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--until-tc", type=float, default=3000.0, help="simulated time of part 1")
    ap.add_argument("--budget", type=float, default=1800.0,
                    help="wall seconds after which a variant of part 1 stops")
    ap.add_argument("--ranks", type=int, nargs="*", default=[2, 4, 8],
                    help="rank counts of part 2 (none: skip it)")
    ap.add_argument("--balance-n", type=int, default=2500, help="grains per aggregate, part 2")
    ap.add_argument("--balance-tc", type=float, default=1000.0, help="simulated time, part 2")
    ap.add_argument("--quick", action="store_true", help="2 x 300, 200 t_c, 2 ranks")
    ap.add_argument("--out", type=Path, default=HERE / "scale" / "scale.json")
    args = ap.parse_args(argv)
    if args.quick:
        args.sizes, args.until_tc, args.ranks = [300], 200.0, [2]
        args.balance_n, args.balance_tc = 300, 200.0

    from jkrdt import rundir
    from jkrdt import scene as scene_module
    from jkrdt.materials import material

    work = Path(tempfile.mkdtemp(prefix="bench_scale_"))

    def scene(n):
        where = work / f"scene_{n}"
        if not where.exists():
            sc = scene_module.Scene(material=material("ice"), n_tar=n, n_pro=n, v_col=args.v,
                                    model=args.model, seed=args.seed)
            rundir.write(where, sc)
        return where

    out = dict(scene=dict(v_col=args.v, model=args.model, seed=args.seed, material="ice",
                          b_off=0.0), variants=VARIANTS, sizes={}, ranks={})
    for n in args.sizes:
        print(f"== 2 x {n}: before and after, side by side", flush=True)
        out["sizes"][str(n)] = alternate(scene(n), VARIANTS, args.until_tc, args.budget)
        save(args.out, out)
    for ranks in args.ranks:
        for balance in ("rcb", "no"):        # the deck's default, and no balancing
            print(f"== 2 x {args.balance_n} on {ranks} ranks, balance {balance}", flush=True)
            got = imbalance(scene(args.balance_n), ranks, args.balance_tc, balance)
            out["ranks"][f"{ranks} {balance}"] = got
            print(json.dumps({k: v for k, v in got.items() if k != "series"}), flush=True)
            save(args.out, out)
    print(json.dumps({n: s["summary"] for n, s in out["sizes"].items()}, indent=1))


def save(path: Path, out: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(out, indent=1))
    tmp.replace(path)


if __name__ == "__main__":
    main()
