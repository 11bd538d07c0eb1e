// The coupling session of fdmDEM with the fluid solver (see coupling_session.h, docs/coupling.md).
#include "coupling_session.h"
#include "message_text.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "lammps.h"
#include "update.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <vector>

using namespace LAMMPS_NS;
namespace cpl = fdm::coupler;

namespace {

using fdm::text::number;

// If LIGGGHTS stops on an error (error->all exits), tell the fluid solver why it lost its peer
// rather than leave it to guess from a closed socket.
void tellPeerWeStopped()
{
  CouplingSession::instance().abandon("fdmDEM stopped before the end of its input (a LIGGGHTS error? see the fdmDEM "
                                      "log)");
}

}  // namespace

CouplingSession &CouplingSession::instance()
{
  static CouplingSession session;
  return session;
}

CouplingSession::CouplingSession() :
  owner_(nullptr), connected_(false), particles_(0), alphaLambda_(0), rhoFluid_(0), meshSize_(0), viscosity_(0),
  start_(0), runs_(0), steps_(0), totalSolve_(0), totalExchange_(0), totalGatherScatter_(0)
{
  for (int face = 0; face < 6; face++)
    for (int c = 0; c < 4; c++) faces_[face][c] = 0.0;
}

void CouplingSession::attach(const void *fix, const Request &request)
{
  owner_ = fix;
  request_ = request;
}

void CouplingSession::detach(const void *fix)
{
  if (owner_ == fix) owner_ = nullptr;
}

void CouplingSession::checkAtoms(LAMMPS *lmp) const
{
  Atom *atom = lmp->atom;
  Error *error = lmp->error;
  if (!atom->sphere_flag || !atom->radius_flag || !atom->rmass_flag || !atom->omega_flag || !atom->torque_flag ||
      !atom->density_flag)
    error->all(FLERR, "fix fdm/couple requires atom_style sphere (radius, mass, density, omega, torque)");
  if (atom->map_style != 1) error->all(FLERR, "fix fdm/couple requires atom_modify map array");
  if (!atom->tag_enable) error->all(FLERR, "fix fdm/couple requires atom IDs (tags)");
  if (atom->natoms > 100000000)
    error->all(FLERR, "fix fdm/couple: more than 10^8 particles are not supported by the coupling messages");
  if (atom->natoms > 0 && atom->map_tag_max != atom->natoms)
    error->all(FLERR, ("fix fdm/couple requires atom IDs 1..N without gaps: there are " +
                       std::to_string((long long) atom->natoms) + " atoms but the largest ID is " +
                       std::to_string(atom->map_tag_max) + " (use reset_atom_ids or renumber the data file)").c_str());
}

void CouplingSession::ensureConnected(LAMMPS *lmp, int nParticles)
{
  if (connected_) return;
  // The count is taken before a setup's re-partitioning (at fix init(), or now when the pair style
  // asks first): LIGGGHTS silently drops an atom put outside a non-periodic face, and the fix must
  // be able to name it.
  if (nParticles <= 0) {
    checkAtoms(lmp);
    nParticles = int(lmp->atom->natoms);
  }
  particles_ = nParticles;  // told to the fluid, for the session
  if (hasFluid()) {
    connectAndHandshake(lmp);
  } else {
    // DEM only: Eq. (31) with each particle's isolated Stokes resistance in place of the fluid's
    // (alpha_lambda = 1 s makes rho_f Vu / alpha_lambda = 6 pi eta a: fix fdm/couple's volumes)
    viscosity_ = request_.viscosity;
    meshSize_ = request_.meshSize;
    rhoFluid_ = request_.fluidDensity;
    alphaLambda_ = 1.0;
    for (int face = 0; face < 6; face++) {
      faces_[face][0] = lmp->domain->periodicity[face / 2] ? facePeriodic : faceNoFluid;
      for (int d = 0; d < 3; d++) faces_[face][1 + d] = 0.0;
    }
    if (lmp->comm->me == 0 && lmp->screen)
      fprintf(lmp->screen, "fdm/couple: transport none: DEM only, no fluid solver; each particle feels its isolated "
              "Stokes drag (viscosity %g Pa s) plus the pair style's forces and sub-grid lubrication (mesh size %g m)\n",
              viscosity_, meshSize_);
    start_ = MPI_Wtime();
  }
  connected_ = true;
}

void CouplingSession::connectAndHandshake(LAMMPS *lmp)
{
  const cpl::Options &options = request_.options;
  std::string problem;
  if (lmp->comm->me == 0) {
    try {
      if (lmp->screen)
        fprintf(lmp->screen, "fdm/couple: connecting to fdmFoam (%s%s)\n", options.transport.c_str(),
                options.transport == "file" ? (" in " + options.directory).c_str() :
                (" " + options.host + (options.portFile.empty() ? ":" + std::to_string(options.port) :
                                       ", port file " + options.portFile)).c_str());
      connection_ = cpl::connect(options);
      static bool hookRegistered = false;
      if (!hookRegistered) std::atexit(tellPeerWeStopped);
      hookRegistered = true;
      cpl::DemHello hello;
      hello.dt = lmp->update->dt;
      hello.lastStep = lmp->update->laststep;
      hello.stresslets = request_.stresslets;
      hello.resumeStep = resumeStep_;
      hello.checkpointEvery = request_.checkpointEvery;
      hello.nParticles = particles_;
      for (int d = 0; d < 3; d++) {
        hello.lo[d] = lmp->domain->boxlo[d];
        hello.hi[d] = lmp->domain->boxhi[d];
        hello.periodic[d] = lmp->domain->periodicity[d] != 0;
      }
      connection_->send(hello.toMessage());
      const cpl::FluidHello reply = cpl::FluidHello::fromMessage(connection_->receive(cpl::MessageType::Hello));
      problem = checkFluidHello(lmp, reply);
      if (problem.empty()) {
        alphaLambda_ = reply.alphaLambda;
        rhoFluid_ = reply.rhoFluid;
        meshSize_ = reply.delta;
        viscosity_ = reply.viscosity;
        for (int d = 0; d < 3; d++) gradP0_[d] = reply.gradP0[d];
        for (int face = 0; face < 6; face++) {
          faces_[face][0] = reply.faces[face].kind;
          for (int d = 0; d < 3; d++) faces_[face][1 + d] = reply.faces[face].velocity[d];
        }
        if (lmp->screen)
          fprintf(lmp->screen, "fdm/couple: connected (%s): %d particles, alpha_lambda %g s, rho_f %g kg/m3, "
                  "viscosity %g Pa s, mesh size %g m\n", connection_->describe().c_str(), particles_, alphaLambda_,
                  rhoFluid_, viscosity_, meshSize_);
      }
    } catch (const std::exception &e) {
      problem = e.what();
    }
  }
  stopIf(lmp, problem);
  MPI_Bcast(&alphaLambda_, 1, MPI_DOUBLE, 0, lmp->world);
  MPI_Bcast(&rhoFluid_, 1, MPI_DOUBLE, 0, lmp->world);
  MPI_Bcast(&meshSize_, 1, MPI_DOUBLE, 0, lmp->world);
  MPI_Bcast(&viscosity_, 1, MPI_DOUBLE, 0, lmp->world);
  MPI_Bcast(gradP0_, 3, MPI_DOUBLE, 0, lmp->world);
  MPI_Bcast(&faces_[0][0], 24, MPI_DOUBLE, 0, lmp->world);
  start_ = MPI_Wtime();
}

std::string CouplingSession::checkFluidHello(LAMMPS *lmp, const cpl::FluidHello &hello) const
{
  const Domain *domain = lmp->domain;
  // (the fluid checks the same and stops first with its own message; this is the DEM's side of it)
  if (hello.resumeStep != resumeStep_)
    return "fdmDEM resumes from the checkpoint of step " + std::to_string(resumeStep_) + " but fdmFoam from step " +
           std::to_string(hello.resumeStep) + " (0: a fresh start): resume both with fdmRun --resume";
  if (hello.nParticlesExpected >= 0 && hello.nParticlesExpected != particles_)
    return "the fluid case expects " + std::to_string(hello.nParticlesExpected) + " particles (constant/fdmProperties "
           "nParticles) but the LIGGGHTS input has " + std::to_string(particles_);
  if (!(hello.alphaLambda > 0) || !(hello.rhoFluid > 0) || !(hello.delta > 0) || !(hello.viscosity > 0))
    return "the fluid solver sent a non-positive alpha_lambda (" + number(hello.alphaLambda) + " s), rho_f (" +
           number(hello.rhoFluid) + " kg/m3), mesh size (" + number(hello.delta) + " m) or viscosity (" +
           number(hello.viscosity) + " Pa s)";
  const char *axis = "xyz";
  for (int d = 0; d < 3; d++) {
    const double lo = hello.lo[d], hi = hello.hi[d];
    const double tolerance = 1e-9 * std::max(std::fabs(domain->prd[d]), std::fabs(hi - lo));
    if (!(std::fabs(lo - domain->boxlo[d]) <= tolerance) || !(std::fabs(hi - domain->boxhi[d]) <= tolerance))
      return std::string(1, axis[d]) + " extent: LIGGGHTS box " + number(domain->boxlo[d]) + " .. " +
             number(domain->boxhi[d]) + " but OpenFOAM mesh " + number(lo) + " .. " + number(hi);
    if (hello.periodic[d] != (domain->periodicity[d] != 0))
      return std::string(1, axis[d]) + " boundary: LIGGGHTS " + (domain->periodicity[d] ? "periodic (p)" :
             "not periodic") + " but the OpenFOAM mesh " + (hello.periodic[d] ? "has cyclic patches" :
             "has no cyclic patches") + " in " + axis[d];
  }
  return "";
}

const char *CouplingSession::faceKindName(int kind)
{
  switch (kind) {
    case facePeriodic: return "a periodic (cyclic) boundary";
    case faceWall: return "a no-slip wall";
    case faceSlip: return "a slip wall";
  }
  return "another kind of boundary";
}

void CouplingSession::fluidFace(int face, int &kind, double velocity[3]) const
{
  kind = int(std::lround(faces_[face][0]));
  for (int d = 0; d < 3; d++) velocity[d] = faces_[face][1 + d];
}

void CouplingSession::abandon(const std::string &why)
{
  if (!connection_) return;
  connection_->sendError(why);
  connection_->close();
  connection_.reset();
}

void CouplingSession::stopIf(LAMMPS *lmp, const std::string &problemOnRank0)
{
  // The problem is known on rank 0 only; every rank must call error->all.
  int length = int(problemOnRank0.size());
  MPI_Bcast(&length, 1, MPI_INT, 0, lmp->world);
  if (length == 0) return;
  std::vector<char> text(problemOnRank0.begin(), problemOnRank0.end());
  text.resize(size_t(length) + 1, '\0');
  MPI_Bcast(text.data(), length, MPI_CHAR, 0, lmp->world);
  if (lmp->comm->me == 0) abandon("fdmDEM: " + problemOnRank0);
  lmp->error->all(FLERR, (std::string("fdm/couple: ") + text.data()).c_str());
}

void CouplingSession::addRun(long steps, double solve, double exchange, double gatherScatter)
{
  runs_++;
  steps_ += steps;
  totalSolve_ += solve;
  totalExchange_ += exchange;
  totalGatherScatter_ += gatherScatter;
}

void CouplingSession::addProfile(const fdm::ParticleStepProfile &run, long fluidSteps)
{
  totalProfile_.add(run);
  fluidSteps_ += fluidSteps;
}

std::string CouplingSession::whoseProfile(int ranks)
{
  return ranks == 1 ? std::string("one rank") : "rank 0's of " + std::to_string(ranks) + " ranks";
}

void CouplingSession::finishAll(LAMMPS *lmp)
{
  if (lmp->comm->me != 0 || !connection_) return;
  try {
    cpl::Finish finish;
    finish.step = lmp->update->ntimestep;
    connection_->send(finish.toMessage());
  } catch (const std::exception &e) {
    if (lmp->screen)
      fprintf(lmp->screen, "fdm/couple: WARNING: could not tell the fluid solver to finish: %s\n", e.what());
  }
  connection_->close();
  connection_.reset();
  const double wall = MPI_Wtime() - start_, percent = wall > 0 ? 100.0 / wall : 0.0;
  char line[512];
  std::snprintf(line, sizeof line,
                "fdm/couple timing total (%d run%s, %ld steps, %.4g s coupled): particle solve %.4g s (%.1f %%), "
                "exchange incl. fluid %.4g s (%.1f %%), gather/scatter %.4g s (%.1f %%)\n",
                runs_, runs_ == 1 ? "" : "s", steps_, wall, totalSolve_, totalSolve_ * percent, totalExchange_,
                totalExchange_ * percent, totalGatherScatter_, totalGatherScatter_ * percent);
  const std::string breakdown =
      line + totalProfile_.report("total, coupled", whoseProfile(lmp->comm->nprocs), wall, steps_, fluidSteps_);
  if (lmp->screen) fputs(breakdown.c_str(), lmp->screen);
  if (lmp->logfile) fputs(breakdown.c_str(), lmp->logfile);
}
