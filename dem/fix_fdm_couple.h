/* fix fdm/couple -- couples LIGGGHTS to the fictitious-domain fluid solver fdmFoam.

   Syntax (docs/dem.md):
     fix ID all fdm/couple [transport socket|file] [host H] [port P] [portfile F] [directory D]
                           [connect_timeout s] [timeout s] [record FILE] [gravity gx gy gz] [move yes|no]
                           [stresslets yes|no] [solver cg|ldlt] [tolerance t] [integrator ab2|euler]
                           [gap_update log|none] [contact_gaps hold|free] [checkpoint N] [walls FILE]
                           [fluid_every K] [held_drag constant|extrapolated]
     fix ID all fdm/couple transport none viscosity eta mesh Delta [fluid_density rho_f] ...   (DEM only)

   Every time step: moves the particles with their velocity (initial_integrate, paper 4.3 step 1),
   then (final_integrate, after every pair and fix force is in f and torque) sends the particles
   to fdmFoam and, every inner iteration, solves Eq. (31) for all particle velocities from the
   integrals it receives, until fdmFoam reports convergence. Replaces fix nve/sphere. With
   pair_style fdm/subgrid, the sub-grid lubrication blocks R^SG (pairs and walls) are gathered on
   rank 0 once per time step and enter the matrix of Eq. (31) (paper section 4.4.2).
   With fluid_every K the fluid is solved at every K-th step only; the steps between hold its force on
   each particle as an isolated sphere's drag toward the velocity the fluid gave it (frozenFluidStep),
   or, with held_drag extrapolated, toward that velocity extrapolated from the last two fluid steps.
   Eq. (31) itself is particle_velocity_system.h; the connection to fdmFoam and what it said at the
   handshake are the process's coupling session (coupling_session.h), which this fix configures.

   Outputs (docs/dem.md): global vector [inner iterations, lambda residual, particle-solve seconds,
   exchange seconds, linear-solver iterations, sub-grid pair blocks, wall blocks, contacts] of the
   last step; per-atom array [F^FDM, T^FDM, F^SG, T^SG] (12 columns), and with stresslets yes
   [S^h (6), s^h, S^c (6), S^SG (6), s^SG] after them (32 columns; S^SG, s^SG: the sub-grid part of
   S^h, s^h). fix fdm/output (fix_fdm_output.h) writes them to binary records and ParaView files.
   walls FILE: rank 0 writes every step the force of the particles on each wall of pair_style
   fdm/subgrid, split into sub-grid lubrication (Eq. D.6) and contact (a text line per step; the
   particle side of the momentum balance of a sheared suspension, docs/dem.md, docs/profiles.md). */

#ifndef FDM_FIX_FDM_COUPLE_H
#define FDM_FIX_FDM_COUPLE_H

#include "fix.h"
#include "fdm/coupler.h"
#include "particle_velocity_system.h"
#include "position_update.h"
#include "particle_checkpoint.h"

#include <memory>
#include <string>
#include <vector>

namespace LAMMPS_NS {

class FixFdmCouple : public Fix {
 public:
  FixFdmCouple(class LAMMPS *, int, char **);
  ~FixFdmCouple();
  int setmask();
  void init();
  void setup(int);
  void setup_pre_exchange();
  void initial_integrate(int);
  void final_integrate();
  void post_run();
  double compute_vector(int);
  double memory_usage();

 private:
  // One particle as gathered on rank 0, stored by tag (index tag-1).
  struct Particle {
    double x[3], radius, v[3], omega[3], f[3], torque[3], mass, density;
    double contactStress[6];  // S^c of Eq. (52), when stresslets are asked for
  };
  // Wall-clock seconds spent in the three parts of the particle side's work.
  struct Timing {
    double solve, exchange, gatherScatter;
    long steps, fluidSteps, solves, solverIterations, solverIterationsMax;
    long gapTargets, gapLimited;   // log-gap targets of the position update, and those limited
    long gapHeld;                  // contact (or closed) gaps held at their straight-step value
    long gapFallbacks;             // steps where the targets contradicted each other (the fallback:
                                   // straight, every gap kept above its bound)
    int gapSweepsMax;
    double gapBoundWorst;          // largest relative bound violation the fallback left
    long contactSlides;            // contacts that began to slide within their step (Coulomb's law at its end)
    long factorisations;           // of Eq. (31) by the direct solvers: per step, and when the downdates grow too large
    long downdates;                // contacts that began to slide handled without a factorisation (Woodbury)
    long backSubstitutions;        // of Eq. (31): one per Coulomb round of each solve
    long coulombRoundsMax;         // the most rounds of one solve (100 stops the rounds where they stand)
    double chordForceMax;          // the largest chord term of a pair spring (Eq. C5 of docs/contact.md) [N]
    Timing() : solve(0), exchange(0), gatherScatter(0), steps(0), fluidSteps(0), solves(0), solverIterations(0), solverIterationsMax(0),
               gapTargets(0), gapLimited(0), gapHeld(0), gapFallbacks(0), gapSweepsMax(0), gapBoundWorst(0),
               contactSlides(0), factorisations(0), downdates(0), backSubstitutions(0), coulombRoundsMax(0),
               chordForceMax(0) {}
  };

  void gather(std::vector<Particle> &particles);
  std::string checkConfiguration(const std::vector<Particle> &particles, bool fromInput) const;
  std::string findOverlap(const std::vector<Particle> &particles) const;
  fdm::coupler::Step makeStep(const std::vector<Particle> &particles) const;
  void assembleSystem(const std::vector<Particle> &particles);
  void setVolumes(const fdm::coupler::Volumes &volumes);
  void solveVelocities(const fdm::coupler::Integrals &integrals);
  std::string systemProblem(const fdm::ParticleVelocitySystem::Error &e, uint64_t step, uint32_t iteration) const;
  void subgridResults(const std::vector<Particle> &particles);
  fdm::coupler::Volumes noFluidVolumes(const std::vector<Particle> &particles) const;
  void backgroundFlow(const std::vector<Particle> &particles, fdm::coupler::Integrals &integrals);
  bool fluidStepDue() const;
  void frozenFluidStep(const std::vector<Particle> &particles);
  void extrapolateHeldDrag(fdm::coupler::Integrals &held);
  void storeStepDone(const fdm::coupler::StepDone &done);
  void planNextMove(const std::vector<Particle> &particles);
  void scatter();
  void fillPerAtomArray();
  void writeWallLoads();
  void checkPeriodicBalance(const std::vector<Particle> &particles);
  void checkOverlaps();
  void allAgree(const std::string &problemOnRank0);
  void fail(const std::string &message);
  void printTiming(const char *what, const Timing &t, double wall, int runs) const;
  // Checkpoint and resume (fix_fdm_couple_checkpoint.cpp, docs/coupling.md)
  bool checkpointDue() const;
  void writeCheckpoint();
  void readResumeCheckpoint();
  void restoreCheckpoint();

  class CouplingSession &session_;  // the connection and what the fluid said (coupling_session.h)
  bool hasFluid_;                   // not transport none
  double gravity_[3];
  bool move_;
  bool adamsBashforth_;      // position update: Adams-Bashforth 2 (default) or Euler
  bool gapUpdate_;           // log-gap correction of the position update (position_update.h)
  bool holdContactGaps_;     // contact gaps held at their straight-step value during that correction
  bool haveVelocities_;
  std::vector<double> currentVelocity_, previousVelocity_;  // 6N by tag, U_n and U_{n-1}
  // The next position update, planned on rank 0 once U_n is known and broadcast: displacement
  // rates (6N by tag, x += dt rate), and the positions x_n it starts from (rank 0, 3N by tag).
  bool havePlan_;
  std::vector<double> moveRate_, planPositions_;
  bool stresslets_;          // per-particle stresslets asked for (fluid, sub-grid, contact)
  fdm::ParticleVelocitySystem::Solver solver_;  // of Eq. (31): cholmod (default), ldlt or cg
  long factorisationsCounted_ = 0;              // the system's factorisations already in run_
  long downdatesCounted_ = 0;                   // and its downdates
  long backSubstitutionsCounted_ = 0;           // and its back-substitutions
  double tolerance_;         // relative residual of the conjugate-gradient solve
  double coulombTolerance_ = fdm::ParticleVelocitySystem::Settings().coulombTolerance;  // of the Coulomb rounds
  bool contactChord_ = true;          // the chord term of the pair springs (Eq. C5 of docs/contact.md)
  class PairFdmSubgrid *pair_;  // the sub-grid / contact pair style, if that is the pair style

  int atomsAtInit_;                // atom count when init() checked the tags 1..N
  int natoms_;                     // N, particles are tags 1..N
  std::vector<double> solution_;   // 6N: (U, Omega) per particle by tag; warm start of the next solve
  std::vector<double> hydro_;      // 6N: hydrodynamic force and torque of the last StepDone, by tag
  std::vector<double> fluidStress_; // 7N: S^FDM (6), s^FDM of the last StepDone (Eq. 12), by tag
  int lastIterations_;
  double lastResidual_;
  long notConverged_;              // steps where the fluid reported converged=0
  Timing run_;                     // this run
  double backgroundShear_ = 0;     // transport none: the simple shear rate the spheres' drag sees
  // fluid_every K: the fluid is solved every K-th step; the steps between hold its force as the drag
  // toward the velocities it gave (frozenFluidStep). lastFluidStep_: the last step the fluid solved
  // (-1: none yet in this session, or a checkpoint's step after a resume)
  long fluidEvery_ = 1;
  bigint lastFluidStep_ = -1;
  // held_drag extrapolated: D U_b of the last two fluid steps (6N each, by tag) and their steps, taken at
  // the first held step after each fluid step; -1: none yet (the held drag is then constant)
  bool heldExtrapolated_ = false;
  std::vector<double> heldDrag_, heldDragBefore_;
  bigint heldDragStep_ = -1, heldDragStepBefore_ = -1;
  double runStart_;
  int nmax_;                       // rows allocated in array_atom
  double **perAtom_;
  int perAtomColumns_;

  // Eq. (31) on rank 0 (particle_velocity_system.h): assembled once per step, solved every inner iteration.
  std::unique_ptr<fdm::ParticleVelocitySystem> system_;
  std::vector<double> subgrid_;    // 6N: F^SG, T^SG of the last step, by tag
  std::vector<double> springs_;    // 6N: implicit part of the contact forces of the last step (Eq. C2), by tag
  std::vector<double> stress_;     // 20N: S^h (6), s^h, S^c (6), S^SG (6), s^SG of the last step, by tag
  long solverIterations_, pairBlocks_, wallBlocks_, contacts_;

  // walls FILE: the particles' loads on the walls (rank 0)
  std::string wallFile_;
  FILE *wallOut_;
  std::vector<double> wallBlockWall_;  // rank 0: the wall (index in pair_->walls()) of each gathered wall block
  std::vector<double> wallContact_;    // rank 0: 3 per wall, the force of the contacts on the wall
  std::vector<double> springWallBlockWall_;  // rank 0: the wall of each gathered implicit wall-spring block
  std::vector<double> springWallForces_;     // rank 0: 6 per implicit wall-spring block, its force on the particle

  long long checkpointEvery_;      // checkpoint N: every N steps and at the end of each run (0: never)
  double checkpointSeconds_;       // wall time spent writing checkpoints (rank 0's)
  // fdmDEM -resume FILE: the checkpoint read by the constructor (every rank), restored before the
  // first step (setup_pre_exchange), then released
  std::unique_ptr<fdm::checkpoint::ParticleCheckpoint> resume_;
  std::string resumeFile_;
  bool resumed_;                   // this session continues a checkpoint (no overlap check at its start)
};

}  // namespace LAMMPS_NS

#endif
