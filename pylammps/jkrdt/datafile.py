"""LAMMPS data files for atom_style sphere (MDAnalysis cannot write them)."""

from __future__ import annotations

import numpy as np

from .atomic import write_atomic


def _num(*values) -> str:
    """Numbers at full double precision, so a data file round-trips exactly."""
    return " ".join(f"{float(value):.17g}" for value in values)


def write_sphere_data(path, x, radius, density, v=None, omega=None, types=None,
                      margin=None, title="jkr/dt aggregates"):
    """Write positions, radii, densities and velocities as a LAMMPS data file.

    Parameters
    ----------
    x : (N, 3) array, m
    radius : float or (N,) array, m
    density : float or (N,) array, kg/m^3. read_data gives a sphere the mass
        4/3 pi r^3 density in 2D runs too (LAMMPS 22 Jul 2025), so 2D grains
        keep the mass of the 3D grain, as in Wada et al. (2007)
    v, omega : (N, 3) arrays, m/s and rad/s, optional
    types : (N,) int array, optional (all 1)
    margin : box margin around the atoms, m (default 10 radii)

    The file is written to a temporary name and renamed, so a reader never sees
    half a file.
    """
    x = np.asarray(x, dtype=float)
    n = len(x)
    radius = np.broadcast_to(np.asarray(radius, dtype=float), (n,))
    density = np.broadcast_to(np.asarray(density, dtype=float), (n,))
    v = np.zeros((n, 3)) if v is None else np.asarray(v, dtype=float)
    omega = np.zeros((n, 3)) if omega is None else np.asarray(omega, dtype=float)
    types = np.ones(n, dtype=int) if types is None else np.asarray(types, dtype=int)
    if not (np.all(radius > 0) and np.all(density > 0)):
        raise ValueError("radii and densities must be > 0")
    if not np.all(np.isfinite(x)) or not np.all(np.isfinite(v)):
        raise ValueError("positions and velocities must be finite")
    margin = 10 * radius.max() if margin is None else margin
    lo = x.min(axis=0) - margin
    hi = x.max(axis=0) + margin
    lines = [f"# {title}", "", f"{n} atoms", f"{types.max()} atom types", ""]
    for k, axis in enumerate("xyz"):
        lines.append(f"{_num(lo[k], hi[k])} {axis}lo {axis}hi")
    lines += ["", "Atoms # sphere", ""]
    lines += [f"{i + 1} {types[i]} {_num(2 * radius[i], density[i], *x[i])}" for i in range(n)]
    lines += ["", "Velocities", ""]
    lines += [f"{i + 1} {_num(*v[i], *omega[i])}" for i in range(n)]
    return write_atomic(path, "\n".join(lines) + "\n")

