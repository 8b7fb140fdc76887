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
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def rss_mb() -> tuple[float, float]:
    """(resident, peak resident) memory of this process, MB."""
    fields = dict(line.split(":", 1) for line in Path("/proc/self/status").read_text().splitlines())
    return (int(fields["VmRSS"].split()[0]) / 1024, int(fields["VmHWM"].split()[0]) / 1024)


def worker(scene: str, variables: str) -> None:
    """Run ``scene`` chunk by chunk on request: a line on stdin runs one check interval
    and answers one JSON line on stdout; 'quit' ends."""
    from lammps import LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR

    from jkrdt.session import Session
    from jkrdt.stopping import DEFAULT_RULE

    with Session(scene, settle=DEFAULT_RULE, variables=json.loads(variables),
                 out=tempfile.mkdtemp()) as s:
        natoms = int(s.lmp.get_natoms())
        tc = s.scene.scales.t_c
        for line in sys.stdin:
            if line.strip() == "quit":
                break
            t0 = time.perf_counter()
            s.lmp.command(f"run {s.check} pre no post no")
            wall = time.perf_counter() - t0
            lo, hi = s.lmp.extract_box()[:2]
            vec = lambda k: s.lmp.extract_fix("settle", LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR, k)
            rss, peak = rss_mb()
            print(json.dumps(dict(
                t_tc=s.lmp.get_thermo("time") / tc, wall=wall,
                us_per_atom_step=1e6 * wall / (natoms * s.check),
                box=[h - l for l, h in zip(lo, hi)], rss_mb=rss, peak_mb=peak,
                departed=vec(5), state=("running", "settled", "cap")[int(vec(0))])),
                flush=True)


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
                    help="compare instead bins against nsq, both departing (the small-scene "
                         "special case, jkrdt.scene.NSQ_MAX)")
    ap.add_argument("--worker", nargs=2, metavar=("SCENE", "VARIABLES"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        return worker(*args.worker)

    from jkrdt import scene as scene_module
    from jkrdt.materials import material

    work = Path(tempfile.mkdtemp())
    sc = scene_module.Scene(material=material("ice"), n_tar=args.n, n_pro=args.n, v_col=args.v,
                            model=args.model, seed=args.seed)
    scene_module.write(work / "scene", sc)
    variants = (dict(yes=dict(depart="yes"), no=dict(depart="no")) if not args.neighbor else
                dict(yes=dict(depart="yes", neighbor="bin", sort="1000 0.0"),
                     no=dict(depart="yes", neighbor="nsq", sort="0 0.0")))
    procs = {d: subprocess.Popen([sys.executable, __file__, "--worker", str(work / "scene"),
                                  json.dumps(v)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                 text=True)
             for d, v in variants.items()}
    series = {d: [] for d in procs}
    spent = {d: 0.0 for d in procs}
    loads = []
    live = dict(procs)
    while live:
        for d in list(live):                    # A B A B: one chunk each in turn
            p = live[d]
            p.stdin.write("step\n")
            p.stdin.flush()
            row = json.loads(p.stdout.readline())
            series[d].append(row)
            spent[d] += row["wall"]
            loads.append(os.getloadavg()[0])
            done = row["state"] != "running" or row["t_tc"] >= args.until_tc
            if d == "no":
                stop_at = series["yes"][-1]["t_tc"] if "yes" not in live else float("inf")
                done = done or spent[d] > args.budget or row["t_tc"] >= stop_at
            if done:
                p.stdin.write("quit\n")
                p.stdin.flush()
                p.wait()
                del live[d]
            print(f"{d:3s} t = {row['t_tc']:7.0f} t_c  {row['us_per_atom_step']:.3f} us/atom-step"
                  f"  box {' x '.join(f'{b * 1e6:.1f}' for b in row['box'])} um"
                  f"  RSS {row['rss_mb']:.0f} MB  departed {row['departed']:.0f}", flush=True)

    def verdict(rows):
        first = rows[0]
        return dict(chunks=len(rows), end_t_tc=rows[-1]["t_tc"], end_state=rows[-1]["state"],
                    cost_first=first["us_per_atom_step"],
                    cost_max_ratio=max(r["us_per_atom_step"] for r in rows) / first["us_per_atom_step"],
                    cost_end_ratio=rows[-1]["us_per_atom_step"] / first["us_per_atom_step"],
                    rss_max_ratio=max(r["rss_mb"] for r in rows) / first["rss_mb"],
                    wall_total=sum(r["wall"] for r in rows))
    out = dict(variants=variants, scene=dict(n_tar=args.n, n_pro=args.n, v_col=args.v, model=args.model,
                          seed=args.seed, material="ice", b_off=0.0),
               load_average=[min(loads), max(loads)],
               summary={d: verdict(series[d]) for d in series}, series=series)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(out, indent=1))
    print(json.dumps(out["summary"], indent=1))


if __name__ == "__main__":
    main()
