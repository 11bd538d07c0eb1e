/* Implicit contact springs (docs/contact.md section 2b, Eqs. C1-C5 there): the blocks that take the
   frictional contact springs of pair_style fdm/subgrid into Eq. (31) at the end of the time step.

   A contact (pair i, j or particle i and a wall) has the unit normal n (from j to i, or from the
   wall into the fluid), the lever arms l_i, l_j from the centres to the contact point, and the
   relative velocity of the contact points, linear in the rigid velocities u = (U_i, Omega_i, U_j,
   Omega_j):

       v_r = B u - U_w,   B = [ I, l_i [n]x, -I, l_j [n]x ]   (pair; U_w = 0)
                          B = [ I, l_i [n]x ]                   (wall moving at U_w)       (C1)

   ([n]x w = n x w). The springs act through K = k_n n n^T + k_t (I - n n^T) (k_t only while the
   contact sticks). The position update moves the contact points by dt rho, rho = c1 v_r(U_{n+1}) +
   c0 v_r(U_n) (ab2: c1 = 3/2, c0 = -1/2; euler: c1 = 1, c0 = 0), so the spring force at the end of
   the step is the force at the start of it (the explicit law, F^c(x_{n+1})) plus -dt K rho. Its
   generalised force on (U_i, Omega_i, U_j, Omega_j) is B^T of it:

       F^c,impl = F^c(x_{n+1}) - R_c (U_{n+1} - gamma U_n) + dt B^T K U_w                 (C2)
       R_c = c1 dt B^T K B,     gamma = -c0/c1  (1/3 with ab2, 0 with euler)              (C3)

   R_c is symmetric positive semi-definite, built from n and scalars only (frame-invariant), and
   B u = 0 for a rigid motion of the pair when l_i + l_j = |x_i - x_j| (the contact point in the
   middle of the gap, l = a + h/2): a rigid motion loads no spring. Plain C++ (no LIGGGHTS, no
   Eigen); tested in dem/tests/test_contact_springs.cpp. */

#ifndef FDM_CONTACT_SPRINGS_H
#define FDM_CONTACT_SPRINGS_H

namespace fdm {
namespace contact {

// c1 dt B^T K B for a pair (12 x 12, row-major, unknowns U_i Omega_i U_j Omega_j); kt = 0 for a
// sliding contact (its tangential force stays explicit, at the Coulomb cap).
void pairSpringBlock(const double n[3], double leverI, double leverJ, double kn, double kt, double c1dt,
                     double R[144]);

// c1 dt B^T K B for a particle and a wall (6 x 6), and the wall-velocity term dt B^T K U_w (6)
// of Eq. (C2) (independent of c1: c1 + c0 = 1).
void wallSpringBlock(const double n[3], double lever, double kn, double kt, double c1dt, double dt,
                     const double wallVelocity[3], double R[36], double wallTerm[6]);

}  // namespace contact
}  // namespace fdm

#endif
