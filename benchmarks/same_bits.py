"""Does this build of the plugin give the same bits as another? Eighteen set-ups of one
collision, each run with both builds; asserts nothing, exits 1 on any difference.

    python benchmarks/same_bits.py --baseline OLD_PLUGIN.so [--this NEW.so] [--size 2500]
                                   [--steps 6000] [--only NAME ...]

A change meant to move no number (a refactoring of the pair loop, a faster path) is
checked here: the scene of ``bench_pair`` (two BPCA ice aggregates of --size grains,
20 m/s, B_off 0.3; contacts form, break and clamp), dt = 0.014 t_c, for --steps steps.
The set-ups:
  four models (full, frictionless, and both with viscoelastic damping, T_vis 6 ps),
      each serial, on 2 OpenMP threads and on 2 MPI ranks          12
  the portable (SSE2) pair loop, full and frictionless, serial        2
  frictionless with constants per type pair (pair_coeff 2 2 with another gamma) and with
      radii per atom (50 grains 1e-4 larger), serial and 2 threads     4
What must be identical: every atom frame (ids, positions, velocities, spins, forces, to
17 digits), every contact frame (dump local of compute jkr/dt/contacts), the thermo
lines (energies, the ledger, N_con, N_cut) and the final restart file's bytes.
Writes benchmarks/speed/same_bits_<tag>.json.
"""

from __future__ import annotations

import dataclasses
import filecmp
import gzip
import json
import sys
import tempfile
import time
from pathlib import Path

from bench_pair import PROLOGUE, copy_builds, scene, timed_run, two_builds
from jkrdt import plugin as installed
from jkrdt.materials import ICE, scales
from jkrdt.scene import pair_coeff

HERE = Path(__file__).resolve().parent
DAMPED = dataclasses.replace(ICE, tvis=6.0e-12)
DECK = PROLOGUE + """{radii}
pair_style jkr/dt kernel {kernel}
pair_coeff * * {coeffs}
{type_coeffs}
neighbor 1.0e-8 bin
neigh_modify every 1 delay 0 check yes
fix integrate all nve/sphere
compute p all pair jkr/dt
compute bonds all jkr/dt/contacts
thermo_style custom step ke pe c_p[*]
thermo_modify format float %.17g norm no
thermo {every}
dump atoms all custom/gz {every} atoms.dump.gz id x y z vx vy vz omegax omegay omegaz fx fy fz
dump_modify atoms sort id format float %.17g
dump contacts all local/gz {every} contacts.dump.gz c_bonds[*]
dump_modify contacts format float %.17g
timestep {dt!r}
run {steps}
write_restart final.restart
"""
# name: (material, model, ranks, threads, kernel, constants by)
SETUPS = {}
for _mat, _model, _name in ((ICE, "frictional", "full"), (ICE, "frictionless", "frictionless"),
                            (DAMPED, "frictional", "damped full"),
                            (DAMPED, "frictionless", "damped frictionless")):
    for _where, _ranks, _threads in (("serial", 1, 1), ("2 threads", 1, 2), ("2 ranks", 2, 1)):
        SETUPS[f"{_name}, {_where}"] = (_mat, _model, _ranks, _threads, "auto", "scene")
for _model, _name in (("frictional", "full"), ("frictionless", "frictionless")):
    SETUPS[f"{_name}, portable"] = (ICE, _model, 1, 1, "portable", "scene")
for _by in ("type", "radii"):
    for _where, _threads in (("serial", 1), ("2 threads", 2)):
        SETUPS[f"frictionless by {_by}, {_where}"] = (ICE, "frictionless", 1, _threads, "auto",
                                                      _by)


def deck(data: Path, setup: tuple, steps: int, every: int) -> str:
    mat, model, _, _, kernel, by = setup
    other = dataclasses.replace(mat, gamma=1.2 * mat.gamma)
    return DECK.format(
        data=data, kernel=kernel, coeffs=pair_coeff(mat, model),
        type_coeffs=f"pair_coeff 2 2 {pair_coeff(other, model)}" if by == "type" else "",
        radii="set atom 1*50 diameter 2.0002e-7" if by == "radii" else "",
        dt=0.014 * scales(ICE, 1.0e-7).t_c, steps=steps, every=every)


def thermo(log: Path) -> list[str]:
    lines = log.read_text().splitlines()
    start = next(k for k, line in enumerate(lines) if line.split()[:2] == ["Step", "KinEng"])
    end = next(k for k, line in enumerate(lines) if line.startswith("Loop time"))
    return lines[start:end]


def differences(a: Path, b: Path) -> list[str]:
    """What differs between two runs' outputs (empty: the same bits)."""
    found = []
    for name in ("atoms.dump.gz", "contacts.dump.gz"):
        with gzip.open(a / name, "rb") as fa, gzip.open(b / name, "rb") as fb:
            if fa.read() != fb.read():
                found.append(name)
    if thermo(a / "log.bench") != thermo(b / "log.bench"):
        found.append("thermo")
    if not filecmp.cmp(a / "final.restart", b / "final.restart", shallow=False):
        found.append("final.restart")
    return found


def run(text: str, work: Path, setup: tuple, plugin: Path) -> float:
    """One set-up's run with one build in ``work``: its wall time (s)."""
    work.mkdir(parents=True)
    return timed_run(text, work, setup[2], setup[3], plugin)["process_seconds"]


def main(argv=None) -> int:
    p = two_builds(__doc__, steps=6000, tag="check")
    p.add_argument("--every", type=int, default=1000, help="frame interval (steps)")
    p.add_argument("--only", nargs="*", default=None, help="set-up names (default: all)")
    args = p.parse_args(argv)
    unknown = set(args.only or ()) - set(SETUPS)
    if unknown:
        p.error(f"unknown set-up(s) {sorted(unknown)}: choose from {list(SETUPS)}")
    data = scene(args.size, args.scenes)
    this = args.this or installed.plugin_path()
    out = dict(size=args.size, steps=args.steps, baseline=str(args.baseline), this=str(this),
               date=time.strftime("%Y-%m-%d"), command=" ".join(sys.argv), setups={})
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        builds = copy_builds(tmp, this, args.baseline)
        for k, name in enumerate(args.only or SETUPS):
            setup = SETUPS[name]
            text = deck(data, setup, args.steps, args.every)
            seconds = {tag: run(text, tmp / f"{k}_{tag}", setup, builds[tag])
                       for tag in ("this", "baseline")}
            found = differences(tmp / f"{k}_this", tmp / f"{k}_baseline")
            out["setups"][name] = dict(same=not found, differ=found, seconds=seconds)
            print(f"{name}: {'same bits' if not found else 'DIFFER in ' + ', '.join(found)}",
                  flush=True)
    out["all_same"] = all(s["same"] for s in out["setups"].values())
    path = HERE / "speed" / f"same_bits_{args.tag}.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {path}")
    return 0 if out["all_same"] else 1


if __name__ == "__main__":
    sys.exit(main())
