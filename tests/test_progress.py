"""What jkrdt run shows while it runs (issue 47): a line per settle check, the same
numbers as the run's table, plain and flushed when the output is not a terminal; none
with --quiet."""

import re
import subprocess
import sys
from pathlib import Path

from jkrdt import rundir
from jkrdt.analysis.tables import read_csv
from jkrdt.progress import complete_rows

BIN = Path(sys.executable).parent
JKRDT = str(BIN / "jkrdt")
LINE = re.compile(r"^step (\d+)  t (\d+) t_c  N_lar (\d+)  fragments (\d+)  contacts (\d+)"
                  r"  \|dE\|/E_imp (\S+)(  (\S+) s/check)?(  cap in .* at most)?$")


def test_jkrdt_run_shows_each_check_as_its_table_holds_it(tmp_path):
    scene = tmp_path / "s"
    subprocess.run([JKRDT, "setup", "--n-tar", "64", "--n-pro", "64", "--v", "20", "--out",
                    str(scene)], check=True, capture_output=True, timeout=300)
    done = subprocess.run([JKRDT, "run", str(scene), "--check", "10"], check=True,
                          capture_output=True, text=True, timeout=600)
    lines = [LINE.match(line) for line in done.stdout.splitlines() if line.startswith("step ")]
    assert lines and all(lines), done.stdout
    rows = read_csv(scene / rundir.CHECKS)
    assert [int(m[1]) for m in lines] == [int(r["step"]) for r in rows]
    assert [int(m[3]) for m in lines] == [int(r["n_largest"]) for r in rows]
    assert [int(m[5]) for m in lines] == [int(r["contacts"]) for r in rows]
    # the energy error so far only grows, and stays below the run's own bound (1e-3)
    errors = [float(m[6]) for m in lines]
    assert errors == sorted(errors) and errors[-1] < 1e-3
    quiet = tmp_path / "q"
    subprocess.run([JKRDT, "setup", "--n-tar", "64", "--n-pro", "64", "--v", "20", "--out",
                    str(quiet)], check=True, capture_output=True, timeout=300)
    done = subprocess.run([JKRDT, "run", str(quiet), "--check", "10", "--quiet"], check=True,
                          capture_output=True, text=True, timeout=600)
    assert not [line for line in done.stdout.splitlines() if line.startswith("step ")]


def test_a_half_written_row_is_not_read(tmp_path):
    table = tmp_path / "checks.csv"
    table.write_text("step,time,n_largest\n100,1e-9,64\n200,2e-9,6")
    assert complete_rows(table) == [dict(step=100.0, time=1e-9, n_largest=64.0)]


SESSION_LINES = """
import sys
from jkrdt.session import Session
from jkrdt.stopping import SettleRule
with Session(sys.argv[1], every=1, settle=SettleRule(check_tc=10)) as run:
    run.run_until_settled()
"""


def test_a_session_and_a_campaign_show_their_checks(tmp_path):
    """Session.run_until_settled shows a line per check as jkrdt run does; a campaign
    shows each run's checks named by its run, at most one a LINE_EVERY_S (here 0 s)."""
    import json
    import os

    scene = tmp_path / "s"
    subprocess.run([JKRDT, "setup", "--n-tar", "64", "--n-pro", "64", "--v", "20", "--out",
                    str(scene)], check=True, capture_output=True, timeout=300)
    done = subprocess.run([sys.executable, "-c", SESSION_LINES, str(scene)], check=True,
                          capture_output=True, text=True, timeout=600)
    lines = [LINE.match(line) for line in done.stdout.splitlines() if line.startswith("step ")]
    rows = read_csv(scene / rundir.CHECKS)
    assert lines and all(lines) and len(lines) == len(rows), done.stdout
    assert [int(m[3]) for m in lines] == [int(r["n_largest"]) for r in rows]
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(dict(n_tar=16, n_pro=16, v_col=[10.0], b_off2=[0.0], seeds=[1],
                                    settle=dict(check_tc=10, cap_tc=4000))))
    script = ("import sys, jkrdt.campaign as c; c.LINE_EVERY_S = 0.0; "
              "c.run_campaign(sys.argv[1], sys.argv[2])")
    done = subprocess.run([sys.executable, "-c", script, str(spec), str(tmp_path / "c")],
                          check=True, capture_output=True, text=True, timeout=600,
                          env=dict(os.environ))
    named = "[ranks 0-0] v 10 B_off^2 0 seed 1: "
    lines = [LINE.match(line[len(named):]) for line in done.stdout.splitlines()
             if line.startswith(named + "step ")]
    rows = read_csv(tmp_path / "c" / "v10" / "b2_0.0000" / "seed1" / rundir.CHECKS)
    assert lines and all(lines) and len(lines) == len(rows), done.stdout
