"""The per-contact kernel (plugin/jkr_dt_contact.h) on its own, without LAMMPS: the C++
checks of tests/kernel/test_contact_kernel.cpp (force against eq. 5, the solver of eq. 4
against Newton's method, the clamps of eqs. 36-38, a run's set-up changing nothing,
angular momentum of one contact, energy of one elastic oscillation, the step's fast
forms against the plain ones, the per-contact state's layouts),
compiled here with the compiler that built the plugin."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def compiler():
    for name in (os.environ.get("CXX"), "c++", "g++", "clang++"):
        if name and shutil.which(name):
            return shutil.which(name)
    pytest.fail("no C++ compiler found (set CXX): the plugin's build needs one too")


def test_contact_kernel_checks(tmp_path):
    exe = tmp_path / "test_contact_kernel"
    subprocess.run([compiler(), "-O2", "-std=c++17", "-Wall", "-Werror", "-Wno-psabi",
                    f"-I{ROOT / 'plugin'}", str(ROOT / "tests/kernel/test_contact_kernel.cpp"),
                    "-o", str(exe)], check=True)
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120)
    lines = run.stdout.splitlines()
    assert lines[-1] == "0 failed", run.stdout
    checks = [line for line in lines[:-1]]
    assert len(checks) == 30 and all(line.startswith("ok ") for line in checks), run.stdout
