"""Records you can trust: a command that is stopped stops its LAMMPS, and what it leaves
is refused as an outcome until it is run again."""

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cut_off import RULE, straight_and_cut

BIN = Path(sys.executable).parent
JKRDT = str(BIN / "jkrdt")


def test_stopping_jkrdt_run_stops_its_lammps(tmp_path):
    d = tmp_path / "scene"
    subprocess.run([JKRDT, "setup", "--n-tar", "64", "--n-pro", "64", "--v", "20", "--out",
                    str(d)], check=True, capture_output=True, timeout=300)
    # on 2 ranks: mpirun's banner about ranks it saw killed is not shown
    run = subprocess.Popen([JKRDT, "run", str(d), "--steps", "50000000", "--np", "2"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    log = d / "log.lammps"
    deadline = time.time() + 120
    while time.time() < deadline and not (log.exists() and "Step" in log.read_text()):
        time.sleep(0.1)
    time.sleep(1.0)                                  # well inside the run
    run.send_signal(signal.SIGTERM)
    t0 = time.time()
    out, err = run.communicate(timeout=20)
    assert time.time() - t0 < 5, "LAMMPS must end within 5 s of the signal"
    assert run.returncode == 2 and err.count("\n") == 1 and "BAD TERMINATION" not in out, err
    assert "stopped by SIGTERM, and LAMMPS with it" in err and f"'jkrdt run {d}'" in err
    # no LAMMPS left writing: no process names the scene, and the log holds still
    size = log.stat().st_size
    time.sleep(2.0)
    assert log.stat().st_size == size
    left = subprocess.run(["pgrep", "-f", str(d)], capture_output=True, text=True)
    assert left.stdout == "", left.stdout
    analysed = subprocess.run([JKRDT, "analyse", str(d), "--no-plots"], capture_output=True,
                              text=True, timeout=300)
    assert analysed.returncode == 2 and "the run was cut off" in analysed.stderr
    assert not (d / "outcome.json").exists()


def test_a_run_cut_off_continues_as_the_uninterrupted_one_and_a_finished_one_is_kept(tmp_path):
    """jkrdt run on a run that was cut off continues it from its newer restart file, adding
    to its record, so that its analysis equals the uninterrupted run's (restarts are exact:
    tests/test_lifecycle.py); on a finished run it refuses without --force."""
    import json

    straight, cut, returncode = straight_and_cut(tmp_path)
    rule = RULE
    assert returncode == 2 and not (cut / "final.restart").exists(), "ended before the cut"
    subprocess.run([JKRDT, "analyse", str(cut), "--partial", "--no-plots"], check=True,
                   capture_output=True, timeout=300)
    assert json.loads((cut / "outcome.json").read_text())["stop_reason"] == "cut off"
    again = subprocess.run([JKRDT, "run", str(cut), *rule], capture_output=True, text=True,
                           timeout=600)
    assert again.returncode == 0, again.stderr
    assert "continuing the run that was cut off, from restart." in again.stdout
    assert not (cut / "outcome.json").exists()       # no stale outcome beside a newer log
    outcomes = []
    for d in (straight, cut):
        subprocess.run([JKRDT, "analyse", str(d), "--no-plots"], check=True,
                       capture_output=True, timeout=300)
        outcomes.append(json.loads((d / "outcome.json").read_text()))
    for key in ("stop_reason", "stop_step", "n_largest", "n_fragments", "contacts_per_particle",
                "gyration_radius_largest", "dissipated_fraction", "energy_error", "N_con",
                "N_cut"):
        assert outcomes[1][key] == outcomes[0][key], key
    frames = [(d / "frames.csv").read_text().splitlines()[1:] for d in (straight, cut)]
    assert [r.split(",")[0] for r in frames[1]] == [r.split(",")[0] for r in frames[0]]
    # the settle table: the same rows but for the timing columns (the later row of a step
    # written twice is the one that counts), and its wall clock goes on across the
    # continuation instead of starting again at 0
    from jkrdt.analysis.tables import read_csv

    timing = ("wall", "memory_mb", "peak_rss_mb")
    tables = []
    for d in (straight, cut):
        rows = {r["step"]: r for r in read_csv(d / "checks.csv")}
        tables.append([{k: v for k, v in r.items() if k not in timing} for r in rows.values()])
    assert tables[1] == tables[0]
    walls = [r["wall"] for r in read_csv(cut / "checks.csv")]
    assert all(b >= a for a, b in zip(walls, walls[1:])), walls
    log = (cut / "log.lammps").read_text()
    assert log.count("Reading restart file") == 1 and log.count("Reading data file") == 1
    kept = (cut / "outcome.json").stat().st_mtime_ns
    refused = subprocess.run([JKRDT, "run", str(cut), *rule], capture_output=True, text=True,
                             timeout=120)
    assert refused.returncode == 2 and "holds a finished run (settled at step" in refused.stderr
    assert "--force" in refused.stderr and (cut / "outcome.json").stat().st_mtime_ns == kept


def wait_for(path: Path, seconds: float = 120.0) -> None:
    deadline = time.time() + seconds
    while not path.exists() and time.time() < deadline:
        time.sleep(0.02)
    assert path.exists(), f"{path} never appeared"


@pytest.mark.parametrize("how", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_stopping_a_campaign_stops_its_lammps_at_once(tmp_path, how):
    # a campaign runs LAMMPS in its own process: any of the three signals ends it within
    # seconds (SIGINT too: not only when the current chunk returns to Python), and the run
    # under way is recorded as cut off, to be resumed
    import json

    from jkrdt import rundir
    from jkrdt.campaign import run_directory

    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(dict(n_tar=64, n_pro=64, v_col=[20.0], b_off2=[0.25], seeds=[2],
                                    settle=dict(check_tc=5, cap_tc=4000))))
    run = run_directory(tmp_path / "c", 20.0, 0.25, 2)
    proc = subprocess.Popen([JKRDT, "campaign", str(spec), str(tmp_path / "c"), "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wait_for(run / "restart.b")
    proc.send_signal(how)
    t0 = time.time()
    _, err = proc.communicate(timeout=20)
    assert time.time() - t0 < 5 and proc.returncode == -how, (proc.returncode, err)
    assert "Traceback" not in err
    # what it left, and how to resume it
    assert f"campaign stopped by {how.name}" in err and "0 of 1 runs finished, 1 cut off" in err
    assert f"cut off, resumes from its last restart file: {run}" in err
    assert f"'jkrdt campaign {spec} {tmp_path / 'c'} --quiet' resumes it" in err
    size = (run / rundir.LOG).stat().st_size
    time.sleep(1.0)
    assert (run / rundir.LOG).stat().st_size == size      # no LAMMPS left writing
    assert rundir.run_status(run).stop_reason == "cut off"
    assert not rundir.finished(run)


def test_stopping_a_campaign_on_two_ranks_says_what_it_left_without_mpiruns_banner(tmp_path):
    import json

    from jkrdt import rundir
    from jkrdt.campaign import run_directory

    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(dict(n_tar=64, n_pro=64, v_col=[20.0], b_off2=[0.0, 0.25],
                                    seeds=[2], settle=dict(check_tc=5, cap_tc=4000))))
    runs = [run_directory(tmp_path / "c", 20.0, b2, 2) for b2 in (0.0, 0.25)]
    proc = subprocess.Popen([JKRDT, "campaign", str(spec), str(tmp_path / "c"), "--np", "2"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wait_for(runs[0] / "restart.b")
    proc.send_signal(signal.SIGTERM)
    t0 = time.time()
    out, err = proc.communicate(timeout=20)
    assert time.time() - t0 < 5 and proc.returncode == 2, (proc.returncode, err)
    assert "BAD TERMINATION" not in out + err and "Traceback" not in err, out + err
    done = sum(rundir.finished(r) for r in runs)
    cut = [r for r in runs if not rundir.finished(r) and (r / rundir.LOG).exists()]
    assert cut, "the campaign was stopped while a run went"
    assert (f"{done} of 2 runs finished, {len(cut)} cut off, {2 - done - len(cut)} not "
            "started") in err, err
    assert all(f"resumes from its last restart file: {r}" in err for r in cut)
    assert f"'jkrdt campaign {spec} {tmp_path / 'c'} --np 2' resumes it" in err
    left = subprocess.run(["pgrep", "-f", str(tmp_path)], capture_output=True, text=True)
    assert left.stdout == "", left.stdout


SESSION_SCRIPT = """
import sys
from jkrdt.session import Session
with Session(sys.argv[1], every=200) as run:
    run.run(50_000_000, chunk=200, progress=False)
"""


def as_in_a_terminal():
    """SIGINT as a foreground process gets it (a shell starts background jobs, CI's among
    them, with SIGINT ignored, and Python then never installs its handler)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_stopping_a_session_script_leaves_its_record_cut_off(tmp_path):
    # Python stops a Session script at SIGINT when its current chunk returns: the session
    # then closes without its end part, so the record says cut off
    from jkrdt import rundir

    d = tmp_path / "scene"
    subprocess.run([JKRDT, "setup", "--n-tar", "64", "--n-pro", "64", "--v", "20", "--out",
                    str(d)], check=True, capture_output=True, timeout=300)
    script = tmp_path / "script.py"
    script.write_text(SESSION_SCRIPT)
    proc = subprocess.Popen([sys.executable, str(script), str(d)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, preexec_fn=as_in_a_terminal)
    wait_for(d / "restart.b")
    proc.send_signal(signal.SIGINT)
    t0 = time.time()
    _, err = proc.communicate(timeout=20)
    assert time.time() - t0 < 5 and proc.returncode != 0 and "KeyboardInterrupt" in err
    status = rundir.run_status(d)
    assert status.stop_reason == "cut off" and rundir.FINISH_LINE in status.problem
    assert not (d / rundir.FINAL_RESTART).exists()


def test_one_run_per_directory(tmp_path):
    """A second jkrdt run on a directory being run is refused in one line naming the
    holder; a stale claim (its process gone) is taken over; a cut-off run exits non-zero."""
    scene = tmp_path / "s"
    subprocess.run([JKRDT, "setup", "--n-tar", "64", "--n-pro", "64", "--v", "20", "--out",
                    str(scene)], check=True, capture_output=True, timeout=300)
    (scene / ".claim").write_text("elsewhere pid 99999999 since long ago\n")    # stale
    first = subprocess.Popen([JKRDT, "run", str(scene), "--check", "10", "--quiet"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wait_for(scene / "log.lammps")
    second = subprocess.run([JKRDT, "run", str(scene), "--check", "10"], capture_output=True,
                            text=True, timeout=120)
    assert second.returncode != 0 and first.poll() is None, "the first run ended too soon"
    assert len(second.stderr.strip().splitlines()) == 1, second.stderr
    assert f"pid {first.pid}" in second.stderr and "is being run by" in second.stderr
    out, err = first.communicate(timeout=600)
    assert first.returncode == 0, err
    assert "settled" in out or "cap" in out
