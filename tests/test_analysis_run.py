"""Analysis of a real LAMMPS run: MDAnalysis reads the atom dump (with radii), the
contact dump is read alongside, and the contact-list and position-based fragment
finders agree on every frame after impact. A 64 + 64 grain head-on collision at
60 m/s, frictionless, E_imp ~ 12 n_k E_break: well past catastrophic disruption."""

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import ICE_SCALES as S, R_GRAIN as R
from jkrdt import ledger, rundir
from jkrdt import scene as scene_module
from jkrdt.analysis import fragments as frag
from jkrdt.analysis.dumps import frames, iter_local
from jkrdt.analysis.run import analyse_run
from jkrdt.analysis.tables import read_csv
from jkrdt.materials import ICE
from jkrdt.session import Session

BIN = Path(sys.executable).parent
N = 64


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    d = tmp_path_factory.mktemp("run")
    rundir.write(d, scene_module.Scene(ICE, N, N, v_col=60.0, seed=11,
                                             model="frictionless"))
    with Session(d, d, every=1000) as session:
        session.run(12000, chunk=1000, progress=False)
        energies, thermo = session.energies(), session.thermo()
    return d, energies, thermo, analyse_run(d)


def test_atom_dump_frames_through_mdanalysis(run):
    d, _, thermo, _ = run
    seen = list(frames(d))
    assert [f.step for f in seen] == list(range(0, 12001, 1000))
    for f in seen:
        assert np.array_equal(f.ids, np.arange(1, 2 * N + 1))
        assert np.all(f.radius == R)
        # the contact dump has exactly the bonded contacts the plugin counts
        assert len(f.pairs) == thermo[ledger.CONTACTS][thermo["Step"] == f.step][0]


def refines(fine, coarse):
    """Whether every fragment of ``fine`` lies inside one fragment of ``coarse``."""
    return all(len(np.unique(coarse[fine == k])) == 1 for k in np.unique(fine))


def test_contact_list_and_positions_agree_after_impact(run):
    d, *_ = run
    for f in frames(d):
        by_contacts = frag.from_contacts(f.ids, f.pairs)
        by_positions = frag.from_positions(f.x, f.radius, S.delta_c)
        index = np.searchsorted(f.ids, f.pairs)
        within = frag.position_pairs(f.x, f.radius, S.delta_c)
        # every bonded pair lies within r_i + r_j + delta_c (float32 positions) ...
        assert set(map(tuple, index)) <= set(map(tuple, within)), f"step {f.step}"
        assert refines(by_contacts, by_positions)
        # ... and the position rule adds only pairs that have not touched: a gap in (0, delta_c]
        bonded = set(map(tuple, index))
        extra = np.array([p for p in map(tuple, within) if p not in bonded], dtype=int).reshape(-1, 2)
        gaps = np.linalg.norm(f.x[extra[:, 0]] - f.x[extra[:, 1]], axis=1) - 2 * R
        assert np.all((gaps > 0) & (gaps <= S.delta_c))
        if f.step == 0:
            # set up delta_c / 2 apart: two bodies by contacts, one by the position rule
            assert len(np.unique(by_contacts)) == 2 and len(np.unique(by_positions)) == 1
    # once the fragments fly apart the two finders give the same fragments
    assert frag.same_partition(by_contacts, by_positions)


def test_outcome_of_a_disruptive_collision(run):
    d, energies, _, out = run
    assert out["E_imp_over_nk_Ebreak"] == pytest.approx(
        0.5 * S.mass * N / 2 * 60.0 ** 2 / ((2 * N - 2) * S.E_break), rel=1e-12)
    assert out["E_imp_over_nk_Ebreak"] > 10        # the DT recipe's catastrophic disruption
    assert out["n_fragments"] > 2 and out["n_largest"] < 2 * N
    assert out["growth_efficiency"] == (out["n_largest"] - N) / N
    assert out["N_cum"][-1] == 2 * N
    # dt = 0.014 t_c at 60 m/s = 19 v0: two grains at this dt drift 2.7e-4 E_imp at v0
    # (tests/test_collision_energy.py); second order in dt
    assert out["energy_error"] < 1e-3
    assert sum(out["dissipated_by_channel"].values()) == pytest.approx(
        out["dissipated_fraction"], rel=1e-12)
    assert out["dissipated_by_channel"]["rolling"] == 0.0           # frictionless
    # the partition adds up: two aggregates without spin in their centre-of-mass frame start
    # with E_imp of kinetic energy, and it goes into kinetic, potential and dissipated
    # energy, less the integration's drift
    # (to the 10 digits of the log's thermo rows)
    assert out["kinetic_start"] == pytest.approx(1.0, rel=1e-9)
    assert (out["kinetic_left"] + out["potential_change"] + out["dissipated_fraction"]
            - out["energy_drift"]) == pytest.approx(out["kinetic_start"], rel=1e-9)
    assert abs(out["energy_drift"]) <= out["energy_error"]


def test_frames_table_matches_the_session(run):
    d, energies, thermo, out = run
    rows = read_csv(d / "frames.csv")
    assert [r["step"] for r in rows] == list(range(0, 12001, 1000))
    sampled = {int(s): k for k, s in enumerate(thermo["Step"])}
    for r in rows:
        k = sampled[int(r["step"])]
        for name in ("kinetic", "potential", "dissipated"):
            assert r[name] == pytest.approx(energies[name][k], rel=1e-9, abs=1e-9 * out["E_imp"])
    assert rows[-1]["n_largest"] == out["n_largest"]
    assert rows[0]["n_fragments"] == 2 and rows[0]["growth_efficiency"] == 0.0
    # N_con and N_cut at every check, none at the start, the outcome's at the end
    assert rows[0]["N_con"] == rows[0]["N_cut"] == 0
    assert (rows[-1]["N_con"], rows[-1]["N_cut"]) == (out["N_con"], out["N_cut"])
    assert all(a["N_con"] <= b["N_con"] and a["N_cut"] <= b["N_cut"]
               for a, b in zip(rows, rows[1:]))


def test_local_dump_stream(run):
    d, *_ = run
    steps = [step for step, _ in iter_local(d / rundir.CONTACTS)]
    assert steps == list(range(0, 12001, 1000))


def test_analyse_command(run):
    d, *_ = run
    done = subprocess.run([str(BIN / "jkrdt"), "analyse", str(d)], capture_output=True,
                          text=True, check=True, timeout=120)
    out = json.loads((d / "outcome.json").read_text())
    assert f"largest remnant N_lar       {out['n_largest']}" in done.stdout
    # the summary shows every term of the partition, and they add up to the start's 1.000
    [line] = [x for x in done.stdout.splitlines() if x.startswith("energy partition / E_imp")]
    kinetic, potential, dissipated, start, drift = map(float, re.findall(
        r"[-+]?\d+\.\d+(?:e[-+]?\d+)?", line))
    assert start == pytest.approx(1.0, abs=5e-4)
    assert kinetic + potential + dissipated == pytest.approx(start + drift, abs=2e-3)
    for name in ("outcome.png", "outcome.pdf", "timeline.png", "timeline.pdf", "energy.png",
                 "energy.pdf"):
        assert (d / name).stat().st_size > 0


def test_collision_outcome_is_an_mdanalysis_analysis(run):
    # the per-frame measures as an AnalysisBase over the run's own Universe: sliced runs
    # give the full run's figures at their frames, and the last frame's N_cum
    from jkrdt.analysis.dumps import atoms_universe
    from jkrdt.analysis.outcome import CollisionOutcome
    d, *_ = run
    rows = read_csv(d / "frames.csv")
    u = atoms_universe(d / rundir.ATOMS)
    full = CollisionOutcome(u, N, N, contacts=d / rundir.CONTACTS).run()
    assert list(full.results.step) == list(range(0, 12001, 1000))
    for name in ("n_largest", "n_fragments", "contacts_per_particle", "growth_efficiency"):
        assert np.allclose(full.results[name], [float(r[name]) for r in rows]), name
    sliced = CollisionOutcome(u, N, N, contacts=d / rundir.CONTACTS).run(start=2, stop=11,
                                                                         step=3)
    assert list(sliced.results.step) == [2000, 5000, 8000]
    assert np.array_equal(sliced.results.n_largest, full.results.n_largest[2:11:3])
    backwards_again = CollisionOutcome(u, N, N, contacts=d / rundir.CONTACTS).run(stop=3)
    assert list(backwards_again.results.step) == [0, 1000, 2000]
    # without the contact dump: fragments from positions within delta_c, the same at the end
    by_positions = CollisionOutcome(u, N, N, tolerance=S.delta_c).run(start=12)
    outcome = json.loads((d / "outcome.json").read_text())
    assert by_positions.results.n_largest[-1] == outcome["n_largest"]
    assert list(full.results.N_cum) == outcome["N_cum"]


def test_two_single_grains_are_analysed_without_the_aggregate_units(tmp_path):
    # n_k = N_tar + N_pro - 2 = 0: E_imp / (n_k E_roll) and / (n_k E_break) are undefined, so
    # the outcome says None for them instead of dividing by zero; at 3 m/s (half the
    # elastic sticking threshold, tests/test_collision_energy.py) the pair sticks
    rundir.write(tmp_path, scene_module.Scene(ICE, 1, 1, v_col=3.0, seed=1))
    done = subprocess.run([str(BIN / "jkrdt"), "run", str(tmp_path)], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    said = subprocess.run([str(BIN / "jkrdt"), "analyse", str(tmp_path), "--no-plots"],
                          capture_output=True, text=True, timeout=120)
    assert said.returncode == 0 and "Traceback" not in said.stderr, said.stderr
    out = json.loads((tmp_path / "outcome.json").read_text())
    assert out["n_k"] == 0
    assert out["E_imp_over_nk_Eroll"] is None and out["E_imp_over_nk_Ebreak"] is None
    assert out["n_largest"] == 2 and out["stop_reason"] == "settled"
    assert "n_k E_break" not in said.stdout and "impact energy E_imp" in said.stdout
