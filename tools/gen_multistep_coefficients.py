"""Generate the Gauss-Jackson / summed-Adams coefficients of tqdyn's multistep integrator.

Writes ``src/tqdyn/numerics/_multistep_coefficients.py`` (pure data): for every
order K in ``ORDERS`` the four ordinate-form coefficient rows of the summed
Stormer-Cowell (Gauss-Jackson) position formulas and the summed Adams velocity
formulas, as exact rationals.

Run from the repository root::

    python tools/gen_multistep_coefficients.py

Only the standard library is used (exact ``fractions.Fraction`` arithmetic;
no rounding anywhere).

Derivation
----------
For r'' = f on the grid t_n = t_0 + n h, write E for the shift (E g_n = g_{n+1}),
nabla = 1 - E^-1 for the backward difference and D for d/dt, so that
h D = log E = -log(1 - nabla).  With the first and second sums of the
accelerations,

    s_n - s_{n-1} = f_n,        S_n - S_{n-1} = s_n,

i.e. s_n = nabla^-1 f_n and S_n = nabla^-2 f_n (their constants fixed at the
start, see below), the exact relations r = h^2 (hD)^-2 f and r' = h (hD)^-1 f
read, as formal power series in nabla,

    r_n  = h^2 nabla^-2 G(nabla) f_n,    G(x) = (x / -log(1 - x))^2
                                              = 1 - x + x^2/12 - x^4/240 - ...
    r'_n = h   nabla^-1 A(nabla) f_n,    A(x) = x / -log(1 - x)
                                              = 1 - x/2 - x^2/12 - x^3/24 - ...

(Henrici 1962, ch. 5; Berry & Healy 2004, J. Astronaut. Sci. 52, 331).
Corrector (implicit, at n+1, accelerations f_{n+1} .. f_{n+1-K}): since
nabla^-2 (1 - nabla) f_{n+1} = S_{n+1} - s_{n+1} = S_n and nabla^-1 f_{n+1} = s_n + f_{n+1},

    r_{n+1}  = h^2 [S_n + sum_{k>=0} G_{k+2} nabla^k f_{n+1}],
    r'_{n+1} = h   [s_n + f_{n+1} + sum_{k>=0} A_{k+1} nabla^k f_{n+1}].

Predictor (explicit, accelerations f_n .. f_{n-K}): E = (1 - nabla)^-1 applied at n,

    r_{n+1}  = h^2 [S_n + sum_{k>=0} P_{k+2} nabla^k f_n],   P(x) = G(x) / (1 - x) = 1 + x^2/12 + x^3/12 + ...
    r'_{n+1} = h   [s_n + sum_{k>=0} Q_{k+1} nabla^k f_n],   Q(x) = A(x) / (1 - x) = 1 + x/2 + 5x^2/12 + ...

(P_1 = 0: the predictor needs S_n alone, no s_n; Q holds the Adams-Bashforth
and G, A the Stormer-Cowell and Adams-Moulton coefficients of the
difference form.)  Order K keeps nabla^0 .. nabla^K: the accelerations are
interpolated by a polynomial of degree K through K + 1 values, and the
formulas are exact when f is a polynomial of degree <= K (r of degree <= K + 2).
The ordinate form expands nabla^k f_m = sum_j (-1)^j C(k, j) f_{m-j}:

    sum_{k=0}^{K} c_k nabla^k f_m = sum_{j=0}^{K} beta_j f_{m-j},
    beta_j = (-1)^j sum_{k=j}^{K} C(k, j) c_k.

Rows written (index j = 0 .. K):

    PREDICTOR_POSITION[K][j]  beta of P_{k+2}, on f_{n-j}       r_{n+1}  = h^2 (S_n + sum_j beta_j f_{n-j})
    PREDICTOR_VELOCITY[K][j]  beta of Q_{k+1}, on f_{n-j}       r'_{n+1} = h   (s_n + sum_j beta_j f_{n-j})
    CORRECTOR_POSITION[K][j]  beta of G_{k+2}, on f_{n+1-j}     r_{n+1}  = h^2 (S_n + sum_j beta_j f_{n+1-j})
    CORRECTOR_VELOCITY[K][j]  beta of A_{k+1}, plus 1 at j = 0  r'_{n+1} = h   (s_n + sum_j beta_j f_{n+1-j})

Start: given r_N, r'_N and f_{N-K} .. f_N, the corrector rows at N (with
n + 1 = N) fix the sums: S_{N-1} = r_N / h^2 - sum_j CP_j f_{N-j},
s_{N-1} = r'_N / h - sum_j CV_j f_{N-j}; then s_N = s_{N-1} + f_N,
S_N = S_{N-1} + s_N.  The ``ERROR_*`` constants are the first omitted
difference-form coefficients (P_{K+3}, Q_{K+2}, G_{K+3}, A_{K+2}): the local
error of the formula is that constant times h^2 nabla^{K+1} f (positions) or
h nabla^{K+1} f (velocities).
"""

from __future__ import annotations

import datetime
from fractions import Fraction
from math import comb
from pathlib import Path

OUTPUT = Path(__file__).resolve().parent.parent / "src" / "tqdyn" / "numerics" / "_multistep_coefficients.py"
#: The orders generated (the allowed range of ``integrator.order``).
ORDERS = tuple(range(4, 17))
_TERMS = max(ORDERS) + 6  # series terms kept (the error constants need K + 3)


def _series_mul(a, b, n):
    return [sum(a[i] * b[k - i] for i in range(k + 1)) for k in range(n)]


def _series_inv(a, n):
    out = [Fraction(0)] * n
    out[0] = 1 / a[0]
    for k in range(1, n):
        out[k] = -sum(a[i] * out[k - i] for i in range(1, k + 1)) / a[0]
    return out


def difference_series(n: int = _TERMS) -> dict:
    """The difference-form series G, A, P, Q (lists of n Fractions, coefficient of nabla^k at index k)."""
    minus_log_over_x = [Fraction(1, k + 1) for k in range(n)]  # -log(1 - x) / x
    A = _series_inv(minus_log_over_x, n)  # x / -log(1 - x)
    G = _series_mul(A, A, n)
    geometric = [Fraction(1)] * n  # 1 / (1 - x)
    return {"G": G, "A": A, "P": _series_mul(geometric, G, n), "Q": _series_mul(geometric, A, n)}


def ordinate(c, K: int) -> list:
    """sum_{k=0}^{K} c_k nabla^k f_m as weights beta_j of f_{m-j}, j = 0..K."""
    return [(-1) ** j * sum(comb(k, j) * c[k] for k in range(j, K + 1)) for j in range(K + 1)]


def coefficients(K: int) -> dict:
    """The four ordinate rows and the error constants of order K (Fractions)."""
    s = difference_series()
    cv = ordinate(s["A"][1:], K)
    cv[0] += 1  # s_{n+1} = s_n + f_{n+1}
    return {
        "PREDICTOR_POSITION": ordinate(s["P"][2:], K),
        "PREDICTOR_VELOCITY": ordinate(s["Q"][1:], K),
        "CORRECTOR_POSITION": ordinate(s["G"][2:], K),
        "CORRECTOR_VELOCITY": cv,
        "ERROR_PREDICTOR_POSITION": s["P"][K + 3],
        "ERROR_PREDICTOR_VELOCITY": s["Q"][K + 2],
        "ERROR_CORRECTOR_POSITION": s["G"][K + 3],
        "ERROR_CORRECTOR_VELOCITY": s["A"][K + 2],
    }


def _wrapped(head: str, items: list, tail: str, width: int = 110) -> list:
    """``head item item ... tail`` as lines of at most ``width`` characters (items indented by 8)."""
    lines, line = [head], " " * 7
    for item in items:
        if len(line) + 1 + len(item) > width:
            lines.append(line)
            line = " " * 7
        line += " " + item
    lines.append(line)
    lines.append("    " + tail)
    return lines


def module_text() -> str:
    rows = {K: coefficients(K) for K in ORDERS}
    out = [
        "# generated by tools/gen_multistep_coefficients.py — do not edit",
        f"# date: {datetime.date.today().isoformat()}",
        "# exact rational arithmetic (fractions.Fraction); orders " + f"{ORDERS[0]}..{ORDERS[-1]}",
        '"""Gauss-Jackson (summed Stormer-Cowell) and summed Adams coefficients, ordinate form.',
        "",
        "For order K, each row has K + 1 exact rationals (index j = 0 .. K); with the",
        "first and second sums s_n - s_{n-1} = f_n, S_n - S_{n-1} = s_n of the",
        "accelerations f_n = r''(t_n) on the grid t_n = t_0 + n h:",
        "",
        "* ``PREDICTOR_POSITION[K]``: r_{n+1}  = h^2 (S_n + sum_j c_j f_{n-j})",
        "* ``PREDICTOR_VELOCITY[K]``: r'_{n+1} = h   (s_n + sum_j c_j f_{n-j})",
        "* ``CORRECTOR_POSITION[K]``: r_{n+1}  = h^2 (S_n + sum_j c_j f_{n+1-j})",
        "* ``CORRECTOR_VELOCITY[K]``: r'_{n+1} = h   (s_n + sum_j c_j f_{n+1-j})",
        "",
        "``ERROR_*[K]``: the first omitted difference-form coefficient (the local",
        "error is it times h^2 nabla^(K+1) f, or h nabla^(K+1) f for velocities).",
        "Derivation: the generating script's docstring.",
        '"""',
        "",
        f"ORDERS = {ORDERS!r}",
        "",
    ]
    for name in ("PREDICTOR_POSITION", "PREDICTOR_VELOCITY", "CORRECTOR_POSITION", "CORRECTOR_VELOCITY"):
        out.append(f"{name} = {{")
        for K in ORDERS:
            out += _wrapped(f"    {K}: (", [f'"{x}",' for x in rows[K][name]], "),")
        out += ["}", ""]
    for name in ("ERROR_PREDICTOR_POSITION", "ERROR_PREDICTOR_VELOCITY", "ERROR_CORRECTOR_POSITION",
                 "ERROR_CORRECTOR_VELOCITY"):
        out.append(f"{name} = {{")
        out += [f'    {K}: "{rows[K][name]}",' for K in ORDERS]
        out += ["}", ""]
    return "\n".join(out)


def main() -> None:
    OUTPUT.write_text(module_text(), encoding="utf-8")
    print(f"wrote {OUTPUT} (orders {ORDERS[0]}..{ORDERS[-1]})")


if __name__ == "__main__":
    main()
