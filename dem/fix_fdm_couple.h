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
   each particle as an isolated sphere's drag toward the velocity the fluid gave it (held_drag.h),
   or, with held_drag extrapolated, toward that velocity extrapolated from the last two fluid steps.
   Eq. (31) itself is particle_velocity_system.h; the connection to fdmFoam and what it said at the
   handshake are the process's coupling session (coupling_session.h), which this fix configures.

   The fix is the LIGGGHTS adapter: it reads the atoms, gathers them on rank 0, broadcasts what rank 0
   found and writes it back; the work is in units that do not know LIGGGHTS: the keywords
   (couple_options.h), the configuration and set-up checks (configuration_checks.h), the step's
   collectives (step_collectives.h: MPI only), the exchange with the fluid
   (fluid_exchange.h), Eq. (31) within a step (coupled_velocity_solve.h), the steps between fluid steps
   (fluid_step_schedule.h, held_drag.h), the position update (position_update.h), the wall loads
   (wall_loads_file.h), the timing line (coupling_timing.h) and the breakdown of the particle step
   (particle_step_profile.h).

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
#include "coupled_velocity_solve.h"
#include "couple_options.h"
#include "coupling_timing.h"
#include "fluid_step_schedule.h"
#include "gathered_particles.h"
#include "held_drag.h"
#include "move_plan.h"
#include "particle_checkpoint.h"
#include "step_collectives.h"
#include "wall_loads_file.h"

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
  using Particles = std::vector<fdm::GatheredParticle>;
  using Profile = fdm::ParticleStepProfile;

  void gather(Particles &particles);
  fdm::ParticleBox box() const;
  void assembleSystem(const Particles &particles);
  void exchangeWithFluid(const Particles &particles);
  void writeWallLoads();
  void planNextMove(const Particles &particles);
  void scatter();
  void fillPerAtomArray();
  void checkOverlaps();
  void allAgree(const std::string &problemOnRank0);
  void fail(const std::string &message);
  // Checkpoint and resume (fix_fdm_couple_checkpoint.cpp, docs/coupling.md)
  bool checkpointDue() const;
  void writeCheckpoint();
  void readResumeCheckpoint();
  void checkResumedRunLength();
  void continueDumps();
  void restoreCheckpoint();

  class CouplingSession &session_;  // the connection and what the fluid said (coupling_session.h)
  fdm::CoupleOptions options_;      // the keywords
  fdm::CouplingTiming run_;         // this run's seconds and counts
  fdm::CoupledVelocitySolve solve_; // Eq. (31) on rank 0, and its results by tag (every rank)
  fdm::FluidStepSchedule schedule_; // fluid_every K
  fdm::HeldDrag heldDrag_;          // the fluid's force between fluid steps
  fdm::MovePlan plan_;              // the next position update and its history (U_n, U_{n-1}, x_n)
  class PairFdmSubgrid *pair_;      // the sub-grid / contact pair style, if that is the pair style

  int atomsAtInit_;                // atom count when init() checked the tags 1..N
  int natoms_;                     // N, particles are tags 1..N
  fdm::BlockCounts blocks_;        // of the last step, for the global vector
  double runStart_;
  int nmax_;                       // rows allocated in array_atom
  double **perAtom_;
  int perAtomColumns_;

  // walls FILE (rank 0): the file, and what the ranks gave of the walls this step
  std::unique_ptr<fdm::WallLoadsFile> wallOut_;
  fdm::WallLoadsFile::StepLoads wallLoads_;

  double checkpointSeconds_;       // wall time spent writing checkpoints (rank 0's)
  // fdmDEM -resume FILE: the checkpoint read by the constructor (every rank), restored before the
  // first step (setup_pre_exchange), then released
  std::unique_ptr<fdm::checkpoint::ParticleCheckpoint> resume_;
  std::string resumeFile_;
  bool resumed_;                   // this session continues a checkpoint (no overlap check at its start)
};

}  // namespace LAMMPS_NS

#endif
