"""How much faster a campaign of many small collisions runs side by side.

One campaign spec (default: 3D BPCA ice, 2 x 64 grains, 4 speeds x 3 B_off^2, one seed:
12 independent runs to the settle rule) is run into fresh directories by

    serial     jkrdt campaign SPEC DIR                                  (1 rank)
    groups     mpirun -np 2 jkrdt campaign SPEC DIR                      (2 groups of 1)
    together   mpirun -np 2 jkrdt campaign SPEC DIR --ranks-per-run 2    (1 group of 2)

interleaved (serial, groups, together, serial, ...) so that the machine's load falls on
all of them alike. It writes benchmarks/campaign/campaign.json: the wall time of each
repeat, the best of each, the speed-ups over serial and the load average around each
run, and checks that every set-up gives the serial campaign's outcomes.

    python benchmarks/bench_campaign.py [--repeats 2] [--out benchmarks/campaign]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

BIN = Path(sys.executable).parent
SPEC = dict(kind="bpca", dim=3, n_tar=64, n_pro=64, material="ice", model="frictional",
            v_col=[5.0, 20.0, 40.0, 80.0], b_off2=[0.0, 0.5, 1.0], seeds=[1],
            settle=dict(check_tc=20))
SETUPS = {"serial": [], "groups": [str(BIN / "mpirun"), "-np", "2"],
          "together": [str(BIN / "mpirun"), "-np", "2"]}


def command(name: str, spec: Path, where: Path) -> list[str]:
    cmd = SETUPS[name] + [str(BIN / "jkrdt"), "campaign", str(spec), str(where), "--quiet"]
    return cmd + (["--ranks-per-run", "2"] if name == "together" else [])


def outcomes(where: Path) -> dict:
    from jkrdt import rundir

    keys = ("n_largest", "n_fragments", "stop_step")
    return {str(p.relative_to(where)): [json.loads(p.read_text())[k] for k in keys]
            for p in sorted(where.rglob(rundir.OUTCOME))}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--out", type=Path, default=Path("benchmarks/campaign"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    times = {name: [] for name in SETUPS}
    loads = {name: [] for name in SETUPS}
    found = {}
    with tempfile.TemporaryDirectory() as tmp:
        spec = Path(tmp) / "spec.json"
        spec.write_text(json.dumps(SPEC))
        for repeat in range(args.repeats):
            for name in SETUPS:
                where = Path(tmp) / f"{name}{repeat}"
                before = os.getloadavg()[0]
                t0 = time.perf_counter()
                subprocess.run(command(name, spec, where), check=True)
                times[name].append(time.perf_counter() - t0)
                loads[name].append([before, os.getloadavg()[0]])
                found[name] = outcomes(where)
                print(f"{name:9s} repeat {repeat}: {times[name][-1]:.1f} s, load "
                      f"{before:.2f} -> {loads[name][-1][1]:.2f}", flush=True)
                shutil.rmtree(where)
    best = {name: min(t) for name, t in times.items()}
    # each group of one rank runs a run exactly as the serial campaign does; a group of two
    # ranks is a different decomposition, so its chaotic outcomes may differ run by run
    same = {name: found[name] == found["serial"] for name in SETUPS}
    report = dict(spec=SPEC, runs=len(found["serial"]), repeats=args.repeats, cores=os.cpu_count(),
                  seconds=times, best_seconds=best, load_before_after=loads,
                  speedup_over_serial={n: best["serial"] / best[n] for n in SETUPS},
                  same_outcomes_as_serial=same, outcomes=found["serial"],
                  date=time.strftime("%Y-%m-%d %H:%M"))
    (args.out / "campaign.json").write_text(json.dumps(report, indent=2) + "\n")
    print(json.dumps({k: report[k] for k in ("best_seconds", "speedup_over_serial",
                                             "same_outcomes_as_serial")}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
