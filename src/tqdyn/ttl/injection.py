"""The closed loop's tilt-to-length as LISA Instrument 2.3 readout injections (docs/lisa-ttl.md).

**Where LISA Instrument's own TTL enters** (``instru/instru_model.py``, ``instru/instru_formulas.py``).
Its TTL terms are velocities (m/s): ``local_ttls`` / ``distant_ttls`` = coefficients x the MOSA angular
jitter *velocities* (rad/s).  The emitting MOSA ji's distant term leaves on its beam
(``carrier_fluctuations``: ``- (nu0 + O_ji) (distant_ttl_ji - x_ji) / c``), is delayed by the
proper pseudorange and scaled by ``1 - d_ppr_ij`` (``propagated_carrier_fluctuations``); the
receiving MOSA ij's local term is added on arrival (``distant_carrier_fluctuations``:
``- (nu0 + O_ji) (local_ttl_ij - x_ij) / c``).  Only the science interferometer's distant beam
carries them, so the TTL part of the science carrier beatnote (``tps_sci_carrier_fluctuations`` =
distant - local + nu0 OMS + ``glitch_readout_sci_carriers``, Hz) is

    -(nu0 + O_ji(t - tau)) [ local_ttl_ij(t) + (1 - d_ppr_ij) distant_ttl_ji(t - tau) ] / c
        = -(nu0 / c) ds_ij/dt  (1 + O(O_ji / nu0) + O(d_ppr))

with s_ij the link's TTL path length of :func:`tqdyn.ttl.coupling.link_ttl` (m; with constant
coefficients ds/dt is exactly LISA Instrument's velocity sum).  The glitch injection point
``readout_isi_carrier_ij`` (``readout_sci_carrier``) is added to that same beatnote, in Hz, with a
plus sign; so the injection

    g_ij(t) = -(nu0 / c) ds_ij/dt    [Hz]

enters the science carrier exactly as LISA Instrument's TTL does, up to the omitted factors: the
carrier offset O_ji (tens of MHz: ~1e-7 relative; <= 16 MHz with lock = "six"), the Doppler factor
1 - d_ppr (|d_ppr| ~ 1e-8) and the delay (tqdyn's light travel time instead of the proper
pseudorange: their difference, the clocks' desynchronisation, is microseconds, a phase 2 pi f dtau).
The upper sideband carries the same TTL with nu0 + O + f_mod (f_mod = 2.4 GHz: 1e-5 relative): the
same g goes to ``readout_isi_usb_ij``.  The laser injection point would put it in every
interferometer of the MOSA (reference and test mass too), the test-mass point in the TMI only: neither
is equivalent.

**Test masses** (optional).  The ``tm_ij`` injection (m/s) is added to ``testmass_noises`` of MOSA ij
(``local_tmi_carrier_fluctuations``: ``- (nu0 + O) (x_ij - testmass_noise_ij - tm_ij) 2 / c``), a
velocity along the MOSA's x axis: the same sign as the bench's ``x_ij``, which the science beatnote
gets as ``+ nu0 x_ij / c`` (a Doppler blue shift: positive towards the distant spacecraft j).  So
tm_ij = the TM's residual (non-gravitational) velocity towards j, the time integral of the closed
loop's ``tm{l}_acceleration`` (along the sensitive axis e_l; along +X_OA_l, the optical axis towards
the distant spacecraft, for every preset: a sign s_l = e_l . X_OA_l = +-1 is applied), by the
trapezoidal rule (relative error (omega dt)^2 / 12: 2e-5 at 10 mHz and 4 Hz) with its mean removed
(the integration constant: a constant velocity is no acceleration).

**Derivative.**  ds/dt of the sampled s by the 9-point (8th-order) central difference, relative error
(omega dt)^8 / 630 (4e-5 at f = fs/10); the 4 samples at each end are NaN.

Units SI (Hz, m, m/s, s); time series 1-D arrays of shape (n,) on one uniform grid.
"""

from __future__ import annotations

import numpy as np

from ..astro.constants import C_LIGHT
from .coupling import MOSAS, link_ttl
from .budget import MOSA_NAMES, mosa_angles_from_outputs

__all__ = ["CENTRAL_FREQ_HZ", "central_derivative", "readout_injections", "tm_velocity_injections",
           "ttl_to_readout_hz"]

#: LISA Instrument 2.3's default laser central frequency ``central_freq`` (Hz).
CENTRAL_FREQ_HZ = 2.816e14

#: 8th-order central first-derivative weights for offsets 1..4 (antisymmetric).
_D8 = (4.0 / 5.0, -1.0 / 5.0, 4.0 / 105.0, -1.0 / 280.0)


def central_derivative(x: np.ndarray, dt: float) -> np.ndarray:
    """dx/dt of x sampled every dt (s) by the 9-point central difference (module docstring); shape (n,),
    NaN at the 4 first and last samples (and wherever the stencil meets a NaN)."""
    x = np.asarray(x, dtype=np.float64)
    out = np.full(x.shape, np.nan)
    n = x.size
    if n > 8:
        acc = np.zeros(n - 8)
        for k, w in enumerate(_D8, start=1):
            acc += w * (x[4 + k:n - 4 + k] - x[4 - k:n - 4 - k])
        out[4:n - 4] = acc / dt
    return out


def ttl_to_readout_hz(s: np.ndarray, dt: float, central_freq: float = CENTRAL_FREQ_HZ) -> np.ndarray:
    """g = -(nu0 / c) ds/dt (Hz): the science-beatnote frequency fluctuation of the TTL path length s (m,
    sampled every dt s), as LISA Instrument's own TTL term makes it (module docstring)."""
    return -(float(central_freq) / C_LIGHT) * central_derivative(s, dt)


def readout_injections(outputs: dict, theta, coeffs, dt: float, delays: dict,
                       central_freq: float = CENTRAL_FREQ_HZ, t0: float = 0.0) -> tuple[dict, dict]:
    """The links' TTL s_ij (m) and their readout injections g_ij (Hz), dicts keyed by link (:data:`MOSAS`).

    outputs: the closed loop's angle outputs (:data:`tqdyn.ttl.budget.ANGLE_OUTPUTS`, rad),
    arrays (n, 3) over the spacecraft, sampled at t0 + k dt (s); theta: opening angle(s) (rad); coeffs:
    constant or time-varying coefficients (:func:`tqdyn.ttl.coupling.ttl_terms`); dt: step (s); delays:
    light travel time per link (s, float or (n,)).  NaN where the derivative's or the delay's stencil leaves the series."""
    phi, eta = mosa_angles_from_outputs(outputs, theta)
    s = link_ttl(phi, eta, coeffs, dt, delays, t0)
    return s, {m: ttl_to_readout_hz(s[m], dt, central_freq) for m in MOSAS}


def tm_velocity_injections(tm1_acceleration: np.ndarray, tm2_acceleration: np.ndarray, dt: float,
                           axis_sign=(1.0, 1.0)) -> dict:
    """The ``tm_ij`` injections (m/s), dict keyed by MOSA: the trapezoidal time integral (mean removed) of
    the residual acceleration of TM l of spacecraft i (``tm{l}_acceleration``, m/s^2, arrays (n, 3) over the
    spacecraft) times ``axis_sign[l - 1]`` (e_l . X_OA_l), at LISA Instrument's MOSA of TM l
    (:data:`tqdyn.ttl.budget.MOSA_NAMES`); dt (s)."""
    out = {}
    for l, acc in enumerate((tm1_acceleration, tm2_acceleration)):
        a = np.asarray(acc, dtype=np.float64)
        v = np.concatenate([np.zeros((1,) + a.shape[1:]), np.cumsum(0.5 * (a[1:] + a[:-1]), axis=0) * dt])
        v = float(axis_sign[l]) * (v - v.mean(axis=0))
        for i in range(a.shape[1]):
            out[MOSA_NAMES[i][l]] = v[:, i]
    return out
