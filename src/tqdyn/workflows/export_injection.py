"""The closed loop's tilt-to-length as a LISA Instrument injection file: the job behind
``tqdyn export CL.h5 --format lisa-injection OUT.h5 --run RUN.h5`` (docs/lisa-ttl.md).

:func:`export_lisa_injection` reads the closed-loop file (:mod:`tqdyn.formats.closed_loop`) and the run
it was made from (checked by SHA-256), forms the MOSA angles of the closed loop's attitude and MOSA
outputs, each link's TTL s_ij (:func:`tqdyn.ttl.coupling.link_ttl`, the distant term delayed by the
run's light travel times of :func:`tqdyn.lightpath.light_travel_times_of`, as ``--format lisa``) and
its science-readout injection g_ij = -(nu0/c) ds_ij/dt
(:mod:`tqdyn.ttl.injection`), and writes them as a LISA Instrument glitch file
(:func:`tqdyn.formats.lisa_injection.write_lisa_injection`) at ``readout_isi_carrier_ij`` and
``readout_isi_usb_ij``; with ``tm=True`` also the TMs' residual velocity (the integral of the closed loop's
``tm{l}_acceleration``) at ``tm_ij``.  It prints nothing; the CLI reports.

Time axis: the file's t is the closed loop's (the run's time axis since its epoch: TT for geocentric
runs, which is the time of ``--format lisa``'s GCRS file; TDB for heliocentric ones, whose BCRS file
counts TCB since the epoch: the two differ by L_B t = 1.55e-8 t, 1.3 ms a day, a phase of the jitter
only).  It starts where the delayed distant term and the derivative are defined (tau/dt + 8 samples
after the closed loop's first sample) and ends 4 samples before its last.
"""

from __future__ import annotations

import json
import math
import os
import pathlib
from dataclasses import dataclass

import numpy as np

from ..ttl.coupling import LINEAR_FIELDS, MOSAS, TimeVaryingTTLCoefficients, TTLCoefficients
from ..ttl.budget import ANGLE_OUTPUTS
from ..ttl.injection import CENTRAL_FREQ_HZ, readout_injections, tm_velocity_injections
from ..formats import trajectory as _io
from ..formats.atomic import check_output
from ..formats.closed_loop import read_closed_loop
from ..formats.lisa_injection import write_lisa_injection
from ..lightpath import light_travel_times_of
from ..lightpath.proper_time import scenario_gm_earth
from .closed_loop import file_sha256
from .export_ttl import coefficient_set
from .memory import check_memory

__all__ = ["LisaInjection", "export_lisa_injection"]

#: Memory per sample of the closed-loop file [bytes]: about 115 float64 measured at the peak (the
#: angles' series, the light travel times on their grid, the injections and their derivatives, the
#: file's image); 128 with a margin.
BYTES_PER_SAMPLE = 128 * 8


@dataclass(frozen=True)
class LisaInjection:
    """Summary of one export: ``path``; ``size`` samples from ``t0`` every ``dt`` [s]; ``coefficients``
    (the spec); ``rms_hz`` the largest RMS of the six injections [Hz]; ``rms_m`` the largest RMS of the
    six TTL path lengths s_ij [m]."""

    path: pathlib.Path
    size: int
    t0: float
    dt: float
    coefficients: str
    rms_hz: float
    rms_m: float


def _delays_at(lp, t: np.ndarray) -> dict:
    """Light travel time (s) of each link at the times t (s): linear in the run's rows (ltt moves by
    ~1e-9 s/s), extrapolated linearly from the first / last two defined rows."""
    tr = np.asarray(lp.t[0], dtype=np.float64) + np.asarray(lp.t[1], dtype=np.float64)
    tau = np.asarray(lp.tau[0], dtype=np.float64) + np.asarray(lp.tau[1], dtype=np.float64)
    out = {}
    for k, m in enumerate(MOSAS):
        ok = np.isfinite(tau[:, k])
        x, y = tr[ok], tau[ok, k]
        if x.size < 2:
            raise ValueError(f"link {m}: fewer than 2 rows with a light travel time")
        v = np.interp(t, x, y)
        lo, hi = t < x[0], t > x[-1]
        v[lo] = y[0] + (t[lo] - x[0]) * (y[1] - y[0]) / (x[1] - x[0])
        v[hi] = y[-1] + (t[hi] - x[-1]) * (y[-1] - y[-2]) / (x[-1] - x[-2])
        out[m] = v
    return out


def _axis_signs(traj, run_file) -> tuple:
    """e_l . X_OA_l (+-1) of the run's two sensitive axes; ValueError unless each is +-X_OA_l."""
    axes = np.asarray(traj.spacecraft.sensitive_axes, dtype=np.float64)
    out = []
    for l in range(2):
        e = axes[l] / np.linalg.norm(axes[l])
        if abs(abs(e[0]) - 1.0) > 1e-12:
            raise ValueError(f"{run_file}: spacecraft.sensitive_axes[{l}] = {axes[l].tolist()}; the TM injection "
                             "needs sensitive axes along +-X_OA (allowed: [1, 0, 0] or [-1, 0, 0])")
        out.append(float(np.sign(e[0])))
    return tuple(out)


def export_lisa_injection(closed_loop_file, run_file, out_path, coefficients: str | TTLCoefficients = "worst-case",
                          *, seed: int | None = None, drift: float | None = None,
                          central_freq: float = CENTRAL_FREQ_HZ, tm: bool = False) -> LisaInjection:
    """Write the LISA Instrument injection file of the closed loop ``closed_loop_file`` of the run
    ``run_file`` (module docstring).  ``coefficients``, ``seed``: as ``--format ttl``
    (:func:`tqdyn.workflows.export_ttl.coefficient_set`: "worst-case", "random" with ``seed``, a TOML/JSON
    file) or a :class:`TTLCoefficients`; ``drift`` [m/rad/s]: every linear coefficient drifts from the
    file's first sample on (:meth:`TimeVaryingTTLCoefficients.drifting`; None or 0: constant); ``central_freq`` [Hz]: LISA Instrument's ``central_freq`` (its default);
    ``tm``: also inject the TMs' residual velocity at ``tm_ij`` (m/s; the run's sensitive axes must be
    +-X_OA_l).

    Raises FileNotFoundError, ValueError (one line: a closed-loop file of another run -- its
    ``source_sha256`` differs from the run file's SHA-256 --, not a closed-loop file, bad coefficients)
    or :class:`tqdyn.formats.trajectory.OutputError`; nothing is written then."""
    if isinstance(coefficients, TTLCoefficients):
        coeffs, model = coefficients, {"kind": "given"}
    else:
        coeffs, model = coefficient_set(coefficients, seed)
    spec = model["kind"] + (f" (seed {model['seed']})" if "seed" in model else "") + (
        f" ({model['file']})" if "file" in model else "")
    rate = 0.0 if drift is None else float(drift)
    if not math.isfinite(rate):
        raise ValueError(f"--drift = {drift!r}: must be a finite number (m/rad/s)")
    nu0 = float(central_freq)
    if not (math.isfinite(nu0) and nu0 > 0):
        raise ValueError(f"central_freq = {central_freq!r}: must be a finite frequency > 0 (Hz)")
    out = check_output(out_path, "OUT", {"CL.h5": closed_loop_file, "--run": run_file,
                                         "--coefficients": model.get("file") and coefficients})
    cl = read_closed_loop(closed_loop_file)
    if not os.path.isfile(run_file):
        raise FileNotFoundError(f"run file {str(run_file)!r} not found")
    digest = file_sha256(run_file)
    if cl.attrs.get("source_sha256") != digest:
        raise ValueError(f"{cl.path} is the closed loop of another run ({cl.attrs.get('source_file')!r}, SHA-256 "
                         f"{str(cl.attrs.get('source_sha256'))[:12]}...) than {str(run_file)!r} (SHA-256 "
                         f"{digest[:12]}...); give the run it was made from")
    traj = _io.read_trajectory(run_file)
    if traj.n_sat != 3:
        raise ValueError(f"{run_file}: n_sat = {traj.n_sat}; the six links need 3 satellites")
    signs = _axis_signs(traj, run_file) if tm else None
    n = int(cl.attrs.get("n_samples", 0))
    check_memory(n * BYTES_PER_SAMPLE, f"CL.h5: the injection of its {n} samples",
                 lambda budget: f"at most {budget / BYTES_PER_SAMPLE:.3g} samples (closed-loop --duration, --fs)")
    ts = cl.timeseries(list(ANGLE_OUTPUTS) + (["tm1_acceleration", "tm2_acceleration"] if tm else []))
    t = np.asarray(ts["time"].values, dtype=np.float64)
    dt = 1.0 / float(cl.attrs["fs"])
    vals = ts["values"].values                                             # (n, 3, 5)
    outputs = {name: vals[:, :, k] for k, name in enumerate(ts["output"].values)}
    # opening angle theta = mosa/angle_1 - mosa/angle_2 (as the closed loop's working points) mid-series
    tr = np.asarray(traj["t"], dtype=np.float64)
    mid = int(np.argmin(np.abs(tr - 0.5 * (t[0] + t[-1]))))
    ang = np.asarray(traj["mosa/angle"][mid], dtype=np.float64)            # (3, 2)
    theta = ang[:, 0] - ang[:, 1]
    if traj.reference.origin == "sun":
        lp = light_travel_times_of(traj)
    else:
        lp = light_travel_times_of(traj, shapiro=False, gm=scenario_gm_earth(traj))
    delays = _delays_at(lp, t)
    base = coeffs
    if rate:
        coeffs = TimeVaryingTTLCoefficients.drifting(coeffs, rate, t_ref=float(t[0]))
        spec += f", drifting {rate * 86400:g} m/rad per day from t = {t[0]:g} s"
    s, g = readout_injections(outputs, theta, coeffs, dt, delays, nu0, t0=float(t[0]))
    v = tm_velocity_injections(outputs["tm1_acceleration"], outputs["tm2_acceleration"], dt, signs) if tm else {}
    ok = np.all([np.isfinite(g[m]) for m in MOSAS], axis=0)
    idx = np.flatnonzero(ok)
    if idx.size < 16 or not ok[idx[0]:idx[-1] + 1].all():
        raise ValueError(f"{cl.path}: {t.size} samples leave {idx.size} with a defined TTL injection "
                         f"(the delay takes {max(float(np.max(v)) for v in delays.values()) / dt:.0f} samples); "
                         "make a longer closed-loop series")
    sl = slice(idx[0], idx[-1] + 1)
    series, desc = {}, {}
    for m in MOSAS:
        for point in ("readout_isi_carrier", "readout_isi_usb"):
            series[f"{point}_{m}"] = g[m][sl]
            desc[f"{point}_{m}"] = (f"-(nu0/c) ds_{m}/dt: the closed loop's tilt-to-length of link {m} as a "
                                    "science-beatnote frequency fluctuation (Hz)")
        if tm:
            series[f"tm_{m}"] = v[m][sl] - v[m][sl].mean()
            desc[f"tm_{m}"] = (f"residual velocity (m/s) of the TM of MOSA {m} towards the distant spacecraft: the "
                               "time integral of the closed loop's tm acceleration, mean removed")
    attrs = {
        "generator": "tqdyn export --format lisa-injection",
        "central_freq": nu0,
        "ttl_coefficients": spec,
        "ttl_coefficients_json": json.dumps({k: getattr(base, k) for k in LINEAR_FIELDS}),
        "ttl_drift_m_per_rad_per_s": rate,
        "opening_angles_rad": json.dumps([float(x) for x in theta]),
        "source_closed_loop": str(cl.path),
        "source_closed_loop_seed": int(cl.attrs.get("seed", 0)),
        "source_run": str(pathlib.Path(run_file).resolve()),
        "source_run_sha256": digest,
        "time_scale": str(cl.attrs.get("source_time_scale", "")) + " seconds since the run's epoch (the closed "
                      "loop's time axis)",
        "ltt_note": lp.note,
        "test_masses": "tm_ij: TM residual velocity (m/s)" if tm else "not injected",
        "convention": "readout_isi_{carrier,usb}_ij = -(nu0/c) d s_ij/dt, s_ij = local TTL of MOSA ij + distant "
                      "TTL of MOSA ji delayed by the light travel time (tqdyn.ttl.coupling.link_ttl)",
    }
    path = write_lisa_injection(out, t[idx[0]], dt, series, attrs, desc)
    return LisaInjection(path=path, size=int(idx.size), t0=float(t[idx[0]]), dt=dt, coefficients=spec,
                         rms_hz=max(float(np.sqrt(np.mean(g[m][sl] ** 2))) for m in MOSAS),
                         rms_m=max(float(np.sqrt(np.nanmean(s[m][sl] ** 2))) for m in MOSAS))
