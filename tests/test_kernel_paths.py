"""The pair loop's paths give the same bits. The loop compiled for AVX2 and the portable one
(pair_style jkr/dt kernel auto|portable): both inline the same source and neither fuses a
multiply with an add. The LEAN step and the general one (pair_style jkr/dt lean yes|no): the
LEAN step is the general step's code with the facts of a contact that held between two atoms
of one thread known at compile time (pair_jkr_dt_step.h). So a colliding aggregate's
trajectory, with contacts forming, breaking and clamping, is the same to the last digit
under each; the AVX2 loop and the LEAN step save instructions only."""

import numpy as np
import pytest

from jkrdt import ledger as jkrdt_ledger
from jkrdt import rundir

from test_bins import far_pairs_scene
from test_invariance import last_local_dump, run_deck, scene  # noqa: F401  (its scene, deck)


def cpu_has_avx2():
    with open("/proc/cpuinfo") as f:
        return " avx2" in f.read()


def last_thermo(log):
    """The energy ledger's last line (ke, erotate, pe and the dissipated channels)."""
    lines = log.splitlines()
    return lines[[k for k, line in enumerate(lines) if line.startswith("Loop time")][-1] - 1]


def channels_at_end(workdir):
    """What each channel of the ledger (events, damping, sliding, rolling, twisting) holds
    at the run's end, read from its log by the columns' names."""
    thermo = rundir.read_thermo(workdir / "log.lammps")
    return [float(thermo[column][-1]) for column in jkrdt_ledger.LEDGER]


@pytest.mark.parametrize("model,tvis", [("frictional", 0.0), ("frictionless", 6e-12)])
def test_avx2_loop_gives_the_portable_bits(scene, model, tvis, tmp_path):  # noqa: F811
    auto = run_deck(tmp_path / "auto", scene, model, tvis=tvis)
    portable = run_deck(tmp_path / "portable", scene, model, tvis=tvis,
                        extra=("-var", "kernel", "portable"))
    logs = {name: (tmp_path / name / "log.lammps").read_text() for name in ("auto", "portable")}
    assert ("AVX2 pair loop" in logs["auto"]) == cpu_has_avx2()
    assert "portable pair loop" in logs["portable"]
    assert np.array_equal(auto, portable)        # positions, velocities and spins
    # the contacts' forces and the ledger of what was dissipated (formation and breaking,
    # damping, the clamps of sliding, rolling and twisting), to the last printed digit
    assert np.array_equal(last_local_dump(tmp_path / "auto"),
                          last_local_dump(tmp_path / "portable"))
    assert last_thermo(logs["auto"]) == last_thermo(logs["portable"])
    ledger = channels_at_end(tmp_path / "auto")
    assert ledger[0] > 0.0 and (tvis > 0.0) == (ledger[1] > 0.0)   # contacts formed or broke
    if model == "frictional":
        assert min(ledger[2:]) > 0.0                                # every channel clamped


@pytest.mark.parametrize("model,tvis,threads", [("frictional", 0.0, 1), ("frictional", 0.0, 2),
                                                ("frictionless", 6e-12, 1),
                                                ("frictionless", 6e-12, 2)])
def test_lean_step_gives_the_general_bits(scene, model, tvis, threads, tmp_path):  # noqa: F811
    """The same pairs, every step, on the LEAN step where it applies (most contacts, most
    steps) and on the general step alone: the same positions, velocities, spins, contact
    forces and ledger. Frictional: the LEAN step hands the tangential step to the lanes;
    frictionless, damped: it books F_D's work; on 2 threads it takes only the pairs whose
    atoms are both the thread's."""
    lean = run_deck(tmp_path / "lean", scene, model, tvis=tvis, threads=threads)
    general = run_deck(tmp_path / "general", scene, model, tvis=tvis, threads=threads,
                       extra=("-var", "kernel", "auto lean no"))
    logs = {name: (tmp_path / name / "log.lammps").read_text() for name in ("lean", "general")}
    assert "(lean no)" in logs["general"] and "(lean no)" not in logs["lean"]
    assert np.array_equal(lean, general)
    assert np.array_equal(last_local_dump(tmp_path / "lean"),
                          last_local_dump(tmp_path / "general"))
    assert last_thermo(logs["lean"]) == last_thermo(logs["general"])
    ledger = channels_at_end(tmp_path / "lean")
    assert ledger[0] > 0.0 and (tvis > 0.0) == (ledger[1] > 0.0)   # contacts formed or broke


def test_kernel_setting_names_its_values(lmp):
    far_pairs_scene(lmp, 1.0e-6)
    with pytest.raises(Exception, match="kernel takes auto or portable"):
        lmp.command("pair_style jkr/dt kernel avx512")
    with pytest.raises(Exception, match="lean takes yes or no"):
        lmp.command("pair_style jkr/dt lean off")
