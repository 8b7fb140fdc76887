"""Continuations under misuse (issue 48): a restart file written on 4 ranks under fix
balance rcb after fragments departed, read on 1, 2 and 4 ranks; a run cut off while it
wrote a compressed frame and half a table row, resumed and analysed. Each ends exact, or as
the same collision with nothing lost."""

import json
import os
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

from jkrdt import ledger, rundir
from jkrdt.analysis.tables import read_csv
from jkrdt.materials import ICE
from jkrdt.scene import Scene

from conftest import SLEEPING_RANKS
from cut_off import RULE, straight_and_cut

BIN = Path(sys.executable).parent
JKRDT = str(BIN / "jkrdt")
# more ranks than cores: ranks that sleep while they wait
SLEEPING = dict(SLEEPING_RANKS, OMP_NUM_THREADS="1")


def deck_run(scene: Path, out: Path, ranks: int, **variables) -> dict:
    """The scene's deck on ``ranks`` ranks; the thermo columns of its log."""
    out.mkdir(parents=True, exist_ok=True)
    cmd = [str(BIN / "lmp"), "-in", str(scene / rundir.DECK), "-log", str(out / "log.lammps"),
           "-screen", "none", "-var", "out", str(out),
           *(w for k, v in variables.items() for w in ("-var", k, str(v)))]
    if ranks > 1:
        cmd = [str(BIN / "mpirun"), "-np", str(ranks)] + cmd
    subprocess.run(cmd, check=True, cwd=scene, timeout=900, capture_output=True,
                   env=dict(os.environ, **SLEEPING))
    return rundir.read_thermo(out / "log.lammps")


@pytest.mark.mpi
def test_a_balanced_restart_with_departed_fragments_reads_on_any_rank_count(tmp_path):
    # a shattering collision (2 x 200 frictionless ice, 39.8 m/s, B_off^2 1/4) run on 4
    # ranks with the deck's fix balance rcb until fragments have departed
    scene = tmp_path / "scene"
    rundir.write(scene, Scene(ICE, 200, 200, v_col=39.8, b_off=0.5, seed=2,
                              model="frictionless"))
    first = tmp_path / "four"
    deck_run(scene, first, 4, steps=24000, every=1000, keep_restarts="yes")
    checks = read_csv(first / rundir.CHECKS)
    assert checks[-1]["departed_grains"] > 0, "no fragment departed: the test needs some"
    restart = first / rundir.FINAL_RESTART
    ends = {}
    for ranks in (1, 2, 4):
        out = tmp_path / f"on{ranks}"
        thermo = deck_run(scene, out, ranks, steps=2000, every=1000,
                          **rundir.continuation(restart))
        # nothing lost at the read: the bonded contacts and the departed
        # fragments' energy (c_kedep, still the same grains) as the run left them
        assert thermo["Step"][0] == 24000
        assert thermo[ledger.CONTACTS][0] == checks[-1]["contacts"]
        assert thermo["c_kedep"][0] == pytest.approx(thermo_last(first)["c_kedep"],
                                                     rel=1e-12)
        rows = read_csv(out / rundir.CHECKS)
        assert rows[0]["departed_grains"] >= checks[-1]["departed_grains"]
        final = np.loadtxt(out / rundir.FINAL_DUMP, skiprows=9)
        ends[ranks] = final[np.argsort(final[:, 0])]
    # on the rank count it was written on, the continuation is the run: continuing the
    # 4-rank run itself gives the same bits
    again = tmp_path / "four_again"
    deck_run(scene, again, 4, steps=2000, every=1000, **rundir.continuation(restart))
    final = np.loadtxt(again / rundir.FINAL_DUMP, skiprows=9)
    assert np.array_equal(final[np.argsort(final[:, 0])], ends[4])


def thermo_last(run: Path) -> dict:
    thermo = rundir.read_thermo(run / "log.lammps")
    return {k: v[-1] for k, v in thermo.items()}


def test_a_run_cut_off_inside_a_frame_and_a_table_row_resumes_as_the_run(tmp_path):
    """jkrdt run stopped by a signal, then its compressed dumps given half a frame (a kill
    while gzip wrote) and its table half a row: the partial analysis reads what is whole,
    and the continued run's outcome is the uninterrupted one's."""
    straight, cut, _ = straight_and_cut(tmp_path)
    rule = RULE
    assert not (cut / rundir.FINAL_RESTART).exists(), "ended before the cut"
    # what a kill inside a write leaves: the compressed stream (flushed after each frame,
    # as LAMMPS does) ending inside a frame, cut mid-line, and a row without its end
    for name in (rundir.ATOMS, rundir.CONTACTS):
        text = _decompressed(cut / name)
        last = text.rindex("ITEM: TIMESTEP")
        step = int(text[last:].split("\n")[1])
        partial = text[last:].replace(f"TIMESTEP\n{step}\n", f"TIMESTEP\n{step + 10**6}\n")
        gz = zlib.compressobj(wbits=31)
        (cut / name).write_bytes(gz.compress((text + partial[: len(partial) // 2]).encode())
                                 + gz.flush(zlib.Z_SYNC_FLUSH))
    with open(cut / rundir.CHECKS, "a") as f:
        f.write("999999,1.2345e-0")
    # the partial analysis reads the whole frames, or says in one line that there are none
    partial = subprocess.run([JKRDT, "analyse", str(cut), "--partial", "--no-plots"],
                             capture_output=True, text=True, timeout=300)
    assert "Traceback" not in partial.stderr
    assert partial.returncode == 0 or (
        len(partial.stderr.strip().splitlines()) == 1 and "no whole frame" in partial.stderr)
    again = subprocess.run([JKRDT, "run", str(cut), *rule], capture_output=True, text=True,
                           timeout=600)
    assert again.returncode == 0, again.stderr
    assert_same_outcome(straight, cut)
    timing = ("wall", "memory_mb", "peak_rss_mb")
    tables = []
    for d in (straight, cut):
        rows = {r["step"]: r for r in read_csv(d / rundir.CHECKS)}
        tables.append([{k: v for k, v in r.items() if k not in timing} for r in rows.values()])
    assert tables[1] == tables[0]


def assert_same_outcome(straight: Path, cut: Path) -> None:
    """Both runs analysed: the continued run's outcome is the uninterrupted one's."""
    outcomes = []
    for d in (straight, cut):
        subprocess.run([JKRDT, "analyse", str(d), "--no-plots"], check=True,
                       capture_output=True, timeout=300)
        outcomes.append(json.loads((d / rundir.OUTCOME).read_text()))
    for key in ("stop_reason", "stop_step", "n_largest", "n_fragments", "contacts_per_particle",
                "gyration_radius_largest", "dissipated_fraction", "energy_error", "N_con",
                "N_cut", "N_cum"):
        assert outcomes[1][key] == outcomes[0][key], key


def _decompressed(path: Path) -> str:
    """The text of a compressed stream that may lack its end."""
    d = zlib.decompressobj(wbits=31)
    return d.decompress(path.read_bytes()).decode()


#: 2 x 2500 at 20 m/s with a frame at every check (2 t_c), 40 t_c in all
KILL_SCENE = ["--n-tar", "2500", "--n-pro", "2500", "--v", "20"]
KILL_RUN = ["--check", "2", "--frames", "1", "--cap", "40", "--quiet"]


def test_a_run_killed_while_gzip_writes_a_frame_resumes_as_the_run(tmp_path):
    """A real SIGKILL to LAMMPS while it writes a compressed atom frame (the file seen
    growing), then jkrdt run: the dumps, the table and the outcome are the uninterrupted
    run's, bit for bit."""
    import gzip
    import shutil
    import signal
    import time

    straight, cut = tmp_path / "straight", tmp_path / "cut"
    subprocess.run([JKRDT, "setup", *KILL_SCENE, "--out", str(straight)], check=True,
                   capture_output=True, timeout=300)
    shutil.copytree(straight, cut)
    subprocess.run([JKRDT, "run", str(straight), *KILL_RUN], check=True, capture_output=True,
                   timeout=600)
    going = subprocess.Popen([JKRDT, "run", str(cut), *KILL_RUN], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE)
    deck = str(cut / rundir.DECK)
    lammps, deadline = [], time.time() + 120
    while not lammps and time.time() < deadline:
        found = subprocess.run(["pgrep", "-f", f"lmp -in {deck}"], capture_output=True,
                               text=True).stdout.split()
        lammps = [int(p) for p in found]
    assert lammps, "LAMMPS never started"
    atoms = cut / rundir.ATOMS
    checks = cut / rundir.CHECKS
    while not checks.exists() or len(read_csv(checks)) < 6:      # a few frames first
        assert going.poll() is None and time.time() < deadline, "the run ended too soon"
        time.sleep(0.01)
    size = atoms.stat().st_size
    while atoms.stat().st_size == size:              # the next frame starts being written
        assert going.poll() is None and time.time() < deadline, "no frame came"
    # LAMMPS runs in a process group of its own (jkrdt run's): the whole group at once,
    # as a lost node would
    for group in {os.getpgid(pid) for pid in lammps}:
        os.killpg(group, signal.SIGKILL)
    going.kill()
    going.wait(timeout=60)
    time.sleep(0.5)
    # the kill landed inside the frame: the stream is cut off
    with pytest.raises(rundir.BROKEN_STREAM):
        with gzip.open(atoms, "rt") as f:
            f.read()
    again = subprocess.run([JKRDT, "run", str(cut), *KILL_RUN], capture_output=True, text=True,
                           timeout=600)
    assert again.returncode == 0, again.stderr
    for name in (rundir.ATOMS, rundir.CONTACTS):       # every member of each stream
        texts = [gzip.decompress((d / name).read_bytes()) for d in (straight, cut)]
        assert texts[1] == texts[0], name
    timing = ("wall", "memory_mb", "peak_rss_mb")
    tables = [[{k: v for k, v in r.items() if k not in timing} for r in read_csv(d / rundir.CHECKS)]
              for d in (straight, cut)]
    assert tables[1] == tables[0]
    assert_same_outcome(straight, cut)
