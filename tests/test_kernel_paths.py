"""The pair loop compiled for AVX2 and the portable one give the same bits (pair_style jkr/dt
kernel auto|portable): both inline the same source and neither fuses a multiply with an add,
so a colliding aggregate's trajectory, with contacts forming, breaking and clamping, is the
same to the last digit under each. The AVX2 loop saves instructions only."""

import numpy as np
import pytest

from test_bins import far_pairs_scene
from test_invariance import last_local_dump, run_deck, scene  # noqa: F401  (its scene, deck)


def cpu_has_avx2():
    with open("/proc/cpuinfo") as f:
        return " avx2" in f.read()


def last_thermo(log):
    """The energy ledger's last line (ke, erotate, pe and the dissipated channels)."""
    lines = log.splitlines()
    return lines[[k for k, line in enumerate(lines) if line.startswith("Loop time")][-1] - 1]


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
    ledger = [float(v) for v in last_thermo(logs["auto"]).split()[5:10]]
    assert ledger[0] > 0.0 and (tvis > 0.0) == (ledger[1] > 0.0)   # contacts formed or broke
    if model == "frictional":
        assert min(ledger[2:]) > 0.0                                # every channel clamped


def test_kernel_setting_names_its_values(lmp):
    far_pairs_scene(lmp, 1.0e-6)
    with pytest.raises(Exception, match="kernel takes auto or portable"):
        lmp.command("pair_style jkr/dt kernel avx512")
