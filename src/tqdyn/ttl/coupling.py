"""Tilt-to-length (TTL) coupling of the six links, in LISA Instrument's convention.

Indices (LISA Instrument 2.3, ``orbiting/constellation_enums.py`` ``MosaID``): MOSA ``ij`` sits on
spacecraft ``i`` and points to spacecraft ``j``; it receives the beam emitted by MOSA ``ji``
(``MosaID.distant``).  Link ``ij`` is named by its receiving MOSA.  Order :data:`MOSAS`.

Angles: phi (yaw) and eta (pitch) of each MOSA, rad, as built by :func:`mosa_angles`.

The TTL path-length term of link ``ij`` (m, positive = a longer apparent optical path, the sign with
which LISA Instrument 2.3 subtracts ``nu (ttl - x) / c`` from the received carrier,
``instru/instru_formulas.py`` ``distant_carrier_fluctuations`` and ``carrier_fluctuations``)::

    s_ij(t) = P^local_ij(phi_ij(t), eta_ij(t)) + P^distant_ji(phi_ji(t - tau_ij), eta_ji(t - tau_ij))

    P^k_m(phi, eta) = c^k_phi,m phi + c^k_eta,m eta + q^k_phiphi,m phi^2 + q^k_etaeta,m eta^2
                      + q^k_phieta,m phi eta                                 (k = local, distant)

The local term uses the receiving MOSA's own angles and its *local* coefficients; the distant term
is formed at the emitting MOSA ``ji`` with *its* distant coefficients (LISA Instrument keys the
distant coefficients by the emitting MOSA: ``distant_ttls[mosa.distant]``,
``instru/instru_model.py`` ``_lock_on_distant``) and delayed by the light travel time tau_ij of the
link (s, at the reception time t).  The linear part is LISA Instrument's ``local_ttls`` and
``distant_ttls`` (``instru/instru_formulas.py``); the quadratic part is tqdyn's (zero by default).
LISA Instrument feeds those functions angular velocities (rad/s) and gets m/s; with constant
coefficients and no quadratic part that is the time derivative of s_ij.

Fractional delay: the emitted term, sampled at t0 + k dt, is evaluated at t - tau_ij by the 8-point
(degree 7) Lagrange interpolant on the nodes floor(u) - 3 .. floor(u) + 4 (u = k - tau/dt), those
of :func:`tqdyn.numerics.lagrange.grid_interp` and of LISA Instrument's ``interp_order=7``; for a
signal of frequency f its relative error is ~ (2 pi f dt)^8 / 8!.  Samples whose stencil leaves the series are NaN.

**Time-varying coefficients** (:class:`TimeVaryingTTLCoefficients`): the linear coefficients are
functions c(t) of the time t (s, on the time axis of the angles' grid t0 + k dt, e.g. the closed-loop
file's "time on the run's time axis since its epoch"); the quadratic ones stay constant.  The local
term of link ``ij`` takes c^local_ij at the reception time t; the distant term takes c^distant_ji at
the *emission* time, as LISA Instrument 2.3 does (``instru/instru_model.py``: ``_assemble_ttl_evol``
samples the coefficients on ``physics_t``, ``distant_ttls`` multiplies them with the emitting MOSA's
angles on that grid, and ``_lock_on_distant`` delays the product by the PPR):

    s_ij(t) = P^local_ij(t; phi_ij(t), eta_ij(t)) + [P^distant_ji(t'; phi_ji(t'), eta_ji(t'))]_{t' = t - tau_ij}

i.e. the product c^distant_ji(t_k) phi_ji(t_k) is formed on the grid and then delayed by the same
Lagrange interpolant as the angles.

Units SI (rad, m, s, m/rad, m/rad^2); time series are 1-D arrays of shape (n,) on one uniform grid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from .._choices import unknown
from ..numerics import lagrange
from ..numerics.finite import finite_number
from ..numerics.lagrange import MARGIN, POINTS

__all__ = ["LINEAR_FIELDS", "LPF_DRIFT_M_PER_RAD_PER_S", "LPF_TEMPERATURE_COEFFICIENT_M_PER_RAD_PER_K", "MOSAS",
           "MOSA_OPENING_ANGLES_RAD", "RANDOM_HALF_WIDTH_M_PER_RAD", "SPACECRAFT", "TTLCoefficients",
           "TimeVaryingTTLCoefficients", "distant_mosa", "link_ttl", "mosa_angles", "ttl_terms"]

#: MOSA (and link) indices, LISA Instrument's order.
MOSAS = ("12", "23", "31", "13", "32", "21")
#: Spacecraft indices.
SPACECRAFT = ("1", "2", "3")
#: Oriented MOSA opening angles (rad): LISA Instrument 2.3 ``instru_defaults.MOSA_ANGLES`` (+/-30 deg).
MOSA_OPENING_ANGLES_RAD = {m: (1.0 if m in ("12", "23", "31") else -1.0) * math.pi / 6 for m in MOSAS}
#: Half-widths (m/rad) of the uniform draws of :meth:`TTLCoefficients.random`: LISA Instrument 2.3
#: ``instru_defaults.random_ttl_coeffs_*`` (LISA-UKOB-INST-ML-0001-i2, 2.2 mm/rad local, 2.4 distant).
RANDOM_HALF_WIDTH_M_PER_RAD = {"local": 2.2e-3, "distant": 2.4e-3}

#: The linear coefficients (m/rad), the ones that may vary in time; LISA Instrument's TTL file calls them
#: ``c_<mosa>_phi_rx``, ``_eta_rx`` (local) and ``_phi_tx``, ``_eta_tx`` (distant).
LINEAR_FIELDS = ("local_phi", "local_eta", "distant_phi", "distant_eta")
#: Drift of LISA Pathfinder's TTL coefficients, 1 um/rad in 100 days (m/rad/s): Armano et al.,
#: "Tilt-to-length coupling in LISA Pathfinder: long-term stability", Phys. Rev. D (2024), arXiv:2407.05852.
LPF_DRIFT_M_PER_RAD_PER_S = 1e-6 / (100 * 86400.0)
#: Temperature coefficient of LISA Pathfinder's TTL coefficients, 8 um/rad/K (same source).
LPF_TEMPERATURE_COEFFICIENT_M_PER_RAD_PER_K = 8e-6

_HALF = POINTS // 2
_NODES = tuple(range(-_HALF + 1, _HALF + 1))  # -3 .. 4 around floor(u)


def distant_mosa(mosa: str) -> str:
    """The MOSA that emits the beam received by ``mosa`` ("12" -> "21")."""
    return mosa[::-1]


def _check_keys(field: str, d, allowed: tuple) -> None:
    if not isinstance(d, dict):
        raise ValueError(f"{field} = {d!r}: expected a dict keyed by {', '.join(allowed)}")
    for k in d:
        if k not in allowed:
            raise ValueError(unknown(field, k, allowed, problem="is not a key"))
    for k in allowed:
        if k not in d:
            raise ValueError(f"{field}: missing key {k!r} (needed: {', '.join(allowed)})")


def _finite_float(field: str, v, unit: str) -> float:
    x = finite_number(v)
    if x is None:
        raise ValueError(f"{field} = {v!r}: must be a finite number ({unit}), not a boolean or a string")
    return x


@dataclass(frozen=True)
class TTLCoefficients:
    """TTL coefficients of the six MOSAs, each a dict MOSA -> value.

    ``local_*`` act on the receiving MOSA's angles, ``distant_*`` on the emitting MOSA's (keyed by
    the emitting MOSA, as LISA Instrument's ``ttl_coeffs``).  Linear ones in m/rad; the optional
    quadratic ones (``*_phiphi``, ``*_etaeta``, ``*_phieta``) in m/rad^2, zero when None.
    Validated on construction (six MOSA keys, finite values)."""

    local_phi: dict
    local_eta: dict
    distant_phi: dict
    distant_eta: dict
    local_phiphi: dict | None = None
    local_etaeta: dict | None = None
    local_phieta: dict | None = None
    distant_phiphi: dict | None = None
    distant_etaeta: dict | None = None
    distant_phieta: dict | None = None

    def __post_init__(self):
        for f in fields(self):
            d = getattr(self, f.name)
            quad = f.name.endswith(("phiphi", "etaeta", "phieta"))
            if d is None:
                d = {m: 0.0 for m in MOSAS}
            _check_keys(f"ttl.{f.name}", d, MOSAS)
            unit = "m/rad^2" if quad else "m/rad"
            object.__setattr__(self, f.name, {m: _finite_float(f"ttl.{f.name}[{m!r}]", d[m], unit) for m in MOSAS})

    @classmethod
    def constant(cls, local_phi: float, local_eta: float, distant_phi: float, distant_eta: float) -> "TTLCoefficients":
        """The same linear coefficients (m/rad) on every MOSA, no quadratic part."""
        return cls(*({m: v for m in MOSAS} for v in (local_phi, local_eta, distant_phi, distant_eta)))

    @classmethod
    def random(cls, seed: int, local_half_width: float = RANDOM_HALF_WIDTH_M_PER_RAD["local"],
               distant_half_width: float = RANDOM_HALF_WIDTH_M_PER_RAD["distant"]) -> "TTLCoefficients":
        """Linear coefficients drawn uniformly in [-w, w) (m/rad) by ``numpy.random.default_rng(seed)``,
        in the order local_phi, distant_phi, local_eta, distant_eta (LISA Instrument's), MOSAs in
        :data:`MOSAS` order; w defaults to LISA Instrument 2.3's ranges."""
        wl = _finite_float("ttl.local_half_width", local_half_width, "m/rad")
        wd = _finite_float("ttl.distant_half_width", distant_half_width, "m/rad")
        rng = np.random.default_rng(seed)
        lp, dp, le, de = ({m: float(rng.uniform(-w, w)) for m in MOSAS} for w in (wl, wd, wl, wd))
        return cls(local_phi=lp, local_eta=le, distant_phi=dp, distant_eta=de)

    def polynomial(self, kind: str, mosa: str, phi: np.ndarray, eta: np.ndarray) -> np.ndarray:
        """P^kind_mosa(phi, eta) (m); kind "local" or "distant"; phi, eta (rad), shape (n,)."""
        c = lambda name: getattr(self, f"{kind}_{name}")[mosa]  # noqa: E731
        out = c("phi") * phi + c("eta") * eta
        q = (c("phiphi"), c("etaeta"), c("phieta"))
        if any(q):
            out = out + q[0] * phi * phi + q[1] * eta * eta + q[2] * phi * eta
        return out


def _per_mosa(field: str, v, unit: str) -> dict:
    """A float (every MOSA) or a dict keyed by MOSA -> dict of finite floats."""
    if not isinstance(v, dict):
        v = {m: v for m in MOSAS}
    _check_keys(field, v, MOSAS)
    return {m: _finite_float(f"{field}[{m!r}]", v[m], unit) for m in MOSAS}


def _per_field(field: str, v, unit: str) -> dict:
    """A float, a dict keyed by MOSA, or a dict keyed by :data:`LINEAR_FIELDS` of either -> {field: {mosa: float}}."""
    if isinstance(v, dict) and any(k in LINEAR_FIELDS for k in v):
        _check_keys(field, v, LINEAR_FIELDS)
        return {f: _per_mosa(f"{field}.{f}", v[f], unit) for f in LINEAR_FIELDS}
    return {f: _per_mosa(field, v, unit) for f in LINEAR_FIELDS}


def _samples(field: str, t, y, order: int, unit: str) -> tuple:
    """Validated (t, y) samples (s, unit) of a series interpolated by a spline of degree ``order``."""
    t = np.asarray(t, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    if t.ndim != 1 or t.size <= order or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise ValueError(f"{field}: times must be a 1-D strictly increasing finite array of more than {order} "
                         f"samples (s), got shape {t.shape}")
    if y.shape != t.shape or not np.all(np.isfinite(y)):
        raise ValueError(f"{field}: values must be finite ({unit}) with the shape {t.shape} of the times, "
                         f"got shape {y.shape}")
    return t, y


def _spline_at(field: str, t_s: np.ndarray, y: np.ndarray, order: int, t: np.ndarray) -> np.ndarray:
    """The interpolating spline of degree ``order`` through (t_s, y) at t -- scipy's
    ``InterpolatedUnivariateSpline``, as LISA Instrument's ``TTLSourceInterp``; t outside [t_s[0], t_s[-1]]
    is refused."""
    from scipy.interpolate import InterpolatedUnivariateSpline

    if t.size and (t.min() < t_s[0] or t.max() > t_s[-1]):
        raise ValueError(f"{field}: covers t = {float(t_s[0])!r} .. {float(t_s[-1])!r} s; needed "
                         f"{float(t.min())!r} .. {float(t.max())!r} s")
    return InterpolatedUnivariateSpline(t_s, y, k=order, ext="raise")(t)


@dataclass(frozen=True, eq=False)
class TimeVaryingTTLCoefficients:
    """Linear TTL coefficients of the six MOSAs that vary in time (m/rad); quadratic ones constant.

    For each linear coefficient (:data:`LINEAR_FIELDS`) and MOSA::

        c(t) = c0 + r (t - t_ref) + k_T (T(t) - T_ref) + d(t)

    ``base``: :class:`TTLCoefficients`, c0 (m/rad) and the constant quadratic part; ``rate``: r (m/rad/s);
    ``temperature_coefficient``: k_T (m/rad/K), both {field: {mosa: float}} or None (zero);
    ``temperature``: (t_T (m,) s, T (m,) K) or None, T_ref (K) = ``temperature_ref``;
    ``series``: (t_d (p,) s, {field: {mosa: (p,) array}} m/rad) or None; ``order``: degree (3 or 5) of
    the interpolating splines through T and d (LISA Instrument's TTL-file interpolation).
    Times t, t_ref on the time axis of the angles' grid (module docstring).  Build with
    :meth:`drifting`, :meth:`thermal` or :meth:`from_series`; evaluate with :meth:`coefficient`."""

    base: TTLCoefficients
    t_ref: float = 0.0
    rate: dict | None = None
    temperature_coefficient: dict | None = None
    temperature: tuple | None = None
    temperature_ref: float = 0.0
    series: tuple | None = None
    order: int = 5

    def __post_init__(self):
        if not isinstance(self.base, TTLCoefficients):
            raise ValueError(f"ttl.base = {self.base!r}: expected a TTLCoefficients")
        if isinstance(self.order, bool) or self.order not in (3, 5):
            raise ValueError(f"ttl.order = {self.order!r}: must be 3 or 5 (LISA Instrument's spline degrees)")
        object.__setattr__(self, "t_ref", _finite_float("ttl.t_ref", self.t_ref, "s"))
        object.__setattr__(self, "temperature_ref", _finite_float("ttl.temperature_ref", self.temperature_ref, "K"))
        for name, unit in (("rate", "m/rad/s"), ("temperature_coefficient", "m/rad/K")):
            v = getattr(self, name)
            if v is not None:
                object.__setattr__(self, name, _per_field(f"ttl.{name}", v, unit))
        if (self.temperature is None) != (self.temperature_coefficient is None):
            raise ValueError("ttl.temperature and ttl.temperature_coefficient: give both or neither")
        if self.temperature is not None:
            t, temp = self.temperature
            object.__setattr__(self, "temperature", _samples("ttl.temperature", t, temp, self.order, "K"))
        if self.series is not None:
            t, vals = self.series
            if not isinstance(vals, dict):
                raise ValueError(f"ttl.series: expected (times, {{field: {{mosa: array}}}}), got {type(vals).__name__}")
            _check_keys("ttl.series", vals, LINEAR_FIELDS)
            out = {}
            for f in LINEAR_FIELDS:
                _check_keys(f"ttl.series.{f}", vals[f], MOSAS)
                out[f] = {m: _samples(f"ttl.series.{f}[{m!r}]", t, vals[f][m], self.order, "m/rad")[1] for m in MOSAS}
            object.__setattr__(self, "series", (_samples("ttl.series", t, t, self.order, "s")[0], out))

    @classmethod
    def drifting(cls, base: TTLCoefficients, rate, t_ref: float = 0.0) -> "TimeVaryingTTLCoefficients":
        """c(t) = c0 + r (t - t_ref): ``rate`` r (m/rad/s) a float for every coefficient, a dict keyed by MOSA,
        or by :data:`LINEAR_FIELDS` (e.g. :data:`LPF_DRIFT_M_PER_RAD_PER_S`)."""
        return cls(base=base, t_ref=t_ref, rate=rate)

    @classmethod
    def thermal(cls, base: TTLCoefficients, k_t, t, temperature, temperature_ref: float | None = None,
                order: int = 5) -> "TimeVaryingTTLCoefficients":
        """c(t) = c0 + k_T (T(t) - T_ref): ``k_t`` (m/rad/K, as ``rate`` of :meth:`drifting`; e.g.
        :data:`LPF_TEMPERATURE_COEFFICIENT_M_PER_RAD_PER_K`), the temperature T (K) sampled at ``t`` (s) and
        interpolated by a spline of degree ``order``; T_ref (K) defaults to the first sample."""
        temp = np.asarray(temperature, dtype=np.float64)
        ref = float(temp.ravel()[0]) if temperature_ref is None and temp.size else temperature_ref
        return cls(base=base, temperature_coefficient=k_t, temperature=(t, temperature),
                   temperature_ref=math.nan if ref is None else ref, order=order)

    @classmethod
    def from_series(cls, t, values: dict, order: int = 5, quadratic: TTLCoefficients | None = None
                    ) -> "TimeVaryingTTLCoefficients":
        """c(t) given as samples: ``values`` {field: {mosa: (p,) array}} (m/rad) at ``t`` (p,) (s), interpolated
        by a spline of degree ``order`` (as LISA Instrument reads its TTL file); the constant quadratic part
        from ``quadratic`` (its linear coefficients are ignored), zero by default."""
        zero = {m: 0.0 for m in MOSAS}
        q = {} if quadratic is None else {f.name: getattr(quadratic, f.name) for f in fields(TTLCoefficients)
                                          if f.name not in LINEAR_FIELDS}
        return cls(base=TTLCoefficients(zero, zero, zero, zero, **q), series=(t, values), order=order)

    def coefficient(self, field: str, mosa: str, t) -> np.ndarray:
        """c(t) (m/rad) of linear coefficient ``field`` (:data:`LINEAR_FIELDS`) of ``mosa`` at the times t (s)."""
        if field not in LINEAR_FIELDS:
            raise ValueError(unknown("field", field, LINEAR_FIELDS))
        if mosa not in MOSAS:
            raise ValueError(unknown("mosa", mosa, MOSAS))
        t = np.asarray(t, dtype=np.float64)
        out = np.full(t.shape, getattr(self.base, field)[mosa])
        if self.rate is not None:
            out = out + self.rate[field][mosa] * (t - self.t_ref)
        if self.temperature is not None:
            temp = _spline_at("ttl.temperature", *self.temperature, self.order, t.ravel()).reshape(t.shape)
            out = out + self.temperature_coefficient[field][mosa] * (temp - self.temperature_ref)
        if self.series is not None:
            ts, vals = self.series
            out = out + _spline_at(f"ttl.series.{field}[{mosa!r}]", ts, vals[field][mosa], self.order,
                                   t.ravel()).reshape(t.shape)
        return out

    def polynomial(self, kind: str, mosa: str, phi: np.ndarray, eta: np.ndarray, t: np.ndarray) -> np.ndarray:
        """P^kind_mosa(t; phi, eta) (m): c_phi(t) phi + c_eta(t) eta + the constant quadratic part; kind
        "local" or "distant"; phi, eta (rad) and t (s) of shape (n,)."""
        out = self.coefficient(f"{kind}_phi", mosa, t) * phi + self.coefficient(f"{kind}_eta", mosa, t) * eta
        c = lambda name: getattr(self.base, f"{kind}_{name}")[mosa]  # noqa: E731
        q = (c("phiphi"), c("etaeta"), c("phieta"))
        if any(q):
            out = out + q[0] * phi * phi + q[1] * eta * eta + q[2] * phi * eta
        return out


def mosa_angles(sc_phi: dict, sc_eta: dict, sc_theta: dict, mosa_phi: dict, mosa_eta: dict,
                opening_rad: dict | None = None) -> tuple[dict, dict]:
    """The phi (yaw) and eta (pitch) angles (rad) of the six MOSAs.

    LISA Instrument 2.3 ``instru/instru_formulas.py`` ``mosa_total_jitter_phis`` and
    ``mosa_total_jitter_etas`` (called in ``instru/instru_model.py``, "Angular jitters")::

        phi_ij = phi_i + phi^MOSA_ij
        eta_ij = cos(a_ij) eta_i - sin(a_ij) theta_i + eta^MOSA_ij

    phi_i, eta_i, theta_i: yaw, pitch, roll of spacecraft i (``sc_*``, keyed "1", "2", "3");
    phi^MOSA, eta^MOSA: the MOSA's own angles (keyed by MOSA); a_ij the oriented opening angle
    (rad; default :data:`MOSA_OPENING_ANGLES_RAD`).  Values: floats or arrays of one shape.
    Returns (phi, eta), dicts keyed by MOSA."""
    opening = MOSA_OPENING_ANGLES_RAD if opening_rad is None else opening_rad
    for name, d, keys in (("sc_phi", sc_phi, SPACECRAFT), ("sc_eta", sc_eta, SPACECRAFT),
                          ("sc_theta", sc_theta, SPACECRAFT), ("mosa_phi", mosa_phi, MOSAS),
                          ("mosa_eta", mosa_eta, MOSAS), ("mosa_opening_rad", opening, MOSAS)):
        _check_keys(name, d, keys)
    a = {m: _finite_float(f"mosa_opening_rad[{m!r}]", opening[m], "rad") for m in MOSAS}
    phi = {m: np.asarray(sc_phi[m[0]]) + np.asarray(mosa_phi[m]) for m in MOSAS}
    eta = {m: math.cos(a[m]) * np.asarray(sc_eta[m[0]]) - math.sin(a[m]) * np.asarray(sc_theta[m[0]])
           + np.asarray(mosa_eta[m]) for m in MOSAS}
    return phi, eta


def _delay(x: np.ndarray, dt: float, tau) -> np.ndarray:
    """x(t_k - tau_k) by the 8-point Lagrange interpolant (NaN where its stencil leaves the series).

    x, tau shape (n,).  The fraction is taken from the shift -tau/dt itself, not from k - tau/dt
    (whose rounding at large k would cost ulp(k) times the slope of x)."""
    n = x.size
    shift = -np.broadcast_to(np.asarray(tau, dtype=np.float64), (n,)) / dt
    fs = np.floor(shift)
    frac = shift - fs
    base = np.arange(n) + fs.astype(np.int64)  # floor(k - tau/dt)
    ok = (base - (_HALF - 1) >= 0) & (base + _HALF <= n - 1)
    out = np.full(n, np.nan)
    k, frac = base[ok], frac[ok]
    w = lagrange.weights(frac, _NODES)                                            # (n_ok, 8)
    out[ok] = np.sum(w * x[k[:, None] + np.asarray(_NODES)[None, :]], axis=1)
    return out


def ttl_terms(phi: dict, eta: dict, coeffs, dt: float, delays: dict, t0: float = 0.0) -> tuple[dict, dict]:
    """The local and (delayed) distant TTL terms of the six links (m), dicts keyed by link.

    phi, eta: MOSA angles (rad), dicts keyed by MOSA, arrays of shape (n,) sampled at t0 + k dt;
    coeffs: :class:`TTLCoefficients` (constant) or :class:`TimeVaryingTTLCoefficients` (evaluated at
    t0 + k dt: the local ones at the reception time, the distant ones at the emission time, module
    docstring); dt: sampling step (s); delays: light travel time tau_ij (s) per link, a float or an (n,)
    array at the reception times; t0: time of the first sample (s; used by time-varying coefficients
    only).  The first ~tau/dt + 4 samples of a distant term are NaN."""
    varying = isinstance(coeffs, TimeVaryingTTLCoefficients)
    if not (varying or isinstance(coeffs, TTLCoefficients)):
        raise ValueError(f"coeffs = {coeffs!r}: expected a TTLCoefficients or a TimeVaryingTTLCoefficients")
    _check_keys("phi", phi, MOSAS)
    _check_keys("eta", eta, MOSAS)
    _check_keys("delays", delays, MOSAS)
    step = _finite_float("dt", dt, "s")
    if step <= 0:
        raise ValueError(f"dt = {dt!r}: must be > 0 (s)")
    ph = {m: np.asarray(phi[m], dtype=np.float64) for m in MOSAS}
    et = {m: np.asarray(eta[m], dtype=np.float64) for m in MOSAS}
    n = ph[MOSAS[0]].size
    for name, d in (("phi", ph), ("eta", et)):
        for m in MOSAS:
            if d[m].shape != (n,):
                raise ValueError(f"{name}[{m!r}]: shape {d[m].shape}, expected ({n},) like phi['12']")
    if n < POINTS + MARGIN:
        raise ValueError(f"phi['12']: {n} samples, need at least {POINTS + MARGIN}")
    tau = {}
    for m in MOSAS:
        t = np.asarray(delays[m], dtype=np.float64)
        if t.shape not in ((), (n,)) or not np.all(np.isfinite(t)) or np.any(t < 0):
            raise ValueError(f"delays[{m!r}] = {delays[m]!r}: must be a finite number >= 0 or ({n},) array (s)")
        tau[m] = t
    if varying:
        t = _finite_float("t0", t0, "s") + step * np.arange(n)
        local = {m: coeffs.polynomial("local", m, ph[m], et[m], t) for m in MOSAS}
        emitted = {m: coeffs.polynomial("distant", m, ph[m], et[m], t) for m in MOSAS}
    else:
        local = {m: coeffs.polynomial("local", m, ph[m], et[m]) for m in MOSAS}
        emitted = {m: coeffs.polynomial("distant", m, ph[m], et[m]) for m in MOSAS}
    distant = {m: _delay(emitted[distant_mosa(m)], step, tau[m]) for m in MOSAS}
    return local, distant


def link_ttl(phi: dict, eta: dict, coeffs, dt: float, delays: dict, t0: float = 0.0) -> dict:
    """s_ij = local + delayed distant TTL term (m) of each link; arguments as :func:`ttl_terms`."""
    local, distant = ttl_terms(phi, eta, coeffs, dt, delays, t0)
    return {m: local[m] + distant[m] for m in MOSAS}
