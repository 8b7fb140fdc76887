"""The quick variants of the validation studies: validation/wada2007_2d.py (2D BCCA
head-on collisions of 2 x 32 grains, quartz and ice, xi_crit = 2 A, 5 speeds, 2 seeds,
against Wada et al. 2007) and validation/bpca3d_models.py (the 3D BPCA paper's four
models at 2 x 24 grains), validation/two_grain_sticking.py (the sticking threshold of
two grains without and with the damping of eq. A.5), validation/departure.py (fragments
that depart against fragments kept flying, 2 x 50 grains shattering, 4 seeds) and
validation/b_off_grid.py (<f_gro> over the paper's twelfths of B_off^2 and over four)."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from jkrdt.analysis.tables import read_csv
from jkrdt.materials import ICE, scales

ROOT = Path(__file__).resolve().parents[1]


def run_quick(study: str, where: Path, *options: str) -> Path:
    """``validation/<study>.py --quick`` with its runs and results below ``where``."""
    subprocess.run([sys.executable, str(ROOT / "validation" / f"{study}.py"), "--quick",
                    "--runs", str(where / "runs"), "--results", str(where / "results"),
                    *options],
                   check=True, timeout=900, capture_output=True)
    return where / "results"


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    results = run_quick("wada2007_2d", tmp_path_factory.mktemp("validation"))
    return json.loads((results / "summary.json").read_text()), \
        read_csv(results / "runs.csv"), results


def test_every_run_settles_within_the_energy_budget(quick):
    summary, rows, results = quick
    assert summary["stop_reasons"] == {"settled": 20}
    # dt = 0.014 t_c up to 20 v0: the tradeoff fit puts the worst run near 1e-4 E_imp
    assert max(r["energy_error"] for r in rows) < 1e-3
    for stem in ("fig7_gyration", "fig11_contacts", "fig14_largest", "fig6_shares"):
        assert (results / f"{stem}.png").stat().st_size > 0


def test_gyration_radius_follows_eq_51(quick):
    eq51 = quick[0]["eq51"]
    # the paper's Fig. 7a scatters by about +-15 % about eq. (51) over its fit range (three
    # structures); at N_total = 64 instead of 256 the BCCAs are denser (Fig. 8), so the
    # mean ratio is held to 20 % and the slope to 0.05 of the paper's -0.12
    assert eq51["fit"]["points"] >= 5
    assert abs(eq51["ratio_mean"] - 1) < 0.2
    assert abs(eq51["fit"]["b"] + 0.12) < 0.05


def test_contacts_grow_as_eq_56(quick):
    eq56 = quick[0]["eq56"]
    # the slope is the paper's to 0.1; the prefactor lies below 1 at N_total = 64, where
    # edge grains (contacts 1) are a larger share (sec. 5.3, Fig. 12): within a factor 1.6
    assert abs(eq56["fit"]["b"] - 0.75) < 0.1
    assert 1 / 1.6 < eq56["ratio_mean"] < 1.6


def test_ice_compacts_further_than_quartz(quick):
    sets = quick[0]["sets"]
    # eq. (57): k = 1.6 for ice against 1.3-1.4 for quartz; E_roll / E_break 1.94 vs 18.6
    assert sets["ice 2A"]["n_con_max"] > sets["quartz 2A"]["n_con_max"] + 0.1
    assert sets["ice 2A"]["n_con_max"] == pytest.approx(sets["ice 2A"]["eq57"][0], abs=0.1)


def test_disruption_is_scaled_by_n_k_E_break(quick):
    sets = quick[0]["sets"]
    # the paper: grains are lost from ~3 n_k E_break, catastrophic above ~10 (Fig. 14);
    # smaller aggregates disrupt more easily (Fig. 15a): a factor 3 either way at N = 64
    for name in ("ice 2A", "quartz 2A"):
        assert 1.0 < sets[name]["disruption_starts_at_y"] < 9.0, name
        assert 10 / 3 < sets[name]["catastrophic_at_y"] < 30, name


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    results = run_quick("bpca3d_models", tmp_path_factory.mktemp("models"))
    return json.loads((results / "summary.json").read_text())


def test_the_four_models_keep_the_papers_order(models):
    """The quick variant of validation/bpca3d_models.py (2 x 24 ice BPCAs, 10, 39.8 and
    100 m/s, B_off^2 0 and 1/2): the 3D BPCA paper's ordering of the models."""
    at = models["24"]
    assert all(reasons == {"settled": 6} for reasons in at["stop_reasons"].values())
    assert at["energy_error_max"] < 1e-3
    curves = models["curves"]["24"]
    # Fig. 2: without friction the aggregates grow less at every speed, and v_fra is lowest.
    # f_gro moves in steps of one grain, 1 / N_pro: at 100 m/s both models leave a largest
    # fragment of about 5 grains, and which is the larger is within that step
    for free, fric in zip(curves["frictionless"]["mean_f_gro"],
                          curves["frictional"]["mean_f_gro"]):
        assert free <= fric + 1 / 24
    assert at["lowest_v_fra"] == "frictionless"
    assert at["v_fra"]["frictionless"] < at["v_fra"]["frictional"]
    # Fig. 3 at 39.8 m/s: frictionless grains without damping end in small fragments far
    # more often than with friction or with damping. One seed at two B_off resolves the
    # order against friction (all 48 grains against 30 with these aggregates), not a factor
    small = at["grains_in_fragments_of_at_most_16"]["39.8"]
    assert small["frictionless"] > small["frictional"]
    assert small["frictionless"] > 2 * small["frictionless, T_vis 6 ps"]


def test_two_grains_stick_at_the_elastic_threshold_and_far_above_it_with_damping(tmp_path):
    # validation/two_grain_sticking.py --quick: without damping the bisected threshold is
    # eq. (6)'s energy balance (a 1 % bracket, dt = 0.005 t_c moves it by < 0.1 %); T_vis
    # = 6 ps of eq. (A.5) only adds dissipation, so the threshold can only rise; with F_D
    # off while the contact is stretched (damp_tension off) less is dissipated than with it
    # on and more than without damping, so the threshold lies between the two
    subprocess.run([sys.executable, str(ROOT / "validation" / "two_grain_sticking.py"),
                    "--quick", "--results", str(tmp_path)], check=True, timeout=300,
                   capture_output=True)
    summary = json.loads((tmp_path / "summary.json").read_text())
    elastic, damped, compressed_only = summary["thresholds"]
    assert (damped["damp_tension"], compressed_only["damp_tension"]) == (True, False)
    v_el = summary["elastic_threshold"]
    assert v_el == pytest.approx(1.9345 * scales(ICE, 1e-7).v0, rel=1e-3)    # sqrt(3.742) v0
    assert elastic["v_stuck"] <= v_el * 1.003 and elastic["v_bounced"] >= v_el * 0.997
    assert damped["v_stuck"] > 2.0 * v_el
    assert elastic["v_bounced"] < compressed_only["v_stuck"]
    assert compressed_only["v_bounced"] < damped["v_stuck"]
    assert (tmp_path / "fig_threshold.png").stat().st_size > 0


def test_departed_fragments_leave_the_outcomes_as_they_were(tmp_path):
    # the quick departure study: 2 x 50 frictionless ice grains head-on at 39.8 m/s, 4
    # seeds, with departures and with every fragment kept flying (depart shadow). The
    # rule lets hundreds of fragments go; none of them would have been touched again
    # (same smallest ID and size at the end of the run that kept it flying), and f_gro,
    # N_lar / N and N_cum(<= 1, 4, 16) agree within two combined standard errors
    results = run_quick("departure", tmp_path)
    summary = json.loads((results / "summary.json").read_text())["comparison"]
    rule = summary.pop("rule")
    errors = summary.pop("energy_error_max")
    assert rule["runs"] == 4 and rule["would_depart"] > 100
    assert rule["wrong"] <= 0.01 * rule["would_depart"]
    assert max(errors.values()) < 1e-3
    (case,) = summary.values()
    assert case["runs"] == {"yes": 4, "shadow": 4}
    for measure in ("f_gro", "N_lar_over_N", "N_cum_le_1_over_N", "N_cum_le_4_over_N",
                    "N_cum_le_16_over_N"):
        assert case[measure]["agree"], measure


def test_the_paper_size_study_runs_end_to_end_in_small(tmp_path):
    # validation/paper_size.py through the user's commands at 2 x 300 grains, the frictional
    # 20 m/s scene with dt from --dt auto --tolerance 1e-3: it sticks (3D BPCA paper, Fig. 2:
    # f_gro near 1 well below v_fra), the energy error keeps the tolerance dt was chosen for,
    # and the stages and the record are measured. The run takes 40 s on a quiet machine;
    # its limit is 10 minutes: with a campaign at nice 10 holding both cores it once ran
    # past 5
    subprocess.run([sys.executable, str(ROOT / "validation" / "paper_size.py"), "--n", "300",
                    "--only", "sticking", "--limit-minutes", "10", "--runs",
                    str(tmp_path / "runs"), "--results", str(tmp_path / "results")],
                   check=True, timeout=900, capture_output=True)
    state = json.loads((tmp_path / "results" / "sticking" / "stages.json").read_text())
    assert state["outcome"]["stop_reason"] == "settled"
    assert state["outcome"]["growth_efficiency"] > 0.9
    assert state["outcome"]["energy_error"] < 1e-3
    assert all(state[stage]["seconds"] > 0 for stage in ("setup", "run", "analyse"))
    assert state["run"]["per_check"]["memory_mb_last"] > 0
    assert 0 < state["outputs"]["run_record_mb"] < 5


def test_the_size_study_places_v_fra_and_runs_seed_2_where_it_lies(tmp_path):
    # validation/vfra_size.py --quick: 2 x 24 ice BPCAs, frictional and frictionless at
    # 10, 39.8 and 100 m/s, B_off^2 0 and 1/2, seed 1, then seed 2 at the two speeds on
    # either side of seed 1's v_fra; dt from --dt auto for 1e-3
    results = run_quick("vfra_size", tmp_path)
    summary = json.loads((results / "summary.json").read_text())
    runs = read_csv(results / "runs.csv")
    at = summary["sizes"]["24"]
    assert all(c["stop_reasons"] == {"settled": 10} for c in at.values())
    # the frictionless bound of jkrdt.timestep was fit on 2 x 100 grains and more; at
    # 2 x 24 and 10 m/s it came out 18 % above the tolerance (1.18e-3), so 2x here
    assert max(r["energy_error"] for r in runs) < 2e-3
    # a campaign on 2 ranks runs one collision per rank: each run's compute is its loop
    # time on one core
    assert all(r["ranks"] == 1 for r in runs)
    for model, c in at.items():
        assert c["core_hours"] == pytest.approx(
            sum(r["loop_seconds"] for r in runs if r["model"] == model) / 3600, rel=1e-12)
        # v_fra lies between the grid speeds where <f_gro> turns from > 0 to <= 0; seed 2
        # ran at the two speeds on either side of seed 1's v_fra (which seed 2 may move),
        # at both offsets
        lo, hi = c["bracket"]
        assert lo < c["v_fra"] < hi
        second = [(r["v_col"], r["B_off"]) for r in runs
                  if r["model"] == model and r["seed"] == 2]
        assert len(second) == 4 and sorted({v for v, _ in second}) == c["seed_2_at"]
        grid = sorted({r["v_col"] for r in runs if r["model"] == model})
        assert c["seeds_v_fra"] and all(grid[0] < v < grid[-1] for v in c["seeds_v_fra"])
    # the 3D paper's order: without friction the aggregates break at lower speed
    assert at["frictionless"]["v_fra"] < at["frictional"]["v_fra"]
    # f_gro per offset (by_offset, 39.8 m/s for the frictionless model): its <f_gro> is
    # eq. (1) over the same runs as the curve's at that speed, the same number
    c = at["frictionless"]
    o = summary["by_offset"]["frictionless"]["by_size"]["48"]
    assert o["mean_f_gro"] == pytest.approx(c["mean_f_gro"][c["v_col"].index(39.8)], abs=1e-12)
    assert len(o["f_gro"]) == 2 and all(-1 <= f <= 1 for f in o["f_gro"].values())
    # the committed runs.csv is the study's ledger: on a machine that lost the runs, a
    # second call runs none of them again and writes the same table and summary
    shutil.rmtree(tmp_path / "runs")
    table = (results / "runs.csv").read_text()
    run_quick("vfra_size", tmp_path)
    assert not (tmp_path / "runs").exists()
    assert (results / "runs.csv").read_text() == table
    assert json.loads((results / "summary.json").read_text())["sizes"] == summary["sizes"]
    # --summary-only runs nothing: with one run taken out of the ledger (as if it had not
    # finished yet), the table lacks just that run and no run directory appears
    lines = table.splitlines(keepends=True)
    (results / "runs.csv").write_text("".join(lines[:-1]))
    run_quick("vfra_size", tmp_path, "--summary-only")
    assert not (tmp_path / "runs").exists()
    assert (results / "runs.csv").read_text() == "".join(lines[:-1])


def test_the_damped_dt_study_compares_two_steps_whose_ledgers_close(tmp_path):
    # validation/damped_dt.py --quick: damped frictionless 2 x 24 ice BPCAs at 63.1 m/s,
    # B_off^2 3/12, 3 seeds, at dt = 0.014 t_c and at --dt auto for 1e-3. The auto step
    # is timestep.choose's for that scene, and larger (else the study compares nothing);
    # every run's energy ledger closes to the tolerance (damping is booked, not lost); the
    # comparison is the ensembles' difference against twice its standard error
    from jkrdt import timestep

    results = run_quick("damped_dt", tmp_path)
    summary = json.loads((results / "summary.json").read_text())
    runs = read_csv(results / "runs.csv")
    assert summary["runs_finished"] == 6
    want, _ = timestep.choose(1e-3, 63.1, scales(ICE, 1e-7).v0,
                              model="frictionless", n_total=48, damped=True)
    assert summary["dt_auto_over_tc"] == [pytest.approx(want, rel=1e-12)]
    assert want > 0.014
    assert max(r["energy_error"] for r in runs) < 1e-3
    f = summary["results"]["frictionless, T_vis 6 ps"]["0.2500"]["f_gro"]
    mine = [r["growth_efficiency"] for r in runs if r["step"] == "dt auto"]
    assert f["at_auto"][0] == pytest.approx(np.mean(mine), abs=1e-12)
    assert f["agree"] == (abs(f["difference"]) <= 2 * f["se"])


def test_the_damped_tension_study_runs_the_variant_and_its_ledgers_close(tmp_path):
    # validation/damped_tension.py --quick: damped frictional 2 x 24 ice BPCAs at 63.1
    # m/s, B_off^2 3/12, 3 seeds, with eq. (A.5) as printed and with damp_tension off. Each
    # variant's deck gives pair jkr/dt its own pair_coeff line; every run's energy ledger
    # closes to --dt auto's tolerance with its damping booked (the variant's damping is
    # booked as the printed one's); the comparison is the ensembles' difference against
    # twice its standard error
    results = run_quick("damped_tension", tmp_path)
    summary = json.loads((results / "summary.json").read_text())
    runs = read_csv(results / "runs.csv")
    assert summary["runs"] == {"as printed": 3, "damp_tension off": 3}
    assert max(r["energy_error"] for r in runs) < 1e-3
    assert all(r["damping_share"] > 0 for r in runs)
    for variant, folder in (("as printed", "as_printed"), ("damp_tension off", "damp_tension_off")):
        decks = list((tmp_path / "runs").rglob(f"{folder}/*/*/*/in.collision.lmp"))
        assert len(decks) == 3
        assert all(("damp_tension off" in d.read_text()) == (variant != "as printed")
                   for d in decks)
    f = summary["results"]["0.2500"]["f_gro"]
    mine = [r["growth_efficiency"] for r in runs if r["variant"] == "damp_tension off"]
    assert f["damp_tension_off"][0] == pytest.approx(np.mean(mine), abs=1e-12)
    assert f["agree"] == (abs(f["difference"]) <= 2 * f["se"])


def test_the_offset_grid_study_averages_the_papers_twelfths_and_the_four(tmp_path):
    # validation/b_off_grid.py --quick: frictional 2 x 24 ice BPCAs at 15.8 m/s, one seed,
    # B_off^2 = 0, 1/12, 2/12, 3/12, 6/12, 9/12, 1. Far below v_fra the head-on pair sticks
    # whole (f_gro = 1); at B_off = 1 the characteristic spheres only touch and the two
    # aggregates part whole (f_gro = 0, at most a grain moved). <f_gro> of eq. (1) is the
    # trapezoid in B_off^2 over every offset run, and over the four of the other studies
    # with the 9/12 value held to 1
    results = run_quick("b_off_grid", tmp_path)
    summary = json.loads((results / "summary.json").read_text())
    runs = read_csv(results / "runs.csv")
    assert len(runs) == 7 and all(r["stop_reason"] == "settled" for r in runs)
    assert max(r["energy_error"] for r in runs) < 1e-3
    f = {round(r["B_off"] ** 2 * 12): r["growth_efficiency"] for r in runs}
    assert f[0] == 1.0
    assert abs(f[12]) <= 1 / 24
    a = summary["results"]["frictional at 15.8 m/s"]
    b2 = sorted(f)
    assert a["mean_f_gro_all"] == pytest.approx(
        np.trapezoid([f[k] for k in b2], [k / 12 for k in b2]), abs=1e-12)
    assert a["mean_f_gro_four"] == pytest.approx(
        np.trapezoid([f[0], f[3], f[6], f[9], f[9]], [0, 0.25, 0.5, 0.75, 1.0]), abs=1e-12)


ICE_TC = scales(ICE, 1.0e-7).t_c


def test_the_paper_protocol_study_averages_twelve_offsets_and_keeps_every_record(tmp_path):
    # validation/paper_protocol.py --quick, questions a and b: 2 x 24 frictionless ice
    # BPCAs, seeds 1 and 2, head-on at 100 m/s (the paper's f_gro about -1: far above this
    # size's v_fra, about 15 m/s, both shatter) and at 39.8 m/s on the paper's twelve
    # offsets. <f_gro> is the trapezoid over k/12 with the grazing 12/12 at 0, each seed
    # on its own and both; the results come from the kept records alone
    results = run_quick("paper_protocol", tmp_path, "--questions", "a", "b")
    runs = read_csv(results / "runs.csv")
    assert len(runs) == 2 + 24 and all(r["stop_reason"] == "settled" for r in runs)
    assert max(r["energy_error"] for r in runs) < 1e-3
    a = [r for r in runs if r["question"] == "a"]
    assert all(r["growth_efficiency"] < -0.5 for r in a)
    summary = json.loads((results / "summary.json").read_text())["results"]
    b = summary["by_question"]["b"]["24"]
    assert b["paper_grid"] and len(b["B_off2"]) == 12
    k = np.arange(13) / 12
    per_seed = {}
    for seed in (1, 2):
        f = [r["growth_efficiency"] for r in sorted(
            (r for r in runs if r["question"] == "b" and r["seed"] == seed),
            key=lambda r: r["B_off"])]
        per_seed[seed] = np.trapezoid(f + [0.0], k)
    m = b["mean_f_gro"]
    assert m["per_seed"]["1"] == pytest.approx(per_seed[1], abs=1e-12)
    assert m["per_seed"]["2"] == pytest.approx(per_seed[2], abs=1e-12)
    assert m["mean"] == pytest.approx(np.mean(list(per_seed.values())), abs=1e-12)
    assert m["se"] == pytest.approx(abs(per_seed[1] - per_seed[2]) / 2, abs=1e-12)
    assert b["sign_open"] is None
    # the same runs on the other studies' four offsets 0, 3/12, 6/12, 9/12, by their
    # quadrature: the trapezoid with 9/12's value held to B_off^2 = 1
    four = b["mean_f_gro_four_offsets"]
    for seed in (1, 2):
        f = {round(12 * float(r["B_off"]) ** 2): r["growth_efficiency"] for r in runs
             if r["question"] == "b" and r["seed"] == seed}
        want = np.trapezoid([f[0], f[3], f[6], f[9], f[9]], [0, 0.25, 0.5, 0.75, 1.0])
        assert four["per_seed"][str(seed)] == pytest.approx(want, abs=1e-12)
    # with offsets still to run, what they must average for <f_gro> < 0: eq. (1) weighs
    # each inner twelfth 1/12, so with 4/12, 5/12 and 7/12 open they weigh 3/12, and the
    # run offsets with the open ones at that average give <f_gro> = 0
    sys.path.insert(0, str(ROOT / "validation"))
    try:
        from paper_protocol import what_the_rest_needs
    finally:
        sys.path.pop(0)
    open_k = (4, 5, 7)
    ran = [j for j in range(12) if j not in open_k]
    need = what_the_rest_needs([j / 12 for j in ran], [b["f_gro"][j] for j in ran])
    assert need["to_run"] == ["4/12", "5/12", "7/12"]
    assert need["weight_to_run"] == pytest.approx(3 / 12, abs=1e-12)
    filled = [need["rest_must_average_below"] if j in open_k else b["f_gro"][j]
              for j in range(12)]
    assert np.trapezoid(filled + [0.0], k) == pytest.approx(0.0, abs=1e-12)
    # N_con - N_cut is the change in bonded contacts, exactly, in every run
    for o in map(json.loads, (p.read_text() for p in (results / "records").rglob(
            "outcome.json"))):
        assert o["N_con"] - o["N_cut"] == o["contacts_end"] - o["contacts_start"]
    # f_gro read from each run's settle checks at the paper's snapshot times: after the run
    # has settled it is the outcome's
    for r in runs:
        if r["time_end_over_tc"] * ICE_TC < 1.6e-6:
            assert r["f_gro_at_1.6_us"] == r["growth_efficiency"]
    rows = {s["paper"].split(" (")[0]: s for s in summary["statements"]}
    assert rows["frictionless, undamped: E_dis,c = E_dis,tot"]["holds"]
    # the runs gone, the records alone give the same results, and a campaign whose every
    # run has its record kept is not run again (a new machine redoes nothing); --again
    # runs it anew, the same collision bit for bit on the same build and ranks
    before = (results / "summary.json").read_text()
    shutil.rmtree(tmp_path / "runs")
    run_quick("paper_protocol", tmp_path, "--summary-only")
    assert (results / "summary.json").read_text() == before
    run_quick("paper_protocol", tmp_path, "--questions", "a")
    assert not list((tmp_path / "runs").rglob("log.lammps"))
    assert (results / "summary.json").read_text() == before
    run_quick("paper_protocol", tmp_path, "--questions", "a", "--again", "0")
    again = sorted((tmp_path / "runs").rglob("outcome.json"))
    assert len(again) == 2
    for path in again:
        o = json.loads(path.read_text())
        kept = json.loads((results / "records" / path.relative_to(tmp_path / "runs"))
                          .read_text())
        for key in ("stop_step", "n_largest", "n_fragments", "N_con", "N_cut",
                    "dissipated_fraction", "energy_error"):
            assert o[key] == kept[key], key
    assert (results / "summary.json").read_text() == before
    record = next((results / "records").rglob("outcome.json")).parent
    assert sorted(p.name for p in record.iterdir()) == sorted(
        ["collision.json", "checks.csv", "frames.csv", "outcome.json", "outcome.png",
         "timeline.png"])
    assert json.loads(before)["left_out"] == json.loads(before)["ended_at_cap"] == []
    # a run that ended at its cap is averaged at its end and listed with the range of its
    # f_gro over the last 1.6 us of its checks (here its whole run, far shorter)
    outcome = json.loads((record / "outcome.json").read_text())
    (record / "outcome.json").write_text(json.dumps(dict(outcome, stop_reason="cap")))
    run_quick("paper_protocol", tmp_path, "--summary-only")
    done = json.loads((results / "summary.json").read_text())
    assert len(read_csv(results / "runs.csv")) == len(runs)
    # the same results, but that the run is read at its cap, not at its settle end
    was, now = json.loads(before)["results"], done["results"]
    question = record.relative_to(results / "records").parts[0].split("_")[1]
    k, seed = f"{outcome['B_off'] ** 2:.4f}", str(outcome["seed"])
    read = now["by_question"][question]["24"]["read"]["per_seed"][k][seed]
    assert read["read_at"] == "cap" and read["f_gro"] == outcome["growth_efficiency"]
    was["by_question"][question]["24"]["read"]["per_seed"][k][seed]["read_at"] = "cap"
    assert now == was
    [cap] = done["ended_at_cap"]
    assert cap["seed"] == outcome["seed"] and done["left_out"] == []
    assert cap["B_off2"] == pytest.approx(outcome["B_off"] ** 2, abs=1e-4)
    checks = read_csv(record / "checks.csv")
    assert checks[-1]["time"] < 1.6e-6
    f = [(c["n_largest"] - outcome["N_tar"]) / outcome["N_pro"] for c in checks]
    assert cap["f_gro_last_span"] == [min(f), max(f)]
    assert f[-1] == outcome["growth_efficiency"]
    # a run that failed or was cut off is left out of the averages, and listed
    (record / "outcome.json").write_text(json.dumps(dict(outcome, stop_reason="cut off")))
    run_quick("paper_protocol", tmp_path, "--summary-only")
    done = json.loads((results / "summary.json").read_text())
    assert len(read_csv(results / "runs.csv")) == len(runs) - 1
    [out] = done["left_out"]
    assert out["stop_reason"] == "cut off" and out["seed"] == outcome["seed"]
    assert out["growth_efficiency"] == outcome["growth_efficiency"]


def test_the_size_trend_study_compares_each_candidate_with_base_on_the_same_seeds(tmp_path):
    # validation/size_trend.py --quick: 2 x 24 ice BPCAs, B_off^2 0 and 1/12, seeds 1 and
    # 2; frictionless at 39.8 m/s in four arms, frictional at 63.1 m/s in two. Each arm
    # changes one thing: dt 0.014 t_c runs at 0.014, base at timestep.choose's step;
    # touching starts with every bond in contact (none lost: 2 (N - 1) contacts in two
    # trees) and its ledger still closes; f_near is the eq. (1)-weighted mean of the
    # offsets per seed, compared by common.within_scatter; f_gro at the snapshot times of a
    # run settled before them is its outcome's
    from jkrdt import timestep

    results = run_quick("size_trend", tmp_path)
    summary = json.loads((results / "summary.json").read_text())
    runs = read_csv(results / "runs.csv")
    assert len(runs) == (4 + 2) * 2 * 2 and summary["runs_finished"] == 24
    assert max(r["energy_error"] for r in runs) < 1e-3
    trend = [r for r in runs if r["question"] == "frictionless_39.8"]
    want, _ = timestep.choose(1e-3, 39.8, scales(ICE, 1e-7).v0, model="frictionless",
                              n_total=48, damped=False)
    steps = {arm: {r["dt_over_tc"] for r in trend if r["arm"] == arm}
             for arm in ("base", "dt_0.014", "touching")}
    assert steps["dt_0.014"] == {0.014}
    assert len(steps["base"]) == 1 and steps["base"] == steps["touching"]
    assert steps["base"].pop() == pytest.approx(want, rel=1e-12)
    for checks in (results / "records" / "frictionless_39.8" / "touching").rglob("checks.csv"):
        assert read_csv(checks)[0]["contacts"] == 2 * (24 - 1)
    asked = summary["asked"]["frictionless 39.8"]
    for arm in ("base", "touching"):
        per_seed = []
        for seed in (1, 2):
            f = {r["b2_twelfths"]: r["f_gro"] for r in trend
                 if r["arm"] == arm and r["seed"] == seed}
            per_seed.append((0.5 * f[0] + f[1]) / 1.5)
        got = asked["arms"][arm]["f_near"]
        assert got[0] == pytest.approx(np.mean(per_seed), abs=1e-12)
        assert got[1] == pytest.approx(abs(per_seed[0] - per_seed[1]) / 2, abs=1e-12)
    t = summary["results"]["frictionless 39.8"]["touching"]
    assert t["agree"] == (abs(t["difference"]) <= 2 * t["se"] + 1e-12)
    assert t["mean_f_gro_difference"] == pytest.approx(t["difference"] * 3.5 / 12)
    assert set(summary["results"]["frictional 63.1"]) >= {"dt 0.014"}
    for r in runs:
        if r["time_end_over_tc"] * ICE_TC < 1.6e-6:
            assert r["f_gro_at_1.6_us"] == r["f_gro"]
    # the dissipation table: each base run's E_dis / E_imp and N_con / N_tot, as recorded
    table = summary["dissipation_by_size"]["24"]["0/12"]
    mine = [json.loads(p.read_text()) for p in (results / "records" / "frictionless_39.8" /
                                                 "base").rglob("outcome.json")]
    mine = [o for o in mine if o["B_off"] == 0]
    assert table["E_dis"] == pytest.approx(np.mean([o["dissipated_fraction"] for o in mine]))
    assert table["N_con"] == pytest.approx(np.mean([o["N_con"] / 48 for o in mine]))


def test_a_grid_that_misses_v_fra_is_extended_along_the_papers_speeds():
    # at 2 x 5000 the damped frictionless <f_gro> was <= 0 already at the slowest speed of
    # the grid that 2 x 1000 placed (50.1 m/s): the study then adds the paper's next speed,
    # 10^(1 + 0.1 k), below it; above the fastest if <f_gro> is > 0 at every speed; none
    # once the slowest speed grows and a crossing is bracketed, or the step would leave the
    # paper's range (10-125.9 m/s)
    sys.path.insert(0, str(ROOT / "validation"))
    try:
        from vfra_size import curve, next_speed
    finally:
        sys.path.pop(0)

    def rows(f_by_v):
        return [dict(v_col=v, B_off=0.0, seed=1, growth_efficiency=f, stop_reason="settled")
                for v, f in f_by_v.items()]

    assert next_speed(curve(rows({50.1: -0.01, 63.1: -0.1, 100.0: -0.05}))) == 39.8
    # a curve near 0 that rises and falls again (one seed) still extends below: v_fra is
    # the first speed at which <f_gro> falls to <= 0
    assert next_speed(curve(rows({50.1: -0.01, 63.1: -0.1, 100.0: 0.001, 125.9: -0.2}))) \
        == 39.8
    assert next_speed(curve(rows({50.1: 0.3, 79.4: 0.1, 100.0: 0.02}))) == 125.9
    assert next_speed(curve(rows({39.8: 0.2, 50.1: -0.01, 63.1: -0.1}))) is None
    assert next_speed(curve(rows({10.0: -0.2, 12.6: -0.3}))) is None
    assert next_speed(curve(rows({100.0: 0.2, 125.9: 0.1}))) is None


def test_seed_2_follows_v_fra_where_it_moves():
    # 2 x 5000, damped frictionless: seed 1 fell to <= 0 between 39.8 and 50.1 m/s, seed 2
    # ran there and grew at 50.1, so both seeds' curve crosses 0 between 50.1 and 63.1:
    # seed 2 must run at 63.1 too (at every offset), and nowhere else
    sys.path.insert(0, str(ROOT / "validation"))
    try:
        from vfra_size import seed_2_missing
    finally:
        sys.path.pop(0)

    def run(v, seed, f, b2=0.0):
        return dict(v_col=v, B_off=b2 ** 0.5, seed=seed, growth_efficiency=f,
                    stop_reason="settled")

    rows = [run(39.8, 1, 0.1), run(50.1, 1, -0.01), run(63.1, 1, -0.1),
            run(39.8, 2, 0.1), run(50.1, 2, 0.2)]
    assert seed_2_missing(rows, offsets=1) == [63.1]
    assert seed_2_missing(rows + [run(63.1, 2, -0.2)], offsets=1) == []
    # with two offsets, seed 2 at 63.1 at one of them is not yet there
    both = [run(r["v_col"], r["seed"], r["growth_efficiency"], b2) for r in rows
            for b2 in (0.0, 0.5)]
    assert seed_2_missing(both + [run(63.1, 2, -0.2)], offsets=2) == [63.1]


def test_both_seeds_run_further_when_only_seed_1_brackets_v_fra(monkeypatch, tmp_path):
    # 2 x 5000, undamped frictional: seed 1 grew at 63.1 m/s and fell to <= 0 at 79.4, so
    # seed 2 ran at those two speeds and grew at both; both seeds' <f_gro> is then > 0 at
    # every speed run. The study must run both seeds at the paper's next speed (100 m/s),
    # then stop once both seeds' curve crosses 0
    sys.path.insert(0, str(ROOT / "validation"))
    try:
        import vfra_size
    finally:
        sys.path.pop(0)
    f_gro = {(1, 39.8): 0.3, (1, 50.1): 0.2, (1, 63.1): 0.05, (1, 79.4): -0.02,
             (2, 63.1): 0.08, (2, 79.4): 0.03, (1, 100.0): -0.1, (2, 100.0): -0.08}
    ran, calls = [], []

    def campaign(name, model, n, speeds, b_off2, seed, home, ranks, ledger):
        calls.append((name, seed, tuple(speeds)))
        new = [dict(v_col=v, B_off=0.0, seed=seed, growth_efficiency=f_gro[seed, v],
                    stop_reason="settled") for v in speeds]
        ran.extend(new)
        return new

    monkeypatch.setattr(vfra_size, "campaign", campaign)
    monkeypatch.setattr(vfra_size, "finished", lambda home, n, model, ledger: list(ran))
    plan = dict(grids={"frictional": [39.8, 50.1, 63.1, 79.4]}, b_off2=[0.0], extend=3,
                follow=2)
    vfra_size.run_model("frictional", 5000, plan, tmp_path, 1, [])
    assert calls == [("seed1", 1, (39.8, 50.1, 63.1, 79.4)), ("seed2", 2, (63.1, 79.4)),
                     ("seed1_v100", 1, (100.0,)), ("seed2_v100", 2, (100.0,))]
    both = vfra_size.curve(ran)
    assert both["bracket"] == [79.4, 100.0]


def test_the_paper_size_collisions_of_the_named_models_run_alone(monkeypatch, tmp_path):
    # --paper-size --models: the 2 x 50000 collisions of the damped models only, offset by
    # offset in the order asked, at each model's PAPER_SIZE speed, seed 1 on all ranks
    sys.path.insert(0, str(ROOT / "validation"))
    try:
        import vfra_size
    finally:
        sys.path.pop(0)
    calls = []
    monkeypatch.setattr(vfra_size, "campaign",
                        lambda name, model, n, speeds, b_off2, seed, home, ranks, ledger,
                        ranks_per_run: calls.append((model, n, speeds, b_off2, seed,
                                                     ranks_per_run)))
    damped = ["frictional, T_vis 6 ps", "frictionless, T_vis 6 ps"]
    vfra_size.run_paper_size(tmp_path, 2, [0.25, 0.75], [], damped)
    assert [(c[0], c[3]) for c in calls] == [(m, [b2]) for b2 in (0.25, 0.75)
                                             for m in reversed(damped)]
    assert all(c[1] == 50000 and c[2] == [63.1] and c[4] == 1 and c[5] == 2 for c in calls)


def test_the_damping_effect_is_the_damped_curve_minus_its_undamped_twin():
    # per size, at the speeds both models ran: <f_gro> (eq. 1) with damping minus without;
    # the paper has the two frictional models within about 0.1 of each other
    sys.path.insert(0, str(ROOT / "validation"))
    try:
        from vfra_size import damping_effect
    finally:
        sys.path.pop(0)

    def run(model, v, f, b2):
        return dict(size=1000, model=model, v_col=v, B_off=b2 ** 0.5, seed=1,
                    growth_efficiency=f, stop_reason="settled")

    rows = [run("frictional", v, f, b2) for v, f in ((63.1, 0.2), (100.0, -0.1))
            for b2 in (0.0, 0.5)]
    rows += [run("frictional, T_vis 6 ps", v, f, b2) for v, f in ((50.1, 0.5), (63.1, 0.25),
                                                                  (100.0, 0.2))
             for b2 in (0.0, 0.5)]
    effect = damping_effect(rows)["frictional, T_vis 6 ps"]["2000"]
    assert effect["v_col"] == [63.1, 100.0]
    assert effect["difference"] == pytest.approx([0.05, 0.3], abs=1e-12)
    assert effect["largest"] == pytest.approx(0.3, abs=1e-12)
    assert damping_effect(rows)["frictionless, T_vis 6 ps"] == {}


def test_the_size_trend_places_v_fra_as_the_smaller_study_did():
    # validation/vfra_size.py takes the committed runs of bpca3d_models (2 x 100, 250,
    # 1000) into its trend of v_fra against N: from those rows it must find the v_fra that
    # the smaller study's summary gives (its seeds averaged per B_off^2, then eq. 1)
    sys.path.insert(0, str(ROOT / "validation"))
    try:
        from vfra_size import SMALLER, size_trend
    finally:
        sys.path.pop(0)
    trend = size_trend(read_csv(SMALLER))
    committed = json.loads((SMALLER.parent / "summary.json").read_text())["curves"]
    for model, t in trend.items():
        for p in t["points"]:
            want = committed[str(int(p["n_total"]) // 2)][model]["v_fra"]
            assert (p["v_fra"] is None) == (want is None), (model, p)
            if want is not None:
                assert p["v_fra"] == pytest.approx(want, rel=1e-12)
                assert p["low"] <= p["v_fra"] <= p["high"]
    # three sizes place the two undamped models: v_fra grows with N (41 -> 54 and
    # 15 -> 22 m/s), and the fit's slope is positive
    for model in ("frictional", "frictionless"):
        assert trend[model]["fit"]["b"] > 0


def test_the_fixed_end_study_continues_settled_runs_as_the_same_collision(tmp_path):
    # validation/fixed_end.py --quick: the quick protocol's head-on 2 x 24 runs at 100 m/s
    # (settled by about 400 t_c) continued from their final.restart to 1200 t_c on 2 ranks
    # (they ran on 1), the settle rule watching only. The continuation is the same
    # collision: its first sample is the settled run's last in every energy channel (the
    # contact state and the ledger come back with the restart file), the conserved total
    # (ke + erot + pe + dissipated) holds to --dt auto's 1e-3 E_imp over it, its checks go
    # on a whole check interval apart, and it ends at the first check at or after the
    # fixed end (a cap is a whole number of checks)
    from jkrdt import ledger, rundir

    protocol_results = run_quick("paper_protocol", tmp_path / "protocol", "--questions", "a")
    results = run_quick("fixed_end", tmp_path / "fixed", "--np", "2",
                        "--protocol-runs", str(tmp_path / "protocol" / "runs"),
                        "--protocol-records", str(protocol_results / "records"))
    summary = json.loads((results / "summary.json").read_text())
    rows = summary["results"]["offsets"]
    assert len(rows) == 2 and all(r["continued"] and r["reaches_fixed_end"] for r in rows)
    for r in rows:
        before = tmp_path / "protocol" / "runs" / r["record"]
        after = tmp_path / "fixed" / "runs" / r["record"]
        meta = json.loads((before / "collision.json").read_text())
        a = ledger.energy_budget(rundir.read_thermo(before / "log.lammps"))
        b = ledger.energy_budget(rundir.read_thermo(after / "log.lammps"))
        for channel in a:
            assert b[channel][0] == a[channel][-1], channel
        assert np.abs(b["total"] - b["total"][0]).max() < 1e-3 * meta["E_imp"]
        first, more = read_csv(before / "checks.csv"), read_csv(after / "checks.csv")
        steps = [c["step"] for c in first] + [c["step"] for c in more]
        assert len(set(np.diff(steps))) == 1
        t_c = first[-1]["time"] / first[-1]["step"] / meta["dt_over_tc"]
        every = steps[1] - steps[0]
        assert 1200 * t_c <= more[-1]["time"] < 1200 * t_c + every * meta["dt_over_tc"] * t_c
        assert r["fixed_end_us"] == pytest.approx(more[-1]["time"] * 1e6, rel=1e-12)
        assert r["f_gro_fixed_end"] == (more[-1]["n_largest"] - 24) / 24
    # the protocol's summary reads each run where its continuation ended: here at the
    # fixed end, f_gro that of the continuation's last check
    def read_by_protocol(continued):
        run_quick("paper_protocol", tmp_path / "protocol", "--summary-only",
                  "--continued", str(continued))
        s = json.loads((protocol_results / "summary.json").read_text())
        return s["results"]["by_question"]["a"]["24"]["read"]["per_seed"]["0.0000"]

    read = read_by_protocol(results / "records")
    for r in rows:
        assert read[str(r["seed"])]["read_at"] == "fixed end"
        assert read[str(r["seed"])]["f_gro"] == r["f_gro_fixed_end"]
        assert read[str(r["seed"])]["time_us"] == r["fixed_end_us"]
    # --shape continues a run under the settle rule with shape watched instead: these
    # shattered runs (a largest fragment of a few grains, below a quarter of the 48, so
    # shape is not watched) stay settled, so each continuation settles at its first check,
    # one check after the run's end, with f_gro as it was
    shaped = run_quick("fixed_end", tmp_path / "shaped", "--np", "2", "--shape",
                       "--protocol-runs", str(tmp_path / "protocol" / "runs"),
                       "--protocol-records", str(protocol_results / "records"))
    for row in json.loads((shaped / "summary.json").read_text())["results"]["offsets"]:
        assert row["continued"] and row["shape_end"] and not row["reaches_fixed_end"]
        more = read_csv(shaped / "records" / row["record"] / "checks.csv")
        before = read_csv(tmp_path / "protocol" / "runs" / row["record"] / "checks.csv")
        every = before[-1]["step"] - before[-2]["step"]
        assert [c["step"] for c in more][-1] == before[-1]["step"] + every
        assert row["f_gro_fixed_end"] == row["f_gro_end"]
    # read there by the protocol's summary: at the shape end, one check on
    read = read_by_protocol(shaped / "records")
    for row in json.loads((shaped / "summary.json").read_text())["results"]["offsets"]:
        assert read[str(row["seed"])]["read_at"] == "shape end"
        assert read[str(row["seed"])]["time_us"] == row["fixed_end_us"]
    # and the study without --shape takes each such continuation on to the fixed end from
    # where it settled, its record extended: the same rows, then on, a check apart
    shaped_rows = {r: read_csv(shaped / "records" / r / "checks.csv")
                   for r in (x["record"] for x in json.loads(
                       (shaped / "summary.json").read_text())["results"]["offsets"])}
    run_quick("fixed_end", tmp_path / "shaped", "--np", "2",
              "--protocol-runs", str(tmp_path / "protocol" / "runs"),
              "--protocol-records", str(protocol_results / "records"))
    for row in json.loads((shaped / "summary.json").read_text())["results"]["offsets"]:
        assert row["reaches_fixed_end"] and not row["shape_end"]
        more = read_csv(shaped / "records" / row["record"] / "checks.csv")
        first = shaped_rows[row["record"]]
        assert more[:len(first)] == first and len(more) > len(first)
        steps = [c["step"] for c in more]
        assert len(set(np.diff(steps))) == 1
    # a settled run whose continuation is not kept and whose run directory is gone (a lost
    # machine) is named, with the command that runs it anew; a run made anew that is not
    # the recorded collision (here its record altered) is not continued onto that record
    first, second = sorted(rows, key=lambda r: r["seed"])
    shutil.rmtree(tmp_path / "fixed" / "results" / "records" / first["record"])
    shutil.rmtree(tmp_path / "protocol" / "runs" / first["record"])
    outcome = protocol_results / "records" / second["record"] / "outcome.json"
    o = json.loads(outcome.read_text())
    outcome.write_text(json.dumps(dict(o, n_largest=o["n_largest"] + 1)))
    shutil.rmtree(tmp_path / "fixed" / "results" / "records" / second["record"])
    shutil.rmtree(tmp_path / "fixed" / "runs" / second["record"])
    said = subprocess.run([sys.executable, str(ROOT / "validation" / "fixed_end.py"), "--quick",
                           "--runs", str(tmp_path / "fixed" / "runs"), "--results",
                           str(results), "--protocol-runs", str(tmp_path / "protocol" / "runs"),
                           "--protocol-records", str(protocol_results / "records")],
                          check=True, capture_output=True, text=True, timeout=600).stdout
    assert f"{second['record']}: not continued: this run is not the one recorded " \
           f"(n_largest {o['n_largest']} against {o['n_largest'] + 1})" in said
    assert not (tmp_path / "fixed" / "runs" / second["record"]).exists()
    summary = json.loads((results / "summary.json").read_text())["results"]
    assert [m["record"] for m in summary["not_at_hand"]] == [first["record"]]
    assert summary["not_at_hand"][0]["twelfths"] == 0
    assert "--questions a --again 0" in said
    # with --anew it is continued all the same, as another run of the same collision: its
    # own small record goes in the continuation's (anew/), and it is read on from its own
    # checks, not the record's: at the fixed end, f_gro that of the continuation's last
    # check, whatever the altered record says
    said = subprocess.run([sys.executable, str(ROOT / "validation" / "fixed_end.py"), "--quick",
                           "--anew", "--runs", str(tmp_path / "fixed" / "runs"), "--results",
                           str(results), "--protocol-runs", str(tmp_path / "protocol" / "runs"),
                           "--protocol-records", str(protocol_results / "records")],
                          check=True, capture_output=True, text=True, timeout=600).stdout
    assert f"{second['record']}: not the run recorded (n_largest" in said
    kept = results / "records" / second["record"]
    run = tmp_path / "protocol" / "runs" / second["record"]
    assert (kept / "anew" / "outcome.json").read_text() == (run / "outcome.json").read_text()
    assert (kept / "anew" / "checks.csv").read_text() == (run / "checks.csv").read_text()
    sys.path.insert(0, str(ROOT / "validation"))
    from paper_protocol import QUICK_CAP_TC
    from readings import read

    last = read_csv(kept / "checks.csv")[-1]
    r = read(json.loads(outcome.read_text()), outcome.parent, kept, QUICK_CAP_TC)
    assert r["anew"] and r["read_at"] == "fixed end"
    assert r["f_gro"] == (last["n_largest"] - 24) / 24
    row = next(x for x in json.loads((results / "summary.json").read_text())["results"][
        "offsets"] if x["record"] == second["record"])
    assert row["anew"] and row["f_gro_fixed_end"] == r["f_gro"]


def test_each_paper_size_record_is_read_where_its_outcome_is_decided():
    # validation/readings.py on the committed records of question b at 2 x 50000: 1/12
    # settled with its body stretching (r_g +4.2 % over the rule's window) and was
    # continued, so it is read at the fixed end, 16000 t_c, from its continuation's check
    # there; 3/12 settled stretching (+2.3 %, above the rule's 1 % tolerance), its
    # continuation was lost, and the run made anew on another build (another run of the
    # same collision) was continued until settled with shape watched, so it is read at
    # that shape end from its own checks; 4/12 grew +0.96 %, within the tolerance, so the
    # rule with shape watched ends it where it ended, its f_gro the record's
    sys.path.insert(0, str(ROOT / "validation"))
    from paper_protocol import PAPER_CAP_TC
    from readings import read

    records = ROOT / "validation" / "paper_protocol" / "records"
    kept = ROOT / "validation" / "fixed_end" / "records"

    def reading(k):
        where = Path(f"n50000_b_b2_{k / 12:.4f}") / "v39.8" / f"b2_{k / 12:.4f}" / "seed1"
        o = json.loads((records / where / "outcome.json").read_text())
        return o, read(o, records / where, kept / where, PAPER_CAP_TC), kept / where

    from jkrdt import rundir

    o, r, more = reading(1)
    fixed = PAPER_CAP_TC * rundir.read(more).scales.t_c     # 4.4 us
    at = next(c for c in read_csv(more / "checks.csv") if c["time"] >= fixed * (1 - 1e-9))
    assert r["read_at"] == "fixed end" and o["growth_efficiency"] > 0.8
    assert r["f_gro"] == pytest.approx((at["n_largest"] - 50000) / 50000, abs=1e-12)
    assert r["f_gro"] == pytest.approx(-0.272, abs=1e-3)
    o, r, more = reading(3)
    assert r["read_at"] == "shape end" and r["anew"] and o["growth_efficiency"] > 0
    last = read_csv(more / "checks.csv")[-1]
    assert r["f_gro"] == pytest.approx((last["n_largest"] - 50000) / 50000, abs=1e-12)
    assert r["f_gro"] == pytest.approx(-0.075, abs=1e-3)
    o, r, _ = reading(4)
    assert r["read_at"] == "settle end" and r["f_gro"] == o["growth_efficiency"]
    # the size trend reads the same records so: 1/12 at its fixed end, 3/12 at its shape
    # end, f_near at 2 x 50000 eq. (1)'s weights 1/24, 1/12, 1/12, 1/12 over 0 ... 3/12;
    # where the settle rule ended them, as they were
    from size_trend import dissipation_runs, size_rows

    big = size_rows(dissipation_runs(ROOT / "validation" / "size_trend" / "records",
                                     records))[50000]
    assert big["per_offset"]["1/12"] == pytest.approx(-0.272, abs=1e-3)
    assert big["per_offset_settle_end"]["1/12"] > 0.8
    assert big["open"] == []
    f = big["per_offset"]
    assert big["f_near"] == pytest.approx(
        (f["0/12"] / 2 + f["1/12"] + f["2/12"] + f["3/12"]) / 3.5, abs=1e-12)
    assert big["f_near"] == pytest.approx(-0.034, abs=1e-3)
    # the paper's "N_cut exceeds N_tot from 10 to 100 m/s" (undamped frictionless) fails
    # at the paper's size only where the two aggregates pass: 11/12 broke 0.87 N_tot, and
    # the committed statement names that run as its exception
    o, _, _ = reading(11)
    assert o["diagnostics"]["N_cut"] / o["n_total"] == pytest.approx(0.873, abs=1e-3)
    said = json.loads((ROOT / "validation" / "paper_protocol" / "summary.json").read_text())
    row = next(s for s in said["results"]["statements"] if "N_cut > N_tot" in s["paper"])
    assert not row["holds"] and row["measured"].endswith(
        "at or below N_tot at 39.8 m/s, B_off^2 11/12 (2 x 50000, seed 1)")
    # the paper-size scenes that vfra_size ran first on four offsets are paired with
    # their runs here; over those four, eq. (1)'s trapezoid of this study's ends is the
    # four-offset mean of question b, and the earlier runs' is vfra_size's own
    same = said["results"]["same_scenes_in_vfra_size"]
    b50 = said["results"]["by_question"]["b"]["50000"]
    # all twelve offsets read where decided: <f_gro> by eq. (1) with 12/12 as no collision,
    # negative as the paper's v_fra of 30 m/s has it at 39.8 m/s
    k = [j / 12 for j in range(13)]
    got = b50["read"]["mean_f_gro"]["per_seed"]["1"]
    assert got == pytest.approx(np.trapezoid(b50["read"]["f_gro"] + [0.0], k), abs=1e-12)
    assert got == pytest.approx(-0.0437, abs=1e-4)
    assert same["four_offsets"]["b"]["50000"]["1"]["here"] == pytest.approx(
        b50["mean_f_gro_four_offsets"]["per_seed"]["1"], abs=1e-12)
    earlier = {round(12 * p["B_off2"]): p["earlier"]["f_gro"] for p in same["pairs"]
               if p["question"] == "b"}
    assert sorted(earlier) == [0, 3, 6, 9]
    # read where decided, the four offsets' trapezoid stays positive where the twelve's
    # eq. (1) is negative: at the paper's size the grid decides the sign (it weighs the
    # sticking head-on run 1/8, not 1/24, and misses 1/12 and 2/12, whose necks parted)
    f = dict(zip([round(12 * b) for b in b50["read"]["B_off2"]], b50["read"]["f_gro"]))
    read_four = same["four_offsets"]["b"]["50000"]["1"]["read"]
    assert read_four == pytest.approx(np.trapezoid([f[0], f[3], f[6], f[9], f[9]],
                                                   [0, 0.25, 0.5, 0.75, 1.0]), abs=1e-12)
    assert read_four > 0 > got
    # g, the undamped frictional model at 63.1 m/s on the twelve offsets at 2 x 5000 (two
    # seeds): <f_gro> of each seed eq. (1)'s trapezoid, about 0 (the paper's v_fra 60 m/s),
    # below the same runs' four-offset mean and the four-offset mean of vfra_size's runs
    g = said["results"]["by_question"]["g"]["5000"]
    for seed in ("1", "2"):
        f = [g["f_gro_per_seed"][f"{j / 12:.4f}"][seed] for j in range(12)]
        assert g["mean_f_gro"]["per_seed"][seed] == pytest.approx(
            np.trapezoid(f + [0.0], k), abs=1e-12)
        assert g["mean_f_gro"]["per_seed"][seed] < g["mean_f_gro_four_offsets"]["per_seed"][
            seed] < same["four_offsets"]["g"]["5000"][seed]["earlier"]
    assert g["mean_f_gro"]["mean"] == pytest.approx(0.0087, abs=1e-4)
    assert same["four_offsets"]["b"]["50000"]["1"]["earlier"] == pytest.approx(np.trapezoid(
        [earlier[0], earlier[3], earlier[6], earlier[9], earlier[9]],
        [0, 0.25, 0.5, 0.75, 1.0]), abs=1e-12)


def test_a_stopped_campaign_keeps_the_records_of_the_runs_it_finished(tmp_path):
    # validation/common.py run_campaigns: two 2 x 64 collisions at 20 m/s, one after the
    # other, stopped by SIGINT while the second runs. The first run's small record is kept
    # as it is (outcome.json to the digit), the second's is not: a campaign cut off by a
    # lost machine or a signal leaves the runs it finished in the repository. A partial
    # analysis of the cut-off run ("cut off") is no record either, and the resumed
    # campaign keeps the second run's record when it ends.
    import os
    import signal
    import time

    from jkrdt import rundir

    spec = dict(kind="bpca", dim=3, n_tar=64, n_pro=64, material="ice", model="frictional",
                v_col=[20.0], b_off2=[0.25], seeds=[1, 2], settle=dict(check_tc=5))
    runs, records = tmp_path / "runs", tmp_path / "records"
    driver = ("import json, sys; sys.path.insert(0, sys.argv[1]); "
              "from pathlib import Path; from common import RECORDS_OF, run_campaigns; "
              "RECORDS_OF[Path(sys.argv[2]).resolve()] = Path(sys.argv[3]); "
              "run_campaigns({'c': json.loads(sys.argv[4])}, Path(sys.argv[2]), 1)")
    cmd = [sys.executable, "-c", driver, str(ROOT / "validation"), str(runs), str(records),
           json.dumps(spec)]
    proc = subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 300
    while time.time() < deadline:
        done = sorted(runs.rglob("outcome.json"))
        going = [p.parent for p in runs.rglob("restart.a") if not (p.parent / "outcome.json")
                 .exists()]
        if len(done) == 1 and going:
            break
        time.sleep(0.02)
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode != 0 and "KeyboardInterrupt" in err, err
    [first] = done
    [cut] = going
    kept = sorted(records.rglob("outcome.json"))
    assert [p.relative_to(records) for p in kept] == [first.relative_to(runs)]
    assert json.loads(kept[0].read_text()) == json.loads(first.read_text())
    assert not (records / cut.relative_to(runs)).exists()
    # the settle rule the runs ended by survives with them (readings depend on its stretch)
    kept_spec = json.loads((records / "c" / "campaign.json").read_text())["spec"]
    assert kept_spec["settle"]["check_tc"] == 5 and kept_spec["settle"]["stretch"] == 0.25
    subprocess.run([str(Path(sys.executable).parent / "jkrdt"), "analyse", str(cut), "--partial",
                    "--no-plots"], check=True, capture_output=True, timeout=300)
    assert rundir.read_outcome(cut)["stop_reason"] == "cut off"
    sys.path.insert(0, str(ROOT / "validation"))
    try:
        from common import keep_records
    finally:
        sys.path.pop(0)
    assert keep_records(runs / "c", records / "c") == []
    subprocess.run(cmd, check=True, capture_output=True, timeout=300)
    kept = sorted(records.rglob("outcome.json"))
    assert len(kept) == 2
    assert json.loads((records / cut.relative_to(runs) / "outcome.json").read_text()) == \
        json.loads((cut / "outcome.json").read_text())


def test_the_papers_other_statements_are_asked_of_each_model_on_the_same_scenes(tmp_path):
    # validation/paper_protocol.py --quick, questions a, e and f: the runs that the paper's
    # statements of App. C bear on, 2 x 24 ice BPCAs. e: the other three models head-on at
    # 100 m/s (seeds 1, 2); f: all four models at 10 m/s on four offsets (seed 1). Each
    # model's energy goes only where its model lets it: the undamped models dissipate
    # nothing by damping and the frictionless ones nothing by sliding, rolling or
    # twisting, so that E_dis,tot = E_dis,c exactly for the undamped frictionless model;
    # the statements compare the models scene by scene (the same speed, offset and seed)
    results = run_quick("paper_protocol", tmp_path, "--questions", "a", "e", "f")
    runs = read_csv(results / "runs.csv")
    models = {r["model_name"] for r in runs}
    assert len(runs) == 2 + 6 + 16 and len(models) == 4
    for r in runs:
        tangential = r["E_dis_sliding"] + r["E_dis_rolling"] + r["E_dis_twisting"]
        assert r["E_dis_tot"] == pytest.approx(r["E_dis_c"] + r["E_dis_v"] + tangential,
                                               rel=1e-9, abs=1e-15)
        if "T_vis" not in r["model_name"]:
            assert r["E_dis_v"] == 0.0
        if r["model_name"].startswith("frictionless"):
            assert tangential == 0.0
        if r["model_name"] == "frictionless":
            assert r["E_dis_c"] == r["E_dis_tot"]
    summary = json.loads((results / "summary.json").read_text())
    assert sorted(summary["results"]["by_question"]["f"]) == sorted(
        f"24, {m}" for m in models)
    rows = {s["paper"].split(" (")[0]: s for s in summary["results"]["statements"]}
    # the damped frictionless model's own row: its runs at 100 m/s (e) and 10 m/s (f), the
    # grazing misses left out (nothing dissipated, nothing made)
    collided = [r for r in runs if r["E_dis_tot"] > 1e-9]
    damped_less = [r for r in collided if r["model_name"] == "frictionless, T_vis 6 ps"]
    row = rows["frictionless, damped: N_con > N_tot for 10 <= v_col <= 100 m/s"]
    assert row["runs"] == len(damped_less) and row["size"] == "2 x 24"
    assert row["holds"] == all(r["N_con"] > r["n_total"] for r in damped_less)
    # frictionless against frictional on the same scene: at 10 m/s each of two models
    # against each of two on the offsets where both collided; at 100 m/s head-on, seed by
    # seed, the undamped (a) and damped (e) frictionless against both frictional models (e)
    slow = [r for r in collided if r["v_col"] == 10.0]
    scene = lambda r: (r["v_col"], r["B_off"], r["seed"])    # noqa: E731
    pairs = [(a, b) for a in collided for b in collided if scene(a) == scene(b)
             and a["model_name"].startswith("frictionless")
             and not b["model_name"].startswith("frictionless")]
    row = rows["E_dis,c of the frictionless models above that of the frictional models for "
               "10 <= v_col <= 100 m/s"]
    assert row["runs"] == len(pairs) == 2 * 2 * 2 + 4 * len({r["B_off"] for r in slow})
    assert row["holds"] == all(a["E_dis_c"] > b["E_dis_c"] for a, b in pairs)
    row = rows["frictional models at about 10 m/s: N_con < N_tot"]
    frictional_slow = [r for r in slow if not r["model_name"].startswith("frictionless")]
    assert row["runs"] == len(frictional_slow)
    assert row["holds"] == all(r["N_con"] < r["n_total"] for r in frictional_slow)
    assert "fig_statements.png" in summary["figures"]
