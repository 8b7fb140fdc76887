"""Collision set-up: a target and a projectile aggregate in the centre-of-mass frame.

Geometry follows the 3D BPCA paper, sec. 3: the projectile moves along -x
towards the target with relative speed v_col, offset along y by the impact
parameter b = B_off (r_c,tar + r_c,pro), with r_c = sqrt(5/3) r_g, and starts
just outside contact.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from .aggregates import first_touch_along_x, gyration_radius, random_rotation


@dataclasses.dataclass
class Collision:
    x: np.ndarray          # (N, 3) positions, m
    v: np.ndarray          # (N, 3) velocities, m/s
    body: np.ndarray       # (N,) 1 = target, 2 = projectile
    radius: float
    meta: dict             # the set-up's geometry: impact parameter b, initial gap (m)


def characteristic_radius(x: np.ndarray) -> float:
    """r_c = sqrt(5/3) r_g, 3D BPCA paper sec. 3."""
    return math.sqrt(5.0 / 3.0) * gyration_radius(x)


def set_up(target: np.ndarray, projectile: np.ndarray, radius: float, v_col: float,
           b_off: float, rng: np.random.Generator, delta_c: float, gap: float | None = None,
           dim: int = 3) -> Collision:
    """Place ``projectile`` (N_pro, 3) to hit ``target`` (N_tar, 3) at ``v_col``.

    Both are rotated at random, centred on their centres of mass, and the
    projectile is slid along x until its nearest grain is ``gap`` (default
    delta_c / 2) outside contact with the target. ``jkrdt.rundir`` writes the result.
    """
    if not 0.0 <= b_off <= 1.0:
        raise ValueError("B_off must lie in [0, 1]")
    gap = 0.5 * delta_c if gap is None else gap
    tar = target @ random_rotation(rng, dim).T
    pro = projectile @ random_rotation(rng, dim).T
    tar -= tar.mean(axis=0)
    pro -= pro.mean(axis=0)
    b = b_off * (characteristic_radius(tar) + characteristic_radius(pro))
    lateral = np.array([0.0, b, 0.0])
    # slide in along -x until the nearest pair is contact + gap apart
    # (no path crosses at a grazing B_off: the projectile flies by, starting level with the target)
    touch = first_touch_along_x(tar, pro + lateral, 2.0 * radius + gap)
    shift = touch[0] if touch else tar[:, 0].max() - pro[:, 0].min() + 2.0 * radius + gap
    pro = pro + lateral + [shift, 0.0, 0.0]

    n_tar, n_pro = len(tar), len(pro)
    n_tot = n_tar + n_pro
    x = np.vstack([tar, pro])
    v = np.zeros_like(x)
    v[:n_tar, 0] = v_col * n_pro / n_tot          # centre-of-mass frame, equal grains
    v[n_tar:, 0] = -v_col * n_tar / n_tot
    x -= x.mean(axis=0)
    body = np.r_[np.ones(n_tar, int), np.full(n_pro, 2)]
    return Collision(x=x, v=v, body=body, radius=radius, meta=dict(b=b, gap=gap))

