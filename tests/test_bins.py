"""Bins that grow with the box (pair_style jkr/dt bins bounded, plugin/pair_jkr_dt_bins.cpp).

LAMMPS's neighbor and sort bins tile the box at half the neighbor cutoff; a shattering
collision's shrink-wrapped box grows as its fragments fly. With ``bins bounded`` (the
default) the bins widen to at most BINS_PER_GRAIN per grain once the box has spread, so a
box of any size costs memory in proportion to its grains. Widening changes which bins a
pair is found through, never which pairs are found: distant pairs of grains then collide
exactly as a lone pair does.
"""

import re

import numpy as np
import pytest

from conftest import two_grain_scene
from jkrdt.materials import ICE, scales

R = 1.0e-7
BINS_PER_GRAIN = 32          # PairJKRDT::BINS_PER_GRAIN
V_REL = 3.0                  # m/s, head-on, each pair


# shrink-wrapped, as a collision scene's box is
SHRINK_WRAPPED = """
        units si
        atom_style sphere
        atom_modify map array
        boundary m m m
        newton off
        comm_modify vel yes
"""


def far_pairs_scene(lmp, gap, settings=""):
    """Two head-on pairs of ice grains, ``gap`` apart along x, y and z, in a
    shrink-wrapped box: 4 grains in a box of about gap^3."""
    s = scales(ICE, R)
    lmp.commands_string(SHRINK_WRAPPED + f"""
        region box block {-R!r} {gap + 3.02 * R!r} {-R!r} {gap + R!r} {-R!r} {gap + R!r}
        create_box 1 box
        create_atoms 1 single 0 0 0
        create_atoms 1 single {2.02 * R!r} 0 0
        create_atoms 1 single {gap!r} {gap!r} {gap!r}
        create_atoms 1 single {gap + 2.02 * R!r} {gap!r} {gap!r}
        set type 1 diameter {2 * R!r}
        set type 1 density {ICE.density!r}
        velocity all set 0 0 0
        set atom 1 vx {0.5 * V_REL!r}
        set atom 2 vx {-0.5 * V_REL!r}
        set atom 3 vx {0.5 * V_REL!r}
        set atom 4 vx {-0.5 * V_REL!r}
        pair_style jkr/dt {settings}
        pair_coeff * * gamma {ICE.gamma!r} E {ICE.E!r} nu {ICE.nu!r} frictionless
        neighbor {2 * s.delta_c!r} bin
        neigh_modify every 1 delay 0 check yes
        fix integrate all nve/sphere
        compute p all pair jkr/dt
        compute erot all erotate/sphere
        thermo_style custom step ke pe
        timestep {0.01 * s.t_c!r}
    """)
    return s


def velocities(lmp):
    ids = lmp.numpy.extract_atom("id")
    v = lmp.numpy.extract_atom("v")
    return v[np.argsort(ids)].copy()


def run_far_pairs(gap, settings="", log=None):
    from jkrdt.session import start_lammps
    lmp = start_lammps()
    try:
        if log:
            lmp.command(f"log {log}")
        far_pairs_scene(lmp, gap, settings)
        lmp.command("run 3000")
        return velocities(lmp), np.subtract(*lmp.extract_box()[1::-1])
    finally:
        lmp.close()


def test_widened_bins_find_the_same_pairs(tmp_path):
    # 10 micron apart: LAMMPS's bins number ~1e6 for 4 grains, bounded ones 128. The
    # same collisions to the last bit: bins only decide where a pair is looked for
    bounded, box = run_far_pairs(1.0e-5, log=tmp_path / "log.lammps")
    lammps_bins, _ = run_far_pairs(1.0e-5, settings="bins box")
    np.testing.assert_array_equal(bounded, lammps_bins)
    log = (tmp_path / "log.lammps").read_text()
    size = float(re.search(r"bins widened to (\S+) m", log).group(1))
    cut = 2 * R + 2 * scales(ICE, R).delta_c       # + a stretched contact's reach, < 1 %
    binned = np.prod(box + 2 * cut)                 # the box and a cutoff of ghosts around it
    assert size == pytest.approx((binned / (BINS_PER_GRAIN * 4)) ** (1 / 3), rel=0.01)
    # what LAMMPS set up: at most 32 bins per grain (it reports "bins = nx ny nz")
    bins = np.prod([int(b) for b in re.search(r"bins = (\d+) (\d+) (\d+)", log).groups()])
    assert 0.3 * BINS_PER_GRAIN * 4 <= bins <= BINS_PER_GRAIN * 4


def test_far_pairs_collide_as_a_lone_pair_does(lmp):
    # 1 cm apart, where LAMMPS's own bins (~1e15) are refused (below): the pair at the
    # origin rebounds exactly as a lone pair does; the far one to the round-off of
    # coordinates of 1 cm (its overlap of ~1e-9 m is a difference of numbers ~1e-2 m)
    far, _ = run_far_pairs(1.0e-2)
    two_grain_scene(lmp, 2.02 * R, v_rel=V_REL)
    lmp.command("run 3000")
    alone = velocities(lmp)
    assert alone[0, 0] < 0 < alone[1, 0], "the lone pair rebounds at 3 m/s"
    np.testing.assert_array_equal(far[:2], alone)
    np.testing.assert_allclose(far[2:], alone, rtol=1e-3)


def test_box_wide_bins_are_what_lammps_refuses(lmp):
    far_pairs_scene(lmp, 1.0e-2, settings="bins box")
    with pytest.raises(Exception, match="[Tt]oo many"):
        lmp.command("run 10")


def test_compact_scene_keeps_lammps_bins(lmp, tmp_path):
    # 6^3 grains at rest on a cubic lattice 2.05 r apart: LAMMPS's bins of half the
    # cutoff number (1.23 + 0.41)^3 / 0.101^3 ~ 4300 < 32 x 216, so none widens
    s = scales(ICE, R)
    lmp.command(f"log {tmp_path / 'log.lammps'}")
    lmp.commands_string(SHRINK_WRAPPED + f"""
        lattice sc {2.05 * R!r}
        region box block 0 6 0 6 0 6
        create_box 1 box
        create_atoms 1 region box
        set type 1 diameter {2 * R!r}
        set type 1 density {ICE.density!r}
        pair_style jkr/dt
        pair_coeff * * gamma {ICE.gamma!r} E {ICE.E!r} nu {ICE.nu!r} frictionless
        neighbor {2 * s.delta_c!r} bin
        fix integrate all nve/sphere
        timestep {0.01 * s.t_c!r}
        run 10
    """)
    log = (tmp_path / "log.lammps").read_text()
    assert "bins widened" not in log
    half_cut = float(re.search(r"master list distance cutoff = (\S+)", log).group(1)) / 2
    assert float(re.search(r"binsize = (\S+),", log).group(1)) == pytest.approx(half_cut)


def test_bins_setting_names_its_values(lmp):
    far_pairs_scene(lmp, 1.0e-6)
    with pytest.raises(Exception, match="bins takes bounded or box"):
        lmp.command("pair_style jkr/dt bins wide")


def flying_apart(lmp, v, every=None):
    """Four single ice grains 1 micron apart flying apart along the diagonals of a cube at
    ``v`` m/s, with ``every``, watched by fix jkr/dt/settle every that many steps (a window
    too long to settle): a shrink-wrapped box that grows in all three directions."""
    s = scales(ICE, R)
    corners = [(1, 1, 1), (-1, -1, 1), (-1, 1, -1), (1, -1, -1)]
    atoms = "\n".join(f"create_atoms 1 single {0.5e-6 * a!r} {0.5e-6 * b!r} {0.5e-6 * c!r}"
                      for a, b, c in corners)
    speeds = "\n".join(f"set atom {k + 1} vx {v * a / 3 ** 0.5!r} vy {v * b / 3 ** 0.5!r} "
                       f"vz {v * c / 3 ** 0.5!r}" for k, (a, b, c) in enumerate(corners))
    lmp.commands_string(SHRINK_WRAPPED + f"""
        region box block -1e-6 1e-6 -1e-6 1e-6 -1e-6 1e-6
        create_box 1 box
        {atoms}
        set type 1 diameter {2 * R!r}
        set type 1 density {ICE.density!r}
        velocity all set 0 0 0
        {speeds}
        pair_style jkr/dt
        pair_coeff * * gamma {ICE.gamma!r} E {ICE.E!r} nu {ICE.nu!r} frictionless
        neighbor {2 * s.delta_c!r} bin
        neigh_modify every 1 delay 0 check yes
        fix integrate all nve/sphere
        timestep {0.3 * s.t_c!r}
    """)
    if every:
        lmp.command(f"fix settle all jkr/dt/settle {every} window 1000 tolerance 0.01 depart no")
    return s


def memory_mb(lmp, tmp_path):
    """LAMMPS's own count of its memory on this rank ('info memory'), MB."""
    lmp.command(f"info memory out overwrite {tmp_path / 'info.txt'}")
    text = (tmp_path / "info.txt").read_text()
    return float(re.search(r"Total dynamically allocated memory: ([0-9.]+) Mbyte", text)[1])


@pytest.mark.parametrize("parts", [True, False], ids=["in parts", "one run"])
def test_bins_outgrown_during_a_run_are_taken_by_the_next(lmp, tmp_path, parts):
    # LAMMPS takes its neighbor bin size when a run is set up. Grains flying apart at
    # 400 m/s spread the box from 1 to ~30 micron in 3000 steps, (30 / 0.1)^3 ~ 2e7 bins of
    # LAMMPS's size: 100 MB. The settle fix ends the run at a check once the pair's bins are
    # outgrown; the next run (as the scene's deck and Session run them) takes the wider
    # size, so the bins stay within ~2 x 32 per grain and the memory where it started.
    # Without the settle fix nothing asks for a new run: one run keeps the first size
    lmp.command(f"log {tmp_path / 'log.lammps'}")
    s = flying_apart(lmp, 400.0, every=100 if parts else None)
    lmp.command("run 0")
    start = memory_mb(lmp, tmp_path)
    x0 = lmp.numpy.extract_atom("x")[:4][np.argsort(lmp.numpy.extract_atom("id")[:4])]
    end, runs = 3000, 0
    while lmp.get_thermo("step") < end:
        lmp.command(f"run {end} upto")
        runs += 1
        if not parts or lmp.extract_fix("settle", 0, 1, 7) != 1.0:
            break
    assert lmp.get_thermo("step") == end
    lmp.command("log none")
    log = (tmp_path / "log.lammps").read_text()
    width = np.subtract(*lmp.extract_box()[1::-1])
    assert width.min() > 25e-6
    # free flight, untouched by the parts: x = x0 + v t to the round-off of the coordinates
    ids = lmp.numpy.extract_atom("id")[:4]
    x = lmp.numpy.extract_atom("x")[:4][np.argsort(ids)]
    v = lmp.numpy.extract_atom("v")[:4][np.argsort(ids)]
    np.testing.assert_allclose(x, x0 + v * end * 0.3 * s.t_c, atol=1e-15)
    memory = memory_mb(lmp, tmp_path)
    if parts:
        assert runs == log.count("jkr/dt/settle: new run for wider bins") + 1 >= 3
        print(f"in parts: {start:.2f} -> {memory:.2f} MB")
        assert memory < 1.5 * start, f"{start:.2f} -> {memory:.2f} MB"
    else:
        assert runs == 1 and "new run for wider bins" not in log
        print(f"one run: {start:.2f} -> {memory:.2f} MB")
        assert memory > 10 * start, f"{start:.2f} -> {memory:.2f} MB: the bins did not grow"
