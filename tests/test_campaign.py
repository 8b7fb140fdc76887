"""A small campaign end to end: v_col x B_off^2 runs, resumed without redoing finished
runs, summarised with eq. (1) of the 3D BPCA paper; under mpirun -np 2 two runs at once
with the serial campaign's results; a killed campaign's run refused by the analysis and
resumed from its restart files; two
campaigns on one directory sharing its runs."""

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from jkrdt.analysis.summary import b_off_average, summarise
from jkrdt.analysis.tables import read_csv
from jkrdt.campaign import run_campaign, run_directory

BIN = Path(sys.executable).parent
SPEC = dict(kind="bpca", dim=3, n_tar=16, n_pro=16, material="ice", model="frictional",
            v_col=[2.0, 80.0], b_off2=[0.0, 0.5, 1.0], seeds=[2],
            settle=dict(check_tc=10, cap_tc=4000))


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    d = tmp_path_factory.mktemp("campaign")
    spec = d / "spec.json"
    spec.write_text(json.dumps(SPEC))
    first = run_campaign(spec, d / "runs", progress=False)
    return spec, d / "runs", first


def test_every_run_is_analysed(campaign):
    _, runs, first = campaign
    assert first == dict(runs=6, skipped=0, ran=6, failed=[])
    outcomes = sorted(runs.rglob("outcome.json"))
    assert len(outcomes) == 6
    for path in outcomes:
        out = json.loads(path.read_text())
        # every run ends by the settle rule, on its last dumped frame, below the cap
        assert out["stop_reason"] == "settled" and out["step"] == out["stop_step"]
        assert out["stop_step"] * 0.014 < SPEC["settle"]["cap_tc"]
        assert out["n_total"] == 32
        assert out["growth_efficiency"] == (out["n_largest"] - 16) / 16
        assert out["energy_error"] < 1e-3


def test_resume_skips_finished_runs(campaign):
    spec, runs, _ = campaign
    outcomes = sorted(runs.rglob("outcome.json"))
    redo = outcomes[2]
    before = {p: p.stat().st_mtime_ns for p in outcomes if p != redo}
    kept = json.loads(redo.read_text())
    redo.unlink()
    again = run_campaign(spec, runs, progress=False)
    assert again == dict(runs=6, skipped=5, ran=1, failed=[])
    assert all(p.stat().st_mtime_ns == t for p, t in before.items())
    # the redone run is the same simulation
    assert json.loads(redo.read_text())["n_largest"] == kept["n_largest"]


def test_a_campaign_recorded_before_the_rule_watched_shape_resumes_without_it(campaign,
                                                                               tmp_path):
    # a campaign.json written before SettleRule.stretch existed holds the rule of its runs:
    # shape not watched. Its spec with "stretch": 0 resumes it (nothing to redo here); the
    # default rule, which watches shape, is another spec, refused with the difference named
    import shutil

    spec, runs, _ = campaign
    old = tmp_path / "old"
    shutil.copytree(runs, old)
    record = json.loads((old / "campaign.json").read_text())
    del record["spec"]["settle"]["stretch"]
    (old / "campaign.json").write_text(json.dumps(record))
    with pytest.raises(ValueError, match="holds the runs of another spec.*stretch"):
        run_campaign(spec, old, progress=False)
    pinned = tmp_path / "pinned.json"
    pinned.write_text(json.dumps(dict(SPEC, settle=dict(SPEC["settle"], stretch=0.0))))
    assert run_campaign(pinned, old, progress=False) == dict(runs=6, skipped=6, ran=0,
                                                              failed=[])


def test_summary_is_the_b_off_weighted_average(campaign):
    _, runs, _ = campaign
    summary = summarise(runs)
    rows = read_csv(runs / "runs.csv")
    assert len(rows) == 6
    for line in summary["table"]:
        mine = sorted((r["B_off"] ** 2, r["growth_efficiency"]) for r in rows
                      if r["v_col"] == line["v_col"])
        b2, f = np.array(mine).T
        assert line["mean_f_gro"] == pytest.approx(float(b_off_average(b2, f)), rel=1e-12)
    assert len(read_csv(runs / "summary.csv")) == 2
    # the paper's Fig. B.1 table: f_gro per B_off^2 (a row) and v_col (a column), seeds
    # averaged, as runs.csv holds them with B_off^2 as a column
    assert all(r["B_off2"] == pytest.approx(r["B_off"] ** 2, abs=1e-12) for r in rows)
    by_offset = read_csv(runs / "f_gro_by_offset.csv")
    for row in by_offset:
        for line in summary["table"]:
            same = [r["growth_efficiency"] for r in rows if r["v_col"] == line["v_col"]
                    and abs(r["B_off2"] - row["B_off2"]) < 1e-4]
            assert row[f"f_gro_{line['v_col']:g}"] == pytest.approx(np.mean(same), rel=1e-12)
    for name in ("growth_efficiency", "cumulative", "disruption", "compression"):
        assert (runs / f"{name}.png").stat().st_size > 0
    # at 2 m/s (0.6 v0, far below v_fra) the aggregates stick at every B_off that touches
    slow = next(line for line in summary["table"] if line["v_col"] == 2.0)
    assert slow["mean_f_gro"] > 0


def same_outcomes(runs, other):
    for path in sorted(runs.rglob("outcome.json")):
        serial = json.loads(path.read_text())
        parallel = json.loads((other / path.relative_to(runs)).read_text())
        for key in ("n_largest", "n_second", "n_fragments", "contacts_per_particle"):
            assert parallel[key] == serial[key], (path, key)
        assert parallel["gyration_radius_largest"] == pytest.approx(
            serial["gyration_radius_largest"], rel=1e-9)


def spans(runs):
    """(claiming process, start, end) of each run: its scene written, its outcome written."""
    out = []
    for d in {p.parent for p in runs.rglob("outcome.json")}:
        who = (d / ".claim").read_text().split()[2]
        out.append((who, (d / "collision.json").stat().st_mtime,
                    (d / "outcome.json").stat().st_mtime))
    return out


@pytest.mark.mpi
def test_campaign_under_two_ranks_matches_serial(campaign, tmp_path):
    spec, runs, _ = campaign
    done = subprocess.run([str(BIN / "mpirun"), "-np", "2", str(BIN / "jkrdt"), "campaign",
                           str(spec), str(tmp_path)], check=True, timeout=600,
                          capture_output=True, text=True)
    same_outcomes(runs, tmp_path)
    # groups of one rank: each rank ran whole collisions, at the same time as the other
    said = re.findall(r"^\[ranks (\d)-(\d)\]", done.stdout, re.M)
    assert sorted(set(said)) == [("0", "0"), ("1", "1")] and len(said) == 6, done.stdout
    mine = spans(tmp_path)
    assert len({who for who, *_ in mine}) == 2
    assert any(a[0] != b[0] and a[1] < b[2] and b[1] < a[2] for a in mine for b in mine)


@pytest.mark.mpi
def test_a_group_of_two_ranks_runs_each_collision_in_parallel(campaign, tmp_path):
    spec, runs, _ = campaign
    done = subprocess.run([str(BIN / "mpirun"), "-np", "2", str(BIN / "jkrdt"), "campaign",
                           str(spec), str(tmp_path), "--ranks-per-run", "2"], check=True,
                          timeout=600, capture_output=True, text=True)
    assert set(re.findall(r"^\[ranks (\d-\d)\]", done.stdout, re.M)) == {"0-1"}
    same_outcomes(runs, tmp_path)
    bad = subprocess.run([str(BIN / "mpirun"), "-np", "2", str(BIN / "jkrdt"), "campaign",
                          str(spec), str(tmp_path / "bad"), "--ranks-per-run", "3"],
                         capture_output=True, text=True, timeout=120)
    assert bad.returncode != 0 and "Traceback" not in bad.stderr
    assert "jkrdt: --ranks-per-run 3 must divide the 2 MPI rank(s) into equal groups" \
        in bad.stderr


def test_two_campaigns_on_one_directory_share_its_runs(campaign, tmp_path):
    spec, runs, _ = campaign
    both = [subprocess.Popen([str(BIN / "jkrdt"), "campaign", str(spec), str(tmp_path),
                              "--quiet"], stdout=subprocess.PIPE, text=True)
            for _ in range(2)]
    said = [p.communicate(timeout=600)[0] for p in both]
    assert all(p.returncode == 0 for p in both)
    ran = [int(re.match(r"(\d+) run\(s\) done", s).group(1)) for s in said]
    assert sum(ran) == 6, said                   # no run done twice, none left out
    for log in tmp_path.rglob("log.lammps"):
        assert log.read_text().count("LAMMPS (") == 1, log
    same_outcomes(runs, tmp_path)


KILLED = dict(SPEC, n_tar=64, n_pro=64, v_col=[20.0], b_off2=[0.25],
              settle=dict(check_tc=5, cap_tc=4000))


def test_a_killed_campaign_resumes_from_its_restart_file(tmp_path):
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(KILLED))
    run_campaign(spec, tmp_path / "whole", progress=False)
    cut = tmp_path / "cut"
    run = run_directory(cut, 20.0, 0.25, 2)
    proc = subprocess.Popen([str(BIN / "jkrdt"), "campaign", str(spec), str(cut), "--quiet"],
                            start_new_session=True)
    deadline = time.time() + 120
    while not (run / "restart.b").exists() and time.time() < deadline:
        time.sleep(0.02)
    time.sleep(0.3)                               # a few more checks, then the kill
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    assert not (run / "outcome.json").exists(), "the run ended before it could be killed"
    # cut off, wherever the kill fell: inside a chunk, or (the log cut back to its last
    # whole chunk, as when the kill falls between two) after a whole run command
    log = run / "log.lammps"
    for between in (False, True):
        if between:
            lines = log.read_text().splitlines(keepends=True)
            last = max(k for k, line in enumerate(lines) if line.startswith("Loop time of"))
            kept = log.read_text()
            log.write_text("".join(lines[:last + 1]))
        analysed = subprocess.run([str(BIN / "jkrdt"), "analyse", str(run), "--no-plots"],
                                  capture_output=True, text=True)
        assert analysed.returncode != 0 and "Traceback" not in analysed.stderr
        assert "the run was cut off" in analysed.stderr, analysed.stderr
        assert not (run / "outcome.json").exists()
    assert "between two of its run commands" in analysed.stderr
    log.write_text(kept)
    assert run_campaign(spec, cut, progress=False) == dict(runs=1, skipped=0, ran=1, failed=[])
    log = (run / "log.lammps").read_text()
    assert log.count("Reading restart file") == 1     # continued, not started again
    whole = json.loads(next((tmp_path / "whole").rglob("outcome.json")).read_text())
    again = json.loads((run / "outcome.json").read_text())
    # the continuation is the uninterrupted run bit for bit, wherever the kill fell
    # (test_invariance.py checks every restart point of a run): same stop, outcome, ledger
    for key in ("stop_reason", "stop_step", "n_largest", "n_fragments", "contacts_per_particle",
                "gyration_radius_largest", "dissipated_fraction", "dissipated_by_channel",
                "energy_error"):
        assert again[key] == whole[key], key
    frames = [r["step"] for r in read_csv(run / "frames.csv")]
    assert frames == [r["step"] for r in read_csv(whole["run"] + "/frames.csv")]


def test_spec_errors_name_the_fix(tmp_path):
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(dict(SPEC, seed=[3])))
    with pytest.raises(ValueError, match=r"unknown keys \['seed'\]"):
        run_campaign(spec, tmp_path / "runs", progress=False)
    spec.write_text(json.dumps(dict(SPEC, b_off2=[0.0, 2.0])))
    with pytest.raises(ValueError, match="must lie in"):
        run_campaign(spec, tmp_path / "runs", progress=False)
    spec.write_text(json.dumps(dict(SPEC, settle=False, steps=4500, every=1000)))
    with pytest.raises(ValueError, match="multiple of every"):
        run_campaign(spec, tmp_path / "runs", progress=False)
    spec.write_text(json.dumps(dict(SPEC, steps=4000)))
    with pytest.raises(ValueError, match="go with \"settle\": false"):
        run_campaign(spec, tmp_path / "runs", progress=False)
    spec.write_text(json.dumps(dict(SPEC, settle=dict(windows=3))))
    with pytest.raises(ValueError, match="settle takes"):
        run_campaign(spec, tmp_path / "runs", progress=False)
    spec.write_text(json.dumps(dict(SPEC, b_off2="twelfths")))
    with pytest.raises(ValueError, match="a list of numbers or \"paper\""):
        run_campaign(spec, tmp_path / "runs", progress=False)
    assert not (tmp_path / "runs").exists()


def test_the_papers_protocol_by_name(tmp_path):
    """"v_col": "paper" and "b_off2": "paper" are the 3D BPCA paper's grids: eleven speeds
    10^(0.1 i) m/s, i = 10 ... 20, and B_off^2 = k/12, k = 0 ... 11."""
    from jkrdt import protocol
    from jkrdt.campaign import plan, read_spec

    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(dict(SPEC, v_col="paper", b_off2="paper")))
    read = read_spec(spec)
    assert read["v_col"] == protocol.V_COL and read["b_off2"] == protocol.B_OFF2
    assert len(plan(read, tmp_path / "runs")) == 11 * 12 * len(read["seeds"])


def jkrdt_campaign(spec, where, *options):
    return subprocess.run([str(BIN / "jkrdt"), "campaign", str(spec), str(where), "--quiet",
                           *options], capture_output=True, text=True, timeout=600)


def test_a_campaign_directory_belongs_to_one_spec(tmp_path):
    one = dict(SPEC, v_col=[20.0], b_off2=[0.0])
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(one))
    assert jkrdt_campaign(spec, tmp_path / "runs").returncode == 0
    record = json.loads((tmp_path / "runs" / "campaign.json").read_text())
    assert record["spec"]["model"] == "frictional" and record["versions"] == ["0.1.0"]
    assert record["spec"]["settle"]["window"] == 5              # the rule written out in full
    spec.write_text(json.dumps(dict(one, v_col=[20], settle=dict(SPEC["settle"], window=5))))
    same = jkrdt_campaign(spec, tmp_path / "runs")          # the same spec, written otherwise
    assert same.returncode == 0 and "0 run(s) done, 1 already finished" in same.stdout
    spec.write_text(json.dumps(dict(one, model="frictionless")))
    refused = jkrdt_campaign(spec, tmp_path / "runs")
    assert refused.returncode == 2 and refused.stderr.count("\n") == 1, refused.stderr
    assert "\"model\" was 'frictional', now 'frictionless'" in refused.stderr
    assert "--fresh" in refused.stderr
    assert jkrdt_campaign(spec, tmp_path / "runs", "--fresh").returncode == 0
    out = json.loads(next((tmp_path / "runs").rglob("outcome.json")).read_text())
    assert out["model"] == "frictionless" and out["stop_reason"] == "settled"


def test_failed_run_is_recorded_and_left_out_of_the_summary(tmp_path):
    spec = tmp_path / "spec.json"
    # T_vis about t_c (45 times the paper's, the most jkrdt.units lets through) at dt 0.39
    # t_c: the damping throws a contact's grains apart faster than the skin holds them in
    # a step, and LAMMPS stops
    spec.write_text(json.dumps(dict(SPEC, v_col=[20.0], b_off2=[0.0], dt=0.39,
                                    material_overrides={"tvis": 2.7e-10})))
    assert run_campaign(spec, tmp_path / "runs", progress=False)["ran"] == 1
    out = json.loads(next((tmp_path / "runs").rglob("outcome.json")).read_text())
    assert out["stop_reason"] == "error" and "raise the skin above" in out["problem"]
    # finished as far as resuming goes: not tried again, and the exit status says so
    again = jkrdt_campaign(spec, tmp_path / "runs")
    assert again.returncode == 1 and "0 run(s) done, 1 already finished" in again.stdout
    assert "1 of the 1 runs failed" in again.stderr and "--retry-failed" in again.stderr
    retried = run_campaign(spec, tmp_path / "runs", progress=False, retry_failed=True)
    assert retried["ran"] == 1 and len(retried["failed"]) == 1     # tried again, failed again
    with pytest.raises(ValueError, match=r"none of its 1 runs is complete \(\['error'\]\)"):
        summarise(tmp_path / "runs", plot=False)


def test_a_campaign_with_dt_auto_runs_each_speed_at_the_dt_chosen_for_its_tolerance(tmp_path):
    # "dt": "auto" is jkrdt setup's --dt auto per speed: the largest dt that the bounds of
    # jkrdt.timestep allow for max |dE| / E_imp <= tolerance, so each run's energy error
    # stays within it (the bounds lie on or above the worst run of their ensembles)
    from jkrdt import rundir, timestep
    from jkrdt.materials import material, scales

    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(dict(SPEC, model="frictionless", v_col=[5.0, 40.0],
                                    b_off2=[0.0], dt="auto", tolerance=1e-3)))
    assert run_campaign(spec, tmp_path / "runs", progress=False)["ran"] == 2
    v0 = scales(material("ice"), 1e-7).v0
    for v in (5.0, 40.0):
        run = run_directory(tmp_path / "runs", v, 0.0, 2)
        want, _ = timestep.choose(1e-3, v, v0, "frictionless", n_total=32)
        meta = json.loads((run / rundir.META).read_text())
        assert meta["dt_over_tc"] == want and "chosen for max |dE|/E_imp <= 0.001" in \
            meta["dt_reason"]
        out = json.loads((run / rundir.OUTCOME).read_text())
        assert out["stop_reason"] == "settled" and out["energy_error"] <= 1e-3, out
    record = json.loads((tmp_path / "runs" / "campaign.json").read_text())
    assert record["spec"]["dt"] == "auto" and record["spec"]["tolerance"] == 1e-3
