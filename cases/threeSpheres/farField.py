"""Velocities of equal rigid spheres in unbounded Stokes flow, far apart: the independent reference of
cases/threeSpheres at large r (paper 5.5 compares with Wilson 2013, whose tables the project does not
have). numpy, and the project's two-sphere resistance functions for the exact pair part.

Units: radius a = 1, viscosity eta = 1; forces are given in units of 6 pi eta a, so that a velocity
comes out in units of F/(6 pi eta a) and an angular velocity in F/(6 pi eta a^2). The spheres carry
the given forces and no torque (the others are force- and torque-free): a mobility problem, no
inversion.

**Method of reflections** (Happel & Brenner 1965 ch. 6; Kim & Karrila 1991 ch. 8), rho = r/a the
smallest centre distance:

  0. a sphere with force F_j in quiescent fluid moves at F_j/(6 pi eta a) and makes the exact flow
         u_j(x) = (1 + (a^2/6) lap) G(x - x_j) . F_j,   G(y) = (I/|y| + y y/|y|^3) / (8 pi eta)     (R1)
     (Stokeslet plus degenerate quadrupole);
  1. every other sphere i moves in that flow by Faxen's laws,
         U_i = (1 + (a^2/6) lap) u(x_i),   Omega_i = (1/2) curl u(x_i)                            (R2)
     -- the Rotne-Prager-Yamakawa tensor, 3/(4 rho)(I + d d) + 1/(2 rho^3)(I - 3 d d) in these units,
     and Omega_i = F_j x (x_i - x_j) / (8 pi eta |x_i - x_j|^3) (the degenerate quadrupole is
     irrotational) -- and, rigid in a straining flow, it exerts the stresslet
         S_i = (20/3) pi eta a^3 E(x_i),   E = (grad u + grad u^T)/2                              (R3)
     (O(rho^-2); every sphere, the forced ones too, feels the flow of the others);
  2. the stresslet field  u_S(y) = -(3/(8 pi eta)) y (y . S . y)/|y|^5                            (R4)
     of each sphere moves the others (U += u_S, O(rho^-4)) and turns them
         Omega += (1/2) curl u_S = (3/(8 pi eta)) y x (S . y)/|y|^5     (O(rho^-5)).               (R5)
     This holds the two-body term of x^a_11 (-15/4 rho^-4) and the leading three-body terms (the
     force on 1 strains sphere 3, whose stresslet moves sphere 2: O(rho^-4); turns it: O(rho^-5)).

Left out: the Faxen correction (a^2/10) lap E of the stresslet and the a^5 part of the stresslet
field (O(rho^-6) in U), the quadrupoles a sphere makes in the curvature of the flow (O(rho^-6) in U,
O(rho^-7) in Omega), the third reflection (O(rho^-7) in U, O(rho^-8) in Omega) -- and in the
two-body functions the O(rho^-7) terms of x^a_12 (75/4 rho^-7) and y^a_12. So `reflection_velocities`
is exact to O(rho^-5) in U (error O(rho^-6)) and to O(rho^-6) in Omega (error O(rho^-7)).
Measured against the exact two-sphere mobility (two_sphere_mobility, Jeffrey & Onishi's full-range
functions of the project's resistance library, `fdmResistance pair --theory --full`): at rho = 4
the largest error is 1.1e-3 (U_2 along the line of centres: the 75/4 rho^-7 term of x^a_12), the
self term along the line 5.0e-4, the transverse ones 2.8e-4, Omega 6.6e-5; at rho = 6: 6.6e-5,
4.2e-5, 2.4e-5, 2.8e-6 (tests/test_three_spheres.py::test_reflections_against_two_sphere_theory).

**Exact pairs** (`method="pairs+reflections"`, the default of `three_spheres`): the two-body part of
the reflections replaced by the exact two-sphere mobility of each pair,
    U = U_refl(3 spheres) + sum over pairs (i, j) [U_exact(i, j) - U_refl(i, j)]                 (R6)
(only the pairs with a force contribute), so what is left is the three-body truncation: the terms
beyond the leading three-body ones, O(rho^-6) in U and O(rho^-7) in Omega, each a three-body term a
factor of order (a/r)^2 smaller than the leading one kept. `three_spheres` reports the size of that
leading three-body term (`three_body`), whose (a/r)^2 fraction is the error estimate.
"""
from __future__ import annotations

import functools
import math
import os

import numpy as np

ETA = 1.0
RADIUS = 1.0
METHODS = ("reflections", "pairs+reflections")


def triangle_positions(side: float, centroid=(0.0, 0.0, 0.0)) -> np.ndarray:
    """The centres of the paper's Fig. 19 triangle of side `side` in the (x, y) plane: sphere 1 on the
    -x side of the centroid (pushed along +x, toward the centroid), spheres 2 and 3 mirror images
    about the x axis through sphere 1 (2 at +y). Rows: spheres 1, 2, 3."""
    c = np.asarray(centroid, dtype=float)
    circumradius = side / math.sqrt(3.0)   # centroid to vertex of an equilateral triangle
    return c + np.array([[-circumradius, 0.0, 0.0],
                         [0.5 * circumradius, 0.5 * side, 0.0],
                         [0.5 * circumradius, -0.5 * side, 0.0]])


def _oseen(y: np.ndarray) -> np.ndarray:
    """G(y) of Eq. (R1), (3, 3)."""
    r = np.linalg.norm(y)
    return (np.eye(3) / r + np.outer(y, y) / r ** 3) / (8 * math.pi * ETA)


def _oseen_laplacian(y: np.ndarray) -> np.ndarray:
    """lap G(y) = (I/|y|^3 - 3 y y/|y|^5) / (4 pi eta), (3, 3)."""
    r = np.linalg.norm(y)
    return (np.eye(3) / r ** 3 - 3 * np.outer(y, y) / r ** 5) / (4 * math.pi * ETA)


def _forced_flow_gradient(y: np.ndarray, force: np.ndarray) -> np.ndarray:
    """grad u of Eq. (R1) at y from the sphere's centre: g[i, k] = d u_i / d y_k, (3, 3)."""
    r = np.linalg.norm(y)
    d = np.eye(3)
    sym = np.einsum("ij,k->ijk", d, y)
    transposed = np.einsum("ik,j->ijk", d, y) + np.einsum("jk,i->ijk", d, y)
    yyy = np.einsum("i,j,k->ijk", y, y, y)
    d_oseen = ((-sym + transposed) / r ** 3 - 3 * yyy / r ** 5) / (8 * math.pi * ETA)
    d_laplacian = (-3 * (sym + transposed) / r ** 5 + 15 * yyy / r ** 7) / (4 * math.pi * ETA)
    return np.einsum("ijk,j->ik", d_oseen + RADIUS ** 2 / 6 * d_laplacian, force)


def reflection_velocities(positions: np.ndarray, forces: np.ndarray, reflections: int = 2) -> tuple[np.ndarray,
                                                                                                     np.ndarray]:
    """Velocities (N, 3) and angular velocities (N, 3) of N equal spheres (radius 1) at `positions`
    (N, 3) carrying `forces` (N, 3, in units of 6 pi eta a) and no torque, in unbounded fluid, by the
    reflections (R1)-(R5) of the module docstring: reflections = 1 stops after (R2) (Rotne-Prager-
    Yamakawa and the Stokeslet's rotation: error O(rho^-4) in U, O(rho^-5) in Omega), 2 adds the
    induced stresslets (R3)-(R5) (error O(rho^-6) in U, O(rho^-7) in Omega)."""
    x = np.asarray(positions, dtype=float)
    f = np.asarray(forces, dtype=float) * 6 * math.pi * ETA * RADIUS
    n = len(x)
    if x.shape != (n, 3) or f.shape != (n, 3):
        raise ValueError("reflection_velocities: positions and forces must both be (N, 3)")
    if reflections not in (1, 2):
        raise ValueError("reflection_velocities: reflections must be 1 or 2, got %r" % (reflections,))
    for i in range(n):
        for j in range(i):
            if np.linalg.norm(x[i] - x[j]) <= 2 * RADIUS:
                raise ValueError("reflection_velocities: spheres %d and %d overlap or touch" % (j + 1, i + 1))
    velocity = f / (6 * math.pi * ETA * RADIUS)
    omega = np.zeros((n, 3))
    stresslets = np.zeros((n, 3, 3))
    for i in range(n):
        for j in range(n):
            if i == j or not f[j].any():
                continue
            y = x[i] - x[j]
            # (R2): Faxen of (R1), (1 + a^2/6 lap)(1 + a^2/6 lap) G = G + (a^2/3) lap G (lap lap G = 0)
            velocity[i] += (_oseen(y) + RADIUS ** 2 / 3 * _oseen_laplacian(y)) @ f[j]
            omega[i] += np.cross(f[j], y) / (8 * math.pi * ETA * np.linalg.norm(y) ** 3)
            gradient = _forced_flow_gradient(y, f[j])
            stresslets[i] += 20.0 / 3.0 * math.pi * ETA * RADIUS ** 3 * 0.5 * (gradient + gradient.T)   # (R3)
    if reflections == 2:
        for i in range(n):
            for j in range(n):
                if i == j:
                    continue
                y = x[i] - x[j]
                r = np.linalg.norm(y)
                s_y = stresslets[j] @ y
                velocity[i] += -3.0 / (8 * math.pi * ETA) * y * (y @ s_y) / r ** 5                       # (R4)
                omega[i] += 3.0 / (8 * math.pi * ETA) * np.cross(y, s_y) / r ** 5                       # (R5)
    return velocity, omega


@functools.lru_cache(maxsize=64)
def _pair_functions(xi: float) -> dict:
    """The full-range X^A, Y^A, Y^B, X^C, Y^C of two equal spheres at reduced gap xi (dimensional /
    eta, a = 1), from the project's resistance library."""
    from fdmsubgrid import theory
    return theory.pair_full_range(1.0, 1.0, xi)


def two_sphere_mobility(x1, x2) -> np.ndarray:
    """The exact velocities of two equal spheres (radius 1, no torques) at x1, x2 in unbounded fluid
    per unit force: a (12, 6) matrix, rows (U1, Omega1, U2, Omega2) in units of F/(6 pi eta a) and
    F/(6 pi eta a^2), columns the force (x, y, z) on sphere 1 then on sphere 2: columns of the inverse
    of the two-sphere resistance matrix, built as dem/resistance/src/blocks.cpp builds it (Eq. A.1,
    B-tilde = -Y^B_ba of Eq. A.3) from the full-range functions of Jeffrey & Onishi (1984)."""
    dx = np.asarray(x2, dtype=float) - np.asarray(x1, dtype=float)
    r = float(np.linalg.norm(dx))
    if r <= 2 * RADIUS:
        raise ValueError("two_sphere_mobility: the spheres overlap or touch (r = %g)" % r)
    d = dx / r
    f = _pair_functions(round(r / RADIUS - 2.0, 15))
    dd = np.outer(d, d)
    cross = np.array([[0, d[2], -d[1]], [-d[2], 0, d[0]], [d[1], -d[0], 0]])   # eps_ijk d_k
    transverse = np.eye(3) - dd
    R = np.zeros((12, 12))
    for a in range(2):
        for b in range(2):
            ab, ba = "%d%d" % (a + 1, b + 1), "%d%d" % (b + 1, a + 1)
            rf, rt, cu, co = 6 * a, 6 * a + 3, 6 * b, 6 * b + 3
            R[rf:rf + 3, cu:cu + 3] = f["XA" + ab] * dd + f["YA" + ab] * transverse
            R[rf:rf + 3, co:co + 3] = -f["YB" + ba] * cross
            R[rt:rt + 3, cu:cu + 3] = f["YB" + ab] * cross
            R[rt:rt + 3, co:co + 3] = f["XC" + ab] * dd + f["YC" + ab] * transverse
    # U = R^-1 F (external force = R U); per unit F/(6 pi eta a), a = 1: 6 pi eta R^-1
    return 6 * math.pi * ETA * RADIUS * np.linalg.inv(ETA * R)[:, [0, 1, 2, 6, 7, 8]]


def velocities(positions: np.ndarray, forces: np.ndarray, method: str = "pairs+reflections") -> tuple[np.ndarray,
                                                                                                     np.ndarray]:
    """Velocities and angular velocities (N, 3) as reflection_velocities, with method
    "pairs+reflections" the two-body part made exact (Eq. R6)."""
    if method not in METHODS:
        raise ValueError("velocities: method must be one of %s, got %r" % (", ".join(METHODS), method))
    x = np.asarray(positions, dtype=float)
    f = np.asarray(forces, dtype=float)
    u, w = reflection_velocities(x, f)
    if method == "reflections":
        return u, w
    for i in range(len(x)):
        for j in range(i + 1, len(x)):
            pair_forces = f[[i, j]]
            if not pair_forces.any():
                continue
            exact = two_sphere_mobility(x[i], x[j]) @ pair_forces.reshape(6)
            u_pair, w_pair = reflection_velocities(x[[i, j]], pair_forces)
            u[[i, j]] += exact.reshape(2, 2, 3)[:, 0] - u_pair
            w[[i, j]] += exact.reshape(2, 2, 3)[:, 1] - w_pair
    return u, w


def summary(u: np.ndarray, w: np.ndarray) -> dict:
    """The paper's 5.5 quantities of the triangle from its velocities (3, 3) and angular velocities:
    U1x, U23x (mean of spheres 2 and 3), dU = U1x - U23x, U23y (mean |U_y| of 2 and 3), W23z (mean
    |Omega_z| of 2 and 3)."""
    u23x = 0.5 * (u[1, 0] + u[2, 0])
    return dict(U1x=float(u[0, 0]), U23x=float(u23x), dU=float(u[0, 0] - u23x),
                U23y=float(0.5 * (abs(u[1, 1]) + abs(u[2, 1]))), W23z=float(0.5 * (abs(w[1, 2]) + abs(w[2, 2]))))


def three_spheres(side: float, method: str = "pairs+reflections") -> dict:
    """The paper's 5.5 quantities (summary) in unbounded fluid for the triangle of side `side` (in a),
    force F e_x on sphere 1, by `method`; with `three_body`, the same quantities' leading three-body
    part (the second reflection's terms through the third sphere: the error estimate of the docstring
    is (a/r)^2 times it), and the velocities."""
    x = triangle_positions(side)
    forces = np.zeros((3, 3))
    forces[0, 0] = 1.0
    u, w = velocities(x, forces, method)
    # the three-body part of the second reflection: all three spheres minus the pairs with sphere 1
    u3, w3 = reflection_velocities(x, forces)
    u_pairs, w_pairs = np.zeros((3, 3)), np.zeros((3, 3))
    for j in (1, 2):
        up, wp = reflection_velocities(x[[0, j]], forces[[0, j]])
        u_pairs[[0, j]] += up
        w_pairs[[0, j]] += wp
    u_pairs[0] -= forces[0]                       # the isolated sphere 1, counted in both pairs
    du, dw = u3 - u_pairs, w3 - w_pairs
    three_body = dict(U1x=abs(du[0, 0]), U23x=abs(0.5 * (du[1, 0] + du[2, 0])),
                      dU=abs(du[0, 0] - 0.5 * (du[1, 0] + du[2, 0])),
                      U23y=abs(0.5 * (du[1, 1] - du[2, 1])), W23z=abs(0.5 * (dw[1, 2] - dw[2, 2])))
    return dict(r=side, method=method, **summary(u, w), three_body={k: float(v) for k, v in three_body.items()},
                velocities=u.tolist(), angular_velocities=w.tolist())
