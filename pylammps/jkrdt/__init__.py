"""jkr/dt: dust-aggregate collisions with the contact model of Wada et al. (2007).

Subpackages and modules
-----------------------
materials   material presets and the derived contact scales (a0, delta_c, F_c, t_c, ...)
session     an in-process LAMMPS with MPI and the jkr/dt plugin loaded
datafile    LAMMPS data files for atom_style sphere
analysis    collision outcome analysis
"""

__version__ = "0.1.0"
