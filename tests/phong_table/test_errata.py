"""The Wang et al. errata E1, E3 and E4 (docs/errata.md), each against the printed form."""

import numpy as np

from phong_table.model import SpectralPhong, average_exponent_Wang
from phong_table.placement import inverse_importance_ratio_Wang, table_importance_Wang
from reference.materials.types import PhongMaterial
from reference.scene.lights import PointLight


def _model(n):
    k = np.full(n.size, 0.5)
    return SpectralPhong(PhongMaterial(k, k, n), PointLight((0.0, 0.0, 5.0)))


def test_E1_an_is_the_average_exponent_not_the_sum():
    n = np.linspace(10.0, 50.0, 41)
    # Source: the text ("an is the average of exponents"); the printed Σ would be 41 times larger.
    assert average_exponent_Wang(n) == np.mean(n)
    m = 20
    nodes = table_importance_Wang(_model(n), m)
    q = np.arange(m + 1) / m
    np.testing.assert_allclose(nodes, q ** (1 / (np.mean(n) + 1)), rtol=1e-13)
    assert not np.allclose(nodes, q ** (1 / (np.sum(n) + 1)))


def test_E3_nodes_index_i_m_over_p_plus_j_with_step_j_p_over_m():
    n = np.full(41, 9.0)
    an, m, p = 9.0, 12, 3
    nodes = table_importance_Wang(_model(n), m, segments=p)
    # Source: Eq. (16), Wang et al. with Erratum E3 written out: segment bounds S_i =
    # (i/p)^(1/(an+1)) (Eq. (15)), node i·(m/p) + j = S_i + j·(p/m)·(S_{i+1} − S_i).
    S = (np.arange(p + 1) / p) ** (1 / (an + 1))
    expected = [S[i] + j * (p / m) * (S[i + 1] - S[i]) for i in range(p) for j in range(m // p)]
    np.testing.assert_allclose(nodes, [*expected, 1.0], rtol=1e-14)
    # The printed index i·p + j would put segment 1 at node 3 and overlap segment 0's nodes 3..
    assert m // p != p


def test_E4_iir_uses_an_plus_one():
    w = np.linspace(0.0, 1.0, 11)
    # Source: Eq. (15), Wang et al. with an + 1 for the printed a + 1: t = w^(1/(an+1)).
    np.testing.assert_allclose(inverse_importance_ratio_Wang(w, 7.5), w ** (1 / 8.5), rtol=1e-14)
