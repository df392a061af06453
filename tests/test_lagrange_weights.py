"""tqdyn.numerics.lagrange.weights: the Lagrange weights of any nodes (and their derivatives).

Reference: first principles -- the interpolant through p nodes reproduces every polynomial of degree
p - 1, so a degree p - 1 polynomial with exactly representable coefficients is given back at any x
(to rounding), and so is its derivative; a polynomial of degree p is not (the error is the node
polynomial times its leading coefficient, analytic)."""

from __future__ import annotations

import numpy as np

from tqdyn.numerics.lagrange import weights


def test_polynomials_of_degree_p_minus_1_are_reproduced_with_their_derivative():
    """The two uses: 8 nodes -3..4 at x in [0, 1] (fractional delays), 10 nodes 0..9 at x in [4, 5]
    (tabulated orbits).  Error relative to sum_j |w_j f_j| (the sum's own rounding scale): measured
    1.1e-16 / 3.5e-16 (values), 1.3e-15 / 5.7e-16 (derivatives); bounds 1e-15 and 1e-14."""
    for offsets, x in ((np.arange(-3, 5), np.linspace(0.0, 1.0, 71)), (np.arange(10), np.linspace(4.0, 5.0, 71))):
        p = offsets.size
        c = np.arange(1, p + 1, dtype=np.float64)[::-1] / 8.0          # degree p - 1
        w, dw = weights(x, offsets, derivative=True)
        f = np.polyval(c, offsets)
        err = np.abs((w * f).sum(axis=1) - np.polyval(c, x)) / np.abs(w * f).sum(axis=1)
        derr = np.abs((dw * f).sum(axis=1) - np.polyval(np.polyder(c), x)) / np.abs(dw * f).sum(axis=1)
        assert err.max() < 1e-15 and derr.max() < 1e-14, (err.max(), derr.max())
        assert np.array_equal(weights(x, offsets), w)


def test_degree_p_leaves_the_node_polynomial():
    """f = x^p on the nodes 0..p-1: the interpolation error at x is prod_j (x - o_j) (analytic;
    measured equal to the last bit, bound 1e-14 relative)."""
    offsets = np.arange(8)
    x = np.array([0.5, 3.25, 6.75])
    w = weights(x, offsets)
    err = x ** 8 - (w * offsets.astype(float) ** 8).sum(axis=1)
    expected = np.prod(x[:, None] - offsets[None, :], axis=1)
    assert np.allclose(err, expected, rtol=1e-14, atol=0)
