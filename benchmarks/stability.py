"""Where velocity Verlet stops holding a jkr/dt contact network: the stable time step.

A resting BPCA aggregate (every grain bonded, the stiffest scene: the sliding
springs couple translation and rotation) is given small random velocities and
spins (kinetic energy ``KICK`` times N F_c delta_c) and run for ``STEPS`` steps at
dt / t_c from 0.05 to 1.5, with the time-step guard off. For each dt the
largest |E - E0| over the run is divided by the initial kinetic energy. A stable
step keeps that ratio bounded and small; past the limit it grows by orders of
magnitude, or the run stops with a named error (the linearised contact oscillators of highest frequency are
integrated with omega dt > 2, which velocity Verlet cannot hold).

Materials: ice and quartz (a stiffness ratio of about 8), frictional and
frictionless. Writes benchmarks/stability/stability.json (committed).

    python benchmarks/stability.py [--quick]
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np

from jkrdt.aggregates import bpca
from jkrdt.datafile import write_sphere_data
from jkrdt.materials import ICE, QUARTZ, scales
from jkrdt.scene import pair_coeff
from jkrdt.session import read_deck, start_lammps
from jkrdt.ledger import CONSERVED

KICK = 0.01          # initial kinetic energy per grain, in F_c delta_c
RATIOS = [0.05, 0.1, 0.2, 0.3, 0.35, 0.4, 0.45, 0.5, 0.6, 0.7, 0.8, 1.0, 1.2, 1.5]
RESULTS = Path(__file__).resolve().parent / "stability"


def resting_run(mat, model: str, ratio: float, n: int, steps: int, seed: int = 1) -> dict:
    r = 1.0e-7
    s = scales(mat, r)
    rng = np.random.default_rng(seed)
    x = bpca(n, r, s.delta0, rng)
    # equal shares of translational and rotational kinetic energy
    v_scale = np.sqrt(KICK * s.F_c * s.delta_c / s.mass)
    v = rng.normal(size=x.shape) * v_scale / np.sqrt(3)
    omega = rng.normal(size=x.shape) * v_scale / (np.sqrt(0.4) * r) / np.sqrt(3)
    with tempfile.TemporaryDirectory() as tmp:
        data = Path(tmp) / "agg.data"
        write_sphere_data(data, x, r, mat.density, v=v, omega=omega)
        lmp = start_lammps()
        try:
            read_deck(lmp, dict(file=data, coeffs=pair_coeff(mat, model),
                                dt=ratio * s.t_c, skin=10 * s.delta_c, dt_check="off"))
            lmp.command(f"variable total equal {CONSERVED}")
            lmp.command("run 0 post no")
            e0 = lmp.extract_variable("total")
            k0 = lmp.get_thermo("ke") + float(lmp.extract_compute("erot", 0, 0))
            worst, blown, chunk = 0.0, None, max(1, steps // 100)
            t0 = time.perf_counter()
            for done in range(0, steps, chunk):
                try:
                    lmp.command(f"run {chunk} pre no post no")
                except Exception as err:                 # a named error of the plugin
                    blown = str(err).splitlines()[0][:200]
                    break
                e = lmp.extract_variable("total")
                if not np.isfinite(e):
                    blown = "non-finite energy"
                    break
                worst = max(worst, abs(e - e0) / k0)
                if worst > 1e3:
                    blown = "energy error above 1e3 of the kinetic energy"
                    break
            seconds = time.perf_counter() - t0
        finally:
            lmp.close()
    return dict(material=mat.name, model=model, dt_over_tc=ratio, N=n, steps=steps,
                max_dE_over_K0=worst, stopped=blown, seconds=seconds)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="fewer grains and steps")
    p.add_argument("--out", default=str(RESULTS / "stability.json"))
    args = p.parse_args(argv)
    n, steps = (32, 2000) if args.quick else (128, 20000)
    rows = []
    for mat in (ICE, QUARTZ):
        for model in ("frictional", "frictionless"):
            for ratio in RATIOS:
                row = resting_run(mat, model, ratio, n, steps)
                rows.append(row)
                print(f"{mat.name:6s} {model:12s} dt = {ratio:4.2f} t_c  max|dE|/K0 = "
                      f"{row['max_dE_over_K0']:.3e}  {row['stopped'] or ''}", flush=True)
    # the stable limit per scene: the largest dt up to which every dt keeps the energy
    # error below the kinetic energy itself and stops with no error
    limits = {}
    for mat in (ICE, QUARTZ):
        for model in ("frictional", "frictionless"):
            stable = 0.0
            for r in sorted((r for r in rows if r["material"] == mat.name and r["model"] == model),
                            key=lambda r: r["dt_over_tc"]):
                if r["stopped"] or r["max_dE_over_K0"] > 1.0:
                    break
                stable = r["dt_over_tc"]
            limits[f"{mat.name} {model}"] = stable
    out = dict(kick_per_grain_FcDc=KICK, N=n, steps=steps, rows=rows,
               stable_dt_over_tc=limits)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(out, indent=2))
    print("largest stable dt / t_c:", limits)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
