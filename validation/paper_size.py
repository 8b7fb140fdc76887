"""The 3D BPCA paper at its own size, end to end: two collisions of 2 x 50000 ice grains.

    shattering   frictionless, 39.8 m/s, B_off 0
    sticking     frictional, 20 m/s, B_off 0

Each goes through the user's three commands, each timed with its peak memory:

    jkrdt setup --n-tar 50000 --n-pro 50000 ... --dt auto --tolerance 1e-3
    jkrdt run DIR --np 2             (to the settle rule, departures on: the defaults)
    jkrdt analyse DIR

and the run's record is measured file by file. A run still going after ``--limit-minutes``
(default 60) is stopped there and analysed with --partial. Writes RESULTS/<name>/ (stages.json with
each stage's wall time and memory, the output sizes, the outcome; and the run's
outcome.json, frames.csv, checks.csv and pictures). Runs go to ``--runs`` (default
validation/runs/paper_size, not committed). A second call skips the stages already done.

    ./run validate paper_size                       # both, 2 ranks
    ./run validate paper_size --only shattering --n 5000
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from common import loop_seconds
from jkrdt import rundir
from jkrdt.analysis.tables import read_csv

HERE = Path(__file__).resolve().parent
BIN = Path(sys.executable).parent
SCENES = {
    "shattering": dict(model="frictionless", v=39.8),
    "sticking": dict(model="frictional", v=20.0),
}
#: what is copied from a run into the results
KEPT = (rundir.OUTCOME, rundir.FRAMES, rundir.CHECKS, "outcome.png", "timeline.png",
        "energy.png")


def timed(cmd: list[str], log: Path, limit: float | None = None) -> dict:
    """Run ``cmd`` under GNU time: wall seconds and the largest resident set of any of its
    processes (for mpirun: of the busiest rank), MB. Past ``limit`` seconds the command and
    all its processes are stopped, and the result says so (``cut_at_limit``)."""
    stats = log.with_name(log.name + ".time")
    t0 = time.time()
    with log.open("w") as out:
        child = subprocess.Popen(["/usr/bin/time", "-f", "%e %M", "-o", str(stats),
                                  *map(str, cmd)], stdout=out, stderr=subprocess.STDOUT,
                                 start_new_session=True)
        try:
            code = child.wait(timeout=limit)
        except subprocess.TimeoutExpired:
            os.killpg(child.pid, signal.SIGTERM)
            child.wait()
            return dict(seconds=round(time.time() - t0, 1), cut_at_limit=True)
    if code != 0:
        raise subprocess.CalledProcessError(code, cmd)
    wall, rss = stats.read_text().split()[-2:]
    return dict(seconds=float(wall), peak_rss_mb=int(rss) / 1024)


def lammps_memory(log: Path) -> dict:
    """LAMMPS's own count of memory per rank (min, avg, max) at the last run, MB."""
    found = re.findall(r"Per MPI rank memory allocation \(min/avg/max\) = "
                       r"([0-9.]+) \| ([0-9.]+) \| ([0-9.]+) Mbytes", log.read_text())
    return dict(zip(("min", "avg", "max"), map(float, found[-1]))) if found else {}


def output_sizes(run: Path) -> dict:
    sizes = {p.name: p.stat().st_size for p in sorted(run.iterdir()) if p.is_file()}
    written = {k: v for k, v in sizes.items() if not k.startswith("stage.")}
    return dict(files_mb={k: round(v / 2 ** 20, 3) for k, v in written.items()},
                total_mb=round(sum(written.values()) / 2 ** 20, 1),
                run_record_mb=round(sum(v for k, v in written.items()
                                        if k not in (rundir.DATA,)) / 2 ** 20, 1))


def per_check(table: Path) -> dict:
    """Wall seconds per check at the start and the end of a run, and the memory per rank,
    from the settle rule's table."""
    rows = read_csv(table)
    wall = np.diff([r["wall"] for r in rows])
    return dict(checks=len(rows) - 1,
                seconds_first_3=float(np.mean(wall[:3])), seconds_last_3=float(np.mean(wall[-3:])),
                memory_mb_first=rows[0]["memory_mb"], memory_mb_last=rows[-1]["memory_mb"],
                peak_rss_mb=max(r["peak_rss_mb"] for r in rows))


def study(name: str, n: int, ranks: int, runs: Path, results: Path,
          limit: float | None) -> dict:
    run = runs / name
    run.mkdir(parents=True, exist_ok=True)
    state_path = run / "stage.json"
    state = json.loads(state_path.read_text()) if state_path.exists() else {}

    def save() -> None:           # after each stage: a second call skips what is done
        state_path.write_text(json.dumps(state, indent=2))

    scene = SCENES[name]
    if "setup" not in state:
        state["setup"] = timed([BIN / "jkrdt", "setup", "--n-tar", n, "--n-pro", n,
                                "--v", scene["v"], "--model", scene["model"], "--b-off", 0,
                                "--seed", 1, "--dt", "auto", "--tolerance", "1e-3",
                                "--out", run, "--force"], run / "stage.setup")
        save()
    if "run" not in state:
        state["run"] = timed([BIN / "jkrdt", "run", run, "--np", ranks], run / "stage.run",
                             limit=limit)
        state["run"]["lammps_memory_per_rank_mb"] = lammps_memory(run / rundir.LOG)
        state["run"]["ranks"] = ranks
        save()
    if "analyse" not in state:
        partial = ["--partial"] if state["run"].get("cut_at_limit") else []
        state["analyse"] = timed([BIN / "jkrdt", "analyse", run, *partial],
                                 run / "stage.analyse")
        save()
    out = rundir.read_outcome(run)
    state["outputs"] = output_sizes(run)
    state["scene"] = dict(n_tar=n, n_pro=n, **scene, b_off=0.0, seed=1,
                          dt_over_tc=json.loads((run / rundir.META).read_text())
                          .get("dt_over_tc"))
    state["outcome"] = {k: out.get(k) for k in (
        "stop_reason", "stop_step", "time_end_over_tc", "n_largest", "n_second",
        "n_fragments", "growth_efficiency", "gyration_radius_largest",
        "contacts_per_particle", "kinetic_left", "kinetic_departed", "energy_error",
        "dissipated_fraction")}
    state["run"]["loop_seconds"] = loop_seconds(run)
    state["run"]["per_check"] = per_check(run / rundir.CHECKS)
    save()
    target = results / name
    target.mkdir(parents=True, exist_ok=True)
    for kept in KEPT:
        if (run / kept).exists():
            shutil.copy2(run / kept, target / kept)
    (target / "stages.json").write_text(json.dumps(state, indent=2) + "\n")
    return state


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=50000, help="grains per aggregate")
    parser.add_argument("--ranks", type=int, default=2)
    parser.add_argument("--limit-minutes", type=float, default=60.0,
                        help="wall time after which a run is stopped and analysed as it is "
                             "(the issue's bound: one hour)")
    parser.add_argument("--only", choices=list(SCENES), action="append")
    parser.add_argument("--runs", type=Path, default=HERE / "runs" / "paper_size")
    parser.add_argument("--results", type=Path, default=HERE / "paper_size")
    args = parser.parse_args(argv)
    for name in args.only or list(SCENES):
        t0 = time.time()
        state = study(name, args.n, args.ranks, args.runs, args.results,
                      60.0 * args.limit_minutes)
        print(f"{name}: " + ", ".join(f"{k} {state[k]['seconds']:.0f} s"
                                       for k in ("setup", "run", "analyse"))
              + f"; record {state['outputs']['run_record_mb']} MB; {state['outcome']}"
              f" ({time.time() - t0:.0f} s this call)", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
