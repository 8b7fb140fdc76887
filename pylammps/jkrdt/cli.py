"""Command line of jkr/dt.

  jkrdt build   build one aggregate (BPCA or BCCA, 2D or 3D) and write it as a data file
  jkrdt setup   build target and projectile (BPCA or BCCA, 2D or 3D) and write a
                collision: data file + collision.json (metadata)
  jkrdt run     run a collision written by setup with its own deck (DIR/in.collision.lmp)
  jkrdt analyse analyse a run directory: outcome per frame and at the end, tables, pictures
  jkrdt campaign run a grid of v_col x B_off^2 x seeds from a JSON spec (resumable)
  jkrdt summarise B_off-weighted campaign statistics (<f_gro>, v_fra, N_cum), tables, plots
  jkrdt demo    setup + run + analyse for two 500-grain ice BPCAs: summary and a picture
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from . import campaign as campaign_module
from . import ledger, timestep
from . import rundir
from . import scene as scene_module
from .aggregates import BUILDERS, bonds, check_fits, gyration_radius
from .atomic import write_json
from .datafile import write_sphere_data
from .materials import PRESETS, material, scales
from .scene import Scene
from .stopping import DEFAULT_RULE, ENERGY_WARN, STOP_WORDS, SettleRule


def run_lammps(deck: Path, out: Path, variables: dict, nproc: int = 1, watch=None) -> None:
    """Run ``deck`` in ``out``; a continued run (``append`` yes) appends to the log.
    ``watch`` (a jkrdt.progress.CheckLines) shows each check as the run writes it."""
    lmp = Path(sys.executable).parent / "lmp"
    log = "none" if variables.get("append") == "yes" else str(out / rundir.LOG)
    cmd = [str(lmp), "-in", str(deck), "-log", log, "-screen", "none"]
    for k, v in variables.items():
        cmd += ["-var", k, str(v)]
    if nproc > 1:
        cmd = [str(Path(sys.executable).parent / "mpirun"), "-np", str(nproc)] + cmd
    try:
        returncode = run_stoppable(cmd, out, watch.poll if watch is not None else None)
    except Stopped as stop:
        raise SystemExit(f"jkrdt: stopped by {stop.how.name}, and LAMMPS with it: the run in "
                         f"{out} is cut off, kept to its last restart file; 'jkrdt run {out}' "
                         "continues it") from None
    if watch is not None:
        watch.close()
    if returncode != 0:
        error = rundir.run_status(out).error or f"exit status {returncode}"
        raise SystemExit(f"jkrdt: LAMMPS stopped: {error} (full log: {out / rundir.LOG})")


#: the signals that stop jkrdt run, and its LAMMPS with it
STOPPING = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def run_stoppable(cmd: list[str], cwd: Path, poll=None, echo: bool = False) -> int:
    """Run ``cmd`` (LAMMPS, or mpirun and its ranks) in a process group of its own and wait
    for it, calling ``poll()`` about once a second meanwhile. SIGINT, SIGTERM or SIGHUP to
    this process stops the whole group with it (TERM, then KILL after ``STOP_GRACE``
    s), so that no LAMMPS goes on writing a run nobody waits for, and then exits with
    ``Stopped``. What the group prints goes to a file: it is shown (``echo``: as it
    comes) unless the group was stopped, so that mpirun's banner about ranks it saw
    killed does not bury the stop's own line."""
    import tempfile

    stopped: list[int] = []

    def stop(signum, _frame):          # only note it: the loop below stops the group
        if not stopped:
            stopped.append(signum)
            try:
                os.killpg(child.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass

    with tempfile.TemporaryFile("w+b") as said:
        child = subprocess.Popen(cmd, cwd=cwd, start_new_session=True, stdout=said,
                                 stderr=subprocess.STDOUT)
        shown = 0

        def show(upto=None):
            nonlocal shown
            said.flush()
            with open(said.fileno(), "rb", closefd=False) as f:
                f.seek(shown)
                text = f.read() if upto is None else f.read(max(0, upto - shown))
            whole = text if upto is None else text[: text.rfind(b"\n") + 1]
            shown += len(whole)
            sys.stdout.write(whole.decode(errors="replace"))
            sys.stdout.flush()

        before = {s: signal.signal(s, stop) for s in STOPPING}
        try:
            since = None
            while True:
                try:
                    returncode = child.wait(timeout=0.2 if stopped else 1.0)
                    break
                except subprocess.TimeoutExpired:
                    pass
                if stopped:
                    since = since or time.time()
                    if time.time() - since > STOP_GRACE:
                        try:
                            os.killpg(child.pid, signal.SIGKILL)
                        except ProcessLookupError:
                            pass
                    continue
                if echo:
                    show(os.fstat(said.fileno()).st_size)
                if poll is not None:
                    poll()
        finally:
            for s, handler in before.items():
                signal.signal(s, handler)
        if stopped:
            raise Stopped(signal.Signals(stopped[0]))
        if echo or returncode != 0:
            show()
    return returncode


#: seconds a stopped LAMMPS (or mpirun) has to end after SIGTERM before it is killed
STOP_GRACE = 3.0


class Stopped(SystemExit):
    """A command stopped by a signal, its LAMMPS with it; its one line is the caller's."""

    def __init__(self, how: signal.Signals):
        super().__init__(128 + how.value)
        self.how = how


def output_interval(steps: int) -> int:
    """About steps/20, dividing steps, so that the last dump is the end of the run."""
    return next(d for d in range(max(1, steps // 20), 0, -1) if steps % d == 0)


MATERIAL_FIELDS = ("gamma", "E", "nu", "G", "density", "xi_crit", "tvis")


def chosen_material(args):
    """The preset named by --material with any of --gamma, --E, ... overriding it."""
    overrides = {f: getattr(args, f) for f in MATERIAL_FIELDS if getattr(args, f) is not None}
    try:
        return material(args.material, **overrides)
    except ValueError as err:
        raise SystemExit(f"jkrdt: {err}") from None


def add_material_options(p) -> None:
    p.add_argument("--material", choices=list(PRESETS), default="ice",
                   help="preset of Wada et al. (2007) Table 2; the options below override it")
    p.add_argument("--gamma", type=float, help="surface energy, J/m^2")
    p.add_argument("--E", type=float, help="Young's modulus, Pa")
    p.add_argument("--nu", type=float, help="Poisson ratio")
    p.add_argument("--G", type=float, help="shear modulus, Pa (default E / (2 (1 + nu)))")
    p.add_argument("--density", type=float, help="kg/m^3")
    p.add_argument("--xi-crit", dest="xi_crit", type=float, help="critical rolling displacement, m")
    p.add_argument("--tvis", type=float, help="viscoelastic time of eq. (A.5), s")
    p.add_argument("--radius", type=float, default=1.0e-7, help="grain radius, m")


def build(args) -> int:
    check_fits(args.n)
    mat = chosen_material(args)
    s = scales(mat, args.radius)
    t0 = time.time()
    x = BUILDERS[args.kind](args.n, args.radius, s.delta0, np.random.default_rng(args.seed),
                            dim=args.dim)
    built = time.time() - t0
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_sphere_data(out / "aggregate.data", x, args.radius, mat.density,
                      title=f"jkr/dt {args.kind.upper()} of {args.n} {mat.name} grains")
    meta = dict(kind=args.kind, dimension=args.dim, N=args.n, seed=args.seed, radius=args.radius,
                material=dataclasses.asdict(mat), r_g=gyration_radius(x),
                n_bonds=len(bonds(x, args.radius, s.delta0)), build_seconds=built)
    write_json(out / "aggregate.json", meta)
    print(f"{args.kind.upper()} of {args.n} grains ({args.dim}D) built in {built:.2f} s: "
          f"r_g = {meta['r_g'] / args.radius:.3f} r, {meta['n_bonds']} bonds; "
          f"wrote {out / 'aggregate.data'} and aggregate.json")
    return 0


def write_scene(scene: Scene, out, tolerance: float | None = None, force: bool = False):
    """Build the scene's aggregates, set up their collision and write it into ``out``,
    which must be empty unless ``force`` (then the files of an earlier scene and its run
    are removed, and nothing else). With ``tolerance`` the time step is chosen for it
    (``jkrdt.timestep.choose``) instead of the scene's."""
    out = Path(out)
    if out.is_dir() and any(out.iterdir()):
        if not force:
            raise SystemExit(f"jkrdt: {out} is not empty; choose another --out, or give --force "
                             "to replace the scene and run outputs there")
        rundir.clear(out)
    if tolerance is not None:
        try:
            scene = scene.with_dt_for(tolerance)
        except ValueError as err:
            raise SystemExit(f"jkrdt: {err}") from None
        dt, expected = scene.dt_over_tc, scene.predicted_error()
        if expected > 1.001 * tolerance:
            print(f"jkrdt: WARNING: --dt auto cannot reach --tolerance {tolerance:g} at "
                  f"{scene.v_col:g} m/s: dt is held at {dt:g} t_c, where the fit expects max "
                  f"|dE| / E_imp = {expected:.2g}", file=sys.stderr)
    t0 = time.time()
    placed = scene.collide()
    built = time.time() - t0
    rundir.write(out, scene, placed, build_seconds=built)
    print(f"{scene.kind.upper()} {scene.n_tar} + {scene.n_pro} ({scene.dim}D, "
          f"{scene.material.name}, {scene.model}) built in {built:.1f} s; E_imp = "
          f"{scene.E_imp:.3e} J; wrote {out / rundir.DATA}, {rundir.META} and "
          f"{rundir.DECK}\n{scene.time_step()[1]}")
    return scene


def run_scene(out: Path, dt: float | None, steps: int | None, nproc: int,
              rule: SettleRule = DEFAULT_RULE, force: bool = False, quiet: bool = False,
              frames: int | None = None) -> None:
    """Run the scene in ``out`` with its own deck, in its own directory: until it
    settles by ``rule`` (the cap included), or ``steps`` steps when given; ``dt`` (t_c)
    overrides the scene's time step. A run that was cut off continues from its newer
    restart file, adding to its record; a finished run is refused unless ``force``, which
    runs it again from the start. Unless ``quiet``, a line per settle check shows the run
    (``jkrdt.progress``). ``frames``: checks between atom frames (the deck's ``frames``
    when None). Another process running ``out`` is refused (its claim, ``rundir.hold``);
    a run that ends cut off exits non-zero."""
    try:
        held = rundir.hold(out)
    except rundir.RunHeld as err:
        raise SystemExit(f"jkrdt: {err}") from None
    try:
        run_held(out, dt, steps, nproc, rule, force, quiet, frames)
    finally:
        held.close()


def run_held(out: Path, dt: float | None, steps: int | None, nproc: int, rule: SettleRule,
             force: bool, quiet: bool, frames: int | None = None) -> None:
    """run_scene's work, with the directory's claim held."""
    from .progress import CheckLines

    scene = rundir.read(out)
    deck = rundir.deck(out)
    variables = dict(out=".", **(rundir.time_variables(scene, dt) if dt is not None else {}))
    ratio = scene.time_step(dt)[0]
    if steps is None:
        variables.update(rule.deck_variables(ratio))
        if frames is not None:
            variables.update(frames=frames)
    else:
        variables.update(rundir.fixed_steps(steps, output_interval(steps)))
    before = rundir.run_status(out) if (out / rundir.LOG).exists() else None
    resume, last_step = None, int(variables["steps"])
    if before is not None and before.problem is None and not force:
        raise SystemExit(f"jkrdt: {out} holds a finished run ({STOP_WORDS[before.stop_reason]} "
                         f"at step {before.stop_step}); --force runs it again from the start, "
                         "replacing its record")
    if before is not None and before.stop_reason == "cut off" and not force:
        resume = rundir.resume_point(out, last_step)
    if resume is not None:
        restart, start = resume
        rundir.cut_back(out, start)
        variables.update(rundir.continuation(restart.name, int(variables["steps"]) - start))
        print(f"continuing the run that was cut off, from {restart.name} at step {start}")
    else:
        rundir.clear_run(out)
    t0 = time.time()
    watch = None if quiet else CheckLines(out, scene.scales.t_c, scene.E_imp, last_step,
                                          resume[1] if resume else 0)
    run_lammps(deck, out, variables, nproc=nproc, watch=watch)
    status = rundir.run_status(out)
    error = ledger.energy_error(ledger.energy_budget(rundir.read_thermo(out / rundir.LOG)),
                                scene.E_imp)
    print(f"{STOP_WORDS[status.stop_reason]} at step {status.stop_step} of at most "
          f"{variables['steps']} ({scene.model}, dt = {ratio:g} t_c) in {time.time() - t0:.1f} s "
          f"on {nproc} rank(s); max |dE| / E_imp = {error:.2e}; log, dumps and restarts in {out}")
    if error > ENERGY_WARN:
        print(f"jkrdt: WARNING: max |dE| / E_imp = {error:.2e} exceeds {ENERGY_WARN:g}: reduce "
              "--dt (see docs/timestep.md, 'Choosing the time step')", file=sys.stderr)
    if status.stop_reason == "cut off":
        raise SystemExit(f"jkrdt: the run in {out} did not finish ({status.problem}); "
                         "jkrdt run continues it")


def chosen_scene(args) -> Scene:
    """The scene of ``jkrdt setup``'s options."""
    try:
        return Scene(material=chosen_material(args), n_tar=args.n_tar, n_pro=args.n_pro,
                     v_col=args.v, b_off=args.b_off, seed=args.seed, kind=args.kind,
                     dim=args.dim, radius=args.radius, model=args.model,
                     dt_over_tc=None if args.dt in (None, "auto") else args.dt, skin=args.skin,
                     dt_reason=None if args.dt in (None, "auto") else
                     f"dt = {args.dt:g} t_c given to jkrdt setup")
    except ValueError as err:
        raise SystemExit(f"jkrdt: {err}") from None


def setup(args) -> int:
    if not args.v > 0:
        raise SystemExit(f"jkrdt: --v is the collision speed and must be > 0 m/s (got {args.v})")
    if not 0 <= args.b_off <= 1:
        raise SystemExit(f"jkrdt: --b-off must lie in [0, 1] (got {args.b_off})")
    if args.tolerance is not None and args.dt != "auto":
        raise SystemExit("jkrdt: --tolerance goes with --dt auto (the energy error dt is "
                         "chosen for); give --dt auto, or leave --tolerance out")
    tolerance = args.tolerance if args.tolerance is not None else timestep.AUTO_TOLERANCE
    write_scene(chosen_scene(args), args.out,
                tolerance=tolerance if args.dt == "auto" else None, force=args.force)
    return 0


def time_step(value: str):
    """argparse type of --dt: a number of t_c, or 'auto'."""
    try:
        return timestep.parse(value)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def settle_rule(args) -> SettleRule:
    """The settle rule of --check, --window, --settle-tol, --settle-counts, --stretch and
    --cap."""
    try:
        return SettleRule(check_tc=args.check, window=args.window, tolerance=args.settle_tol,
                          counts=args.settle_counts, stretch=args.stretch, cap_tc=args.cap)
    except ValueError as err:
        raise SystemExit(f"jkrdt: {err}") from None


def add_settle_options(p) -> None:
    d = DEFAULT_RULE
    p.add_argument("--steps", type=int, default=None,
                   help="run exactly this many steps instead of until the collision settles")
    p.add_argument("--cap", type=float, default=d.cap_tc,
                   help="simulated time at which an unsettled run stops, in t_c "
                        "(default %(default)g)")
    p.add_argument("--check", type=float, default=d.check_tc,
                   help="time between settle checks and dumps, in t_c (default %(default)g)")
    p.add_argument("--window", type=int, default=d.window,
                   help="checks over which fragments, contacts and dissipation must hold "
                        "still (default %(default)d)")
    p.add_argument("--settle-tol", type=float, default=d.tolerance,
                   help="allowed relative change of the contact count and of the dissipated "
                        "energy over the window (default %(default)g)")
    p.add_argument("--settle-counts", type=float, default=d.counts,
                   help="allowed change of N_lar and of the number of fragments over the "
                        "window, as a fraction of all grains (default %(default)g: unchanged "
                        "below 10^4 grains)")
    p.add_argument("--stretch", type=float, default=d.stretch,
                   help="watch the shape of a largest fragment of this share of all grains "
                        "or more: not settled while its r_g grows by more than --settle-tol "
                        "over the window (default %(default)g; 0: shape not watched)")


def model_name(text: str) -> str:
    """--model: one of scene.MODELS; any other name is told the paper's four models."""
    if text not in scene_module.MODELS:
        raise argparse.ArgumentTypeError(
            f"unknown model {text!r}: use 'frictional' or 'frictionless'; the 3D paper's "
            f"four models are {scene_module.PAPER_MODELS}")
    return text


def run(args) -> int:
    if args.dt == "auto":
        raise SystemExit("jkrdt: --dt auto belongs to jkrdt setup (it is written into the "
                         "scene); jkrdt run takes a number of t_c or the scene's dt")
    if args.steps is not None and args.steps < 1:
        raise SystemExit(f"jkrdt: --steps must be >= 1 (got {args.steps})")
    if args.frames is not None and args.frames < 1:
        raise SystemExit(f"jkrdt: --frames is a number of settle checks >= 1 (got {args.frames})")
    run_scene(Path(args.dir).resolve(), args.dt, args.steps, args.np, settle_rule(args),
              force=args.force, quiet=args.quiet, frames=args.frames)
    return 0


def demo(args) -> int:
    from jkrdt.analysis.run import analyse_run, summary_text

    out = Path(args.out).resolve()
    try:
        scene = Scene(material=material("ice", tvis=args.tvis), n_tar=args.n, n_pro=args.n,
                      v_col=args.v, b_off=args.b_off, seed=args.seed, model=args.model)
    except ValueError as err:
        raise SystemExit(f"jkrdt: {err}") from None
    write_scene(scene, out, force=True)    # the demo's directory is its own
    run_scene(out, None, args.steps, args.np, settle_rule(args), quiet=args.quiet)
    print()
    print(summary_text(analyse_run(out)))
    print(f"tables                      {out / 'frames.csv'}, {out / 'outcome.json'}")
    return 0


def analyse(args) -> int:
    from jkrdt.analysis.run import analyse_run, summary_text

    from jkrdt.analysis.dumps import TruncatedDump
    from jkrdt.analysis.run import RunNotComplete

    try:
        out = analyse_run(args.dir, tolerance=args.tolerance, plots=not args.no_plots,
                          partial=args.partial)
    except (RunNotComplete, FileNotFoundError, TruncatedDump) as err:
        raise SystemExit(f"jkrdt: {err}") from None
    print(summary_text(out))
    return 0


def resume_command(args) -> str:
    """The command line that resumes the campaign this process runs (never --fresh)."""
    import shlex

    words = [w for w in args.argv if w != "--fresh"]
    return shlex.join(["jkrdt", *words])


def campaign_stopped(args, how: signal.Signals) -> str:
    return (f"jkrdt: campaign stopped by {how.name}, and its LAMMPS with it: "
            f"{campaign_module.left(args.spec, args.dir)}\n"
            f"jkrdt: '{resume_command(args)}' resumes it (finished runs are kept)")


def stop_at_once(say) -> None:
    """Make each of STOPPING end this process at once, by the signal, after ``say(how)``
    (None: silently). A campaign's LAMMPS runs in this process and holds the main thread
    in C for a whole chunk, where no Python handler runs; but Python's C-level handler
    writes each signal to the wakeup fd in whatever thread takes it, so a thread of our
    own reads it there, says what was left, and lets the signal end the process with its
    default action (SIGHUP too, where the parent ignored it)."""
    import ctypes
    import threading

    woken, wake = os.pipe()
    os.set_blocking(wake, False)
    signal.set_wakeup_fd(wake, warn_on_full_buffer=False)
    for how in STOPPING:
        signal.signal(how, lambda *_: None)      # the wakeup fd does the work

    def wait():
        how = signal.Signals(os.read(woken, 1)[0])
        try:
            if say is not None:
                print(say(how), file=sys.stderr, flush=True)
        finally:
            sys.stdout.flush()
            ctypes.CDLL(None).signal(int(how), 0)      # SIG_DFL, set from this thread
            os.kill(os.getpid(), how)
            os._exit(128 + how.value)

    threading.Thread(target=wait, name="jkrdt-stop", daemon=True).start()


def campaign_under_mpirun(args) -> int:
    """jkrdt campaign --np N: the campaign under mpirun -np N, its lines shown as they
    come; a signal stops it with one account of what was left, without mpirun's banner."""
    inner, skip = [], False
    for w in args.argv:                           # the same command, less --np N
        if skip:
            skip = False
        elif w == "--np":
            skip = True
        elif not w.startswith("--np="):
            inner.append(w)
    cmd = [str(Path(sys.executable).parent / "mpirun"), "-np", str(args.np),
           str(Path(sys.executable).parent / "jkrdt"), *inner]
    try:
        return run_stoppable(cmd, Path.cwd(), echo=True)
    except Stopped as stop:
        raise SystemExit(campaign_stopped(args, stop.how)) from None


def campaign(args) -> int:
    from .campaign import run_campaign

    if args.np > 1:
        return campaign_under_mpirun(args)
    from mpi4py import MPI

    # the campaign's LAMMPS runs in this process: each of STOPPING ends it at once (SIGINT
    # too, not when the current chunk returns to Python), leaving the run under way cut
    # off for the next campaign to resume; the first rank says what was left
    stop_at_once((lambda how: campaign_stopped(args, how)) if MPI.COMM_WORLD.rank == 0
                 else None)
    done = run_campaign(args.spec, args.dir, progress=not args.quiet,
                        ranks_per_run=args.ranks_per_run, fresh=args.fresh,
                        retry_failed=args.retry_failed)
    busy = done["runs"] - done["skipped"] - done["ran"]
    if MPI.COMM_WORLD.rank == 0:
        print(f"{done['ran']} run(s) done, {done['skipped']} already finished"
              + (f", {busy} run by another campaign at the same time" if busy > 0 else "")
              + f", in {args.dir}")
        if done["failed"]:
            print(f"jkrdt: {len(done['failed'])} of the {done['runs']} runs failed (the first: "
                  f"{done['failed'][0]}); --retry-failed runs them again", file=sys.stderr)
    # the exit status says whether a run of the grid failed (runs another campaign on the
    # same directory still holds are its to finish)
    return 1 if done["failed"] else 0


def summarise(args) -> int:
    from jkrdt.analysis.summary import summarise as summarise_campaign

    try:
        summary = summarise_campaign(args.dir, plot=not args.no_plots,
                                     include_cap=args.include_cap)
    except ValueError as err:
        raise SystemExit(f"jkrdt: {err}") from None
    from jkrdt.analysis.summary import offset_table_text

    for row in summary["table"]:
        se = row["mean_f_gro_se"]
        print(f"{row['model']:<40} v_col {row['v_col']:7.3g} m/s  <f_gro> {row['mean_f_gro']:+.3f}"
              + (f" +- {se:.3f} ({row['seeds']} seeds)" if se == se else "")
              + f"  ({row['runs']} runs" + (f", {row['left_out']} left out" if row["left_out"]
                                           else "")
              + (f", {row['capped']} hit the cap" if row["capped"] else "")
              + (", the paper's offsets" if row["paper_grid"] else "") + ")")
    print(offset_table_text(summary["f_gro_by_offset"]))
    for gone in summary["left_out"]:
        print(f"left out ({gone['stop_reason']}): {gone['run']}"
              + (f": {gone['problem']}" if gone.get("problem") else ""))
    for body in summary["stretching_at_end"]:
        print(f"settled while its largest body still stretched (r_g "
              f"{100 * body['r_g_growth']:+.1f} % over the settle window; f_gro "
              f"{body['growth_efficiency']:+.3f} may yet fall): {body['run']}")
    for model, v in summary["v_fra"].items():
        print(f"v_fra ({model}): " + (f"{v:.3g} m/s" if v else "no crossing of <f_gro> = 0"))
    for p in summary.get("pictures", []):
        if p.endswith(".png"):
            print(f"picture: {p}")
    return 0


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Descriptions as written; each option's default shown unless its help names one."""

    def _get_help_string(self, action):
        text = action.help or ""
        if "default" not in text and shows_default(action.default) and action.option_strings:
            text += " (default: %(default)s)"
        return text


def shows_default(value) -> bool:
    """A default worth printing: not None, not False, not argparse's SUPPRESS."""
    return not (value is None or value is False or value is argparse.SUPPRESS)


class ArgumentParser(argparse.ArgumentParser):
    """argparse with its errors in one line, ``jkrdt: <what> (<how to fix>)``, status 2,
    and the defaults in --help."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", HelpFormatter)
        super().__init__(*args, **kwargs)

    def add_argument(self, *args, **kwargs):
        # argparse prints no line for an option without help: give it one with its default
        if args and args[0].startswith("-") and not kwargs.get("help") \
                and shows_default(kwargs.get("default")):
            kwargs["help"] = "(default: %(default)s)"
        return super().add_argument(*args, **kwargs)

    def error(self, message):
        self.exit(2, f"jkrdt: {message} (see '{self.prog} --help')\n")


def negative_values_joined(argv: list[str]) -> list[str]:
    """``--v -2e1`` as ``--v=-2e1``: argparse takes a word that starts with '-' and is not
    a plain number (-2e1, -1e-7) for an option, and says only 'expected one argument'; so
    such a value reaches the option's own check, which names the problem."""
    out: list[str] = []
    for word in argv:
        if (out and out[-1].startswith("--") and "=" not in out[-1]
                and re.fullmatch(r"-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?", word)):
            out[-1] = f"{out[-1]}={word}"
        else:
            out.append(word)
    return out


def _arguments_demo(sub) -> None:
    d = sub.add_parser("demo", help="collide two BPCA ice aggregates and report the outcome")
    d.add_argument("--n", type=int, default=500, help="grains per aggregate")
    d.add_argument("--v", type=float, default=20.0, help="collision speed, m/s")
    d.add_argument("--b-off", type=float, default=0.3, help="impact parameter B_off")
    add_settle_options(d)
    d.add_argument("--np", type=int, default=1, help="MPI ranks")
    d.add_argument("--quiet", action="store_true", help="no line per settle check")
    d.add_argument("--model", type=model_name, default="frictional",
                   help="Wada et al. (2007) with sliding, rolling, twisting (xi_crit = 8 A), "
                        "or the frictionless model of the 3D BPCA paper; with --tvis 6e-12 "
                        "the paper's damped ones")
    d.add_argument("--tvis", type=float, default=0.0,
                   help="viscoelastic time of eq. (A.5), s (the paper's 6 ps: 6e-12)")
    d.add_argument("--seed", type=int, default=1)
    d.add_argument("--out", default="runs/demo")


def _arguments_setup(sub) -> None:
    st = sub.add_parser("setup", help="build two aggregates and write a collision scene")
    st.add_argument("--kind", choices=list(BUILDERS), default="bpca")
    st.add_argument("--dim", type=int, choices=[2, 3], default=3)
    st.add_argument("--n-tar", type=int, default=256, help="grains in the target")
    st.add_argument("--n-pro", type=int, default=256, help="grains in the projectile")
    st.add_argument("--v", type=float, default=20.0, help="collision speed, m/s")
    st.add_argument("--b-off", type=float, default=0.0, help="impact parameter B_off")
    add_material_options(st)
    st.add_argument("--model", type=model_name, default="frictional",
                    help="frictional or frictionless; with --tvis 6e-12 the 3D paper's "
                         "damped models")
    st.add_argument("--seed", type=int, default=1)
    st.add_argument("--dt", type=time_step, default=None,
                    help="the scene's time step in units of t_c, or 'auto' to choose it from "
                         "--tolerance and the impact speed (default: 0.014, the papers')")
    st.add_argument("--force", action="store_true",
                    help="write into a non-empty --out, replacing an earlier scene and its run")
    st.add_argument("--tolerance", type=float, default=None,
                    help="max |dE| / E_imp that --dt auto aims at (default "
                         f"{timestep.AUTO_TOLERANCE:g})")
    st.add_argument("--skin", type=float, default=None,
                    help="neighbor skin, m (default: 1e-8, or 8 v_col dt where grains move "
                         "farther in a step: large grains, fast collisions)")
    st.add_argument("--out", default="runs/scene")


def _arguments_build(sub) -> None:
    bd = sub.add_parser("build", help="build one aggregate and write it as a data file")
    bd.add_argument("--kind", choices=list(BUILDERS), default="bpca")
    bd.add_argument("--dim", type=int, choices=[2, 3], default=3)
    bd.add_argument("--n", type=int, default=1024, help="grains (a power of two for BCCA)")
    bd.add_argument("--seed", type=int, default=1)
    bd.add_argument("--out", default="runs/aggregate")
    add_material_options(bd)


def _arguments_run(sub) -> None:
    rn = sub.add_parser("run", help="run a scene written by 'jkrdt setup'")
    rn.add_argument("dir", help="directory with collision.data and collision.json")
    add_settle_options(rn)
    rn.add_argument("--dt", type=time_step, default=None,
                    help="time step in units of t_c for this run (default: the scene's); the "
                         "model is the scene's, set by jkrdt setup --model")
    rn.add_argument("--np", type=int, default=1, help="MPI ranks")
    rn.add_argument("--quiet", action="store_true", help="no line per settle check")
    rn.add_argument("--frames", type=int, default=None,
                    help="atoms and contacts dumped every this many settle checks and at the "
                         "end (default: the deck's variable frames)")
    rn.add_argument("--force", action="store_true",
                    help="run a finished run again from the start, replacing its record (a "
                         "run that was cut off continues without it)")


def _arguments_analyse(sub) -> None:
    an = sub.add_parser("analyse", help="outcome of a run directory: metrics per frame, "
                        "outcome.json, frames.csv, pictures")
    an.add_argument("dir")
    an.add_argument("--tolerance", type=float, default=None,
                    help="position tolerance on r_i + r_j when the run has no contact dump, "
                         "m (default delta_c)")
    an.add_argument("--no-plots", action="store_true")
    an.add_argument("--partial", action="store_true",
                    help="analyse a run that failed or was cut off, as far as its dumps go")


def _arguments_campaign(sub) -> None:
    cp = sub.add_parser("campaign", help="run a grid of collisions from a JSON spec "
                        "(resumes: finished runs are skipped)",
                        description=campaign_module.__doc__)
    cp.add_argument("spec", help="the campaign's JSON spec (keys above)")
    cp.add_argument("dir", help="where the runs go, one directory each")
    cp.add_argument("--ranks-per-run", type=int, default=1,
                    help="MPI ranks per collision under mpirun -np N: N / K collisions run "
                         "side by side (default %(default)d)")
    cp.add_argument("--np", type=int, default=1,
                    help="MPI ranks: runs the campaign under mpirun -np N (default 1; or "
                         "start it as mpirun -np N jkrdt campaign ...)")
    cp.add_argument("--quiet", action="store_true", help="no line per finished run")
    cp.add_argument("--fresh", action="store_true",
                    help="delete the runs the directory holds (of this or another spec) and "
                         "start afresh")
    cp.add_argument("--retry-failed", action="store_true",
                    help="run the runs that failed again, from the start")


def _arguments_summarise(sub) -> None:
    sm = sub.add_parser("summarise", help="B_off-weighted statistics of a campaign: "
                        "runs.csv, summary.csv, summary.json, plots")
    sm.add_argument("dir")
    sm.add_argument("--no-plots", action="store_true")
    sm.add_argument("--include-cap", action="store_true",
                    help="average in the runs that hit the settle cap (left out by default)")

#: the commands: their arguments, and what runs them
COMMANDS = {"demo": (_arguments_demo, demo), "setup": (_arguments_setup, setup),
            "build": (_arguments_build, build), "run": (_arguments_run, run),
            "analyse": (_arguments_analyse, analyse),
            "campaign": (_arguments_campaign, campaign),
            "summarise": (_arguments_summarise, summarise)}


def parser() -> ArgumentParser:
    """jkrdt's command line: a sub-command each of COMMANDS."""
    top = ArgumentParser(prog="jkrdt", description=__doc__)
    sub = top.add_subparsers(dest="command", required=True)
    for arguments, _ in COMMANDS.values():
        arguments(sub)
    top.add_argument("--debug", action="store_true",
                     help="show the Python traceback of an error instead of one line")
    return top


def main(argv=None) -> int:
    words = negative_values_joined(sys.argv[1:] if argv is None else [str(a) for a in argv])
    args = parser().parse_args(words)
    args.argv = words
    command = COMMANDS[args.command][1]
    try:
        return command(args)
    except SystemExit as stop:           # the commands' own one-line errors
        if not isinstance(stop.code, str):
            raise
        print(stop.code, file=sys.stderr)
        return 2
    except (ValueError, FileNotFoundError, RuntimeError) as err:
        if args.debug:
            raise
        message = " ".join(str(err).split())
        print(f"jkrdt: {message} (jkrdt --debug {args.command} ... shows where)", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
