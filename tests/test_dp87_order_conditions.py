"""Order conditions of the Prince-Dormand RK8(7)13M tableau in ``_dp87_tableau``.

Reference values: the rooted-tree order conditions Phi(t) = 1/gamma(t)
(Butcher 1963; Hairer, Norsett & Wanner, *Solving ODEs I*, Sect. II.2), where
gamma(t) is the tree density and Phi(t) = sum_i b_i g_i(t) the elementary
weight with g(t) = prod over the subtrees u of the root of (A g(u)) and
g(single node) = 1.  A method is of order p iff the conditions hold for all
trees with at most p nodes.

Trees are generated here independently of ``tools/gen_dp87_tableau.py``: as
canonical level sequences with the Beyer-Hedetniemi successor rule
(SIAM J. Comput. 9 (1980) 706), and elementary weights are evaluated by
recursion over the level sequence.  All arithmetic is mpmath at DPS digits.
"""

from fractions import Fraction
from functools import lru_cache

import mpmath
import pytest
from mpmath import mp, mpf

from tqdyn.numerics import _dp87_tableau as tab

DPS = 60
MAX_ORDER = 8
#: OEIS A000081: number of rooted trees with n = 1..8 nodes.
A000081 = (1, 1, 2, 4, 9, 20, 48, 115)


# --------------------------------------------------------------------------
# Rooted trees as level sequences
# --------------------------------------------------------------------------

def level_sequences(n):
    """All rooted trees with n nodes as canonical level sequences (root = 1).

    Beyer-Hedetniemi: start from the path (1, 2, ..., n); the successor of L
    takes p = last index with L[p] != 2 and q = last index before p with
    L[q] = L[p] - 1 (the parent of p), then repeats L[q:p] cyclically from
    position p on.  Stops at the star (1, 2, ..., 2).
    """
    seq = list(range(1, n + 1))
    while True:
        yield tuple(seq)
        p = max((i for i in range(n) if seq[i] != 2), default=0)
        if p == 0:
            return
        q = max(i for i in range(p) if seq[i] == seq[p] - 1)
        for i in range(p, n):
            seq[i] = seq[i - (p - q)]


def subtrees(seq):
    """Level sequences of the subtrees hanging from the root of ``seq``."""
    starts = [i for i, level in enumerate(seq) if level == seq[0] + 1]
    ends = starts[1:] + [len(seq)]
    return [seq[s:e] for s, e in zip(starts, ends)]


def density(seq):
    """gamma(t) = |t| * prod gamma(subtrees)."""
    gamma = len(seq)
    for sub in subtrees(seq):
        gamma *= density(sub)
    return gamma


def trees_up_to(max_order):
    return [seq for n in range(1, max_order + 1) for seq in level_sequences(n)]


# --------------------------------------------------------------------------
# Tableaus and elementary weights
# --------------------------------------------------------------------------

def number(text):
    """mpf from a published "p/q" string or a corrected decimal string."""
    if "/" in text:
        value = Fraction(text)
        return mpf(value.numerator) / value.denominator
    return mpf(text)


def tableau(a_rows, b, bhat, c):
    return {
        "a": [[number(s) for s in row] for row in a_rows],
        "b": [number(s) for s in b],
        "bhat": [number(s) for s in bhat],
        "c": [number(s) for s in c],
    }


def weight_function(a):
    """g(t) as a function of the level sequence t, memoised, for matrix a."""

    @lru_cache(maxsize=None)
    def g(seq):
        result = [mpf(1)] * len(a)
        for sub in subtrees(seq):
            g_sub = g(sub)
            a_g = [mpmath.fsum(a[i][j] * g_sub[j] for j in range(i)) for i in range(len(a))]
            result = [r * x for r, x in zip(result, a_g)]
        return tuple(result)

    return g


def residuals(tab_data, weights_key, max_order, min_order=1):
    """Phi(t) - 1/gamma(t) for all trees with min_order <= |t| <= max_order."""
    g = weight_function(tab_data["a"])
    w = tab_data[weights_key]
    return [mpmath.fdot(w, g(seq)) - mpf(1) / density(seq)
            for seq in trees_up_to(max_order) if len(seq) >= min_order]


def worst(values):
    return max(abs(v) for v in values)


@pytest.fixture(scope="module")
def precision():
    with mp.workdps(DPS):
        yield


@pytest.fixture(scope="module")
def corrected(precision):
    return tableau(tab.A_CORRECTED, tab.B_CORRECTED, tab.BHAT_CORRECTED, tab.C_CORRECTED)


@pytest.fixture(scope="module")
def published(precision):
    return tableau(tab.A_PUBLISHED, tab.B_PUBLISHED, tab.BHAT_PUBLISHED, tab.C_PUBLISHED)


# --------------------------------------------------------------------------
# Tests
# --------------------------------------------------------------------------

def test_tree_counts_match_oeis_a000081():
    """Reference: OEIS A000081 (1, 1, 2, 4, 9, 20, 48, 115); checks the generator."""
    counts = tuple(len(set(level_sequences(n))) for n in range(1, MAX_ORDER + 1))
    assert counts == A000081
    assert len(trees_up_to(8)) == 200
    assert len(trees_up_to(7)) == 85


def test_tree_densities_of_small_trees():
    """Reference: HNW I, Sect. II.2 (the 8 trees of order <= 4 and their gamma)."""
    densities = sorted(density(seq) for seq in trees_up_to(4))
    assert densities == sorted([1, 2, 3, 6, 4, 8, 12, 24])


def test_shapes():
    """Layout promised by the module docstring: row i of A holds i entries."""
    assert tab.STAGES == 13
    for a_rows in (tab.A_PUBLISHED, tab.A_CORRECTED):
        assert [len(row) for row in a_rows] == list(range(tab.STAGES))
    for vector in (tab.B_PUBLISHED, tab.BHAT_PUBLISHED, tab.C_PUBLISHED,
                   tab.B_CORRECTED, tab.BHAT_CORRECTED, tab.C_CORRECTED):
        assert len(vector) == tab.STAGES


def test_corrected_b_is_order_8(corrected, record_number):
    """Reference: all 200 order conditions Phi(t) = 1/gamma(t), |t| <= 8 (measured 5.3e-41; README and
    docs/precision.md quote it)."""
    w = worst(residuals(corrected, "b", 8))
    assert w <= mpf("3e-40")
    record_number("dp87.corrected_order_conditions", float(w))


def test_corrected_bhat_is_order_7(corrected):
    """Reference: all 85 order conditions Phi(t) = 1/gamma(t), |t| <= 7 (measured 1.3e-41)."""
    assert worst(residuals(corrected, "bhat", 7)) <= mpf("3e-40")


def test_corrected_c_is_row_sum_of_a(corrected):
    """Reference: the row-sum condition c_i = sum_j a_ij (HNW I, Sect. II.1)."""
    for c_i, row in zip(corrected["c"], corrected["a"]):
        assert abs(c_i - mpmath.fsum(row)) <= mpf("1e-40")


def test_zero_pattern_is_published_one():
    """Reference: published tableau (GSL rk8pd.c / GMAT PrinceDormand78.cpp)."""
    def pattern(strings):
        return [s == "0" for s in strings]

    for pub, cor in zip(tab.A_PUBLISHED, tab.A_CORRECTED):
        assert pattern(pub) == pattern(cor)
    for pub, cor in ((tab.B_PUBLISHED, tab.B_CORRECTED),
                     (tab.BHAT_PUBLISHED, tab.BHAT_CORRECTED),
                     (tab.C_PUBLISHED, tab.C_CORRECTED)):
        assert pattern(pub) == pattern(cor)


def test_corrections_are_tiny(corrected, published, record_number):
    """Reference: published rationals; the correction must not be a new method.

    docs/precision.md: every coefficient is corrected by at most 2.16e-17 relative (measured): relative bound
    1e-16, absolute below |value| = 1e-3 (all published nonzero coefficients are larger than 1e-2, so in
    practice this is relative).  The corrections are not all zero (the published tableau's defect, below,
    needs them): the largest is above 3e-18.
    """
    pairs = [(p, c) for prow, crow in zip(published["a"], corrected["a"])
             for p, c in zip(prow, crow)]
    for key in ("b", "bhat", "c"):
        pairs += list(zip(published[key], corrected[key]))
    for pub, cor in pairs:
        assert abs(cor - pub) <= mpf("1e-16") * max(abs(pub), mpf("1e-3"))
    largest = max(abs(cor - pub) / abs(pub) for pub, cor in pairs if pub != 0)
    assert largest > mpf("3e-18")
    record_number("dp87.largest_relative_correction", float(largest))


def test_published_b_is_order_7_but_not_exactly_order_8(published, record_number):
    """Reference: order conditions |t| <= 7 and |t| = 8.

    The published rationals satisfy them only to ~6.5e-18 (docs/precision.md; measured: 6.5e-18 for |t| <= 7,
    6.4e-18 for |t| = 8); this defect is why the corrected tableau is the default.  Bounds ~3-5x either side.
    """
    assert mpf("1e-18") < worst(residuals(published, "b", 7)) <= mpf("3e-17")
    order8 = worst(residuals(published, "b", 8, min_order=8))
    assert mpf("1e-18") < order8 < mpf("3e-17")
    record_number("dp87.published_order_conditions", float(max(order8, worst(residuals(published, "b", 7)))))


def test_bhat_is_not_order_8(corrected):
    """Reference: order-8 conditions; bhat must violate one, else no error estimate."""
    assert worst(residuals(corrected, "bhat", 8, min_order=8)) > mpf("1e-6")
