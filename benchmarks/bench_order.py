"""Does the order of the atoms in memory matter, now that the contact state is in
neighbor-list order? Writes JSON; asserts nothing.

    python benchmarks/bench_order.py [--n 25000] [--repeat 2]

The 2 x n BPCA scene of bench_pair.py, its atoms written in three orders (IDs renumbered
to match), each run with LAMMPS's own sorting off so that the order holds:
  build       the builders' order: each grain sticks to any earlier one
  spatial     sorted by bins of half the neighbor cutoff, as 'atom_modify sort' does
  contacts    breadth-first along the contact graph (aggregates are nearly trees), so
              that bonded grains sit next to each other in memory
and, for reference, the build order with LAMMPS's default sort (every 1000 steps).
The styles run interleaved (A B C D A B C D), full model, serial.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import breadth_first_order, connected_components
from scipy.spatial import cKDTree

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_pair  # noqa: E402

from jkrdt.materials import ICE, scales  # noqa: E402

R = bench_pair.R


def read_atoms(path: Path):
    """Header lines up to 'Atoms', the atom rows and the velocity rows of a sphere data file."""
    lines = path.read_text().splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith("Atoms"))
    atoms, k = [], start + 2
    while k < len(lines) and lines[k].strip():
        atoms.append(lines[k].split())
        k += 1
    vel = []
    marks = [j for j in range(k, len(lines)) if lines[j].startswith("Velocities")]
    if marks:
        k = marks[0] + 2
        while k < len(lines) and lines[k].strip():
            vel.append(lines[k].split())
            k += 1
    return lines[:start], np.array(atoms, dtype=float), np.array(vel, dtype=float)


def write_atoms(path: Path, header, atoms, vel, order):
    """The data file with the atoms in ``order``, renumbered 1..N in that order."""
    out = list(header) + ["Atoms # sphere", ""]
    for new, old in enumerate(order, start=1):
        a = atoms[old]
        out.append(f"{new} {int(a[1])} " + " ".join(repr(float(v)) for v in a[2:7]))
    if len(vel):
        by_id = {int(v[0]): v for v in vel}
        out += ["", "Velocities", ""]
        for new, old in enumerate(order, start=1):
            v = by_id[int(atoms[old][0])]
            out.append(f"{new} " + " ".join(repr(float(x)) for x in v[1:7]))
    path.write_text("\n".join(out) + "\n")


def spatial_order(x, binsize):
    """Atoms by bin, bins in x-fastest order, as LAMMPS's spatial sort."""
    b = np.floor((x - x.min(axis=0)) / binsize).astype(np.int64)
    nb = b.max(axis=0) + 1
    key = (b[:, 2] * nb[1] + b[:, 1]) * nb[0] + b[:, 0]
    return np.argsort(key, kind="stable")


def contact_order(x, radius, skin):
    """Breadth-first along bonded pairs (centres closer than r_i + r_j), component by
    component, each from its lowest index."""
    pairs = cKDTree(x).query_pairs(2 * radius.max() + skin, output_type="ndarray")
    d = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
    pairs = pairs[d <= radius[pairs[:, 0]] + radius[pairs[:, 1]]]
    n = len(x)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n)).tocsr()
    ncomp, label = connected_components(graph, directed=False)
    order = []
    for c in range(ncomp):
        root = int(np.flatnonzero(label == c)[0])
        order.extend(breadth_first_order(graph, root, directed=False,
                                         return_predecessors=False).tolist())
    return np.array(order)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--n", type=int, default=25000, help="grains per aggregate")
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--atom-steps", type=float, default=2e7)
    parser.add_argument("--scenes", type=Path, default=Path("benchmarks/scenes"))
    parser.add_argument("--out", type=Path, default=Path("benchmarks/speed/order.json"))
    args = parser.parse_args(argv)

    data = bench_pair.scene(args.n, args.scenes)
    header, atoms, vel = read_atoms(data)
    x, radius = atoms[:, 4:7], 0.5 * atoms[:, 2]
    skin = 1.0e-8
    cut = 2 * radius.max() + scales(ICE, R).delta_c + skin
    orders = {"build": np.arange(len(atoms)),
              "spatial": spatial_order(x, 0.5 * cut),
              "contacts": contact_order(x, radius, skin)}
    natoms, steps = len(atoms), max(10, int(args.atom_steps / len(atoms)))
    dt = 0.014 * scales(ICE, R).t_c
    results: dict = {}
    load = [os.getloadavg()[0]]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        files = {}
        for name, order in orders.items():
            files[name] = tmp / f"{name}.data"
            write_atoms(files[name], header, atoms, vel, order)
        variants = {name: (files[name], "atom_modify sort 0 0.0") for name in orders}
        variants["build, LAMMPS sort"] = (files["build"], "")
        for rep in range(args.repeat):
            for name, (path, sort) in variants.items():
                deck = bench_pair.DECK.format(data=path, pair=bench_pair.JKRDT_FULL,
                                              steps=steps, dt=dt, skin=1.0e-8)
                deck = deck.replace("read_data", f"{sort}\nread_data") if sort else deck
                run = bench_pair.per_atom_step(bench_pair.timed_run(deck, tmp, 1, 1),
                                               natoms, steps)
                results.setdefault(name, []).append(run)
                print(f"{name:20s} {run['loop_us_per_atom_step']:.3f} us/atom-step "
                      f"(pair {run['pair_us_per_atom_step']:.3f})", flush=True)
            load.append(os.getloadavg()[0])
    best = {name: min(r["loop_us_per_atom_step"] for r in runs) for name, runs in results.items()}
    report = dict(scene=f"2 x {args.n} BPCA ice, jkr/dt full model, serial, {steps} steps",
                  best_us_per_atom_step=best,
                  relative_to_spatial={k: v / best["spatial"] for k, v in best.items()},
                  load_average_1min=load, results=results)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=2))
    print(json.dumps({k: report[k] for k in ("best_us_per_atom_step", "relative_to_spatial")},
                     indent=2))


if __name__ == "__main__":
    main()
