"""Outcome metrics on hand-built configurations with known answers, and the campaign
statistics of eq. (1) of the 3D BPCA paper on functions with known integrals."""

import numpy as np
import pytest

from conftest import ICE_SCALES as S, R_GRAIN as R
from jkrdt.aggregates import bonds, bpca, gyration_radius
from jkrdt.analysis import fragments as frag
from jkrdt.analysis.summary import b_off_average, cumulative_on, threshold_velocity
from jkrdt.analysis.outcome import measure

BOND = 2 * R - S.delta0


def chain(n, gaps=()):
    """n grains on the x axis at the bond length, with extra gaps {after grain k: extra}."""
    steps = np.full(n - 1, BOND)
    for k, extra in dict(gaps).items():
        steps[k] += extra
    x = np.zeros((n, 3))
    x[1:, 0] = np.cumsum(steps)
    return x


def test_two_separate_aggregates():
    rng = np.random.default_rng(3)
    a, b = bpca(40, R, S.delta0, rng), bpca(25, R, S.delta0, rng)
    b += [np.ptp(a[:, 0]) + np.ptp(b[:, 0]) + 10 * R, 0, 0]
    x = np.vstack([a, b])
    pairs = bonds(x, R, S.delta0)
    by_contacts = frag.from_contacts(np.arange(1, 66), pairs + 1)
    by_positions = frag.from_positions(x, R, S.delta_c)
    assert frag.same_partition(by_contacts, by_positions)
    out = measure(x, by_positions, pairs, 40, 25)
    assert (out.n_largest, out.n_second, out.n_fragments) == (40, 25, 2)
    assert out.growth_efficiency == 0.0                       # (N_lar - N_tar) / N_pro
    assert out.contacts_per_particle == pytest.approx(39 / 40)   # a tree: N - 1 bonds
    assert out.gyration_radius_largest == pytest.approx(gyration_radius(a), rel=1e-12)
    n, n_cum = frag.cumulative_number(by_positions)
    assert n.tolist() == [25, 40] and n_cum.tolist() == [25, 65]


@pytest.mark.parametrize("extra, expected", [(0.5, [10]), (1.5, [6, 4])])
def test_chain_breaks_beyond_delta_c(extra, expected):
    # a contact holds in tension to r_i + r_j + delta_c and breaks beyond (Wada et al. sec. 2.1)
    x = chain(10, {5: 2 * R - BOND + extra * S.delta_c})
    labels = frag.from_positions(x, R, S.delta_c)
    assert frag.sizes_by_rank(labels).tolist() == expected
    out = measure(x, labels, frag.position_pairs(x, R, S.delta_c), 7, 3)
    assert out.n_largest == expected[0]
    assert out.growth_efficiency == pytest.approx((expected[0] - 7) / 3)
    assert out.contacts_per_particle == pytest.approx((expected[0] - 1) / expected[0])


def test_contact_list_overrides_geometry():
    # the plugin's list decides: a pair within delta_c that never touched stays apart
    x = chain(6, {2: 2 * R - BOND + 0.5 * S.delta_c})
    pairs = np.array([[1, 2], [2, 3], [4, 5], [5, 6]])
    assert frag.sizes_by_rank(frag.from_contacts(np.arange(1, 7), pairs)).tolist() == [3, 3]
    assert frag.sizes_by_rank(frag.from_positions(x, R, S.delta_c)).tolist() == [6]


def test_gyration_radius_eq50():
    side = 3 * R
    square = np.array([[0, 0, 0], [side, 0, 0], [0, side, 0], [side, side, 0]]) + 7 * R
    assert gyration_radius(square) == pytest.approx(side / np.sqrt(2), rel=1e-14)
    assert gyration_radius(chain(2)) == pytest.approx(BOND / 2, rel=1e-14)
    # a straight chain of n: r_g^2 = d^2 (n^2 - 1) / 12
    assert gyration_radius(chain(9)) == pytest.approx(BOND * np.sqrt(80 / 12), rel=1e-12)


def test_contacts_naming_unknown_atoms_are_refused():
    with pytest.raises(ValueError, match="same run"):
        frag.from_contacts(np.arange(1, 5), np.array([[1, 9]]))


B2 = np.arange(13) / 12          # the grid of the 3D BPCA paper, appendix B


def test_b_off_average_eq1():
    assert b_off_average(B2, np.ones(13)) == pytest.approx(1.0, rel=1e-14)
    # A = B^2: int_0^1 2 B B^2 dB = 1/2, exact for the trapezoid rule in B^2
    assert b_off_average(B2, B2) == pytest.approx(0.5, rel=1e-14)
    # A = B: 2/3; the rule's error on the paper's grid is below 1e-2
    assert b_off_average(B2, np.sqrt(B2)) == pytest.approx(2 / 3, abs=1e-2)
    # order does not matter, and columns (N_cum curves) average independently
    shuffled = np.random.default_rng(1).permutation(13)
    both = np.stack([np.ones(13), B2], axis=1)[shuffled]
    assert np.allclose(b_off_average(B2[shuffled], both), [1.0, 0.5], rtol=1e-14)


def test_eq1_on_the_papers_offsets_takes_the_grazing_end_as_no_collision():
    """The paper's protocol runs B_off^2 = k/12, k = 0 ... 11; at 12/12 the aggregates
    graze (f_gro 0). The trapezoid over the thirteen points then weighs the head-on run
    1/24, each inner offset 1/12 and 11/12 1/24: A = 1 wherever run averages to 23/24."""
    from jkrdt import protocol

    b2 = np.array(protocol.B_OFF2)
    assert len(b2) == 12 and protocol.is_paper_grid(b2) and not protocol.is_paper_grid(B2)
    assert b_off_average(b2, np.ones(12), grazing=0.0) == pytest.approx(23 / 24, rel=1e-14)
    # A = B^2 with its own value (1) at the grazing end: exact, 1/2
    assert b_off_average(b2, b2, grazing=1.0) == pytest.approx(0.5, rel=1e-14)
    # weights: head-on 1/24, then 1/12 each
    head_on = np.eye(12)[0]
    assert b_off_average(b2, head_on, grazing=0.0) == pytest.approx(1 / 24, rel=1e-14)
    # a grid that reaches 1 ignores it; without it the last value is held
    assert b_off_average(B2, np.ones(13), grazing=0.0) == pytest.approx(1.0, rel=1e-14)
    assert protocol.V_COL == [10.0, 12.6, 15.8, 20.0, 25.1, 31.6, 39.8, 50.1, 63.1, 79.4,
                              100.0]


def test_b_off_average_refuses_bad_grids():
    with pytest.raises(ValueError, match="B_off\\^2 must lie"):
        b_off_average([0.0, 1.5], [1, 1])
    with pytest.raises(ValueError, match="repeated"):
        b_off_average([0.0, 0.5, 0.5], [1, 1, 1])


def test_threshold_velocity_interpolates_in_log_v():
    v = 10 ** (0.1 * np.arange(10, 21))               # the paper's 10 ... 100 m/s
    f = np.log(60.0 / v) / np.log(2.0)                # linear in log v, 0 at 60 m/s
    assert threshold_velocity(v, f) == pytest.approx(60.0, rel=1e-12)
    assert threshold_velocity(v, np.ones_like(v)) is None


def test_cumulative_on_a_grid():
    assert cumulative_on(np.arange(1, 8), [2, 5], [4, 9]).tolist() == [0, 4, 4, 4, 9, 9, 9]
