"""The partial answer of a run that is still going, and of one killed between two atom
frames (issue 47): the outcome at the last settle check, from the settle rule's table
and the log, with the last atom frame marked."""

import json
import signal
import subprocess
import time

from cut_off import JKRDT

from jkrdt import rundir
from jkrdt.analysis.tables import read_csv

#: 2 x 2500 ice at 20 m/s, checks every 2 t_c (143 steps), atom frames every 4 checks
SCENE = ["--n-tar", "2500", "--n-pro", "2500", "--v", "20"]
FRAMES = 4
RUN = ["--check", "2", "--frames", str(FRAMES), "--quiet"]


def whole_rows(run):
    path = run / rundir.CHECKS
    return read_csv(path) if path.exists() else []


def wait_for_rows(run, count, process, timeout=300):
    deadline = time.time() + timeout
    while len(whole_rows(run)) < count:
        assert process.poll() is None, "the run ended before it could be watched"
        assert time.time() < deadline, "the run wrote too few checks"
        time.sleep(0.01)


def analyse(run, *options):
    done = subprocess.run([JKRDT, "analyse", str(run), "--partial", *options],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and "Traceback" not in done.stderr, done.stderr
    return done.stdout, json.loads((run / rundir.OUTCOME).read_text())


def assert_outcome_is_the_check(out, row):
    """The outcome is the check's row of checks.csv: N_lar, fragments, f_gro, n_con."""
    assert out["last_step"] == int(row["step"])
    assert out["n_largest"] == int(row["n_largest"])
    assert out["n_fragments"] == int(row["n_fragments"])
    assert out["growth_efficiency"] == (int(row["n_largest"]) - 2500) / 2500
    assert out["contacts_per_particle"] == int(row["contacts_largest"]) / int(row["n_largest"])


def test_a_run_in_progress_and_then_killed_between_two_frames_is_read_from_its_checks(tmp_path):
    run = tmp_path / "run"
    subprocess.run([JKRDT, "setup", *SCENE, "--out", str(run)], check=True,
                   capture_output=True, timeout=300)
    going = subprocess.Popen([JKRDT, "run", str(run), *RUN], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    try:
        # while it goes: "in progress", never "cut off", and not a finished run
        wait_for_rows(run, FRAMES + 3, going)
        said, out = analyse(run, "--no-plots")
        assert "is in progress at step" in said and "CUT OFF" not in said, said
        assert out["stop_reason"] == rundir.IN_PROGRESS
        assert not rundir.finished(run), "a partial outcome must not end the run"
        rows = whole_rows(run)
        assert out["last_step"] >= int(rows[FRAMES + 2]["step"])
        # killed one check after an atom frame: the last check comes after the last frame
        seen, deadline = len(whole_rows(run)), time.time() + 300
        while (len(whole_rows(run)) - 1) % FRAMES != 1 or len(whole_rows(run)) <= seen:
            assert going.poll() is None and time.time() < deadline
            time.sleep(0.005)
        going.send_signal(signal.SIGINT)
        going.communicate(timeout=60)
    finally:
        if going.poll() is None:
            going.kill()
    assert going.returncode != 0, "a run cut off must not exit 0"
    said, out = analyse(run)
    rows = whole_rows(run)
    last = rows[-1]
    assert out["stop_reason"] == "cut off" and "CUT OFF" in said
    assert_outcome_is_the_check(out, last)
    frame = out["last_frame_step"]
    assert frame < out["last_step"] and frame % (FRAMES * 143) == 0, (frame, out["last_step"])
    assert f"the last atom frame is at step {frame}" in said
    # the timeline is every check, the energies at the last check from the log
    timeline = read_csv(run / rundir.FRAMES)
    assert [r["step"] for r in timeline] == [r["step"] for r in rows]
    thermo = rundir.read_thermo(run / rundir.LOG)
    assert out["time_end"] == float(thermo["Time"][list(thermo["Step"]).index(out["last_step"])])
    # the partition holds at that check: kinetic + potential change + dissipated - drift
    # is the kinetic energy at the start, to rounding (the ledger is one sum)
    total = (out["kinetic_left"] + out["potential_change"] + out["dissipated_fraction"]
             - out["energy_drift"])
    assert abs(total - out["kinetic_start"]) < 1e-12
    assert not rundir.finished(run), "jkrdt run and campaigns must still continue it"
    assert {"outcome.png", "timeline.png"} <= {p.rsplit("/", 1)[-1] for p in out["pictures"]}
