"""jkr/dt: dust-aggregate collisions with the contact model of Wada et al. (2007).

The core, which imports nothing of ``jkrdt.analysis``:

materials   material presets and the derived contact scales (a0, delta_c, F_c, t_c, ...)
aggregates  the BPCA and BCCA builders
collision   the set-up of two aggregates to collide (orientation, offset, COM frame)
scene       what a scene is; its directory, its deck and its pair_coeff line
ledger      the energy ledger of compute pair jkr/dt and the energy budget
stopping    the settle rule's defaults and the energy watch
timestep    the time step from an energy tolerance
session     an in-process LAMMPS with MPI and the plugin loaded, running a scene's deck
datafile    LAMMPS data files for atom_style sphere

On top of it: ``jkrdt.analysis`` (outcomes of runs and campaigns), and the applications
``campaign`` (grids of runs across MPI ranks) and ``cli`` (the ``jkrdt`` command).
"""

__version__ = "0.1.0"
