"""jkr/dt: dust-aggregate collisions with the contact model of Wada et al. (2007).

The core, which imports nothing of ``jkrdt.analysis``:

materials   material presets and the derived contact scales (a0, delta_c, F_c, t_c, ...)
units       values far from grain scales refused at set-up
aggregates  the BPCA and BCCA builders
collision   the set-up of two aggregates to collide (orientation, offset, COM frame)
scene       what a scene is (a value): its time step, its skin, its pair_coeff line
rundir      a run directory: its files, the deck's variables, a run's status, outcome.json
protocol    the 3D BPCA paper's speeds and offsets by name
ledger      the energy ledger of compute pair jkr/dt and the energy budget
stopping    the settle rule's defaults and the energy watch
timestep    the time step from an energy tolerance
instance    an in-process LAMMPS with MPI and the plugin loaded
session     Python-driven runs of a scene's deck
progress    a line per settle check while a run goes
atomic, datafile, plugin   whole-file writes, data files, where the plugin lives

On top of it: ``jkrdt.analysis`` (outcomes of runs and campaigns), and the applications
``campaign`` (grids of runs across MPI ranks) and ``cli`` (the ``jkrdt`` command).
The manual's "Layout" page (docs/layout.md) says the same for every file.
"""

__version__ = "0.1.0"
