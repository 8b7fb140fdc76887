"""The settle rule's in-run table (checks.csv) and the run's sparse record.

A shattering 2 x 100 collision (frictionless ice, 39.8 m/s, head-on, departures on) runs
its own deck on 2 MPI ranks with a frame dumped at every check. The table written during
the run must then equal what the analysis finds in the full dumps, frame by frame: the
fragments are the same graph, so sizes and counts agree exactly, and r_g of the largest
to the float32 precision of MDAnalysis' positions. With the default sparse frames the
analysis of the table and of the first and last frames gives the same outcome.
"""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from jkrdt import rundir

from jkrdt import scene as scene_module
from jkrdt.analysis import dumps
from jkrdt.analysis.outcome import from_checks, measure_frame
from jkrdt.analysis.run import analyse_run
from jkrdt.analysis.tables import read_csv
from jkrdt.materials import ICE
from jkrdt.stopping import SettleRule

BIN = Path(sys.executable).parent
RULE = SettleRule(check_tc=20, window=5, tolerance=0.01, cap_tc=1500, depart="yes")
N = 100


def run_deck(directory: Path, **words) -> None:
    variables = dict(RULE.deck_variables(0.014), **words)
    cmd = [str(BIN / "mpirun"), "-np", "2", str(BIN / "lmp"), "-in", rundir.DECK,
           "-log", rundir.LOG, "-screen", "none"]
    for name, value in variables.items():
        cmd += ["-var", name, str(value)]
    subprocess.run(cmd, cwd=directory, check=True, timeout=900)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The scene run with a frame at every check, and with the default sparse frames."""
    out = {}
    for name, frames in (("every", 1), ("sparse", None)):
        d = tmp_path_factory.mktemp(name)
        rundir.write(d, scene_module.Scene(ICE, N, N, v_col=39.8, seed=1,
                                                 model="frictionless"))
        run_deck(d, **({} if frames is None else dict(frames=frames)))
        out[name] = d
    return out


def test_the_table_equals_the_analysis_of_every_frame(runs):
    run = runs["every"]
    table = {row["step"]: row for row in
             from_checks(read_csv(run / rundir.CHECKS), N, N)}
    seen = 0
    for frame in dumps.frames(run):
        labels, measured = measure_frame(frame, N, N)
        row = table[frame.step]
        for name in ("n_total", "n_largest", "n_second", "n_fragments", "contacts_per_particle"):
            assert row[name] == getattr(measured, name), (frame.step, name)
        # MDAnalysis holds positions in float32: 1e-7 of the box, r_g to about 1e-6
        assert row["gyration_radius_largest"] == pytest.approx(
            measured.gyration_radius_largest, rel=1e-5), frame.step
        sizes = np.bincount(labels)
        for k in (1, 4, 16):
            assert row[f"N_cum_{k}"] == sizes[sizes <= k].sum(), (frame.step, k)
        seen += 1
    assert seen == len(table) > 10
    # the cost and memory come with the run: wall-clock seconds that only grow, and the
    # memory per rank as LAMMPS counts it
    steps = sorted(table)
    wall = np.array([table[k]["wall"] for k in steps])
    assert np.all(np.diff(wall) >= 0) and wall[-1] > 0
    assert all(table[k]["memory_mb"] > 0 for k in steps)
    last = table[max(table)]
    assert last["n_fragments"] > 20 and last["N_cum_1"] > 0     # it shattered
    # what left plus what stayed is every grain: the table's departed grains are those the
    # last frame marks as departed, whole fragments of it
    departed = last["departed_grains"]
    assert departed > 0
    at = dumps.atoms_universe(run / rundir.ATOMS)
    at.trajectory[-1]
    gone = np.asarray(at.trajectory.ts.data[dumps.DEPARTED_AT]) > 0
    assert gone.sum() == departed


def test_the_sparse_record_gives_the_same_outcome(runs):
    full = analyse_run(runs["every"], plots=False)
    sparse = analyse_run(runs["sparse"], plots=False)
    universe = dumps.atoms_universe(runs["sparse"] / rundir.ATOMS)
    steps = [int(ts.data["step"]) for ts in universe.trajectory]
    assert steps[0] == 0 and steps[-1] == sparse["stop_step"] and len(steps) <= 3
    for key in ("n_largest", "n_second", "n_fragments", "fragment_sizes", "N_cum",
                "stop_step", "stop_reason", "growth_efficiency"):
        assert sparse[key] == full[key], key
    # the timeline has every check in both
    rows = read_csv(runs["sparse"] / "frames.csv")
    assert len(rows) == len(read_csv(runs["every"] / "frames.csv")) > 10
    # the rolling restart files are gone once final.restart is written
    assert (runs["sparse"] / "final.restart").exists()
    assert not (runs["sparse"] / "restart.a").exists()
