/* Eq. (31) of the paper (Orsi, Lobry & Peters 2023, 4.3-4.4): the linear system for the rigid
   velocities u = (U_p, Omega_p) of all N particles, unknowns ordered by tag,

       [ (rho_f/rho_p) J / alpha_lambda + R^SG ] u = F^tot,

   with (rho_f/rho_p) J/alpha_lambda the rigid-body block of each particle from the fluid's indicator
   function, (rho_f/alpha_lambda) [[Vu 1, -[m1]x], [[m1]x, J]] (RigidVolume: the discrete sphere's volume,
   first moment and inertia tensor; the paper's diagonal when m1 = 0 and J = Ju 1), R^SG the frame-invariant sub-grid matrix of the close pairs and wall gaps (Eq. 21,
   Appendices C.2, D; built by pair_style fdm/subgrid) and F^tot of Eq. (32): the fluid integral +
   the buoyant weight (rho_p - rho_f)/rho_p m g + every other force on the particle (contacts,
   external) + the moving walls' term R_w[:, 0:3] U_w of Eq. (D.6).

   Per time step: assemble() once (R^SG; the positions do not move during the inner iterations),
   setVolumes() once (they depend only on the positions: the rigid-body blocks, and the LDLT factorisation),
   then solve() every inner iteration (a back-substitution, or conjugate gradients warm-started from
   the previous solution); after the last one, the sub-grid force, torque and stresslets.

   Plain C++ and Eigen (no LIGGGHTS): fix fdm/couple uses it on rank 0; tested on its own in
   dem/tests/test_particle_velocity_system.cpp. */

#ifndef FDM_PARTICLE_VELOCITY_SYSTEM_H
#define FDM_PARTICLE_VELOCITY_SYSTEM_H

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace fdm {

template <class History>
class BasicAndersonMixing;  // fdm/anderson_mixing.h

// The records of the sub-grid blocks, as pair_style fdm/subgrid builds them on every rank and
// fix fdm/couple gathers them on rank 0. R already contains the viscosity (F = -R u).
namespace subgrid {
// pair: [tag1, tag2, R (12 x 12, row-major, unknowns U1 Omega1 U2 Omega2)]
const int pairRecord = 2 + 144;
// with stresslets, after it: the rows of S_1 (6), S_2 (6), s_1, s_2 (14 x 12; S^SG = -rows u)
const int pairStressRecord = 14 * 12;
// wall: [tag, R_w (6 x 6), R_w[:, 0:3] U_w (6)]
const int wallRecord = 1 + 36 + 6;
// with stresslets, after it: the rows of S, s (7 x 6) and their wall-velocity term (7)
const int wallStressRecord = 7 * 6 + 7;
}  // namespace subgrid

// The records of the implicit contact springs (contact_springs.h, docs/contact.md 2b, 2c), built by
// pair_style fdm/subgrid with contact_integration implicit: R_c of Eq. (C3) enters the matrix, its
// known part (Eq. C2) the right-hand side; they are kept apart from R^SG in the outputs. The friction
// tail lets the solve keep Coulomb's law at the end of the step (2c): a sticking contact (kt c1 dt > 0)
// whose implicit tangential force exceeds the cap mu_s F_n slides within the step.
namespace springs {
// pair: [tag1, tag2, R_c (12 x 12), branch x2 - x1 (3), weight a1/(a1 + a2) of Eq. (52),
//        friction tail: n (3, from 2 to 1), l1, l2, kt c1 dt (0: no tangential spring), mu_s,
//        F_n (the normal force at the start), kn c1 dt, F_t (3: the explicit tangential force on 1)]
const int pairFriction = 2 + 144 + 4;
const int pairRecord = pairFriction + 12;
// wall: [tag, R_c (6 x 6), wall-velocity term dt B^T K U_w (6), branch from the centre to the wall (3),
//        friction tail: n (3, into the fluid), l, kt c1 dt, kt dt, mu_s, F_n, kn c1 dt, F_t (3), U_w (3)]
const int wallFriction = 1 + 36 + 6 + 3;
const int wallRecord = wallFriction + 15;
}  // namespace springs

class ParticleVelocitySystem {
 public:
  enum Solver { cholmod, ldlt, cg };

  struct Settings {
    // sparse Cholesky factorised once per step (and when contacts begin to slide): CHOLMOD's
    // supernodal LL^T, or Eigen's simplicial LDL^T; or Jacobi-preconditioned CG
    Solver solver = cholmod;
    double tolerance = 1e-10;          // relative residual of CG
    double alphaLambda = 0;            // direct-forcing penalty [s] (Eq. 29)
    double rhoFluid = 0;               // [kg/m3]
    double gravity[3] = {0, 0, 0};     // [m/s2]
    bool stresslets = false;           // the block records carry their stress rows (subgrid::*StressRecord)
    // Coulomb's law at the end of the step (docs/contact.md 2c) is solved by rounds, one
    // back-substitution each, until no sliding contact's force changes by more than this fraction of
    // its size (plus its F_t at the start); Anderson-mixed rounds unless coulombAcceleration is off
    double coulombTolerance = 1e-6;
    bool coulombAcceleration = true;
    // How a contact slides (docs/contact.md 2c). frozen: along the direction of its force in the round
    // it began to slide, for the rest of the step, its whole tangential spring out of the matrix (a slide
    // may then follow its friction: the known limit there). consistent: every round takes the law
    // itself, the force cap T/|T| of the trial force T (T under the cap: the contact sticks again, its
    // spring back in the matrix); the matrix holds the law's Jacobian, cap/|T| of the spring across the
    // slide (semismooth Newton), renewed where a contact's direction or |T| moved too far since.
    bool coulombConsistent = false;
  };

  // What Eq. (32) needs of a particle besides the fluid; index = tag - 1.
  struct Particle {
    double x[3] = {0, 0, 0};           // for the error messages
    double radius = 0;                 // for the error messages
    double mass = 0, density = 0;      // buoyant weight (rho_p - rho_f)/rho_p m g
    double force[3] = {0, 0, 0};       // everything else: contacts, external forces (F^c + F^ext)
    double torque[3] = {0, 0, 0};
  };

  // A problem with the system: what() is for the user and names the particle (index `particle`,
  // -1 if none). noVolume: the fluid gave a particle Vu <= 0 or Ju <= 0 (smaller than a mesh cell?);
  // fluidValue: a non-finite volume or fluid integral; the others are the system's own.
  class Error : public std::runtime_error {
   public:
    enum Kind { noVolume, fluidValue, badBlock, notSolved };
    Error(Kind kind, int particle, const std::string &what) : std::runtime_error(what), kind(kind), particle(particle) {}
    Kind kind;
    int particle;
  };

  explicit ParticleVelocitySystem(const Settings &settings);
  ~ParticleVelocitySystem();

  // The solver as messages and the run-end timing name it: "CHOLMOD", "LDLT" or "CG".
  static const char *solverName(Solver solver);

  // The implicit contact springs of a step (Eqs. C2, C3 of docs/contact.md): their records (layouts
  // above) and U_n with its weight gamma (1/3 with ab2, 0 with euler) in the known part.
  struct Springs {
    std::vector<double> pairs, walls;
    std::vector<double> previous;      // 6N: U_n by tag (may be empty if gamma = 0 and dt = 0)
    double gamma = 0;
    // the time step, for the chord term of the pair springs (Eq. C5 of docs/contact.md: the straight
    // step opens a sliding or rolling pair by dt^2 |rho_t|^2/(2r), estimated from U_n = previous);
    // 0 leaves it out
    double dt = 0;
  };

  // Once per time step: the particles and R^SG from the gathered block records (layouts above),
  // and the implicit contact springs if any. The last solution stays the warm start unless the
  // number of particles changed.
  void assemble(std::vector<Particle> particles, std::vector<double> pairs, std::vector<double> walls,
                Springs springs);
  void assemble(std::vector<Particle> particles, std::vector<double> pairs, std::vector<double> walls);
  // What the fluid's indicator function gives a particle, r = x - x_p: Vu = int I_u dV, m1 = int I_u r dV,
  // J = int I_u (|r|^2 1 - r r) dV (xx xy xz yy yz zz). Eq. (30) integrated over the stencil: the
  // rigid motion U + Omega x r contributes Vu U - m1 x Omega to the force and m1 x U + J Omega to the
  // torque. With all of it in Eq. (31), a converged free particle carries no force and no torque of
  // lambda whatever its position in the mesh and its velocity (with the paper's diagonal, m1 = 0 and
  // J = Ju 1, it turns in a uniform flow: docs/validation.md).
  struct RigidVolume {
    double Vu = 0;
    double m1[3] = {0, 0, 0};
    double J[6] = {0, 0, 0, 0, 0, 0};
  };
  // Once per time step, after assemble(): every particle's rigid-body block. Factorises (ldlt) or sets
  // up the preconditioner (cg) if the blocks changed since the last call.
  void setVolumes(const std::vector<RigidVolume> &volumes);
  // The paper's diagonal: m1 = 0, J = Ju 1 (a sphere on a symmetry point of the mesh; tests, no fluid).
  void setVolumes(const std::vector<double> &Vu, const std::vector<double> &Ju);
  // Every inner iteration: the fluid part of F^tot (6 per particle: F, T; Eq. 32) -> u (6 per
  // particle: U, Omega). Throws Error if an input or the solution is not finite or CG does not converge.
  const std::vector<double> &solve(const std::vector<double> &fluidForces);

  int particles() const { return n_; }
  const std::vector<double> &velocities() const { return u_; }      // the last solution, 6N
  double diagonal(int k) const;                                      // of the rigid-body blocks
  // The rigid-body blocks times u (6N): the part (rho_f/alpha) int I_u (U + Omega x r) of Eq. (31)
  std::vector<double> rigidBlocksTimes(const std::vector<double> &u) const;
  long pairBlocks() const { return pairBlocks_; }
  long wallBlocks() const { return wallBlocks_; }
  // Index pairs (2 per pair) that have a sub-grid block this step.
  std::vector<int> closePairs() const;
  long lastIterations() const { return iterations_; }   // CG's, of the last solve (the most of its Coulomb rounds; 1 for LDLT)
  long factorisations() const { return factorisations_; }
  // The wall seconds of every factorisation (or CG preconditioner) since construction: the step's
  // (setVolumes) and those its Coulomb rounds fall back to when the downdates grow too large (in solve())
  double factorisationSeconds() const { return factorisationSeconds_; }
  // Contacts that began to slide handled by a low-rank downdate of the step's factorisation instead
  // of a new one (Woodbury; CHOLMOD and LDLT): the number of such downdates since construction.
  long downdates() const { return downdates_; }
  // Back-substitutions (or CG solves) since construction: one per Coulomb round of each solve().
  long backSubstitutions() const { return backSubstitutions_; }
  // The Coulomb rounds of the last solve (at most 100: it then stops where the rounds stand).
  long lastRounds() const { return rounds_; }

  // After the last solve: F^SG, T^SG = -(R^SG u - wall term) (Eqs. 21, D.6), 6 per particle.
  std::vector<double> subgridForces() const;
  // After the last solve: the sub-grid force and torque of each wall block on its particle,
  // R_w[:, 0:3] U_w - R_w u_p (Eq. D.6), 6 per block in the order of the wall records given to
  // assemble() (their sum over the blocks of a particle is the wall part of subgridForces()).
  std::vector<double> wallBlockForces() const;
  // After the last solve: adds the sub-grid stresslets S^SG = -rows u (+ wall term) (Eq. 13) to
  // `stresslets`, 7 per particle (S xx xy xz yy yz zz, s). Needs Settings::stresslets.
  void addSubgridStresslets(std::vector<double> &stresslets) const;
  // After the last solve: the implicit part of the contact forces, -R_c (u - gamma U_n) + wall term
  // (Eq. C2), 6 per particle (F, T; 0 without springs), and its contact stresslet (Eq. 52, 6 per
  // particle: xx xy xz yy yz zz) added to `stresslets` if not null; `wallBlockForces` (if not null)
  // receives 6 per implicit wall spring, its force and torque on its particle, in block order.
  std::vector<double> springForces(std::vector<double> *stresslets = nullptr,
                                   std::vector<double> *wallBlockForces = nullptr) const;
  // Contacts that stuck at the start of the step and slide within it (Coulomb's law at the end of
  // the step, docs/contact.md 2c), counted since the last assemble().
  long slidingSwitches() const { return slidingSwitches_; }
  // After the last solve: the contacts that slide, and those of them whose slip over the step goes
  // along their friction force by more than the cap's worth of spring (k_t c1 dt (rho_t . t) > cap:
  // friction doing work on the slip, which the rounds do not undo: a known limit, docs/contact.md 2c)
  struct SlidingCount {
    long sliding = 0, alongFriction = 0;
  };
  SlidingCount slidingAtEnd() const;
  // After the last solve: how far the contact forces are from Coulomb's law at the solution, each
  // friction contact's tangential force f against the projection P(T) of its trial force T onto the
  // disc of radius cap: |f - P(T)| / (|P(T)| + |F_t|), its largest value and the contacts beyond 1e-3.
  // 0 for a consistent solve (to its tolerance); frozen slides show the known limit.
  struct CoulombConsistency {
    long contacts = 0, inconsistent = 0;
    double worst = 0;
  };
  CoulombConsistency coulombConsistency() const;
  // Sliding contacts that stuck again within their step (coulomb_solve consistent), since the last assemble().
  long stickingSwitches() const { return stickingSwitches_; }
  // The chord terms of this step (Eq. C5): the largest k_n dt^2 |rho_t|^2/(2r) of a pair spring [N]
  double largestChordForce() const { return largestChordForce_; }
  long springBlocks() const { return long(springPairs_.size() / springs::pairRecord + springWalls_.size() / springs::wallRecord); }

 private:
  int tagIndex(double tag) const;
  // LDLT's factorisation (its pattern analysed once per step) or CG's preconditioner of the current
  // matrix; `when` ends the error message if LDLT fails.
  void factorise(const std::string &when);
  // Coulomb's law at the end of the step (docs/contact.md 2c): sticking contacts whose implicit
  // tangential force at u exceeds mu_s F_n slide from now on in this step (their tangential spring
  // leaves the matrix, the capped force along the trial direction replaces F_t in F^tot); true if
  // any did (their blocks then leave by downdateOrFactorise).
  bool slideOverloadedContacts();
  // The same with Coulomb's law kept consistently (Settings::coulombConsistent): one round, true if
  // the rhs or the matrix changed (then solve again).
  bool consistentCoulombRound();
  // The part of a sliding contact's tangential spring that is out of the matrix (12 x 12 or 6 x 6) and,
  // for a wall, its wall-velocity term: the whole spring (frozen slides), or along slideDirection_ and
  // (1 - slideKeep_) of it across (consistent slides)
  void removedSpring(size_t record, const double *tail, bool wall, double *R, double *wallTerm) const;
  // The part of a contact's tangential spring out of the matrix while it slides along t keeping `keep` of it
  // across t (contact::pairSlideBlock, wallSlideBlock; the wall term into wallTerm)
  static void slidePart(const double *tail, bool wall, const double *t, double keep, double *R, double *wallTerm);
  // The tangential force a sliding contact applies at w (its unknowns' u - gamma U_n): F_t + the rhs term
  // + the part of its spring still in the matrix
  void slidingForce(size_t record, const double *tail, const double *w, bool wall, double force[3]) const;
  // mu_s times the smaller of the normal force at the start and at the end of the step (docs/contact.md 2c)
  double coulombCap(size_t record, const double *tail, const double *w, bool wall) const;
  // A symmetric block (12 x 12 or 6 x 6) out of the matrix (negative: back into it), and out of the known
  // part gamma R U_n; its columns of V follow in downdateOrFactorise
  void takeOutOfMatrix(const int *base, int size, const double *R);
  // A sliding contact's rhs term (slideForce_) set to `term`, F^tot changed by B^T of the difference; false if
  // it was that already
  bool setSlideTerm(size_t record, const double term[3], const double *tail, const int *base, int size, bool wall);
  // The tangential spring blocks that left the matrix (columns of V, R_t = V V^T): a low-rank
  // downdate of the factorisation (Woodbury), or a new factorisation once the downdate grows large.
  void downdateOrFactorise();
  // The chord term of each pair spring (Eq. C5 of docs/contact.md) from U_n (Springs::previous), into
  // F^tot, once per step (assemble).
  void setChordForces();
  // Every implicit contact spring of this step, pairs then walls: visit(record, friction tail, the
  // first unknowns 6 i of its particles, 12 or 6 unknowns, wall). `record` indexes the per-spring
  // state (springSlides_, slideForce_, ...); chordForce_ has the pairs' records only.
  template <class Visit>
  void forEachSpring(Visit &&visit) const;
  double springVelocity(int k) const;  // u - gamma U_n, the unknowns' part of the contact displacement
  // The tangential force at the end of the step of a contact that sticks (docs/contact.md 2c), from its
  // friction tail and w = u - gamma U_n of its unknowns (12, or 6 for a wall)
  void stickingForce(const double *tail, const double *w, bool wall, double end[3]) const;

  struct Matrices;                     // Eigen's, in the .cpp
  Settings settings_;
  int n_;
  std::vector<Particle> particles_;
  std::vector<double> pairs_, walls_;  // the block records of this step
  std::vector<double> springPairs_, springWalls_, springPrevious_;  // implicit contact springs of this step
  double springGamma_;
  double springDt_ = 0;                // the step's dt for the chord term (0: none)
  std::vector<double> chordForce_;     // per pair spring record: k_n times its chord (Eq. C5), set by assemble()
  double largestChordForce_ = 0;
  std::vector<char> springSlides_;     // per spring record (pairs, then walls): slides since this step's start
  std::vector<double> slideForce_;     // per spring record: capped force - F_t (3) of a contact that slides
  std::vector<double> slideDirection_; // per spring record: the direction of its sliding force (3)
  std::vector<double> slideCap_;       // per spring record: the cap of a contact that slides, as in the last solve
  std::vector<double> slideKeep_;      // per spring record: the fraction of its spring across slideDirection_ kept in the matrix
  std::vector<int> coulombFlips_;      // per spring record: stick/slide changes in this solve (consistent slides)
  std::vector<int> coulombRenewals_;   // per spring record: its slide's Jacobian renewed in this solve
  std::vector<char> coulombFrozen_;    // per spring record: slides along slideDirection_ for the rest of this solve
  long slidingSwitches_, stickingSwitches_ = 0;
  int pairRecord_, wallRecord_;
  long pairBlocks_, wallBlocks_;
  std::vector<RigidVolume> volumes_;   // of this step, for the messages
  std::vector<double> u_;              // the last solution: warm start of the next solve
  long iterations_, factorisations_, downdates_, backSubstitutions_ = 0, rounds_ = 0;
  double factorisationSeconds_ = 0;
  double lastCoulombResidual_ = 0;     // the largest change of a cap in the last round of this solve
  std::unique_ptr<Matrices> m_;
  static const int coulombMixingDepth = 10;              // differences kept: a solve takes 5-20 rounds
  std::unique_ptr<BasicAndersonMixing<double> > coulombMixing_;  // of the caps over the Coulomb rounds of one solve
};

}  // namespace fdm

#endif
