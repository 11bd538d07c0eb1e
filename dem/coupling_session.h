/* The coupling session of this fdmDEM process with the fluid solver fdmFoam (docs/coupling.md):
   the connection, the handshake (Hello both ways and their checks), what the fluid said (alpha_lambda,
   rho_f, mesh size, viscosity, the kind and wall velocity of every box face), and the end: Finish
   after the input, or Error when fdmDEM stops early. With transport none (DEM only) there is no
   fluid and the same values come from fix fdm/couple's keywords.

   One per process: it outlives runs and even the fix (unfix / fix again). fix fdm/couple registers
   what it asks for (attach) and uses the connection; pair_style fdm/subgrid asks it for the
   viscosity, the mesh size and the walls before LIGGGHTS builds neighbour lists (connecting then
   if needed), without knowing the fix. Rank 0 talks; what it learns is broadcast on the LIGGGHTS
   communicator. */

#ifndef FDM_COUPLING_SESSION_H
#define FDM_COUPLING_SESSION_H

#include "fdm/coupler.h"
#include "particle_step_profile.h"

#include <memory>
#include <string>

namespace LAMMPS_NS {

class LAMMPS;

class CouplingSession {
 public:
  // What fix fdm/couple asks for (its keywords).
  struct Request {
    fdm::coupler::Options options;   // transport "none": DEM only
    bool stresslets = false;         // StepDone must carry the FDM stresslets
    // transport none: the values the fluid would have given
    double viscosity = 0, meshSize = 0, fluidDensity = 1000;
    long long checkpointEvery = 0;   // fix fdm/couple checkpoint N (0: none), told to the fluid
  };

  // The boundary of the fluid case on a box face (coupler's layout::BoundaryKind), or none at all.
  enum FaceKind { facePeriodic = 0, faceWall = 1, faceSlip = 2, faceOther = 3, faceNoFluid = -1 };

  static CouplingSession &instance();

  // Resume (fdmDEM -resume FILE, docs/coupling.md "Checkpoint and resume"): the particle checkpoint
  // fix fdm/couple restores, and the step it holds, which the Hello tells the fluid (0: fresh start).
  void setResumeFile(const std::string &file) { resumeFile_ = file; }
  const std::string &resumeFile() const { return resumeFile_; }
  void setResumeStep(long long step) { resumeStep_ = step; }
  long long resumeStep() const { return resumeStep_; }
  // fdmDEM -until L: the resumed run was extended (or cut) to end at step L, so its input's `run L upto`
  // differs from the checkpoint's last step on purpose (0: it must not differ)
  void setResumeUntil(long long lastStep) { resumeUntil_ = lastStep; }
  long long resumeUntil() const { return resumeUntil_; }

  // fix fdm/couple's constructor registers its request, its destructor withdraws it.
  void attach(const void *fix, const Request &request);
  void detach(const void *fix);
  // A fix fdm/couple exists: Eq. (31) has a fluid (or its DEM-only stand-in); without, contact only.
  bool attached() const { return owner_ != nullptr; }

  // Every rank: what the coupling needs of the atoms (atom_style sphere, map array, IDs 1..N).
  void checkAtoms(LAMMPS *lmp) const;
  // Every rank (collective): connects and shakes hands with the fluid, or takes the DEM-only values,
  // unless done. nParticles: the N to announce; 0: check the atoms and announce atom->natoms.
  void ensureConnected(LAMMPS *lmp, int nParticles = 0);
  bool connected() const { return connected_; }

  // What the fluid said (every rank, once connected).
  int particles() const { return particles_; }   // N announced at the handshake
  bool hasFluid() const { return request_.options.transport != "none"; }
  double alphaLambda() const { return alphaLambda_; }
  double rhoFluid() const { return rhoFluid_; }
  double meshSize() const { return meshSize_; }
  double viscosity() const { return viscosity_; }
  // The fluid's imposed mean pressure gradient [Pa/m] (Eq. 42; 0 without a fluid)
  const double *gradP0() const { return gradP0_; }
  // Box face 0..5 (xlo xhi ylo yhi zlo zhi): kind and wall velocity.
  void fluidFace(int face, int &kind, double velocity[3]) const;
  static const char *faceKindName(int kind);

  // Rank 0: the connection to the fluid (null once closed, on other ranks, or without a fluid).
  fdm::coupler::Transport *transport() { return connection_.get(); }
  // Best effort (any rank; only rank 0 holds the connection): tells the fluid why fdmDEM stops
  // (Error) and closes the connection.
  void abandon(const std::string &why);
  // Every rank (collective): if rank 0 found a problem, tells the fluid and stops every rank with
  // error->all("fdm/couple: " + problem). Does nothing if the problem is empty.
  void stopIf(LAMMPS *lmp, const std::string &problemOnRank0);

  // The seconds of each coupled run (rank 0's), for the session's total.
  void addRun(long steps, double solve, double exchange, double gatherScatter);
  // The breakdown of each run (rank 0's, the rank that solves Eq. 31 and talks to the fluid), for the
  // session's total; whose: how the breakdown names the rank it is of
  void addProfile(const fdm::ParticleStepProfile &run, long fluidSteps);
  static std::string whoseProfile(int ranks);
  double totalSolve() const { return totalSolve_; }
  double totalExchange() const { return totalExchange_; }
  // Every rank, by the fdmDEM driver after the input script: tells the fluid to finish (Finish),
  // closes the connection and prints the session's timing.
  void finishAll(LAMMPS *lmp);

 private:
  CouplingSession();
  void connectAndHandshake(LAMMPS *lmp);
  std::string checkFluidHello(LAMMPS *lmp, const fdm::coupler::FluidHello &hello) const;

  const void *owner_;
  Request request_;
  std::string resumeFile_;
  long long resumeStep_ = 0;
  long long resumeUntil_ = 0;
  std::unique_ptr<fdm::coupler::Transport> connection_;  // rank 0
  bool connected_;                                       // every rank: handshake done
  int particles_;
  double alphaLambda_, rhoFluid_, meshSize_, viscosity_;
  double gradP0_[3] = {0, 0, 0};
  double faces_[6][4];                                   // kind, wall velocity
  double start_;                                         // MPI_Wtime of the handshake
  int runs_;
  long steps_;
  double totalSolve_, totalExchange_, totalGatherScatter_;
  fdm::ParticleStepProfile totalProfile_;
  long fluidSteps_ = 0;
};

}  // namespace LAMMPS_NS

#endif
