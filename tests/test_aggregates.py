"""Aggregate builders: bonds at the JKR equilibrium, no other contact, a tree,
reproducible from a seed; BCCA structure against Wada et al. (2007) eq. (53);
LAMMPS reads the aggregates at rest with zero force."""

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from conftest import ICE_SCALES as S, R_GRAIN
from jkrdt.aggregates import (bcca, bonds, bpca, bpca_plain, fractal_fit, gyration_radius,
                              stick_head_on)
from jkrdt.datafile import write_sphere_data
from jkrdt.materials import ICE
from jkrdt.scene import pair_coeff
from jkrdt.session import start_lammps

BOND = 2 * R_GRAIN - S.delta0
BUILDERS = {"bpca": bpca, "bcca": bcca}


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("kind", list(BUILDERS))
def test_bonds_at_equilibrium_form_a_tree(kind, dim):
    n = 256
    x = BUILDERS[kind](n, R_GRAIN, S.delta0, np.random.default_rng(5), dim=dim)
    pairs = bonds(x, R_GRAIN, S.delta0)          # every pair closer than contact 2r
    assert len(pairs) == n - 1                   # n_k = N - 1: no contact besides the bonds
    length = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
    assert np.abs(length - BOND).max() < 1e-9 * S.delta0
    graph = coo_matrix((np.ones(n - 1), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    assert connected_components(graph, directed=False)[0] == 1   # connected with N - 1 edges
    assert np.abs(x.mean(axis=0)).max() < 1e-12 * R_GRAIN
    if dim == 2:
        assert np.all(x[:, 2] == 0.0)


@pytest.mark.parametrize("kind", list(BUILDERS))
def test_same_seed_same_aggregate(kind):
    a = BUILDERS[kind](64, R_GRAIN, S.delta0, np.random.default_rng(11))
    b = BUILDERS[kind](64, R_GRAIN, S.delta0, np.random.default_rng(11))
    c = BUILDERS[kind](64, R_GRAIN, S.delta0, np.random.default_rng(12))
    assert np.array_equal(a, b) and not np.array_equal(a, c)


def test_bcca_needs_a_power_of_two():
    with pytest.raises(ValueError, match="power of two"):
        bcca(100, R_GRAIN, S.delta0, np.random.default_rng(0))


def bcca_ensemble(dim, levels, members, seed=0):
    """r_g / r_1 of every cluster at every level of ``members`` BCCAs of 2^levels grains."""
    rg = {}
    for m in range(members):
        rng = np.random.default_rng(seed + m)
        clusters = [np.zeros((1, 3)) for _ in range(2 ** levels)]
        while len(clusters) > 1:
            clusters = [stick_head_on(clusters[k], clusters[k + 1], R_GRAIN, S.delta0, rng, dim)
                        for k in range(0, len(clusters), 2)]
            rg.setdefault(len(clusters[0]), []).extend(gyration_radius(c) / R_GRAIN
                                                       for c in clusters)
    return rg


def test_2d_bcca_follows_eq53():
    # eq. (53), from 10^4 2D BCCAs: N = 1.37 (r_g / r_1)^1.57. Measured here (16 BCCAs of
    # 1024): the mean r_g at N = 16 ... 1024 lies within 3 % of it
    rg = bcca_ensemble(2, 10, 16)
    for n, values in rg.items():
        if n >= 16:
            assert np.mean(values) == pytest.approx((n / 1.37) ** (1 / 1.57), rel=0.06), n
    n = np.array([k for k, v in rg.items() for _ in v if k >= 16])
    r = np.array([x for k, v in rg.items() for x in v if k >= 16])
    d_f, k0 = fractal_fit(n, r)
    print(f"2D BCCA: N = {k0:.2f} (r_g/r_1)^{d_f:.3f}")
    assert d_f == pytest.approx(1.57, abs=0.12)


def test_3d_bcca_fractal_dimension_near_1_9():
    rg = bcca_ensemble(3, 10, 8)
    n = np.array([k for k, v in rg.items() for _ in v if k >= 16])
    r = np.array([x for k, v in rg.items() for x in v if k >= 16])
    d_f, k0 = fractal_fit(n, r)
    print(f"3D BCCA: N = {k0:.2f} (r_g/r_1)^{d_f:.3f}")
    assert d_f == pytest.approx(1.9, abs=0.15)


@pytest.mark.parametrize("dim", [2, 3])
def test_lammps_reads_aggregates_at_rest_with_zero_force(tmp_path, dim):
    x = bcca(128, R_GRAIN, S.delta0, np.random.default_rng(2), dim=dim)
    data = write_sphere_data(tmp_path / "agg.data", x, R_GRAIN, ICE.density)
    lmp = start_lammps()
    try:
        lmp.commands_string(f"""
            units si
            dimension {dim}
            atom_style sphere
            atom_modify map array
            boundary m m {'p' if dim == 2 else 'm'}
            comm_modify vel yes
            read_data {data}
            pair_style jkr/dt
            pair_coeff * * {pair_coeff(ICE)}
            neighbor 1e-8 bin
            compute p all pair jkr/dt
            thermo_style custom step pe
            run 0
        """)
        f = lmp.numpy.extract_atom("f")
        assert np.abs(f).max() < 1e-9 * S.F_c
        assert lmp.numpy.extract_compute("p", 0, 1)[9] == 127          # all bonds found
        assert np.allclose(lmp.numpy.extract_atom("rmass"), S.mass, rtol=1e-12)
        assert np.abs(lmp.numpy.extract_atom("v")).max() == 0.0
    finally:
        lmp.close()


def test_bpca_matches_the_plain_process_and_is_compact():
    # the grid and the lines thrown 64 at a time change the cost, not the process: r_g of
    # 12 BPCAs of 512 grains agrees with the plain one-line-at-a-time process within 3
    # combined standard errors (about 1.5 % each); and a BPCA is compact, D_f = 3
    # (Mukai et al. 1992): r_g grows as N^(1/3) from 512 to 4096 grains, to within 0.15
    rg_fast = [gyration_radius(bpca(512, R_GRAIN, S.delta0, np.random.default_rng(s)))
               for s in range(12)]
    rg_plain = [gyration_radius(bpca_plain(512, R_GRAIN, S.delta0, np.random.default_rng(100 + s)))
                for s in range(12)]
    se = np.hypot(np.std(rg_fast, ddof=1), np.std(rg_plain, ddof=1)) / np.sqrt(12)
    print(f"difference {(np.mean(rg_fast) - np.mean(rg_plain)) / se:+.2f} standard errors")
    assert abs(np.mean(rg_fast) - np.mean(rg_plain)) < 3 * se, (rg_fast, rg_plain)
    rg_big = [gyration_radius(bpca(4096, R_GRAIN, S.delta0, np.random.default_rng(s)))
              for s in range(3)]
    d_f = np.log(8) / np.log(np.mean(rg_big) / np.mean(rg_fast))
    print(f"BPCA r_g/r: {np.mean(rg_fast) / R_GRAIN:.2f} (plain process "
          f"{np.mean(rg_plain) / R_GRAIN:.2f}) at 512, {np.mean(rg_big) / R_GRAIN:.2f} at 4096; "
          f"D_f = {d_f:.3f}")
    assert d_f == pytest.approx(3.0, abs=0.15)
