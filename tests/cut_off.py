"""A run and its twin cut off by a signal, for the tests of what a cut-off record resumes
to (tests/test_records.py, tests/test_resume_misuse.py)."""

import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

JKRDT = str(Path(sys.executable).parent / "jkrdt")
#: the settle rule of these runs: a check every 10 t_c
RULE = ["--check", "10"]


def straight_and_cut(where: Path):
    """(straight, cut, the cut jkrdt run's return code): a 2 x 64 scene at 20 m/s run to
    its end in ``straight``, and the same scene's run in ``cut`` stopped by SIGINT a few
    checks after its second restart file."""
    straight, cut = where / "straight", where / "cut"
    subprocess.run([JKRDT, "setup", "--n-tar", "64", "--n-pro", "64", "--v", "20", "--out",
                    str(straight)], check=True, capture_output=True, timeout=300)
    shutil.copytree(straight, cut)
    subprocess.run([JKRDT, "run", str(straight), *RULE], check=True, capture_output=True,
                   timeout=600)
    run = subprocess.Popen([JKRDT, "run", str(cut), *RULE], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 300
    while not (cut / "restart.b").exists() and time.time() < deadline:
        time.sleep(0.02)
    time.sleep(0.3)                                  # a few more checks
    run.send_signal(signal.SIGINT)
    run.communicate(timeout=30)
    return straight, cut, run.returncode
