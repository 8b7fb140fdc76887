"""Values given in the wrong unit (issue 47): a radius in micron, tvis in ps, xi_crit in
Angstrom, E in GPa, gamma in mJ/m^2 or a speed far beyond grain collisions is refused at
set-up in one line that names the SI unit and the value probably meant; the papers' own
values pass."""

import subprocess
import sys
from pathlib import Path

import pytest

from jkrdt.materials import ICE, material
from jkrdt.scene import Scene

JKRDT = str(Path(sys.executable).parent / "jkrdt")


@pytest.mark.parametrize("option,value,meant", [
    ("--radius", "0.1", "1e-07 if you meant 0.1 micron"),
    ("--tvis", "6", "6e-12 if you meant 6 ps"),
    ("--xi-crit", "8", "8e-10 if you meant 8 Angstrom"),
    ("--E", "7", "7e+09 if you meant 7 GPa"),
    ("--gamma", "100", "0.1 if you meant 100 mJ/m^2"),
    ("--v", "40000", "speeds are in m/s"),
])
def test_a_value_in_the_wrong_unit_is_refused_at_setup(tmp_path, option, value, meant):
    done = subprocess.run([JKRDT, "setup", "--n-tar", "8", "--n-pro", "8", "--v", "20",
                           option, value, "--out", str(tmp_path / "s")],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode != 0
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert meant in done.stderr
    assert not (tmp_path / "s" / "collision.data").exists()


def test_the_papers_values_pass():
    # 0.1 micron ice, T_vis 6 ps (< t_c = 0.27 ns), xi_crit 8 A, 100 m/s
    Scene(material("ice", tvis=6e-12), 10, 10, v_col=100.0)
    Scene(ICE, 10, 10, v_col=39.8, radius=1e-6)


def test_an_unknown_model_is_told_the_papers_four():
    done = subprocess.run([JKRDT, "setup", "--n-tar", "8", "--n-pro", "8", "--v", "20",
                           "--model", "frictional+damping", "--out", "/nonexistent"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and "tvis 6e-12" in done.stderr
    assert "frictionless with normal dissipation" in done.stderr
