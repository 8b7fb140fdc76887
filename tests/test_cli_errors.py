"""A user's mistake on the command line or in a campaign spec is one line,
'jkrdt: <what> (<how to fix>)', with exit status 2 and no traceback."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from jkrdt import rundir
from jkrdt.analysis.dumps import iter_local

JKRDT = str(Path(sys.executable).parent / "jkrdt")


def jkrdt(*args, cwd=None):
    done = subprocess.run([JKRDT, *map(str, args)], capture_output=True, text=True, timeout=120,
                          cwd=cwd)
    return done.returncode, done.stderr


def one_line_error(args, match, cwd=None):
    code, err = jkrdt(*args, cwd=cwd)
    assert code == 2, err
    assert "Traceback" not in err and err.count("\n") == 1, err
    assert err.startswith("jkrdt: ") and match in err, err


@pytest.mark.parametrize("args, match", [
    (["setup", "--v", "-20"], "--v is the collision speed and must be > 0"),
    (["setup", "--b-off", "1.5"], "--b-off must lie in [0, 1]"),
    (["run", ".", "--dt", "0"], "--dt must be > 0 (in units of t_c; got 0)"),
    (["run", ".", "--dt", "-0.01"], "--dt must be > 0"),
    (["run", ".", "--steps", "0"], "--steps must be >= 1"),
    (["setup", "--dt", "fast"], "--dt takes a time step in units of t_c or 'auto'"),
    (["demo", "--window", "0"], "settle window must be a whole number of checks >= 1"),
    (["setup", "--v", "-2e1"], "--v is the collision speed and must be > 0"),
    (["setup", "--radius", "-1e-7"], "the grain radius must be > 0 m (got -1e-07)"),
    (["setup", "--dt", "5"], "--dt must be at most 0.4 t_c"),
    (["setup", "--tolerance", "1e-3"], "--tolerance goes with --dt auto"),
    (["build", "--n", "1073741824"], "1073741824 grains need about 4e+03 GiB to build"),
    (["demo", "--settle-counts", "1"], "settle counts is a fraction of all grains in [0, 1)"),
])
def test_option_errors(tmp_path, args, match):
    one_line_error(args, match, cwd=tmp_path)


def test_analyse_of_a_directory_that_is_no_scene(tmp_path):
    one_line_error(["analyse", tmp_path], "has no collision.json: analyse a directory written by")


def test_setup_refuses_a_used_directory_unless_forced(tmp_path):
    setup = ["setup", "--kind", "bcca", "--dim", "2", "--n-tar", "8", "--n-pro", "8",
             "--out", tmp_path]
    (tmp_path / rundir.ATOMS).write_text("an earlier run's dump")
    (tmp_path / "notes.txt").write_text("the user's own file")
    one_line_error(setup, "is not empty; choose another --out, or give --force")
    code, err = jkrdt(*setup, "--force")
    assert code == 0, err
    assert not (tmp_path / rundir.ATOMS).exists()                 # what it owns is cleared
    assert (tmp_path / "notes.txt").read_text() == "the user's own file"
    assert (tmp_path / "collision.json").exists()


SPEC = dict(n_tar=8, n_pro=8, v_col=[10], b_off2=[0.0])


@pytest.mark.parametrize("change, match", [
    (dict(v_col=5), '"v_col" must be a non-empty list of speeds > 0'),
    (dict(v_col=[10, -5]), '"v_col" must be a non-empty list of speeds > 0'),
    (dict(settle=False, steps=4000, every=0), '"every" must be a whole number of steps >= 1'),
    (dict(n_tar=8.5), '"n_tar" must be a whole number of grains >= 1'),
    (dict(dim=4), '"dim" must be 2 or 3'),
    (dict(seeds="1"), '"seeds" must be a non-empty list of whole numbers'),
    (dict(material="granite"), "unknown material 'granite'"),
    (dict(material_overrides={"hardness": 3}), '"material"/"material_overrides"'),
    (dict(dt=5), '"dt" must be a time step in (0, 0.4] in units of t_c, or "auto"'),
    (dict(dt="auto", tolerance=2), '"tolerance" must be a relative energy error in (0, 1)'),
    (dict(tolerance=1e-3), '"tolerance" goes with "dt": "auto"'),
])
def test_campaign_spec_errors_name_the_key(tmp_path, change, match):
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(dict(SPEC, **change)))
    one_line_error(["campaign", spec, tmp_path / "runs"], match)
    assert not (tmp_path / "runs").exists()


@pytest.mark.parametrize("text, match", [
    ('{"n_tar": 8, "n_pro": 8,', "spec.json is not valid JSON: Expecting"),
    ("[8, 8]", "spec.json: a campaign spec is a JSON object of keys"),
    (json.dumps(dict(SPEC, n_tar=2 ** 30)), "grains need about"),
])
def test_campaign_spec_files_that_cannot_run_are_named(tmp_path, text, match):
    spec = tmp_path / "spec.json"
    spec.write_text(text)
    one_line_error(["campaign", spec, tmp_path / "runs"], match)
    assert not (tmp_path / "runs").exists()


def test_contact_snapshot_without_contacts_is_read(tmp_path):
    # every total fragmentation ends with an empty contact list
    dump = tmp_path / "contacts.dump"
    dump.write_text("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ENTRIES\n0\nITEM: BOX BOUNDS mm mm mm\n"
                    "0 1\n0 1\n0 1\nITEM: ENTRIES c_bonds[1] c_bonds[2] c_bonds[3] c_bonds[4] "
                    "c_bonds[5] c_bonds[6] c_bonds[7] c_bonds[8]\n")
    [(step, rows)] = list(iter_local(dump))
    assert step == 0 and rows.shape == (0, 8) and rows.dtype == np.float64


def test_help_shows_defaults_and_the_campaign_spec():
    setup = subprocess.run([JKRDT, "setup", "--help"], capture_output=True, text=True,
                           check=True).stdout
    for line in ("--n-tar N_TAR         grains in the target (default: 256)",
                 "--b-off B_OFF         impact parameter B_off (default: 0.0)",
                 "--kind {bpca,bcca}    (default: bpca)"):
        assert line in setup, setup
    spec = subprocess.run([JKRDT, "campaign", "--help"], capture_output=True, text=True,
                          check=True).stdout
    assert "n_tar, n_pro, v_col and b_off2 are required" in spec
    assert '"settle": {"check_tc": 50' in spec
