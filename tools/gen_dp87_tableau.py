"""Generate corrected Prince-Dormand RK8(7)13M coefficients.

Writes ``src/tqdyn/integrators/_dp87_tableau.py`` (pure data) containing both
the published rational coefficients and a corrected tableau that satisfies
every Runge-Kutta order condition to ~1e-40.

Run from the repository root::

    python tools/gen_dp87_tableau.py

Only mpmath, numpy and the standard library are used (not tqdyn).

Published coefficients
----------------------
P. J. Prince and J. R. Dormand, "High order embedded Runge-Kutta formulae",
J. Comput. Appl. Math. 7 (1981) 67-75, method RK8(7)13M.  The rationals below
were transcribed from GNU GSL ``ode-initval/rk8pd.c`` (mirror
github.com/BrianGladman/gsl, commit 64b9eeab24e4daf54d9f09d1844a1029915fcd99:
arrays ``ah`` = c_2..c_11, ``b21``, ``b3`` .. ``b13`` = rows of a, ``Abar`` = b,
``A`` = bhat) and cross-checked digit for digit against NASA GMAT
``src/base/propagator/PrinceDormand78.cpp`` (github.com/nasa/GMAT, commit
fba14dc42271c3e84359e293231af35be49d6d13: ``ai`` = c, ``bij`` = a, ``cj`` = b,
``cjhat`` = bhat); the two sources agree on every entry.  c_12 = c_13 = 1.

Why a correction is needed
--------------------------
The published rationals are ~10-digit rational approximations of the real
(irrational) tableau, so the order conditions of every order (already
sum_i b_i = 1) hold only to ~6e-18, and c_i differs from the row sum of a by
up to ~1e-17.  In high-precision arithmetic that defect, not round-off,
dominates the local error.

Correction method
-----------------
Unknowns are the nonzero entries of a, b and bhat (the published zero pattern
is kept; c_i is *defined* as the row sum of a, so c_i = sum_j a_ij holds
exactly).  The residual vector is

    Phi_b(t) - 1/gamma(t)      for all 200 rooted trees t with |t| <= 8,
    Phi_bhat(t) - 1/gamma(t)   for all  85 rooted trees t with |t| <= 7,

(Butcher 1963; Hairer, Norsett & Wanner, Solving ODEs I, Sect. II.2),
evaluated in mpmath with ``mp.dps = 80``.  Gauss-Newton iterations take the
minimum-norm *relative* correction (columns scaled by the current coefficient
values) from a float64 Jacobian computed by forward-mode differentiation of
the elementary weights; the residual itself is always evaluated in mpmath, so
each iteration reduces it by roughly (1e-16 * condition number) until
max |residual| <= 1e-40.
"""

from __future__ import annotations

import datetime
import math
from fractions import Fraction
from pathlib import Path

import mpmath
import numpy as np
from mpmath import mp, mpf

DPS = 80
TARGET_RESIDUAL = mpf("1e-40")
MAX_ITERATIONS = 20
OUTPUT_DIGITS = 45
#: relative singular-value cut-off for the (rank-deficient) Gauss-Newton step
RCOND = 1e-11
OUTPUT = Path(__file__).resolve().parents[1] / "src" / "tqdyn" / "integrators" / "_dp87_tableau.py"

STAGES = 13

C_PUBLISHED = (
    "0", "1/18", "1/12", "1/8", "5/16", "3/8", "59/400", "93/200",
    "5490023248/9719169821", "13/20", "1201146811/1299019798", "1", "1",
)

A_PUBLISHED = (
    (),
    ("1/18",),
    ("1/48", "1/16"),
    ("1/32", "0", "3/32"),
    ("5/16", "0", "-75/64", "75/64"),
    ("3/80", "0", "0", "3/16", "3/20"),
    ("29443841/614563906", "0", "0", "77736538/692538347",
     "-28693883/1125000000", "23124283/1800000000"),
    ("16016141/946692911", "0", "0", "61564180/158732637",
     "22789713/633445777", "545815736/2771057229", "-180193667/1043307555"),
    ("39632708/573591083", "0", "0", "-433636366/683701615",
     "-421739975/2616292301", "100302831/723423059", "790204164/839813087",
     "800635310/3783071287"),
    ("246121993/1340847787", "0", "0", "-37695042795/15268766246",
     "-309121744/1061227803", "-12992083/490766935", "6005943493/2108947869",
     "393006217/1396673457", "123872331/1001029789"),
    ("-1028468189/846180014", "0", "0", "8478235783/508512852",
     "1311729495/1432422823", "-10304129995/1701304382",
     "-48777925059/3047939560", "15336726248/1032824649",
     "-45442868181/3398467696", "3065993473/597172653"),
    ("185892177/718116043", "0", "0", "-3185094517/667107341",
     "-477755414/1098053517", "-703635378/230739211", "5731566787/1027545527",
     "5232866602/850066563", "-4093664535/808688257", "3962137247/1805957418",
     "65686358/487910083"),
    ("403863854/491063109", "0", "0", "-5068492393/434740067",
     "-411421997/543043805", "652783627/914296604", "11173962825/925320556",
     "-13158990841/6184727034", "3936647629/1978049680",
     "-160528059/685178525", "248638103/1413531060", "0"),
)

B_PUBLISHED = (
    "14005451/335480064", "0", "0", "0", "0", "-59238493/1068277825",
    "181606767/758867731", "561292985/797845732", "-1041891430/1371343529",
    "760417239/1151165299", "118820643/751138087", "-528747749/2220607170",
    "1/4",
)

BHAT_PUBLISHED = (
    "13451932/455176623", "0", "0", "0", "0", "-808719846/976000145",
    "1757004468/5645159321", "656045339/265891186", "-3867574721/1518517206",
    "465885868/322736535", "53011238/667516719", "2/45", "0",
)


# --------------------------------------------------------------------------
# Rooted trees
# --------------------------------------------------------------------------

class Trees:
    """All rooted trees up to a given order.

    Tree ``k`` is stored as the non-increasing tuple of the indices of its
    children (the children form a multiset of smaller trees), so every tree
    has exactly one representation.  Trees are numbered by increasing order.
    """

    def __init__(self, max_order: int):
        self.children: list[tuple[int, ...]] = []
        self.order: list[int] = []
        self.gamma: list[int] = []  # density gamma(t) = |t| * prod gamma(children)
        for n in range(1, max_order + 1):
            for forest in list(self._forests(n - 1, len(self.children) - 1)):
                self.children.append(forest)
                self.order.append(n)
                self.gamma.append(n * math.prod(self.gamma[k] for k in forest))

    def _forests(self, total: int, max_index: int):
        """Multisets (non-increasing index tuples) of trees of total order ``total``."""
        if total == 0:
            yield ()
            return
        for k in range(max_index, -1, -1):
            if self.order[k] <= total:
                for rest in self._forests(total - self.order[k], k):
                    yield (k,) + rest

    def indices_up_to(self, order: int) -> list[int]:
        return [k for k, n in enumerate(self.order) if n <= order]


# --------------------------------------------------------------------------
# Tableau <-> unknown vector
# --------------------------------------------------------------------------

def to_mpf(value: Fraction):
    return mpf(value.numerator) / value.denominator


def published_tableau():
    """Published (A, b, bhat) as full 13x13 / 13 lists of Fractions."""
    a = [[Fraction(0)] * STAGES for _ in range(STAGES)]
    for i, row in enumerate(A_PUBLISHED):
        for j, entry in enumerate(row):
            a[i][j] = Fraction(entry)
    b = [Fraction(s) for s in B_PUBLISHED]
    bhat = [Fraction(s) for s in BHAT_PUBLISHED]
    return a, b, bhat


class Layout:
    """Positions of the unknowns (nonzero published entries) in x."""

    def __init__(self, a, b, bhat):
        self.a_pos = [(i, j) for i in range(STAGES) for j in range(i) if a[i][j] != 0]
        self.b_pos = [i for i in range(STAGES) if b[i] != 0]
        self.bhat_pos = [i for i in range(STAGES) if bhat[i] != 0]
        self.size = len(self.a_pos) + len(self.b_pos) + len(self.bhat_pos)

    def pack(self, a, b, bhat) -> list:
        return ([a[i][j] for i, j in self.a_pos]
                + [b[i] for i in self.b_pos]
                + [bhat[i] for i in self.bhat_pos])

    def unpack(self, x, zero):
        """Full (A, b, bhat) from the unknown vector; ``zero`` fills the pattern."""
        a = [[zero] * STAGES for _ in range(STAGES)]
        b = [zero] * STAGES
        bhat = [zero] * STAGES
        values = iter(x)
        for i, j in self.a_pos:
            a[i][j] = next(values)
        for i in self.b_pos:
            b[i] = next(values)
        for i in self.bhat_pos:
            bhat[i] = next(values)
        return a, b, bhat


# --------------------------------------------------------------------------
# Order conditions
# --------------------------------------------------------------------------

def stage_weights(trees: Trees, a) -> list[list]:
    """g(t)_i for every tree: g(t) = prod over children u of (A g(u)), g(.) = 1."""
    weights, a_times = [], []
    for children in trees.children:
        g = [mpf(1)] * STAGES
        for child in children:
            ag = a_times[child]
            g = [gi * agi for gi, agi in zip(g, ag)]
        weights.append(g)
        a_times.append([mpmath.fsum(a[i][j] * g[j] for j in range(i)) for i in range(STAGES)])
    return weights


def residuals(trees: Trees, layout: Layout, x) -> tuple[list, list]:
    """mpmath residuals Phi(t) - 1/gamma(t): (b, order<=8), (bhat, order<=7)."""
    a, b, bhat = layout.unpack(x, mpf(0))
    weights = stage_weights(trees, a)

    def conditions(weight_vector, max_order):
        return [mpmath.fdot(weight_vector, weights[k]) - mpf(1) / trees.gamma[k]
                for k in trees.indices_up_to(max_order)]

    return conditions(b, 8), conditions(bhat, 7)


def jacobian(trees: Trees, layout: Layout, x) -> np.ndarray:
    """float64 Jacobian of the residual vector by forward-mode differentiation."""
    a, b, bhat = layout.unpack([float(v) for v in x], 0.0)
    a, b, bhat = np.array(a), np.array(b), np.array(bhat)
    n_a = len(layout.a_pos)
    rows_a = np.array([i for i, _ in layout.a_pos])
    cols_a = np.array([j for _, j in layout.a_pos])

    a_times, d_a_times, g_all, dg_all = [], [], [], []
    for children in trees.children:
        g = np.ones(STAGES)
        dg = np.zeros((STAGES, layout.size))
        for child in children:
            w, dw = a_times[child], d_a_times[child]
            dg = dg * w[:, None] + g[:, None] * dw
            g = g * w
        g_all.append(g)
        dg_all.append(dg)
        d_ag = a @ dg
        d_ag[rows_a, np.arange(n_a)] += g[cols_a]
        a_times.append(a @ g)
        d_a_times.append(d_ag)

    def block(weight_vector, positions, offset, max_order):
        rows = []
        for k in trees.indices_up_to(max_order):
            row = weight_vector @ dg_all[k]
            row[offset:offset + len(positions)] += g_all[k][positions]
            rows.append(row)
        return rows

    offset_b = n_a
    offset_bhat = n_a + len(layout.b_pos)
    return np.array(block(b, layout.b_pos, offset_b, 8)
                    + block(bhat, layout.bhat_pos, offset_bhat, 7))


def max_abs(values):
    return max(abs(v) for v in values)


def gauss_newton(trees: Trees, layout: Layout, x0: list) -> list:
    """Minimum-norm relative Gauss-Newton correction of x0 onto the order conditions."""
    x = list(x0)
    for iteration in range(MAX_ITERATIONS):
        res_b, res_bhat = residuals(trees, layout, x)
        r = res_b + res_bhat
        worst = max_abs(r)
        print(f"  iteration {iteration}: max |residual| = {mpmath.nstr(worst, 3)}")
        if worst <= TARGET_RESIDUAL:
            return x
        scale = np.array([abs(float(v)) for v in x])
        jac = jacobian(trees, layout, x) * scale
        norm = float(worst)
        rhs = np.array([float(v / norm) for v in r])
        step, *_ = np.linalg.lstsq(jac, -rhs, rcond=RCOND)
        x = [xi + mpf(float(si * sc)) * norm for xi, si, sc in zip(x, step, scale)]
    raise RuntimeError(f"no convergence after {MAX_ITERATIONS} iterations")


# --------------------------------------------------------------------------
# Output
# --------------------------------------------------------------------------

def decimal_string(value) -> str:
    if value == 0:
        return "0"
    return mpmath.nstr(value, OUTPUT_DIGITS, strip_zeros=False,
                       min_fixed=-mpmath.inf, max_fixed=mpmath.inf)


def format_vector(name: str, strings) -> str:
    body = "".join(f'    "{s}",\n' for s in strings)
    return f"{name} = (\n{body})\n"


def format_matrix(name: str, rows) -> str:
    lines = [f"{name} = ("]
    for row in rows:
        if not row:
            lines.append("    (),")
            continue
        lines.append("    (")
        lines.extend(f'        "{s}",' for s in row)
        lines.append("    ),")
    lines.append(")")
    return "\n".join(lines) + "\n"


def module_text(corrected, stats) -> str:
    a, b, bhat, c = corrected
    header = f'''\
# generated by tools/gen_dp87_tableau.py — do not edit
# date: {datetime.date.today().isoformat()}
# mpmath working precision: mp.dps = {DPS}
# max |Phi(t) - 1/gamma(t)|, corrected b,    all 200 trees of order <= 8: {stats["res_b"]}
# max |Phi(t) - 1/gamma(t)|, corrected bhat, all  85 trees of order <= 7: {stats["res_bhat"]}
# max relative correction of any coefficient (a, b, bhat, c): {stats["max_rel"]}
"""Prince-Dormand RK8(7)13M Butcher tableau: published and corrected.

Source of the ``*_PUBLISHED`` rationals: P. J. Prince and J. R. Dormand,
"High order embedded Runge-Kutta formulae", J. Comput. Appl. Math. 7 (1981)
67-75, as transcribed in GNU GSL ``ode-initval/rk8pd.c`` and, identically,
NASA GMAT ``PrinceDormand78.cpp``.  These rationals approximate the real
tableau and satisfy the order conditions (of every order, already
sum b_i = 1) only to ~{stats["pub_res_b"]}.

The ``*_CORRECTED`` coefficients are the published ones moved by a
minimum-norm relative correction (Gauss-Newton in mpmath, dps={DPS}) onto the
full set of rooted-tree order conditions Phi(t) = 1/gamma(t): all 200 trees
of order <= 8 for b and all 85 trees of order <= 7 for bhat.  The published
zero pattern is kept and c_i is the row sum of a.  Values are given to
{OUTPUT_DIGITS} significant digits; exact zeros are "0".

Layout: ``A_*[i]`` (0-based stage i) holds a[i][0..i-1]; row 0 is empty.
``B_*`` are the 8th-order weights, ``BHAT_*`` the embedded 7th-order weights.
"""

STAGES = {STAGES}

'''
    blocks = [
        format_vector("C_PUBLISHED", C_PUBLISHED),
        format_matrix("A_PUBLISHED", A_PUBLISHED),
        format_vector("B_PUBLISHED", B_PUBLISHED),
        format_vector("BHAT_PUBLISHED", BHAT_PUBLISHED),
        format_vector("C_CORRECTED", [decimal_string(v) for v in c]),
        format_matrix("A_CORRECTED",
                      [[decimal_string(v) for v in a[i][:i]] for i in range(STAGES)]),
        format_vector("B_CORRECTED", [decimal_string(v) for v in b]),
        format_vector("BHAT_CORRECTED", [decimal_string(v) for v in bhat]),
    ]
    return header + "\n".join(blocks)


def max_relative_change(old, new) -> mpf:
    return max((abs(n - o) / abs(o) for o, n in zip(old, new) if o != 0), default=mpf(0))


def main() -> None:
    mp.dps = DPS
    trees = Trees(8)
    counts = [trees.order.count(n) for n in range(1, 9)]
    print(f"rooted trees per order 1..8: {counts} (total {len(trees.order)})")

    a_pub, b_pub, bhat_pub = published_tableau()
    layout = Layout(a_pub, b_pub, bhat_pub)
    print(f"unknowns: {len(layout.a_pos)} a + {len(layout.b_pos)} b "
          f"+ {len(layout.bhat_pos)} bhat")
    x0 = [to_mpf(v) for v in layout.pack(a_pub, b_pub, bhat_pub)]

    pub_b, pub_bhat = residuals(trees, layout, x0)
    c_pub = [to_mpf(Fraction(s)) for s in C_PUBLISHED]
    c_defect = [c - mpmath.fsum(row) for c, row in zip(c_pub, layout.unpack(x0, mpf(0))[0])]
    print(f"published: max residual b (order<=8) {mpmath.nstr(max_abs(pub_b), 3)}, "
          f"bhat (order<=7) {mpmath.nstr(max_abs(pub_bhat), 3)}, "
          f"max |c - row sum| {mpmath.nstr(max_abs(c_defect), 3)}")

    x = gauss_newton(trees, layout, x0)
    res_b, res_bhat = residuals(trees, layout, x)
    a, b, bhat = layout.unpack(x, mpf(0))
    c = [mpmath.fsum(row) for row in a]

    max_rel = max(max_relative_change(x0, x), max_relative_change(c_pub, c))
    stats = {
        "res_b": mpmath.nstr(max_abs(res_b), 3),
        "res_bhat": mpmath.nstr(max_abs(res_bhat), 3),
        "max_rel": mpmath.nstr(max_rel, 3),
        "pub_res_b": mpmath.nstr(max_abs(pub_b), 2),
    }
    print(f"corrected: max residual b (order<=8) {stats['res_b']}, "
          f"bhat (order<=7) {stats['res_bhat']}, max relative correction {stats['max_rel']}")

    OUTPUT.write_text(module_text((a, b, bhat, c), stats), encoding="utf-8")
    print(f"wrote {OUTPUT}")


if __name__ == "__main__":
    main()
