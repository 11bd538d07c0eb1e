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

// The part of a contact's tangential spring that leaves Eq. (31) when it slides along the unit
// tangent t with Coulomb's law solved consistently (docs/contact.md 2c, coulomb_solve consistent):
// c1 dt B^T kt [t t^T + (1 - keep)(I - n n^T - t t^T)] B, the spring along t and (1 - keep) of it
// across t; what stays, keep kt across t, is the Jacobian of the capped force cap T/|T| at the trial
// force T (keep = cap/|T|). keep = 0 takes the whole tangential spring out. For a wall, the
// wall-velocity term of that part, dt B^T K_part U_w, too (ktdt = kt dt).
void pairSlideBlock(const double n[3], double leverI, double leverJ, const double t[3], double keep, double ktc1dt,
                    double R[144]);
void wallSlideBlock(const double n[3], double lever, const double t[3], double keep, double ktc1dt, double ktdt,
                    const double wallVelocity[3], double R[36], double wallTerm[6]);

// Coulomb's law inside the step (docs/contact.md 2c). u_rel: the unknowns' part of the contact points'
// displacement rate, u - gamma U_n, of the pair (12) or the particle (6). The tangential force of a
// sticking contact at the end of the step, F_t,end = F_t - kt dt (I - n n^T) rho with
// rho = c1 B u_rel - U_w (Eqs. C1, C2): ktc1dt = kt c1 dt, ktdt = kt dt (the wall term).
void pairTangentialForceAtEnd(const double n[3], double leverI, double leverJ, double ktc1dt, const double ft[3],
                              const double uRel[12], double out[3]);
void wallTangentialForceAtEnd(const double n[3], double lever, double ktc1dt, double ktdt, const double ft[3],
                              const double wallVelocity[3], const double uRel[6], double out[3]);
// B^T f: the generalised force on (U_i, Omega_i, U_j, Omega_j) of a force f on i at the contact point
// (and -f on j): (f, -l_i n x f, -f, -l_j n x f); for a wall (f, -l n x f).
void pairGeneralisedForce(const double n[3], double leverI, double leverJ, const double f[3], double out[12]);
void wallGeneralisedForce(const double n[3], double lever, const double f[3], double out[6]);

}  // namespace contact
}  // namespace fdm

#endif
