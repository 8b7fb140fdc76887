"""Runs that end when the collision has ended, say why they stopped, and are refused by
the analysis when they failed or were cut off.

The settle rule (fix jkr/dt/settle, jkrdt.stopping) is checked against what the Python
analysis finds independently in the dumps: over the window that let the run stop, the
fragments did not change, and the plugin's union-find over all ranks gives the same
N_lar and number of fragments as analysis.fragments on the contact dump."""

import dataclasses
import gc
import subprocess
import tempfile
import sys
from pathlib import Path

import numpy as np
import pytest

from jkrdt import rundir

from jkrdt import scene as scene_module
from jkrdt.analysis.summary import summarise
from jkrdt.analysis.tables import read_csv
from jkrdt.analysis.dumps import frames
from jkrdt.analysis.fragments import from_contacts
from jkrdt.analysis.run import RunNotComplete, analyse_run
from jkrdt.rundir import SETTLE_LINE
from jkrdt.materials import ICE, scales
from jkrdt.session import Session
from jkrdt.stopping import SettleRule

BIN = f"{Path(sys.executable).parent}/"
ROOT = Path(__file__).resolve().parents[1]
R = 1.0e-7
S = scales(ICE, R)
RULE = SettleRule(check_tc=20, window=5, tolerance=0.01, cap_tc=6000)


def write_scene(directory, v=10.0, seed=3, n=32, skin=None):
    scene = scene_module.Scene(ICE, n, n, v_col=v, seed=seed, kind="bcca", dim=2, skin=skin)
    return rundir.write(directory, scene)


def settle_line(log):
    line = [w for w in log.read_text().splitlines() if w.startswith(SETTLE_LINE)][-1].split()
    return dict(zip(line[1::2], line[2::2]))


@pytest.fixture(scope="module")
def settled(tmp_path_factory):
    d = write_scene(tmp_path_factory.mktemp("settled"))
    with Session(d, d, every=1, settle=RULE, variables=dict(frames=1)) as s:
        s.run_until_settled(progress=False)
        reason, energy_error = s.stop_reason, s.energy_error()
    return d, reason, energy_error


def test_session_stops_when_the_fragments_and_contacts_hold_still(settled):
    d, reason, energy_error = settled
    assert reason == "settled"
    fields = settle_line(d / "log.lammps")
    stop = int(fields["step"])
    check = RULE.check_steps(0.014)
    assert stop % check == 0 and stop < RULE.cap_steps(0.014)
    seen = [(f.step, from_contacts(f.ids, f.pairs)) for f in frames(d)]
    assert seen[-1][0] == stop                          # the last frame is the stop
    window = [labels for step, labels in seen if step >= stop - RULE.window * check]
    assert len(window) == RULE.window + 1
    for labels in window:                               # the partition held still
        sizes = np.bincount(labels)
        assert sizes.max() == int(fields["N_lar"]) and len(sizes) == int(fields["fragments"])
    assert energy_error < 1e-4


def test_counts_allow_the_fragments_to_vary_by_a_fraction_of_all_grains(tmp_path):
    """counts c lets N_lar and the number of fragments vary by floor(c N) over the window,
    as the analysis of the dumps measures it. With the contacts and dissipation left loose
    (tolerance 0.9) the counts decide: a disruptive 2 x 32 collision whose small fragments
    keep meeting stops earlier at c = 0.15 (9 grains) than with the counts unchanged."""
    stops, ranges = {}, {}
    for c in (0.0, 0.15):
        d = write_scene(tmp_path / f"c{c}", v=80.0, seed=1)
        rule = SettleRule(check_tc=20, window=5, tolerance=0.9, counts=c, cap_tc=6000)
        with Session(d, d, every=1, settle=rule, variables=dict(frames=1)) as s:
            s.run_until_settled(progress=False)
            assert s.stop_reason == "settled"
        stop = int(settle_line(d / "log.lammps")["step"])
        check = rule.check_steps(0.014)
        window = [np.bincount(from_contacts(f.ids, f.pairs)) for f in frames(d)
                  if f.step >= stop - rule.window * check]
        assert len(window) == rule.window + 1
        stops[c] = stop
        ranges[c] = [np.ptp([w.max() for w in window]), np.ptp([len(w) for w in window])]
    assert ranges[0.0] == [0, 0]
    assert max(ranges[0.15]) <= int(0.15 * 64)                # floor(c N) = 9
    assert stops[0.15] < stops[0.0]


def test_outcome_records_why_and_how_well_the_run_ended(settled):
    d, *_ = settled
    out = analyse_run(d, plots=False)
    assert out["stop_reason"] == "settled" and out["settled"] is True
    assert out["last_step"] == out["stop_step"] == int(settle_line(d / "log.lammps")["step"])
    # kinetic_left is ke + erotate at the last frame over E_imp, from the log
    assert 0.0 <= out["kinetic_left"] < 0.5
    assert out["energy_warning"] is False


def test_cap_ends_an_unsettled_run_and_is_flagged_in_the_campaign(settled, tmp_path):
    d, *_ = settled
    cap = write_scene(tmp_path / "camp" / "v10" / "cap")
    short = SettleRule(check_tc=20, window=5, cap_tc=100)
    with Session(cap, cap, every=1, settle=short) as s:
        s.run_until_settled(progress=False)
        assert s.stop_reason == "cap"
    out = analyse_run(cap, plots=False)
    assert out["stop_reason"] == "cap" and out["stop_step"] == short.cap_steps(0.014)
    # a campaign of one settled and one capped run averages only the settled one
    done = tmp_path / "camp" / "v10" / "done"
    done.mkdir()
    for name in ("collision.json", "outcome.json"):
        (done / name).write_text((d / name).read_text())
    summary = summarise(tmp_path / "camp", plot=False)
    assert [g["stop_reason"] for g in summary["left_out"]] == ["cap"]
    assert summary["table"][0]["runs"] == 1 and summary["table"][0]["capped"] == 1
    with_cap = summarise(tmp_path / "camp", plot=False, include_cap=True)
    assert with_cap["table"][0]["runs"] == 2


def test_failed_run_is_refused_by_the_analysis_with_the_cause(tmp_path):
    # at 2000 m/s a pair closes 7.7 nm per step at the papers' dt: more than half of a
    # 1 nm skin (the user's; the scene's own would be 61 nm)
    d = write_scene(tmp_path / "failed", v=2000.0, skin=1e-9)
    done = subprocess.run([BIN + "jkrdt", "run", str(d)], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode != 0
    assert "more than half the neighbor skin" in done.stderr
    refused = subprocess.run([BIN + "jkrdt", "analyse", str(d), "--no-plots"],
                             capture_output=True, text=True, timeout=120)
    assert refused.returncode != 0
    assert refused.stderr.startswith("jkrdt: ") and "Traceback" not in refused.stderr
    assert "the run failed: ERROR on proc 0: pair jkr/dt: atoms" in refused.stderr
    assert "--partial" in refused.stderr


def test_cut_off_run_is_refused_unless_partial(settled, tmp_path):
    d, *_ = settled
    cut = tmp_path / "cut"
    cut.mkdir()
    for name in ("collision.json", rundir.ATOMS, rundir.CONTACTS):
        (cut / name).write_bytes((d / name).read_bytes())
    # the log of a process killed in mid-run: it ends inside a thermo block
    log = (d / "log.lammps").read_text().splitlines()
    last_loop = max(k for k, line in enumerate(log) if line.startswith("Loop time of"))
    (cut / "log.lammps").write_text("\n".join(log[:last_loop]) + "\n")
    with pytest.raises(RunNotComplete, match="ends inside a run.*cut off"):
        analyse_run(cut, plots=False)
    out = analyse_run(cut, plots=False, partial=True)
    assert out["stop_reason"] == "cut off" and out["problem"]


def test_deck_settles_and_says_so(tmp_path):
    log = tmp_path / "log.lammps"
    subprocess.run([BIN + "lmp", "-in", "inputs/bcca_2d_head_on.lmp", "-var", "out",
                    str(tmp_path), "-log", str(log), "-screen", "none"], check=True,
                   timeout=300, cwd=ROOT)
    fields = settle_line(log)
    assert fields["stop_reason"] == "settled" and int(fields["N_lar"]) == 128
    assert int(fields["step"]) < 1000000


@pytest.mark.mpi
def test_two_ranks_find_the_fragments_the_analysis_finds(tmp_path):
    d = write_scene(tmp_path / "mpi", v=60.0, seed=5)       # a disruptive collision
    subprocess.run([BIN + "jkrdt", "run", str(d), "--np", "2", "--check", "20", "--cap",
                    "3000"], check=True, timeout=300, capture_output=True)
    fields = settle_line(d / "log.lammps")
    last = list(frames(d))[-1]
    sizes = np.bincount(from_contacts(last.ids, last.pairs))
    assert last.step == int(fields["step"])
    assert sizes.max() == int(fields["N_lar"]) and len(sizes) == int(fields["fragments"])


@pytest.mark.parametrize("cut", [rundir.ATOMS, rundir.CONTACTS])
def test_truncated_dump_is_refused_unless_partial(settled, tmp_path, cut):
    d, *_ = settled
    run = tmp_path / "run"
    run.mkdir()
    for name in ("collision.json", "log.lammps", rundir.ATOMS, rundir.CONTACTS):
        (run / name).write_bytes((d / name).read_bytes())
    data = (run / cut).read_bytes()
    (run / cut).write_bytes(data[: int(0.97 * len(data))])   # killed while writing
    with pytest.raises(RunNotComplete, match=r"the dumps end at step \d+, before the run's end"):
        analyse_run(run, plots=False)
    copies = lambda: set(Path(tempfile.gettempdir()).glob(f"{cut}.*.readable"))
    before = copies()
    out = analyse_run(run, plots=False, partial=True)
    assert out["stop_reason"] == "cut off" and out["last_step"] < out["stop_step"]
    gc.collect()
    assert copies() <= before, "the readable copy of a cut-off dump outlived its reader"


def hinge(where):
    """Three frictionless grains bent at 90 degrees (two contacts at the equilibrium
    distance 2R - delta_0), the end grains moving apart at 1 m/s across their arms, so
    that they open like a hinge: no rolling or sliding resistance, so the contacts, N_lar
    = 3 and the fragments hold still and nothing is dissipated, while r_g of the three
    goes from 2/3 d at 90 degrees to sqrt(2/3) d straight. Returns (run, d)."""
    from jkrdt.collision import Collision

    d = 2 * R - S.delta0
    u = 1.0
    x = np.array([[0.0, 0.0, 0.0], [d, 0.0, 0.0], [0.0, d, 0.0]])
    v = np.array([[0.0, 0.0, 0.0], [0.0, -u, 0.0], [-u, 0.0, 0.0]])
    scene = scene_module.Scene(ICE, 2, 1, v_col=u, seed=1, kind="bpca", dim=3,
                               model="frictionless")
    return rundir.write(where, scene, placed=Collision(
        x=x, v=v, body=np.array([1, 1, 2]), radius=R, meta=dict(b=0.0, gap=0.0))), d


def test_a_frictionless_hinge_settles_once_it_has_opened(tmp_path):
    """The rule watches shape (stretch 0.25, the default): the hinge's r_g grows by more
    than the tolerance over every window while it opens, so the run goes on until it
    is straight, where r_g is at its largest, sqrt(2/3) d, and grows no more; the outcome
    flags nothing."""
    from jkrdt.analysis.run import summary_text

    run, d = hinge(tmp_path / "hinge")
    assert RULE.stretch == 0.25
    with Session(run, run, every=1, settle=RULE, variables=dict(frames=1)) as s:
        s.run_until_settled(progress=False)
        assert s.stop_reason == "settled"
    out = analyse_run(run, plots=False)
    assert out["n_largest"] == 3 and out["dissipated_fraction"] == 0.0
    rows = read_csv(run / rundir.CHECKS)
    r_g = [r["gyration_radius_largest"] for r in rows]
    assert len(rows) > 3 * (RULE.window + 1)
    # every window before the last grew by more than the tolerance; the last did not
    growth = [b / a - 1 for a, b in zip(r_g, r_g[RULE.window:])]
    assert all(g > RULE.tolerance for g in growth[:-1]) and growth[-1] <= RULE.tolerance
    # straight, to within the last check's step past r_g's maximum (flat there)
    assert r_g[-1] == pytest.approx(np.sqrt(2 / 3) * d, rel=1e-3)
    assert out["shape_at_end"]["stretching"] is False
    assert "a neck may still part it" not in summary_text(out)
    # validation/end_rule.py's replay of the rule on a run's checks (counts, contacts and
    # shape; nothing is dissipated here) stops where the fix stopped, and without shape
    # where the rule without it stops (after one window)
    from jkrdt.analysis.outcome import from_checks

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "validation"))
    try:
        from end_rule import settle_replay
    finally:
        sys.path.pop(0)
    table = from_checks(read_csv(run / rundir.CHECKS), 2, 1)
    for row, raw in zip(table, rows):
        row["contacts"] = raw["contacts"]
    assert settle_replay(table, RULE, shape=True) == len(rows) - 1
    assert settle_replay(table, RULE, shape=False) == RULE.window


def test_a_frictionless_hinge_opening_counts_as_settled_without_shape_and_says_so(tmp_path):
    """Without shape watched (stretch 0, the rule of the runs made before it): the rule
    ends the run after one window while the hinge is still opening. The outcome measures
    the growth of r_g over the rule's window from checks.csv and flags the body as still
    stretching, with a warning in the summary."""
    from jkrdt.analysis.run import summary_text

    run, d = hinge(tmp_path / "hinge")
    rule = dataclasses.replace(RULE, stretch=0.0)
    with Session(run, run, every=1, settle=rule, variables=dict(frames=1)) as s:
        s.run_until_settled(progress=False)
        assert s.stop_reason == "settled"
    out = analyse_run(run, plots=False)
    assert out["n_largest"] == 3 and out["contacts_end"] == 2
    assert out["dissipated_fraction"] == 0.0
    rows = read_csv(run / rundir.CHECKS)
    assert len(rows) == RULE.window + 1                 # settled at the first full window
    r_g = [r["gyration_radius_largest"] for r in rows]
    assert r_g[0] == pytest.approx(2 / 3 * d, rel=1e-3)           # 90 degrees at the start
    assert all(b > a for a, b in zip(r_g, r_g[1:])) and r_g[-1] < np.sqrt(2 / 3) * d
    shape = out["shape_at_end"]
    assert shape["window"] == RULE.window
    assert shape["r_g_growth"] == pytest.approx(r_g[-1] / r_g[0] - 1, rel=1e-12)
    assert shape["r_g_growth"] > RULE.tolerance and shape["stretching"] is True
    assert "a neck may still part it" in summary_text(out)
    summary = summarise(tmp_path, plot=False)            # a campaign's summary flags it
    assert summary["runs"] == 1 and summary["stretching_at_end"] == [dict(
        run=str(run), growth_efficiency=out["growth_efficiency"],
        r_g_growth=shape["r_g_growth"])]
    row, = read_csv(tmp_path / "runs.csv")
    assert row["stretching_at_end"] == "True"
    assert row["r_g_growth_at_end"] == pytest.approx(shape["r_g_growth"], rel=1e-12)
