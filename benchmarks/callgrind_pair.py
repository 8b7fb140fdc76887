"""Instructions of the pair loop, counted by callgrind: this build against another.

    python benchmarks/callgrind_pair.py --baseline OLD_PLUGIN.so --this NEW_PLUGIN.so
                                        [--size 2500] [--steps 200]

Callgrind counts instructions, not seconds: the same binary and input give the same count
whatever else the machine runs, so a small change in the per-pair step (a counter, a
branch) is measured where an interleaved timing would drown it in noise. Each build runs
the scene of ``bench_pair`` (two BPCA ice aggregates of --size grains, 20 m/s, B_off 0.3),
full and frictionless, for --steps steps on 1 rank under ``valgrind --tool=callgrind``;
the JSON gives the instructions inclusive in PairJKRDT::compute, the list pairs per step
(LAMMPS's neighbor count) and the instructions per list pair per evaluation, and their
ratio to the baseline's. Writes benchmarks/speed/callgrind_<tag>.json; asserts nothing.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_pair import DECK, JKRDT_BARE, JKRDT_FULL, copy_builds, lammps_command, scene, two_builds
from jkrdt import plugin as installed
from jkrdt.materials import ICE, scales

HERE = Path(__file__).resolve().parent


def count(deck: str, workdir: Path, plugin: Path) -> dict:
    """Instructions inclusive in PairJKRDT::compute for one run of ``deck`` with ``plugin``."""
    (workdir / "in.bench").write_text(deck)
    cmd, env = lammps_command(1, 1, plugin)
    out = workdir / "callgrind.out"
    subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                    "--toggle-collect=*PairJKRDT::compute*", *cmd, "-in", "in.bench",
                    "-log", "log.bench", "-screen", "none"], cwd=workdir, env=env, check=True,
                   capture_output=True)
    total = subprocess.run(["callgrind_annotate", str(out)], capture_output=True, text=True,
                           check=True).stdout
    found = re.search(r"([0-9,]+) \(100.0%\)\s+PROGRAM TOTALS", total)
    if found is None:
        sys.exit(f"callgrind_pair: no instructions counted in PairJKRDT::compute of {plugin}: "
                 "that build has no symbol table (the wheel's is stripped); build one with "
                 "'cmake -B build && cmake --build build' and give --this build/jkrdtplugin.so")
    ir = int(found.group(1).replace(",", ""))
    log = (workdir / "log.bench").read_text()
    pairs = int(re.search(r"Total # of neighbors = (\d+)", log).group(1))
    return dict(instructions=ir, list_pairs=pairs)


def main(argv=None) -> int:
    p = two_builds(__doc__, steps=200, tag="events")
    args = p.parse_args(argv)
    if shutil.which("valgrind") is None:
        p.error("valgrind is not installed: apt-get install valgrind")
    data = scene(args.size, args.scenes)
    dt = 0.014 * scales(ICE, 1.0e-7).t_c
    out = dict(size=args.size, steps=args.steps, baseline=str(args.baseline),
               this=str(args.this or installed.plugin_path()),
               date=time.strftime("%Y-%m-%d"), command=" ".join(sys.argv), models={})
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        builds = copy_builds(tmp, args.this or installed.plugin_path(), args.baseline)
        for model, pair in (("full", JKRDT_FULL), ("frictionless", JKRDT_BARE)):
            deck = DECK.format(data=data, pair=pair, skin=1.0e-8, steps=args.steps, dt=dt)
            row = {}
            for tag in ("this", "baseline"):
                work = tmp / f"{tag}_{model}"
                work.mkdir()
                c = count(deck, work, builds[tag])
                c["per_list_pair"] = c["instructions"] / (c["list_pairs"] * (args.steps + 1))
                row[tag] = c
            row["ratio"] = row["this"]["instructions"] / row["baseline"]["instructions"]
            out["models"][model] = row
            print(f"{model}: {row['this']['instructions']:,} against "
                  f"{row['baseline']['instructions']:,} instructions ({row['ratio']:.4f}x), "
                  f"{row['this']['per_list_pair']:.1f} per list pair", flush=True)
    path = HERE / "speed" / f"callgrind_{args.tag}.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
