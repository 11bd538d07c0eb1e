/* The keywords of fix fdm/couple (docs/dem.md, "fix fdm/couple"), parsed by one keyword table and
   checked together (the keywords that go only with or without the fluid solver). No LIGGGHTS: the
   fix hands its arguments after "fix ID all fdm/couple" and turns a KeywordError into error->all. */

#ifndef FDM_COUPLE_OPTIONS_H
#define FDM_COUPLE_OPTIONS_H

#include "coupling_session.h"
#include "fdm/coupler.h"
#include "keyword_table.h"
#include "particle_velocity_system.h"
#include "position_update.h"

#include <string>
#include <vector>

namespace fdm {

struct CoupleOptions {
  coupler::Options connection;       // transport none: DEM only, no fluid solver
  // transport none: what the fluid would have said (the sub-grid model's mesh size among them)
  double viscosity = 0, meshSize = 0, fluidDensity = 1000;
  double gravity[3] = {0, 0, 0};     // enters Eq. (32) as the buoyant weight
  bool move = true;
  bool adamsBashforth = true;        // position update: Adams-Bashforth 2, or Euler
  bool gapUpdate = true;             // the log-gap correction of the position update (position_update.h)
  bool holdContactGaps = true;       // contact gaps held at their straight-step value during it
  bool stresslets = false;           // per-particle stresslets (fluid, sub-grid, contact)
  ParticleVelocitySystem::Solver solver = ParticleVelocitySystem::cholmod;
  double tolerance = 1e-10;          // relative residual of the conjugate-gradient solve of Eq. (31)
  double coulombTolerance = ParticleVelocitySystem::Settings().coulombTolerance;
  bool coulombConsistent = false;    // coulomb_solve consistent|frozen (docs/contact.md 2c)
  bool contactChord = true;          // the chord term of the pair springs (Eq. C5 of docs/contact.md)
  long long checkpointEvery = 0;     // 0: no checkpoints
  std::string wallFile;              // the particles' loads on the walls (empty: none)
  double backgroundShear = 0;        // transport none: the simple shear the spheres' drag sees [1/s]
  long long fluidEvery = 1;          // the fluid solved every K-th particle step
  bool heldExtrapolated = false;     // held_drag extrapolated (else constant)

  bool hasFluid() const { return connection.transport != "none"; }
  // Eq. (31)'s settings but the fluid's values (alpha_lambda, rho_f), and the position update's
  ParticleVelocitySystem::Settings systemSettings() const;
  motion::Options moveOptions() const;
  // What the fix asks of the process's coupling session (coupling_session.h)
  LAMMPS_NS::CouplingSession::Request sessionRequest() const;
};

// The options of `args` (the keywords and their values), or KeywordError naming the first problem.
CoupleOptions parseCoupleOptions(const std::vector<std::string> &args);

}  // namespace fdm

#endif
