"""Builder timings and measured fractal structure. Writes JSON; asserts nothing.

    python benchmarks/bench_builders.py [--max-bpca 100000] [--max-bcca 131072]
                                        [--out benchmarks/results/builders.json]

Timings (one core, seconds and microseconds per grain):
  BPCA 3D and 2D, N = 10^3 ... --max-bpca (the grid, 64 lines at a time), and the
  reference in the same run: the plain process (one line at a time against every
  grain, ``bpca_plain``), up to 10^4;
  BCCA 3D and 2D, N = 2^10 ... --max-bcca.
Structure: fits of N = k0 (r_g/r_1)^D_f over ensembles (Wada et al. 2007, eqs. 52-53),
for 2D BCCA to compare with eq. 53 (D_f 1.57, k0 1.37), for 3D BCCA (D_f ~ 1.9) and BPCA.
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from pathlib import Path

import numpy as np

from jkrdt.aggregates import bcca, bpca, bpca_plain, fractal_fit, gyration_radius
from jkrdt.materials import ICE, scales

R = 1.0e-7
DELTA0 = scales(ICE, R).delta0


def timed(build, n, dim, seed=1):
    t0 = time.perf_counter()
    x = build(n, R, DELTA0, np.random.default_rng(seed), dim=dim)
    seconds = time.perf_counter() - t0
    return dict(N=n, dim=dim, seconds=seconds, us_per_grain=1e6 * seconds / n,
                rg_over_r=gyration_radius(x) / R)


def ensemble_fit(build, sizes, count, dim):
    n, rg = [], []
    for size in sizes:
        for seed in range(count):
            x = build(size, R, DELTA0, np.random.default_rng(1000 * size + seed), dim=dim)
            n.append(size)
            rg.append(gyration_radius(x) / R)
    d_f, k0 = fractal_fit(np.array(n), np.array(rg))
    return dict(sizes=list(sizes), per_size=count, D_f=d_f, k0=k0)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-bpca", type=int, default=100000)
    parser.add_argument("--max-bcca", type=int, default=2 ** 17)
    parser.add_argument("--out", default="benchmarks/results/builders.json")
    args = parser.parse_args(argv)

    timings = []
    for dim in (3, 2):
        for n in [1000, 3000, 10000, 30000, 50000, 100000]:
            if n <= args.max_bpca:
                timings.append(dict(builder="bpca", **timed(bpca, n, dim)))
                print(timings[-1], flush=True)
            if n <= 10000:
                timings.append(dict(builder="bpca_plain", **timed(bpca_plain, n, dim)))
                print(timings[-1], flush=True)
        for k in range(10, 18, 2 if args.max_bcca > 2 ** 14 else 1):
            if 2 ** k <= args.max_bcca:
                timings.append(dict(builder="bcca", **timed(bcca, 2 ** k, dim)))
                print(timings[-1], flush=True)
        if args.max_bcca >= 2 ** 17:
            timings.append(dict(builder="bcca", **timed(bcca, 2 ** 17, dim)))

    fits = {
        "bcca_2d": ensemble_fit(bcca, [2 ** k for k in range(4, 11)], 20, 2),
        "bcca_3d": ensemble_fit(bcca, [2 ** k for k in range(4, 12)], 10, 3),
        "bpca_3d": ensemble_fit(bpca, [2 ** k for k in range(6, 13)], 5, 3),
        "bpca_2d": ensemble_fit(bpca, [2 ** k for k in range(6, 13)], 5, 2),
    }
    report = dict(machine=platform.machine(), processor=platform.processor(),
                  python=platform.python_version(), radius=R, material="ice",
                  timings=timings, fractal_fits=fits,
                  reference_eq53_2d_bcca=dict(D_f=1.57, k0=1.37))
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".tmp")
    tmp.write_text(json.dumps(report, indent=2))
    tmp.replace(out)
    print(json.dumps(fits, indent=2))


if __name__ == "__main__":
    main()
