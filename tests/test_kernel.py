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


def test_python_names_the_kernels_channels(tmp_path):
    """The channels are declared once, in the kernel (JKRDT_NORMAL_CHANNELS and
    JKRDT_TANGENTIAL_CHANNELS): the ledger's columns and compute pair jkr/dt's values, in
    the order the compiled kernel gives them, are the names Python reads logs and sessions
    by (jkrdt.ledger). A new channel is one line in the kernel and its name here."""
    from jkrdt import ledger

    source = tmp_path / "names.cpp"
    source.write_text('#include "jkr_dt_contact.h"\n#include <cstdio>\n'
                      'int main() {\n'
                      '  for (const char *name : JKRDT::VALUE_NAME) std::puts(name);\n'
                      '  std::printf("%d %d %d\\n", (int) JKRDT::NLOSS, (int) JKRDT::NCHANNEL,'
                      ' (int) JKRDT::VALUE_LOSS);\n}\n')
    exe = tmp_path / "names"
    subprocess.run([compiler(), "-std=c++17", "-Wall", "-Werror", f"-I{ROOT / 'plugin'}",
                    str(source), "-o", str(exe)], check=True)
    *names, counts = subprocess.run([str(exe)], capture_output=True, text=True,
                                    check=True).stdout.splitlines()
    assert names == ledger.VALUES
    nloss, nchannel, first_loss = map(int, counts.split())
    assert names[first_loss:first_loss + nloss] == ledger.CHANNELS
    assert len(ledger.POTENTIALS) == 1 + nchannel
    assert ledger.LEDGER[0] == f"c_p[{first_loss + 1}]"
