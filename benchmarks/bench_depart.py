"""Cost per step of a shattering collision as its fragments fly apart, with and without
departure (fix jkr/dt/settle depart yes|no), side by side.

Two worker processes run the same scene, one check interval (50 t_c) at a time, taking
turns (A B A B ...), so both see the same machine load. After each chunk a worker reports
the wall time of the chunk, the box, its resident memory and the departed grains. The
departing run goes to the settle rule or ``--until-tc``; the other stops at the same
simulated time or at ``--budget`` seconds of its own wall time, whichever comes first.

    python benchmarks/bench_depart.py                        # 2 x 2500, frictionless, 39.8 m/s
    python benchmarks/bench_depart.py --n 1000 --out /tmp/d.json

Writes JSON (default benchmarks/depart/depart.json): per chunk t/t_c, us per atom-step,
box lengths, RSS; and per variant the largest cost and memory against the first chunk's.
With ``--neighbor`` the two variants ("yes", "no") are instead bins and nsq, both departing.
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

from side_by_side import alternate

HERE = Path(__file__).resolve().parent


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--n", type=int, default=2500, help="grains per aggregate")
    ap.add_argument("--v", type=float, default=39.8, help="v_col, m/s")
    ap.add_argument("--model", default="frictionless")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--budget", type=float, default=900.0,
                    help="wall seconds after which the run without departure stops")
    ap.add_argument("--until-tc", type=float, default=3000.0,
                    help="simulated time (t_c) at which both stop, settled or not")
    ap.add_argument("--out", type=Path, default=HERE / "depart" / "depart.json")
    ap.add_argument("--neighbor", action="store_true",
                    help="compare instead bins against nsq, both departing and neither sorting "
                         "its atoms (nsq was the path of scenes up to 2000 grains until "
                         "bins were bounded; jkrdt.rundir.UNSORTED_MAX)")
    args = ap.parse_args(argv)

    from jkrdt import rundir
    from jkrdt import scene as scene_module
    from jkrdt.materials import material

    work = Path(tempfile.mkdtemp())
    sc = scene_module.Scene(material=material("ice"), n_tar=args.n, n_pro=args.n, v_col=args.v,
                            model=args.model, seed=args.seed)
    rundir.write(work / "scene", sc)
    variants = (dict(yes=dict(depart="yes"), no=dict(depart="no")) if not args.neighbor else
                dict(yes=dict(depart="yes", neighbor="bin", sort="0"),
                     no=dict(depart="yes", neighbor="nsq", sort="0")))
    # the run without departure (or with nsq) has the budget; the other runs to its end
    budget = dict(yes=float("inf"), no=args.budget)
    ran = alternate(work / "scene", variants, args.until_tc, budget, bounded_by="yes")
    out = dict(variants=variants, scene=dict(n_tar=args.n, n_pro=args.n, v_col=args.v,
                                             model=args.model, seed=args.seed, material="ice",
                                             b_off=0.0), **ran)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(out, indent=1))
    print(json.dumps(out["summary"], indent=1))


if __name__ == "__main__":
    main()
