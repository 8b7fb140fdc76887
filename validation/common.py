"""What the validation studies share: running their campaigns and saving their figures."""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

BIN = Path(sys.executable).parent
HERE = Path(__file__).resolve().parent


def campaign_study_parser(doc: str) -> argparse.ArgumentParser:
    """The options every campaign study takes: --quick, --np, --runs, --results."""
    p = argparse.ArgumentParser(description=doc,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="the small variant of the tests")
    p.add_argument("--np", type=int, default=min(2, os.cpu_count() or 1),
                   help="MPI ranks, one collision each (default %(default)s)")
    p.add_argument("--runs", type=Path, default=None,
                   help="where the runs go (default validation/runs/STUDY[_quick])")
    p.add_argument("--results", type=Path, default=None,
                   help="where the tables and figures go (default validation/STUDY[_quick])")
    return p


#: where each study's runs go -> where their small records go (``study_paths``)
RECORDS_OF: dict[Path, Path] = {}


def study_paths(args, study: str) -> tuple[Path, Path]:
    """(runs, results) of ``study`` for the parsed options; the results folder made. The
    small record of every run a campaign below ``runs`` finishes goes to the same place
    below ``results/records`` (``run_campaigns``)."""
    tag = study + ("_quick" if args.quick else "")
    runs = args.runs or HERE / "runs" / tag
    results = args.results or HERE / tag
    results.mkdir(parents=True, exist_ok=True)
    RECORDS_OF[Path(runs).resolve()] = results / "records"
    return runs, results


def records_of(campaign: Path) -> Path | None:
    """Where the records of ``campaign``'s runs go: its place below its study's runs,
    below the study's ``results/records``; None outside every study's runs."""
    campaign = Path(campaign).resolve()
    for runs, records in RECORDS_OF.items():
        if campaign.is_relative_to(runs):
            return records / campaign.relative_to(runs)
    return None


def loop_times(run: Path) -> list[tuple[float, int]]:
    """(wall seconds, MPI ranks) of each LAMMPS run in a run directory (its log's 'Loop
    time of T on N procs' lines)."""
    from jkrdt.rundir import LOG

    return [(float(m.group(1)), int(m.group(2))) for m in
            re.finditer(r"Loop time of ([0-9.eE+-]+) on (\d+) procs", (run / LOG).read_text())]


def loop_seconds(run: Path) -> float:
    """The wall time LAMMPS spent in the runs of a run directory."""
    return sum(seconds for seconds, _ in loop_times(run))


def loop_ranks(run: Path) -> int:
    """The MPI ranks that a run directory's runs used (1 if its log says nothing): with
    ``loop_seconds``, the core-seconds the run cost."""
    return max((ranks for _, ranks in loop_times(run)), default=1)


def read_committed(results: Path, ints: tuple[str, ...]) -> list[dict]:
    """The rows of a study's committed ``results/runs.csv``, the columns ``ints`` as whole
    numbers (none if there is no such file yet): what earlier calls, on this machine or
    another, finished."""
    from jkrdt.analysis.tables import read_csv

    path = results / "runs.csv"
    if not path.exists():
        return []
    return [{k: int(v) if k in ints and v != "" else v for k, v in r.items()}
            for r in read_csv(path)]


def campaign_paths(specs: dict[str, dict], runs: Path) -> dict[str, Path]:
    """The directory of each spec's campaign below ``runs`` (its spec beside it, .json)."""
    return {name: runs / re.sub(r"[^A-Za-z0-9.]+", "_", name) for name in specs}


def run_campaigns(specs: dict[str, dict], runs: Path, ranks: int,
                  ranks_per_run: int = 1) -> dict[str, Path]:
    """Run one ``jkrdt campaign`` per spec (``runs/<name>``), each over ``ranks`` MPI ranks
    in groups of ``ranks_per_run`` (each group runs whole collisions); a second call resumes
    them. As each campaign ends, or stops (a signal, a lost rank), its finished runs' small
    records are kept (``records_of``, ``keep_records``), so that a run that finished is kept
    however its campaign ended. Returns the campaign directories."""
    runs.mkdir(parents=True, exist_ok=True)
    where = campaign_paths(specs, runs)
    for name, spec in specs.items():
        path = runs / f"{where[name].name}.json"
        path.write_text(json.dumps(spec))
        cmd = [str(BIN / "jkrdt"), "campaign", str(path), str(where[name]), "--quiet"]
        if ranks > 1:
            cmd = [str(BIN / "mpirun"), "-np", str(ranks)] + cmd + \
                ["--ranks-per-run", str(min(ranks_per_run, ranks))]
        t0 = time.time()
        returncode = wait_keeping_records(subprocess.Popen(cmd), where[name])
        if returncode not in (0, 1):             # 1: some runs failed, recorded as such
            raise SystemExit(f"{name}: jkrdt campaign stopped (exit status {returncode}); "
                             "its finished runs' records are kept, run again to resume")
        print(f"{name}: campaign done in {time.time() - t0:.0f} s"
              + (" (some runs failed: see their outcome.json)" if returncode else ""),
              flush=True)
    return where


def all_kept(name: str, spec: dict, runs: Path) -> bool:
    """Whether every run of the campaign ``name`` (``spec``, below ``runs``) has its small
    record kept: a study whose results come from its records alone need not run it again
    on a machine that has lost (or never had) its run directories."""
    from jkrdt import rundir
    from jkrdt.campaign import plan

    where = campaign_paths({name: spec}, runs)[name]
    records = records_of(where)
    return records is not None and all(
        (records / run.relative_to(where) / rundir.OUTCOME).exists()
        for *_, run in plan(spec, where))


#: how often (s) a running campaign's newly finished runs have their records kept
KEEP_EVERY = 30.0


def wait_keeping_records(campaign, where: Path) -> int:
    """Wait for the ``campaign`` process (running in ``where``), keeping each of its runs'
    small records as soon as the run finishes, not only when the whole campaign does, and
    once more as it ends, however it ends: on Ctrl-C here the campaign is stopped too (it
    resumes later) and what it finished is kept. Returns its exit status."""
    import signal

    records = records_of(where)
    try:
        while True:
            try:
                return campaign.wait(timeout=KEEP_EVERY)
            except subprocess.TimeoutExpired:
                if records is not None:
                    keep_records(where, records)
    except BaseException:
        campaign.send_signal(signal.SIGINT)
        campaign.wait()
        raise
    finally:
        if records is not None:
            keep_records(where, records)


def keep_records(campaign: Path, records: Path) -> list[Path]:
    """Copy the small record (``jkrdt.rundir.RECORD``) of every finished run below
    ``campaign`` (``rundir.finished``: not the partial outcome of a run cut off) to the same
    place below ``records``, so that the study re-analyses and re-plots from the repository
    alone once its run directories are gone. A record is copied whole or not at all (its
    outcome.json last) and never replaced; returns the records it copied. The campaign's
    spec (``jkrdt.campaign.SPEC_RECORD``: the settle rule its runs ended by, among the
    rest) goes beside its records once, as soon as one is kept."""
    import shutil

    from jkrdt import rundir
    from jkrdt.campaign import SPEC_RECORD

    kept = []
    spec = Path(campaign) / SPEC_RECORD
    for outcome in sorted(Path(campaign).rglob(rundir.OUTCOME)):
        run = outcome.parent
        to = records / run.relative_to(campaign)
        if (to / rundir.OUTCOME).exists() or not rundir.finished(run):
            continue
        copy_record(run, to)
        kept.append(to)
    if spec.exists() and records.exists() and not (records / SPEC_RECORD).exists():
        shutil.copy2(spec, records / SPEC_RECORD)
    return kept


def copy_record(run: Path, to: Path) -> None:
    """The small record (``jkrdt.rundir.RECORD``) of the finished run ``run`` copied to
    ``to``, its outcome.json last, so that a record with an outcome is whole."""
    import shutil

    from jkrdt import rundir

    to.mkdir(parents=True, exist_ok=True)
    for name in rundir.RECORD:
        if (run / name).exists() and name != rundir.OUTCOME:
            shutil.copy2(run / name, to / name)
    shutil.copy2(run / rundir.OUTCOME, to / rundir.OUTCOME)


def save(fig, results: Path, stem: str) -> list[Path]:
    """``fig`` as results/stem.png and .pdf."""
    import matplotlib.pyplot as plt

    out = []
    for suffix in (".png", ".pdf"):
        fig.savefig(results / f"{stem}{suffix}", dpi=120)
        out.append(results / f"{stem}{suffix}")
    plt.close(fig)
    return out


def write_summary(results: Path, summary: dict, name: str = "summary.json") -> int:
    """A study's summary (``name``) in ``results``, its "results" part printed; 0, the
    study's exit status."""
    (results / name).write_text(json.dumps(summary, indent=2) + "\n")
    print(json.dumps(summary["results"], indent=1))
    return 0


def mean_se(values) -> tuple[float, float]:
    """An ensemble's mean and the standard error of that mean (NaN for one value)."""
    x = np.asarray(values, dtype=float)
    return float(x.mean()), float(x.std(ddof=1) / np.sqrt(len(x))) if len(x) > 1 else float("nan")


def within_scatter(a: tuple[float, float], b: tuple[float, float]) -> tuple[float, float, bool]:
    """Two ensembles' (mean, standard error): the difference b - a, its standard error, and
    whether they agree (|difference| within two of its standard errors). Collisions are
    chaotic, so outcomes are compared this way, never run against run."""
    se = float(np.hypot(a[1], b[1]))
    return b[0] - a[0], se, bool(abs(b[0] - a[0]) <= 2 * se + 1e-12)
