"""The linearised plant of one spacecraft around its working point (derivation: docs/closed-loop.md).

Degrees of freedom (20; the state is [q, q'], 40 states), frames and units:

* ``u``   (3)  spacecraft centre-of-mass displacement from its nominal orbit, S components [m];
* ``phi`` (3)  small rotation of the body frame B from the nominal S (T_B_I = (I - [phi x]) T_S_I) [rad];
* ``x1``, ``x2`` (3 each) TM l centre of mass minus its electrode-housing (EH) centre, OA_l components [m];
* ``eta1``, ``eta2`` (3 each) small rotation of TM l relative to its housing, OA_l components [rad];
* ``dth`` (2) MOSA angle perturbations (the angle of X_OA_l from X_S about Z_S, ``mosa/angle``) [rad].

Inputs (named, python-control signal names): ``F[0..2]`` thrust [N, B axes], ``T[0..2]`` thruster
torque [N m, B], ``f1[0..2]``, ``f2[..]`` electrostatic force on TM l [N, OA_l], ``t1[..]``,
``t2[..]`` electrostatic torque on TM l [N m, OA_l], ``a1[..]``, ``a2[..]`` TM force noise [m/s^2,
OA_l, not reacted on the spacecraft], ``b1[..]``, ``b2[..]`` TM torque noise [rad/s^2, OA_l],
``tm[0..1]`` MOSA actuator torque [N m about Z_S].  Outputs: every coordinate of q (same names as
the DOFs, ``u[0]`` ... ``dth[1]``) and the TM's non-gravitational acceleration ``acc1[..]``,
``acc2[..]`` [m/s^2, OA_l] (electrostatic force / m + force noise - stiffness x: the residual
acceleration of the TM against its geodesic) and the relative acceleration ``xdd1[..]``,
``xdd2[..]`` (x_l'', what a local readout sees) [m/s^2, OA_l].

The working point (:class:`WorkingPoint`) holds the coefficients that change over days: the
gravity-gradient tensor at the spacecraft in S, the nominal omega, omega_dot, the MOSA angle and
rate, the DC electrostatic force and torque (``tm/a_suspension``, ``tm/alpha_suspension``) and the
DC drag-free acceleration in S.  Time scale: instantaneous (frozen coefficients).
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np

from ..constellation.control import oa_rotation

__all__ = ["PlantParameters", "WorkingPoint", "dof_names", "linear_plant", "plant_matrices", "plant_parameters",
           "sensitive_basis", "tm_stiffness"]

Z = np.array([0.0, 0.0, 1.0])


def _skew(v) -> np.ndarray:
    """[v x] (3, 3): skew(v) @ w = v x w."""
    x, y, z = v
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


@dataclass(frozen=True)
class PlantParameters:
    """Masses, inertias, geometry and stiffness of one spacecraft (SI; the same for the three).

    sc_mass [kg]; sc_inertia (3,) [kg m^2] principal moments about the S axes; tm_mass [kg];
    tm_side [m] (cube: moment of inertia tm_mass tm_side^2 / 6); mosa_inertia [kg m^2] about Z_S;
    mosa_stiffness [N m/rad] of the MOSA mechanism; stiffness (2, 3) [s^-2] per TM and OA_l axis,
    x'' = -stiffness x + ... (electrostatic + self-gravity gradient; negative = destabilising);
    rotational_stiffness (2, 3) [s^-2] likewise for eta; crosstalk: the electrostatic actuation
    cross-talk, the fraction of a force (torque) commanded on one axis of a TM that appears on each
    other axis of the same TM; housing_centers (2, 3) [m, S], lever_arms (2, 3) [m, S] (EH centre
    minus MOSA pivot) and sensitive_axes (2, 3) [unit, OA_l] from the trajectory's spacecraft.
    n_tm : 2, or 1 for a spacecraft with one TM (TianQin-1: TM 2's coordinates are then placeholders);
    mosa : True for housings on articulated MOSAs, False for housings fixed in the body (a single
    spacecraft: LISA Pathfinder, TianQin-1; the MOSA angles are then placeholders).  A placeholder
    coordinate is decoupled from everything, unexcited and damped (q'' = -q' - q per 1 s^2, poles at
    -0.5 +- 0.87i rad/s), so that every plant has the same coordinates and named outputs (zero there).
    """

    sc_mass: float
    sc_inertia: tuple
    tm_mass: float
    tm_side: float
    mosa_inertia: float
    mosa_stiffness: float
    stiffness: np.ndarray
    rotational_stiffness: np.ndarray
    crosstalk: float
    housing_centers: np.ndarray
    lever_arms: np.ndarray
    sensitive_axes: np.ndarray
    n_tm: int = 2
    mosa: bool = True

    @property
    def tm_inertia(self) -> float:
        """TM moment of inertia [kg m^2] (a homogeneous cube)."""
        return self.tm_mass * self.tm_side ** 2 / 6.0


@dataclass(frozen=True)
class WorkingPoint:
    """Frozen coefficients of one spacecraft (S frame unless noted; SI).

    gamma (3, 3) [s^-2] gravity-gradient tensor at the spacecraft in S; omega (3,) [rad/s],
    omega_dot (3,) [rad/s^2]; theta [rad] the opening angle (MOSA angles +-theta/2), theta_dot
    [rad/s]; a_suspension (2, 3) [m/s^2, OA_l] and alpha_suspension (2, 3) [rad/s^2, OA_l] the DC
    electrostatic actuation; a_dragfree (3,) [m/s^2, S] the DC drag-free acceleration;
    self_gravity (2, 3) [m/s^2, OA_l] the DC self-gravity at the TMs (``tm/self_gravity``); t [s]
    the time it belongs to (the run's time axis).
    """

    gamma: np.ndarray
    omega: np.ndarray
    omega_dot: np.ndarray
    theta: float
    theta_dot: float
    a_suspension: np.ndarray
    alpha_suspension: np.ndarray
    a_dragfree: np.ndarray
    self_gravity: np.ndarray
    t: float = 0.0


def plant_parameters(plant: dict, craft, theta: float) -> PlantParameters:
    """The :class:`PlantParameters` of a spacecraft from the ``[closed_loop.plant]`` values ``plant`` (the
    keys of :data:`tqdyn.scenario.closed_loop.PLANT_KEYS`, e.g. :func:`tqdyn.closedloop.missions.default_plant`;
    the per-axis stiffnesses ``stiffness`` of both TMs unless ``tm2_stiffness`` gives TM 2's) and the geometry
    of ``craft`` (:class:`tqdyn.constellation.spacecraft.Spacecraft`) at the opening angle ``theta`` [rad]."""
    return PlantParameters(sc_mass=plant["sc_mass"], sc_inertia=plant["sc_inertia"], tm_mass=plant["tm_mass"],
                           tm_side=plant["tm_side"], mosa_inertia=plant["mosa_inertia"],
                           mosa_stiffness=plant["mosa_stiffness"], stiffness=tm_stiffness(plant),
                           rotational_stiffness=tm_stiffness(plant, "rotational_stiffness"),
                           crosstalk=plant["crosstalk"], housing_centers=craft.housing_centers(theta),
                           lever_arms=craft.lever_arms(theta), sensitive_axes=craft.sensitive_axes_array)


def tm_stiffness(plant: dict, key: str = "stiffness") -> np.ndarray:
    """(2, 3) [s^-2]: ``plant[key]`` for TM 1 and ``plant["tm2_" + key]`` (default the same) for TM 2."""
    return np.array([plant[key], plant.get(f"tm2_{key}", plant[key])], dtype=np.float64)


def dof_names() -> list[str]:
    """The 20 coordinates q in state order (module docstring)."""
    out = []
    for g, n in (("u", 3), ("phi", 3), ("x1", 3), ("x2", 3), ("eta1", 3), ("eta2", 3), ("dth", 2)):
        out += [f"{g}[{i}]" for i in range(n)]
    return out


def sensitive_basis(p: PlantParameters) -> np.ndarray:
    """(2, 3, 3): for each TM, rows e_l (sensitive axis), p_l = Z x e_l, q = Z, in OA_l components.
    The closed loop needs e_l perpendicular to Z (every preset: X_OA_l); ValueError otherwise."""
    out = np.zeros((2, 3, 3))
    for l in range(2):
        e = np.asarray(p.sensitive_axes[l], dtype=np.float64)
        e = e / np.linalg.norm(e)
        if abs(e[2]) > 1e-12:
            raise ValueError(f"spacecraft.sensitive_axes: {p.sensitive_axes[l].tolist()} has a Z_S component; "
                             "allowed: sensitive axes in the plane of the constellation for the closed loop")
        out[l] = [e, np.cross(Z, e), Z]
    return out


def _gg_torque_jacobian(gamma: np.ndarray, J: np.ndarray) -> np.ndarray:
    """d(gravity-gradient torque / J)/d phi (3, 3): torque_i = eps_ijk Gamma_kl S_jl with S = tr(J)/2 - J
    and Gamma_B = Gamma - [phi x] Gamma + Gamma [phi x] (the attitude perturbation)."""
    S = 0.5 * np.trace(J) * np.eye(3) - J
    eps = np.zeros((3, 3, 3))
    eps[0, 1, 2] = eps[1, 2, 0] = eps[2, 0, 1] = 1.0
    eps[0, 2, 1] = eps[2, 1, 0] = eps[1, 0, 2] = -1.0
    out = np.zeros((3, 3))
    for a in range(3):
        P = _skew(np.eye(3)[a])
        dG = -P @ gamma + gamma @ P
        out[:, a] = np.einsum("ijk,kl,jl->i", eps, dG, S)
    return np.linalg.solve(J, out)


#: First rows of x_l, eta_l (l = 1, 2) and dth_1 in q (:func:`dof_names` order); u is 0, phi 3.
_IX, _IETA, _ITH = (6, 9), (12, 15), 18


class _Equations:
    """M q'' + D q' + K q = B w (module docstring) of :func:`linear_plant`, filled block by block: the
    spacecraft's rows (:meth:`spacecraft`), then each TM's and MOSA's (:meth:`test_mass`)."""

    def __init__(self, p: PlantParameters, wp: WorkingPoint):
        n = 20
        self.p, self.wp = p, wp
        self.M, self.D, self.K = np.eye(n), np.zeros((n, n)), np.zeros((n, n))
        self.inputs = ([f"F[{i}]" for i in range(3)] + [f"T[{i}]" for i in range(3)]
                       + [f"f{l}[{i}]" for l in (1, 2) for i in range(3)]
                       + [f"t{l}[{i}]" for l in (1, 2) for i in range(3)]
                       + [f"a{l}[{i}]" for l in (1, 2) for i in range(3)]
                       + [f"b{l}[{i}]" for l in (1, 2) for i in range(3)] + ["tm[0]", "tm[1]"])
        self.col = {s: k for k, s in enumerate(self.inputs)}
        self.B = np.zeros((n, len(self.inputs)))
        self.G = np.asarray(wp.gamma, dtype=np.float64)
        self.W, self.Wd = _skew(wp.omega), _skew(wp.omega_dot)
        self.W2 = self.W @ self.W
        self.J = np.diag(np.asarray(p.sc_inertia, dtype=np.float64))
        self.Jinv = np.linalg.inv(self.J)
        self.R = np.transpose(oa_rotation(wp.theta), (0, 2, 1))          # (2, 3, 3): T_S_OA_l (OA_l -> S)
        self.X = np.eye(3) + p.crosstalk * (np.ones((3, 3)) - np.eye(3))  # cross-talk of the actuation

    def spacecraft(self) -> None:
        """The rows of u and phi (their own terms; the TMs' and MOSAs' reactions: :meth:`test_mass`)."""
        D, K, B, G, W, Wd, J, Jinv = self.D, self.K, self.B, self.G, self.W, self.Wd, self.J, self.Jinv
        F, T = self.col["F[0]"], self.col["T[0]"]
        # spacecraft translation u (S): u'' = (Gamma - W' - W^2) u - 2 W u' + F_S/M - [G x] phi + reactions / M
        K[0:3, 0:3] = -(G - Wd - self.W2)
        D[0:3, 0:3] = 2 * W
        B[0:3, F:F + 3] = np.eye(3) / self.p.sc_mass
        K[0:3, 3:6] = _skew(self.wp.a_dragfree)                 # + phi x G_S  ->  K = -[phi x G] coefficient
        # spacecraft rotation: J phi'' + (J W - [(J w) x] + W J) phi' + (J W' - [(J w) x] W + W J W) phi = T
        Jw = _skew(J @ self.wp.omega)
        D[3:6, 3:6] = Jinv @ (J @ W - Jw + W @ J)
        K[3:6, 3:6] = Jinv @ (J @ Wd - Jw @ W + W @ J @ W) - _gg_torque_jacobian(G, J)
        B[3:6, T:T + 3] = Jinv

    def test_mass(self, l: int) -> None:
        """The rows of x_l, eta_l and dth_l (TM l = ``l`` + 1, its MOSA) and their reactions on the spacecraft."""
        p, wp, M, D, K, B, R, X = self.p, self.wp, self.M, self.D, self.K, self.B, self.R, self.X
        G, W, Wd, W2, Jinv = self.G, self.W, self.Wd, self.W2, self.Jinv
        m, Msc, Itm, Im = p.tm_mass, p.sc_mass, p.tm_inertia, p.mosa_inertia
        half = 0.5 * wp.theta_dot
        rh = np.asarray(p.housing_centers, dtype=np.float64)[l]
        rho = np.asarray(p.lever_arms, dtype=np.float64)[l]
        rh_dot = np.cross((1.0, -1.0)[l] * half * Z, rho) if p.mosa else np.zeros(3)   # w_oa x rho
        Rl, kx, kr = R[l], np.diag(p.stiffness[l]), np.diag(p.rotational_stiffness[l])
        xs, es = slice(_IX[l], _IX[l] + 3), slice(_IETA[l], _IETA[l] + 3)
        th = _ITH + l
        c = np.cross(Z, rho) if p.mosa else np.zeros(3)      # d r_h / d dth_l (S); fixed housings: none
        col = self.col
        F = col["F[0]"]
        fcol, tcol, acol, bcol = col[f"f{l + 1}[0]"], col[f"t{l + 1}[0]"], col[f"a{l + 1}[0]"], col[f"b{l + 1}[0]"]
        # --- TM translation, in OA_l: x = R^T x_S
        # x_S'' + 2 W x_S' + (W' + W^2 - Gamma) x_S = attitude + MOSA terms + f_S/m - F/M - R kx x
        M[xs, 3:6] = -Rl.T @ _skew(rh)                       # - [r_h x] phi''  (moved to the left)
        M[xs, th] = Rl.T @ c                                  # + c dth''
        D[xs, xs] = Rl.T @ (2 * W) @ Rl
        K[xs, xs] = Rl.T @ (Wd + W2 - G) @ Rl + kx
        rx, wrx = _skew(rh), _skew(W @ rh)
        D[xs, 3:6] = -Rl.T @ (2 * _skew(rh_dot) + rx @ W + wrx + W @ rx)
        K[xs, 3:6] = -Rl.T @ (2 * _skew(rh_dot) @ W + rx @ Wd + wrx @ W + W @ rx @ W
                              - G @ rx + _skew(G @ rh))
        D[xs, th] = Rl.T @ (2 * W @ c)
        K[xs, th] = Rl.T @ ((Wd + W2 - G) @ c - np.cross(Z, Rl @ wp.a_suspension[l]))
        B[xs, fcol:fcol + 3] = X / m + X / Msc            # own force, and its reaction on the spacecraft
        B[xs, acol:acol + 3] = np.eye(3)
        B[xs, F:F + 3] = -Rl.T / Msc
        # reactions on the spacecraft: -R f (force), -r_h x R f - R t (torque), stiffness likewise
        B[0:3, fcol:fcol + 3] = -Rl @ X / Msc
        B[3:6, fcol:fcol + 3] = -Jinv @ _skew(rh) @ Rl @ X
        B[3:6, tcol:tcol + 3] = -Jinv @ Rl @ X
        K[0:3, xs] = -(m / Msc) * Rl @ kx
        K[3:6, xs] = -(m * Jinv @ _skew(rh) @ Rl @ kx)
        K[3:6, es] = -(Itm * Jinv @ Rl @ kr)
        # the reactions on the spacecraft move both housings: x_k'' contains -F_sc/M (k = 1, 2)
        other = 1 - l
        ox = slice(_IX[other], _IX[other] + 3)
        B[ox, fcol:fcol + 3] = R[other].T @ Rl @ X / Msc
        for k in range(2):
            ks = slice(_IX[k], _IX[k] + 3)
            K[ks, xs] += (m / Msc) * R[k].T @ Rl @ kx
        # --- TM rotation, in OA_l: eta'' = tau/I - R^T(phi'' + dth'' Z) - [Wt x](eta' + R^T(phi' + dth' Z))
        #                                  - [Wt' x](eta + R^T(phi + dth Z)) - kr eta
        Wt = Rl.T @ (wp.omega + np.array([0.0, 0.0, (1 if l == 0 else -1) * half]))
        Sw, Swd = _skew(Wt), _skew(wp.alpha_suspension[l])
        M[es, 3:6] = Rl.T
        zm = Z if p.mosa else np.zeros(3)                      # the housing turns with its MOSA (if any)
        M[es, th] = Rl.T @ zm
        D[es, es] = Sw
        D[es, 3:6] = Sw @ Rl.T
        D[es, th] = Sw @ Rl.T @ zm
        K[es, es] = Swd + kr
        K[es, 3:6] = Swd @ Rl.T
        K[es, th] = Swd @ Rl.T @ zm
        B[es, tcol:tcol + 3] = X / Itm
        B[es, bcol:bcol + 3] = np.eye(3)
        # --- MOSA: Im (Z . (phi'' + W' phi + W phi') + dth'') + k dth = tau  (reaction -tau Z on the spacecraft)
        M[th, 3:6] = Z
        D[th, 3:6] = Z @ W
        K[th, 3:6] = Z @ Wd
        K[th, th] = p.mosa_stiffness / Im
        B[th, col[f"tm[{l}]"]] = 1.0 / Im
        B[3:6, col[f"tm[{l}]"]] = -Jinv @ Z

    def placeholders(self) -> None:
        """Absent coordinates (:class:`PlantParameters`: TM 2 of a single-TM spacecraft, the MOSA angles of
        fixed housings): decoupled, unexcited, damped (q'' + q' + q = 0)."""
        idx = []
        if self.p.n_tm == 1:
            idx += list(range(_IX[1], _IX[1] + 3)) + list(range(_IETA[1], _IETA[1] + 3)) + [_ITH + 1]
        if not self.p.mosa:
            idx += [_ITH + l for l in range(self.p.n_tm)]
            for l in range(2):                              # no MOSA actuator: its torque reaches nothing
                self.B[:, self.col[f"tm[{l}]"]] = 0.0
        for i in idx:
            for m in (self.M, self.D, self.K, self.B):
                m[i, :] = 0.0
            for m in (self.M, self.D, self.K):
                m[:, i] = 0.0
            self.M[i, i] = self.D[i, i] = self.K[i, i] = 1.0

    def outputs(self, A, Bs) -> tuple[list, list, list]:
        """(C blocks, D blocks, names) of the outputs: q, the TMs' non-gravitational accelerations (OA_l)
        and the relative accelerations x_l'', of the state space (``A``, ``Bs``)."""
        p, wp, R, X, n = self.p, self.wp, self.R, self.X, self.M.shape[0]
        C = [np.hstack([np.eye(n), np.zeros((n, n))])]
        Dm = [np.zeros((n, self.B.shape[1]))]
        outs = dof_names()
        for l in range(2):
            xs = slice(_IX[l], _IX[l] + 3)
            Cacc = np.zeros((3, 2 * n))
            Cacc[:, xs] = -np.diag(p.stiffness[l])
            Dacc = np.zeros((3, self.B.shape[1]))
            fcol, acol = self.col[f"f{l + 1}[0]"], self.col[f"a{l + 1}[0]"]
            Dacc[:, fcol:fcol + 3] = X / p.tm_mass
            Dacc[:, acol:acol + 3] = np.eye(3)
            # the body-fixed DC forces (suspension + self-gravity) turn with the attitude, the suspension
            # also with the MOSA: (phi + dth Z) x F_dc, seen along the nominal (inertial) OA_l axes
            Rl = R[l]
            dc = Rl @ (np.asarray(wp.a_suspension[l]) + np.asarray(wp.self_gravity[l]))
            Cacc[:, 3:6] = -Rl.T @ _skew(dc)
            Cacc[:, _ITH + l] = -Rl.T @ _skew(Rl @ np.asarray(wp.a_suspension[l])) @ Z
            C.append(Cacc)
            Dm.append(Dacc)
            outs += [f"acc{l + 1}[{i}]" for i in range(3)]
        for l in range(2):
            xs = slice(n + _IX[l], n + _IX[l] + 3)
            C.append(A[xs, :])
            Dm.append(Bs[xs, :])
            outs += [f"xdd{l + 1}[{i}]" for i in range(3)]
        return C, Dm, outs


def linear_plant(p: PlantParameters, wp: WorkingPoint, name: str = "plant") -> control.StateSpace:
    """The linearised plant (module docstring) as a named python-control StateSpace (continuous)."""
    A, Bs, C, D, inputs, outs, states = plant_matrices(p, wp)
    return control.ss(A, Bs, C, D, inputs=inputs, outputs=outs, states=states, name=name)


def plant_matrices(p: PlantParameters, wp: WorkingPoint) -> tuple:
    """The linearised plant's (A (40, 40), B (40, 32), C (32, 40), D (32, 32), input names, output names,
    state names) of :func:`linear_plant`: A = [[0, I], [-M^-1 K, -M^-1 D]], B = [[0], [M^-1 B_q]] (the
    states [q, q'], SI)."""
    eq = _Equations(p, wp)
    eq.spacecraft()
    for l in range(p.n_tm):
        eq.test_mass(l)
    eq.placeholders()
    n = eq.M.shape[0]
    Minv = np.linalg.inv(eq.M)
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -Minv @ eq.K
    A[n:, n:] = -Minv @ eq.D
    Bs = np.vstack([np.zeros((n, eq.B.shape[1])), Minv @ eq.B])
    C, Dm, outs = eq.outputs(A, Bs)
    states = dof_names() + [f"d{s}" for s in dof_names()]
    return A, Bs, np.vstack(C), np.vstack(Dm), list(eq.inputs), outs, states
