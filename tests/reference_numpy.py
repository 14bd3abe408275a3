"""An independent numpy/scipy implementation of the wobblestone model, written from MODEL.md alone.

It shares no code with jaxcelt and deliberately takes different routes where the model allows:

* complete elliptic integrals from ``scipy.special.ellipk/ellipe`` (parameter m = e^2);
* the body->global rotation R built from explicit Euler angles (Z-X-Y sequence,
  R = Rz(psi) Rx(theta) Ry(phi), n = third row of R = (-sin phi cos theta, sin theta,
  cos phi cos theta); MODEL.md section 4) instead of the (u, w) construction;
* psi_dot solved from the angular-velocity map of the Euler angles (a 3x3 linear solve),
  not the closed form of eq. (6);
* r_dot (eq. 4) by the complex-step derivative of r(n) along n_dot (exact to rounding);
* the normal force N by solving d/dt (v_A . n) = -kappa (v_A . n) directly: the constraint
  rate is affine in N because every contact load is proportional to N, so it is evaluated
  at N = 0 and N = 1 from the Newton-Euler accelerations (not the closed-form quotient of
  MODEL.md section 8).

Parameters are a plain ``dict`` of floats with the same names as ``jaxcelt.CeltParams``
(``paper_params()`` gives section 3 of the paper). State y = (v, omega, n, r_C, psi) (13,).
"""

from __future__ import annotations

import numpy as np
from scipy.special import ellipe, ellipk

PAPER = dict(
    a1=0.110,
    a2=0.025,
    a3=0.025,
    m=0.5436,
    B1=2.463e-4,
    B2=1.3589e-3,
    B3=1.3747e-3,
    B12=1.728e-4,
    B13=0.0,
    B23=0.0,
    k1=0.0,
    k2=0.0,
    k3=-4.29e-3,
    g=9.81,
    a_hat=6.192e-3,
    b=0.1813,
    mu=0.2241,
    k_r=0.4345,
    b_r=1.196,
    S0=0.1498,
    S2=0.1121,
    S3=0.0589,
    b_Ts=0.5305,
    b_Ms=0.2476,
    m_Ts=0.8161,
    m_Ms=0.5366,
    eps=1e-4,
    eps_R=1e-4,
    q_pi=0.04,
    omega_pi=17.0,
    kappa=0.0,
    v_pi_sign=1.0,
    derivative_exact=0.0,
)


def paper_params(**overrides) -> dict:
    p = dict(PAPER)
    unknown = set(overrides) - set(p)
    assert not unknown, unknown
    p.update({k: float(v) for k, v in overrides.items()})
    return p


def elliptic_constants(b: float) -> tuple[float, float, float, float]:
    """K(e), E(e), G = (K - E)/e^2, H = (E + (e^2 - 1) K)/e^2 with e^2 = 1 - b^2 (MODEL.md section 2)."""
    m = 1.0 - b * b
    K, E = float(ellipk(m)), float(ellipe(m))
    return K, E, (K - E) / m, (E + (m - 1.0) * K) / m


def inertia(p: dict) -> np.ndarray:
    return np.array(
        [
            [p["B1"], -p["B12"], -p["B13"]],
            [-p["B12"], p["B2"], -p["B23"]],
            [-p["B13"], -p["B23"], p["B3"]],
        ]
    )


def contact_point(n, p: dict):
    """r = O -> A = -A n / sqrt(n^T A n) (eq. 4). Works for complex n (complex step)."""
    A = np.array([p["a1"] ** 2, p["a2"] ** 2, p["a3"] ** 2])
    return -A * n / np.sqrt(np.sum(n * A * n))


def contact_point_rate(n: np.ndarray, n_dot: np.ndarray, p: dict) -> np.ndarray:
    """d r / dt along n_dot, by the complex-step derivative (no subtraction, exact to rounding)."""
    h = 1e-30
    return np.imag(contact_point(n + 1j * h * n_dot, p)) / h


def rotation(n: np.ndarray, psi: float) -> np.ndarray:
    """Body -> global rotation R = Rz(psi) Rx(theta) Ry(phi) from n and psi (rows E1, E2, E3 = n)."""
    theta = np.arcsin(np.clip(n[1], -1.0, 1.0))
    phi = np.arctan2(-n[0], n[2])
    c, s = np.cos, np.sin
    Rz = np.array([[c(psi), -s(psi), 0.0], [s(psi), c(psi), 0.0], [0.0, 0.0, 1.0]])
    Rx = np.array([[1.0, 0.0, 0.0], [0.0, c(theta), -s(theta)], [0.0, s(theta), c(theta)]])
    Ry = np.array([[c(phi), 0.0, s(phi)], [0.0, 1.0, 0.0], [-s(phi), 0.0, c(phi)]])
    return Rz @ Rx @ Ry


def psi_rate(n: np.ndarray, omega: np.ndarray) -> float:
    """psi_dot from omega = Ry^T Rx^T (0,0,psi_dot) + Ry^T (theta_dot,0,0) + (0,phi_dot,0) (body comps)."""
    theta = np.arcsin(np.clip(n[1], -1.0, 1.0))
    phi = np.arctan2(-n[0], n[2])
    c, s = np.cos, np.sin
    Rx = np.array([[1.0, 0.0, 0.0], [0.0, c(theta), -s(theta)], [0.0, s(theta), c(theta)]])
    Ry = np.array([[c(phi), 0.0, s(phi)], [0.0, 1.0, 0.0], [-s(phi), 0.0, c(phi)]])
    M = np.column_stack([Ry.T @ Rx.T @ np.array([0.0, 0.0, 1.0]), Ry.T @ np.array([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]])
    return float(np.linalg.solve(M, omega)[0])


def patch_axes(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """e_x = normalised projection of body x1 on the base plane; e_y = n x e_x (MODEL.md section 5)."""
    ex = np.array([1.0, 0.0, 0.0]) - n[0] * n
    ex = ex / np.linalg.norm(ex)
    return ex, np.cross(n, ex)


def friction(vsx, vsy, ws, d_c, d_s, p: dict) -> tuple[float, float, float]:
    """Generalised Pade approximant (eq. 13, 15), printed grouping or derivative-exact (A13a)."""
    _, E, G, H = elliptic_constants(p["b"])
    b, S0, S2, S3, bT, bM, mT, mM = (p[k] for k in ("b", "S0", "S2", "S3", "b_Ts", "b_Ms", "m_Ts", "m_Ms"))
    V = np.sqrt(vsx * vsx + vsy * vsy + p["eps"])
    aw = abs(ws)
    DT = (V ** (3 * mT) + bT**mT * aw ** (3 * mT)) ** (1.0 / mT)
    DM = (bM**mM * aw ** (3 * mM) + V ** (3 * mM)) ** (1.0 / mM)
    pi = np.pi
    if p["derivative_exact"]:
        nx = V**2 * vsx + ws * (
            bT * (4 * G * S0 * vsx * ws - 4 * G * S2 * b * d_s * ws**2) - pi * S3 * (b * d_s * vsy**2 + d_c * vsx * vsy)
        )
        ny = V**2 * vsy + ws * (
            bT * (4 * H * S0 * vsy * ws + 4 * H * S2 * d_c * ws**2) + pi * S3 * (d_c * vsx**2 + b * d_s * vsx * vsy)
        )
    else:
        nx = V**2 * vsx + ws * (
            bT * (4 * G * S0 * vsx * ws - b * d_s * (pi * S3 * vsy**2 + 4 * G * S2 * ws**2)) - pi * S3 * d_c * vsx * vsy
        )
        ny = V**2 * vsy + ws * (
            bT * (4 * H * S0 * vsy * ws + d_c * (pi * S3 * vsx**2 + 4 * H * S2 * ws**2)) + pi * b * S3 * d_s * vsx * vsy
        )
    nm = 4 * bM * E * S2 * ws**3 + pi * S3 * ((vsx**2 + b**2 * vsy**2) * ws + V**2 * (d_c * vsy - b * d_s * vsx))
    return nx / DT, ny / DT, nm / DM


def contact_quantities(t: float, y: np.ndarray, p: dict) -> dict:
    """Everything of MODEL.md sections 3-7 at one state: slip, spin, distortion, loads per unit N."""
    y = np.asarray(y, dtype=float)
    v, w, n, psi = y[0:3], y[3:6], y[6:9], y[12]
    k = np.array([p["k1"], p["k2"], p["k3"]])
    r = contact_point(n, p)
    rho = r - k
    n_dot = -np.cross(w, n)
    r_dot = contact_point_rate(n, n_dot, p)
    R = rotation(n, psi)
    E1 = R[0]
    v_pi = p["v_pi_sign"] * p["q_pi"] * p["omega_pi"] * np.sin(p["omega_pi"] * t) * E1
    v_A = v + np.cross(w, rho)
    ex, ey = patch_axes(n)
    ah = p["a_hat"]
    vs = (v_A - v_pi) / ah
    vr = vs + r_dot / ah
    vsx, vsy, ws = vs @ ex, vs @ ey, w @ n
    vrx, vry = vr @ ex, vr @ ey
    b = p["b"]
    DR = np.sqrt(vrx**2 + vry**2 / (b * p["b_r"]) ** 2 + p["eps_R"])
    d_c, d_s = p["k_r"] * vrx / DR, p["k_r"] * vry / (b * DR)
    Tx, Ty, Ms = friction(vsx, vsy, ws, d_c, d_s, p)
    t_N = -p["mu"] * (Tx * ex + Ty * ey)
    ms_N = -p["mu"] * ah * Ms * n
    mr_N = ah * np.pi * p["S3"] * (b * d_s * ex - d_c * ey)
    return dict(
        r=r, rho=rho, n_dot=n_dot, r_dot=r_dot, R=R, v_A=v_A, v_pi=v_pi, e_x=ex, e_y=ey,
        v_sx=vsx, v_sy=vsy, omega_s=ws, v_rx=vrx, v_ry=vry, d_c=d_c, d_s=d_s,
        T_sx=Tx, T_sy=Ty, M_s=Ms, t_N=t_N, ms_N=ms_N, mr_N=mr_N,
    )  # fmt: skip


def _accelerations(N: float, y: np.ndarray, c: dict, p: dict):
    v, w = y[0:3], y[3:6]
    n = y[6:9]
    B = inertia(p)
    F = N * (n + c["t_N"])
    v_dot = -np.cross(w, v) - p["g"] * n + F / p["m"]
    torque = np.cross(c["rho"], F) + N * (c["ms_N"] + c["mr_N"])
    w_dot = np.linalg.solve(B, torque - np.cross(w, B @ w))
    return v_dot, w_dot


def _constraint_rate(N, y, c, p):
    """d/dt (v_A . n) in body components: (v_dot + w_dot x rho + w x r_dot) . n + v_A . n_dot."""
    n = y[6:9]
    w = y[3:6]
    v_dot, w_dot = _accelerations(N, y, c, p)
    return (v_dot + np.cross(w_dot, c["rho"]) + np.cross(w, c["r_dot"])) @ n + c["v_A"] @ c["n_dot"]


def normal_force(t: float, y: np.ndarray, p: dict, c: dict | None = None) -> float:
    """N such that d/dt(v_A . n) = -kappa v_A . n (affine in N: two evaluations, one division)."""
    c = contact_quantities(t, y, p) if c is None else c
    f0 = _constraint_rate(0.0, y, c, p)
    f1 = _constraint_rate(1.0, y, c, p)
    target = -p["kappa"] * (c["v_A"] @ y[6:9])
    return (target - f0) / (f1 - f0)


def rhs(t: float, y: np.ndarray, p: dict) -> np.ndarray:
    """dy/dt (13,) of MODEL.md section 8."""
    y = np.asarray(y, dtype=float)
    c = contact_quantities(t, y, p)
    N = normal_force(t, y, p, c)
    v_dot, w_dot = _accelerations(N, y, c, p)
    rC_dot = c["R"] @ y[0:3]
    return np.concatenate([v_dot, w_dot, c["n_dot"], rC_dot, [psi_rate(y[6:9], y[3:6])]])


def initial_state(p: dict, omega=(0.0, 0.0, 0.0), n=(0.0, 0.0, 1.0), psi=0.0, v_A=(0.0, 0.0, 0.0), position=(0.0, 0.0)):
    """State on the manifold: v = v_A - omega x rho, r_C = R(-rho) + (x, y, 0)."""
    w = np.asarray(omega, float)
    n = np.asarray(n, float)
    n = n / np.linalg.norm(n)
    vA = np.asarray(v_A, float)
    vA = vA - (vA @ n) * n
    rho = contact_point(n, p) - np.array([p["k1"], p["k2"], p["k3"]])
    v = vA - np.cross(w, rho)
    r_C = rotation(n, psi) @ (-rho) + np.array([position[0], position[1], 0.0])
    return np.concatenate([v, w, n, r_C, [psi]])


def energy(y: np.ndarray, p: dict) -> float:
    """1/2 m |v|^2 + 1/2 w^T B w + m g (k - r) . n (MODEL.md section 10)."""
    v, w, n = y[0:3], y[3:6], y[6:9]
    rho = contact_point(n, p) - np.array([p["k1"], p["k2"], p["k3"]])
    return 0.5 * p["m"] * v @ v + 0.5 * w @ inertia(p) @ w - p["m"] * p["g"] * (rho @ n)


def solve(p: dict, y0: np.ndarray, t_eval: np.ndarray, rtol: float = 1e-12, atol: float = 1e-14):
    """scipy solve_ivp(DOP853) of `rhs`."""
    from scipy.integrate import solve_ivp

    return solve_ivp(
        lambda t, y: rhs(t, y, p), (0.0, float(t_eval[-1])), y0, method="DOP853", t_eval=t_eval, rtol=rtol, atol=atol
    )


# Aliases used by some tests (same names, same meaning).
paper = paper_params


def pieces(t: float, y: np.ndarray, p: dict) -> dict:
    """Short-named contact quantities: vsx, vsy, ws, dc, ds, Tsx, Tsy, Ms (+ everything of contact_quantities)."""
    c = contact_quantities(t, y, p)
    short = dict(vsx="v_sx", vsy="v_sy", ws="omega_s", dc="d_c", ds="d_s", Tsx="T_sx", Tsy="T_sy", Ms="M_s")
    return {**c, **{k: c[v] for k, v in short.items()}}
