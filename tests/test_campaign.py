"""A small campaign end to end: v_col x B_off^2 runs, resumed without redoing finished
runs, summarised with eq. (1) of the 3D BPCA paper, and the same under mpirun -np 2."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from jkrdt.analysis.campaign import b_off_average, summarise
from jkrdt.analysis.tables import read_csv
from jkrdt.campaign import run_campaign

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
    assert first == dict(runs=6, skipped=0, ran=6)
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
    assert again == dict(runs=6, skipped=5, ran=1)
    assert all(p.stat().st_mtime_ns == t for p, t in before.items())
    # the redone run is the same simulation
    assert json.loads(redo.read_text())["n_largest"] == kept["n_largest"]


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
    for name in ("growth_efficiency", "cumulative", "disruption", "compression"):
        assert (runs / f"{name}.png").stat().st_size > 0
    # at 2 m/s (0.6 v0, far below v_fra) the aggregates stick at every B_off that touches
    slow = next(line for line in summary["table"] if line["v_col"] == 2.0)
    assert slow["mean_f_gro"] > 0


@pytest.mark.mpi
def test_campaign_under_two_ranks_matches_serial(campaign, tmp_path):
    spec, runs, _ = campaign
    subprocess.run([str(BIN / "mpirun"), "-np", "2", str(BIN / "jkrdt"), "campaign", str(spec),
                    str(tmp_path), "--quiet"], check=True, timeout=600)
    for path in sorted(runs.rglob("outcome.json")):
        serial = json.loads(path.read_text())
        parallel = json.loads((tmp_path / path.relative_to(runs)).read_text())
        for key in ("n_largest", "n_second", "n_fragments", "contacts_per_particle"):
            assert parallel[key] == serial[key], (path, key)
        assert parallel["gyration_radius_largest"] == pytest.approx(
            serial["gyration_radius_largest"], rel=1e-9)


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
    assert not (tmp_path / "runs").exists()


def test_failed_run_is_recorded_and_left_out_of_the_summary(tmp_path):
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(dict(SPEC, v_col=[20.0], b_off2=[0.0], dt=0.6)))
    assert run_campaign(spec, tmp_path / "runs", progress=False)["ran"] == 1
    out = json.loads(next((tmp_path / "runs").rglob("outcome.json")).read_text())
    assert out["stop_reason"] == "error" and "above 0.4 t_c" in out["problem"]
    # finished as far as resuming goes: not tried again
    assert run_campaign(spec, tmp_path / "runs", progress=False)["skipped"] == 1
    with pytest.raises(ValueError, match=r"none of its 1 runs is complete \(\['error'\]\)"):
        summarise(tmp_path / "runs", plot=False)
