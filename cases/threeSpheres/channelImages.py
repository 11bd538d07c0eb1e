"""The box effect of cases/threeSpheres as a point-force model: the flow of a point force F between two
no-slip walls at rest (y = 0 and y = H), periodic in x (L_x) and z (L_z) -- the simulation box --
minus the flow of the same force in unbounded fluid (the Stokeslet). That difference, the flow of
the images (the walls, the periodic copies and the mean flow the force drives through the periodic
channel), moves and turns the spheres; to first order in (a/L) it is what the box adds to the
velocities of the triangle: with F on sphere 1 alone,

    U_i(box) - U_i(unbounded) ~ u_img(x_i),    Omega_i(box) - Omega_i(unbounded) ~ (1/2) curl u_img(x_i)  (I1)

(Faxen's laws, Eq. R2 of farField.py, without their a^2/6 lap term, and without the images of the
stresslets of spheres 2 and 3: both of relative order (a/L)^2). For sphere 1 itself u_img(x_1) is the
regular part of the channel's Green's function at the force: for a point force midway between two
walls, h from each, it tends to Faxen's -1.004 a/h (in units of F/(6 pi eta a); Happel & Brenner
1965, section 7-4) as L_x, L_z -> infinity: -0.12554 against -0.1255 at h = 8 a
(tests/test_three_spheres.py).

The channel's Green's function, Fourier series in x and z (wave vector k, |k| = kappa, e = k/kappa,
t = e x y), each mode an ordinary differential equation in y (D = d/dy) solved exactly:

    u(x) = (1/(L_x L_z)) sum_k u_k(y) exp(i k . (x - x_0))                                         (C1)
    transverse:  (D^2 - kappa^2) u_t = -(F.t/eta) delta(y - y_0),         u_t = 0 at the walls      (C2)
    poloidal:    (D^2 - kappa^2)^2 v = (kappa^2/eta) F_y delta(y - y_0) + (i kappa/eta) F.e delta'(y - y_0),
                 v = Dv = 0 at the walls,   u_e = (i/kappa) D v   (continuity)                       (C3)
    k = 0:       eta D^2 u_0 = -F_h delta(y - y_0), u_0 = 0 at the walls  (the mean flow: a tent,
                 F_h y_< (H - y_>)/(eta H)), v_0 = 0                                               (C4)

(C3) follows from the momentum equations along e and y with the pressure eliminated; its solution is
(A + B y) e^{kappa y} + (C + D y) e^{-kappa y} on each side of y_0, continuous with its first
derivative there, the second and third derivatives jumping by the delta' and delta strengths
(an 8 x 8 system per mode, in a basis of exponentials bounded by 1). The series converge like
exp(-kappa |y - y_0|): they are summed up to kappa |y - y_0| = 40 (terms below 1e-15 of the first).
At the force's own height the self term is extrapolated from points above and below it
(u_img(y_0 +- d), d = 1 ... 2.5 a, even polynomial in d).
"""
from __future__ import annotations

import math

import numpy as np

ETA = 1.0
DECAY_CUTOFF = 40.0        # kappa |y - y0| at which the series stop
SELF_DISTANCES = (1.0, 1.5, 2.0, 2.5)
MODES_PER_CHUNK = 100000


def _basis(y: np.ndarray, kappa: np.ndarray, y0: float, H: float, upper: bool, n: int) -> np.ndarray:
    """The n-th y-derivative, divided by kappa^n, of the four basis functions of one side at heights y
    (modes M): (M, 4). Lower side: e^{k(y-y0)}, (y-y0) e^{k(y-y0)}, e^{-ky}, y e^{-ky}; upper side:
    e^{-k(y-y0)}, (y-y0) e^{-k(y-y0)}, e^{k(y-H)}, (y-H) e^{k(y-H)} (every one at most 1 where used)."""
    if upper:
        parts = ((-1.0, y0, y0), (1.0, H, H))
    else:
        parts = ((1.0, y0, y0), (-1.0, 0.0, 0.0))
    columns = []
    for sign, centre, origin in parts:
        s = sign * kappa
        e = np.exp(s * (y - origin))
        columns.append(sign ** n * e)                                        # (s/kappa)^n e
        columns.append((sign ** n * (y - centre) + n * sign ** (n - 1) / kappa) * e)   # d^n[(y-c) e]/kappa^n
    return np.stack(columns, axis=-1)


def _poloidal_coefficients(kappa: np.ndarray, y0: float, H: float, jump2: np.ndarray, jump3: np.ndarray) -> np.ndarray:
    """Coefficients (M, 8) of (C3): lower side 0-3, upper side 4-7, for the jumps [v''] = jump2 and
    [v'''] = jump3 at y0 (each (M,), complex)."""
    m = len(kappa)
    A = np.zeros((m, 8, 8))
    b = np.zeros((m, 8), dtype=complex)
    zero, top, mid = np.zeros(m), np.full(m, float(H)), np.full(m, float(y0))
    A[:, 0, 0:4] = _basis(zero, kappa, y0, H, False, 0)
    A[:, 1, 0:4] = _basis(zero, kappa, y0, H, False, 1)
    A[:, 2, 4:8] = _basis(top, kappa, y0, H, True, 0)
    A[:, 3, 4:8] = _basis(top, kappa, y0, H, True, 1)
    for n in range(4):
        A[:, 4 + n, 4:8] = _basis(mid, kappa, y0, H, True, n)
        A[:, 4 + n, 0:4] = -_basis(mid, kappa, y0, H, False, n)
    b[:, 6] = jump2 / kappa ** 2
    b[:, 7] = jump3 / kappa ** 3
    solution = np.linalg.solve(A, np.stack([b.real, b.imag], axis=-1))   # a real matrix, two right-hand sides
    return solution[:, :, 0] + 1j * solution[:, :, 1]


def _transverse(y: np.ndarray, kappa: np.ndarray, y0: float, H: float) -> tuple[np.ndarray, np.ndarray]:
    """g and dg/dy of the Dirichlet Green's function of -(D^2 - kappa^2): sinh(k y<) sinh(k (H - y>)) /
    (k sinh(k H)), written with decaying exponentials only."""
    low, high = np.minimum(y, y0), np.maximum(y, y0)
    a, b = low, H - high
    common = np.exp(kappa * (a + b - H)) / (2 * kappa * (1 - np.exp(-2 * kappa * H)))
    g = common * (1 - np.exp(-2 * kappa * a)) * (1 - np.exp(-2 * kappa * b))
    # d/dy: below y0 only a = y varies, above only b = H - y
    da = common * kappa * (1 + np.exp(-2 * kappa * a)) * (1 - np.exp(-2 * kappa * b))
    db = common * kappa * (1 - np.exp(-2 * kappa * a)) * (1 + np.exp(-2 * kappa * b))
    return g, np.where(y < y0, da, -db)


def _modes_sum(p: np.ndarray, x0: np.ndarray, f: np.ndarray, kx: np.ndarray, kz: np.ndarray, kappa: np.ndarray,
               y0: float, H: float, eta: float) -> tuple[np.ndarray, np.ndarray]:
    """Sum over the modes (kx, kz) of (C1) (without 1/(L_x L_z)) of the velocity and the vorticity at
    the points p: (n, 3) each."""
    ex, ez = kx / kappa, kz / kappa
    tx, tz = -ez, ex
    f_e = f[0] * ex + f[2] * ez
    f_t = f[0] * tx + f[2] * tz
    coefficients = _poloidal_coefficients(kappa, y0, H, 1j * kappa * f_e / eta, kappa ** 2 * f[1] / eta)
    velocity = np.zeros((len(p), 3))
    vorticity = np.zeros((len(p), 3))
    for n, point in enumerate(p):
        y = np.full(len(kappa), point[1])
        upper = point[1] > y0
        c = coefficients[:, 4:8] if upper else coefficients[:, 0:4]
        v, dv, d2v = [np.einsum("mj,mj->m", _basis(y, kappa, y0, H, upper, q), c) * kappa ** q for q in range(3)]
        u_e, du_e = 1j / kappa * dv, 1j / kappa * d2v
        g, dg = _transverse(y, kappa, y0, H)
        u_t, du_t = f_t / eta * g, f_t / eta * dg
        phase = np.exp(1j * (kx * (point[0] - x0[0]) + kz * (point[2] - x0[2])))
        ux, uz = ex * u_e + tx * u_t, ez * u_e + tz * u_t
        dux, duz = ex * du_e + tx * du_t, ez * du_e + tz * du_t
        velocity[n] = [np.real(np.sum(ux * phase)), np.real(np.sum(v * phase)), np.real(np.sum(uz * phase))]
        vorticity[n] = [np.real(np.sum((duz - 1j * kz * v) * phase)),
                        np.real(np.sum((1j * kz * ux - 1j * kx * uz) * phase)),
                        np.real(np.sum((1j * kx * v - dux) * phase))]
    return velocity, vorticity


def channel_flow(points: np.ndarray, x0: np.ndarray, force: np.ndarray, box: tuple[float, float, float],
                 eta: float = ETA) -> tuple[np.ndarray, np.ndarray]:
    """Velocity (n, 3) and vorticity (n, 3) at `points` (n, 3; none at the force's height y0) of the point
    force `force` at x0 in the channel `box` = (L_x, H, L_z) (walls y = 0, H; Eqs. C1-C4)."""
    Lx, H, Lz = (float(v) for v in box)
    p = np.atleast_2d(np.asarray(points, dtype=float))
    x0 = np.asarray(x0, dtype=float)
    f = np.asarray(force, dtype=float)
    y0 = float(x0[1])
    dy = np.abs(p[:, 1] - y0)
    if (dy < 1e-3).any() or not (0 < y0 < H) or ((p[:, 1] <= 0) | (p[:, 1] >= H)).any():
        raise ValueError("channel_flow: points must lie inside the channel, off the force's height y0 = %g" % y0)
    kappa_max = DECAY_CUTOFF / dy.min()
    nx, nz = int(math.ceil(kappa_max * Lx / (2 * math.pi))), int(math.ceil(kappa_max * Lz / (2 * math.pi)))
    ix, iz = np.meshgrid(np.arange(-nx, nx + 1), np.arange(-nz, nz + 1), indexing="ij")
    kx, kz = (2 * math.pi * ix / Lx).ravel(), (2 * math.pi * iz / Lz).ravel()
    kappa = np.hypot(kx, kz)
    keep = (kappa > 0) & (kappa <= kappa_max)
    kx, kz, kappa = kx[keep], kz[keep], kappa[keep]
    area = Lx * Lz
    velocity = np.zeros((len(p), 3))
    vorticity = np.zeros((len(p), 3))
    for start in range(0, len(kappa), MODES_PER_CHUNK):
        chunk = slice(start, start + MODES_PER_CHUNK)
        u_chunk, w_chunk = _modes_sum(p, x0, f, kx[chunk], kz[chunk], kappa[chunk], y0, H, eta)
        velocity += u_chunk / area
        vorticity += w_chunk / area
    for n, point in enumerate(p):
        # k = 0 (C4): the tent profile of the horizontal force, and its shear
        low, high = min(point[1], y0), max(point[1], y0)
        tent = low * (H - high) / (eta * H * area)
        slope = ((H - y0) if point[1] < y0 else -y0) / (eta * H * area)
        velocity[n, 0] += f[0] * tent
        velocity[n, 2] += f[2] * tent
        vorticity[n, 0] += f[2] * slope       # omega_x = d u_z / dy
        vorticity[n, 2] -= f[0] * slope       # omega_z = -d u_x / dy
    return velocity, vorticity


def stokeslet(points: np.ndarray, x0: np.ndarray, force: np.ndarray, eta: float = ETA) -> tuple[np.ndarray,
                                                                                                   np.ndarray]:
    """Velocity and vorticity (n, 3) of the point force in unbounded fluid: G . F (Eq. R1 of farField.py
    without its a^2 term) and F x y / (4 pi eta |y|^3)."""
    y = np.atleast_2d(np.asarray(points, dtype=float)) - np.asarray(x0, dtype=float)
    f = np.asarray(force, dtype=float)
    r = np.linalg.norm(y, axis=1)[:, None]
    velocity = (f / r + y * (y @ f)[:, None] / r ** 3) / (8 * math.pi * eta)
    vorticity = np.cross(f, y) / (4 * math.pi * eta * r ** 3)
    return velocity, vorticity


def image_flow(points: np.ndarray, x0: np.ndarray, force: np.ndarray, box: tuple[float, float, float]) -> tuple[
        np.ndarray, np.ndarray]:
    """The images' velocity and angular velocity (half the vorticity) at `points`: channel minus
    Stokeslet (Eq. I1)."""
    u_box, w_box = channel_flow(points, x0, force, box)
    u_free, w_free = stokeslet(points, x0, force)
    return u_box - u_free, 0.5 * (w_box - w_free)


def self_image(x0: np.ndarray, force: np.ndarray, box: tuple[float, float, float],
               distances: tuple[float, ...] = SELF_DISTANCES) -> np.ndarray:
    """The images' velocity at the force itself (the regular part of the channel's Green's function),
    extrapolated from the mean of u_img(x0 +- d e_y) over `distances` d by a polynomial in d^2."""
    x0 = np.asarray(x0, dtype=float)
    d = np.asarray(distances, dtype=float)
    points = np.concatenate([x0 + np.outer(d, [0, 1, 0]), x0 - np.outer(d, [0, 1, 0])])
    u, _ = image_flow(points, x0, force, box)
    even = 0.5 * (u[:len(d)] + u[len(d):])
    fit = np.polynomial.polynomial.polyfit(d ** 2, even, len(d) - 2)
    return fit[0]


def triangle_box_effect(positions: np.ndarray, box: tuple[float, float, float],
                        force_on_first: float = 6 * math.pi) -> dict:
    """What the box adds (Eq. I1) to the paper's 5.5 quantities of the triangle at `positions` (rows:
    spheres 1, 2, 3, in the box's coordinates), force force_on_first along +x on sphere 1, in units of
    F/(6 pi eta a) and F/(6 pi eta a^2) (a = 1): U1x, U23x, dU, and the signed changes of U23y and W23z
    (positive: the box increases the magnitude, taken as outward for 2 and 3's y velocity and with the
    sign of sphere 2's unbounded rotation, +z)."""
    x = np.asarray(positions, dtype=float)
    force = np.array([force_on_first, 0.0, 0.0])
    unit = force_on_first / (6 * math.pi * ETA)
    u_self = self_image(x[0], force, box) / unit
    u, w = image_flow(x[1:], x[0], force, box)
    u, w = u / unit, w / unit
    u23x = 0.5 * (u[0, 0] + u[1, 0])
    return dict(U1x=float(u_self[0]), U23x=float(u23x), dU=float(u_self[0] - u23x),
                U23y=float(0.5 * (u[0, 1] - u[1, 1])), W23z=float(0.5 * (w[0, 2] - w[1, 2])))
