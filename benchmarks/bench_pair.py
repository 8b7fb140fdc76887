"""Speed and memory of pair jkr/dt against pair granular on the same aggregate
collision, in the same run. Writes JSON; asserts nothing.

    python benchmarks/bench_pair.py [--n 2000] [--steps 4000] [--out benchmarks/results/pair.json]

Pairs compared (time per atom-step, best of --repeat):
  full model   jkr/dt with sliding, rolling, twisting   vs  granular jkr + mindlin + sds + marshall
  normal only  jkr/dt frictionless                       vs  granular jkr, no tangential history
The granular runs use the same E, nu, gamma; their tangential laws differ from
Wada et al. (k_roll = k_r = 12 pi gamma; mu_s = 0.5, mu_roll = 0.1 stand in for
the critical force and torque), so only the cost is comparable, not the outcome.
"""

from __future__ import annotations

import argparse
import json
import platform
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from jkrdt import collision
from jkrdt.aggregates import bpca
from jkrdt.materials import ICE, scales

R = 1.0e-7
COMMON = """
units si
atom_style sphere
atom_modify map array
boundary m m m
newton off
comm_modify vel yes
read_data {data}
{pair}
neighbor 1.0e-8 bin
neigh_modify every 1 delay 0 check yes
fix integrate all nve/sphere
thermo {steps}
timestep {dt!r}
run {steps}
"""
K_ROLL = 12 * 3.141592653589793 * ICE.gamma        # eq. (22): 4 F_c / R
GRANULAR_JKR = f"pair_coeff * * jkr {ICE.E!r} 0.0 {ICE.nu!r} {ICE.gamma!r} damping velocity "
STYLES = {
    "jkr/dt full": "pair_style jkr/dt\npair_coeff * * " + ICE.pair_coeff(),
    "granular jkr mindlin sds marshall": (
        "pair_style granular\n" + GRANULAR_JKR +
        f"tangential mindlin NULL 0.0 0.5 rolling sds {K_ROLL!r} 0.0 0.1 twisting marshall"),
    "jkr/dt frictionless": "pair_style jkr/dt\npair_coeff * * " + ICE.pair_coeff(frictionless=True),
    "granular jkr, no tangential history": (
        "pair_style granular\n" + GRANULAR_JKR + "tangential linear_nohistory 0.0 0.0"),
}
PAIRS = {"full model": ("jkr/dt full", "granular jkr mindlin sds marshall"),
         "normal only": ("jkr/dt frictionless", "granular jkr, no tangential history")}


def timed_run(deck: str, workdir: Path) -> dict:
    lmp = Path(sys.executable).parent / "lmp"
    (workdir / "in.bench").write_text(deck)
    start = time.perf_counter()
    subprocess.run([str(lmp), "-in", "in.bench", "-log", "log.bench", "-screen", "none"],
                   cwd=workdir, check=True)
    wall = time.perf_counter() - start
    log = (workdir / "log.bench").read_text()
    loop = float(re.search(r"Loop time of ([0-9.eE+-]+)", log).group(1))
    pair = float(re.search(r"^Pair\s*\|\s*([0-9.eE+-]+)", log, re.M).group(1))
    memory = float(re.search(r"Per MPI rank memory allocation \(min/avg/max\) = [0-9.]+ \| "
                             r"([0-9.]+)", log).group(1))
    return dict(loop_seconds=loop, pair_seconds=pair, process_seconds=wall,
                memory_mbytes_per_rank=memory)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--n", type=int, default=2000, help="grains per aggregate")
    parser.add_argument("--steps", type=int, default=4000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--out", default="benchmarks/results/pair.json")
    args = parser.parse_args(argv)

    s = scales(ICE, R)
    rng = np.random.default_rng(3)
    scene = collision.set_up(bpca(args.n, R, s.delta0, rng), bpca(args.n, R, s.delta0, rng),
                             R, v_col=20.0, b_off=0.3, rng=rng, material=ICE)
    natoms = 2 * args.n
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        data = collision.write(scene, ICE, tmp)
        for name, pair in STYLES.items():
            deck = COMMON.format(data=data, pair=pair, steps=args.steps, dt=0.014 * s.t_c)
            runs = [timed_run(deck, tmp) for _ in range(args.repeat)]
            best = min(runs, key=lambda r: r["loop_seconds"])
            best["loop_us_per_atom_step"] = 1e6 * best["loop_seconds"] / (natoms * args.steps)
            best["pair_us_per_atom_step"] = 1e6 * best["pair_seconds"] / (natoms * args.steps)
            results[name] = best
    ratios = {}
    for label, (ours, peer) in PAIRS.items():
        a, b = results[ours], results[peer]
        ratios[label] = dict(jkrdt=ours, granular=peer,
                             loop_jkrdt_over_granular=a["loop_seconds"] / b["loop_seconds"],
                             pair_jkrdt_over_granular=a["pair_seconds"] / b["pair_seconds"])
    full, bare = results["jkr/dt full"], results["jkr/dt frictionless"]
    report = dict(
        scene=f"two ice BPCA of {args.n} grains, 20 m/s, B_off 0.3, dt = 0.014 t_c",
        atoms=natoms, steps=args.steps, repeat=args.repeat, machine=platform.machine(),
        results=results, ratios=ratios,
        jkrdt_full_over_frictionless_pair=full["pair_seconds"] / bare["pair_seconds"])
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(report, indent=2))
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
