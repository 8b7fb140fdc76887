"""Does the damping of a stretched contact keep the damped frictional model from fragmenting?

At 2 x 5000 grains the damped frictional model's <f_gro> stays above 0 up to 125.9 m/s
(``vfra_size``), where the 3D BPCA paper has v_fra = 50 m/s; its gap does not close with
size as the damped frictionless model's does. Eq. (A.5) gives the damping force
F_D = 2 T_vis E* / nu^2 a v_rel "between two particles in contact" and leaves open whether
it acts on a contact under tension (delta < 0, the contact radius a still > 0). This study
tests that single reading: the damped frictional model at 2 x 1000 grains, 63.1 m/s, the
two offsets whose f_gro decides <f_gro> there (B_off^2 = 3/12, 6/12), 6 seeds, dt from
--dt auto (1e-3), once with eq. (A.5) as printed (F_D at every delta of a bonded contact:
the runs of ``damped_dt`` at dt auto, the same spec) and once with ``damp_tension off`` (F_D
only while compressed). For one contact the variant lowers the head-on sticking threshold
from 11.0 to 9.7 times the elastic one (``two_grain_sticking``). Collisions are chaotic,
so the two are compared as ensembles: per offset, the means of f_gro and N_lar / N with
their standard errors, and the difference against twice its standard error; and the
share of E_imp dissipated by damping.

Writes RESULTS (default validation/damped_tension/): runs.csv and summary.json.

    ./run validate damped_tension            # 2 offsets x 6 seeds x 2 variants, 2 ranks
    ./run validate damped_tension --quick    # 2 x 24 grains, 3 seeds (tests)
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from bpca3d_models import model_spec
from common import (campaign_paths, campaign_study_parser, mean_se, run_campaigns,
                    study_paths, within_scatter, write_summary)
from jkrdt import rundir
from jkrdt.analysis.tables import write_csv
from jkrdt.stopping import COMPLETE
from vfra_size import TOLERANCE, model_home, outcome_rows

MODEL = "frictional, T_vis 6 ps"
FULL = dict(n=1000, v_col=63.1, b_off2=[0.25, 0.5], seeds=[1, 2, 3, 4, 5, 6])
QUICK = dict(n=24, v_col=63.1, b_off2=[0.25], seeds=[1, 2, 3])
# the material field each variant sets (jkrdt.materials.Material.damp_tension)
VARIANTS = {"as printed": {}, "damp_tension off": {"damp_tension": False}}


def spec(plan: dict, variant: str) -> dict:
    s = model_spec(MODEL, plan["n"], v_col=[plan["v_col"]], b_off2=plan["b_off2"],
                   seeds=plan["seeds"], dt="auto", tolerance=TOLERANCE)
    s["material_overrides"].update(VARIANTS[variant])
    return s


def variant_rows(where: Path, n: int, variant: str) -> list[dict]:
    """``vfra_size.outcome_rows`` of one variant's finished runs, with the part of E_imp
    that F_D of eq. (A.5) dissipated (the outcome's ledger)."""
    outcomes = [json.loads(p.read_text()) for p in sorted(where.rglob(rundir.OUTCOME))]
    return [dict(r, variant=variant, damping_share=o["dissipated_by_channel"]["damping"])
            for r, o in zip(outcome_rows(where, n, MODEL), outcomes)
            if r["stop_reason"] in COMPLETE]


def compare(rows: list[dict], b2: float) -> dict:
    """f_gro, N_lar / N and the damping share of one offset under both variants, and
    whether they agree (``common.within_scatter``)."""
    out = {}
    for measure, value in (("f_gro", lambda r: r["growth_efficiency"]),
                           ("N_lar_over_N", lambda r: r["n_largest"] / r["n_total"]),
                           ("damping_share", lambda r: r["damping_share"])):
        at = {name: mean_se([value(r) for r in rows if r["variant"] == name
                             and abs(r["B_off"] ** 2 - b2) < 1e-9]) for name in VARIANTS}
        difference, se, agree = within_scatter(at["as printed"], at["damp_tension off"])
        out[measure] = dict(as_printed=list(at["as printed"]),
                            damp_tension_off=list(at["damp_tension off"]),
                            difference=difference, se=se, agree=agree)
    return out


def main(argv=None) -> int:
    args = campaign_study_parser(__doc__).parse_args(argv)
    plan = QUICK if args.quick else FULL
    runs, results = study_paths(args, "damped_tension")
    home = model_home(runs, plan["n"], MODEL)
    specs = {name: spec(plan, name) for name in VARIANTS}
    run_campaigns(specs, home, args.np)
    rows = [r for name, where in campaign_paths(specs, home).items()
            for r in variant_rows(where, plan["n"], name)]
    write_csv(results / "runs.csv", rows)
    summary = dict(plan=plan, model=MODEL, variants=VARIANTS, tolerance=TOLERANCE,
                   results={f"{b2:.4f}": compare(rows, b2) for b2 in plan["b_off2"]},
                   runs={name: sum(r["variant"] == name for r in rows) for name in VARIANTS},
                   loop_minutes={name: sum(r["loop_seconds"] for r in rows
                                           if r["variant"] == name) / 60 for name in VARIANTS},
                   energy_error_max=max((r["energy_error"] for r in rows), default=None),
                   runs_finished=len(rows))
    return write_summary(results, summary)


if __name__ == "__main__":
    sys.exit(main())
