// fix fdm/couple: the particle side of the coupled FDM method (Orsi, Lobry & Peters 2023, 4.2-4.4).
// See fix_fdm_couple.h for what it does and docs/dem.md for its use.
#include "fix_fdm_couple.h"
#include "gather_to_root.h"

#include "coupling_session.h"
#include "message_text.h"
#include "pair_fdm_subgrid.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "dump.h"
#include "output.h"
#include "update.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

using namespace LAMMPS_NS;
namespace cpl = fdm::coupler;

namespace {

// Per-atom values gathered to rank 0: tag, then the fields of Particle (the contact stresslet
// only when stresslets are asked for).
const int gatherWidth = 19, gatherStressWidth = 6;

using fdm::text::number;
using fdm::text::particleId;
using fdm::text::point;

}  // namespace

FixFdmCouple::FixFdmCouple(LAMMPS *lmp, int narg, char **arg) :
  Fix(lmp, narg, arg), session_(CouplingSession::instance()), hasFluid_(true), move_(true), adamsBashforth_(true), gapUpdate_(true), holdContactGaps_(true), haveVelocities_(false), havePlan_(false), stresslets_(false), solver_(fdm::ParticleVelocitySystem::cholmod), tolerance_(1e-10), pair_(nullptr),
  atomsAtInit_(0), natoms_(0), lastIterations_(0), lastResidual_(0.0), notConverged_(0), runStart_(0.0),
  nmax_(0), perAtom_(nullptr), perAtomColumns_(12), solverIterations_(0), pairBlocks_(0),
  wallBlocks_(0), contacts_(0), wallOut_(nullptr), checkpointEvery_(0), checkpointSeconds_(0), resumed_(false)
{
  if (igroup != 0) error->all(FLERR, "fix fdm/couple must be applied to group all (every particle is in the fluid)");
  time_integrate = 1;
  vector_flag = 1;
  size_vector = 8;
  global_freq = 1;
  extvector = 0;
  peratom_flag = 1;
  size_peratom_cols = 12;
  peratom_freq = 1;
  gravity_[0] = gravity_[1] = gravity_[2] = 0.0;
  CouplingSession::Request request;
  cpl::Options &options = request.options;
  options.name = "fluid solver fdmFoam";

  for (int i = 3; i < narg; i++) {
    const std::string key = arg[i];
    auto value = [&](int n) -> const char * {
      if (i + n >= narg) error->all(FLERR, ("fix fdm/couple: keyword " + key + " needs a value").c_str());
      return arg[i + n];
    };
    if (key == "transport") {
      options.transport = value(1);
      if (options.transport != "socket" && options.transport != "file" && options.transport != "none")
        error->all(FLERR, ("fix fdm/couple: transport " + options.transport + " is not socket, file or none").c_str());
      i++;
    } else if (key == "host") { options.host = value(1); i++; }
    else if (key == "port") { options.port = force->inumeric(FLERR, value(1)); i++; }
    else if (key == "portfile") { options.portFile = value(1); i++; }
    else if (key == "directory") { options.directory = value(1); i++; }
    else if (key == "connect_timeout") { options.connectTimeout = force->numeric(FLERR, value(1)); i++; }
    else if (key == "timeout") { options.receiveTimeout = force->numeric(FLERR, value(1)); i++; }
    else if (key == "record") { options.recordFile = value(1); i++; }
    else if (key == "gravity") {
      for (int d = 0; d < 3; d++) gravity_[d] = force->numeric(FLERR, value(d + 1));
      i += 3;
    } else if (key == "move") {
      const std::string v = value(1);
      if (v != "yes" && v != "no") error->all(FLERR, "fix fdm/couple: move must be yes or no");
      move_ = (v == "yes");
      i++;
    } else if (key == "viscosity") {
      request.viscosity = force->numeric(FLERR, value(1));
      i++;
    } else if (key == "mesh") {
      request.meshSize = force->numeric(FLERR, value(1));
      i++;
    } else if (key == "fluid_density") {
      request.fluidDensity = force->numeric(FLERR, value(1));
      i++;
    } else if (key == "integrator") {
      const std::string v = value(1);
      if (v != "euler" && v != "ab2") error->all(FLERR, "fix fdm/couple: integrator must be euler or ab2");
      adamsBashforth_ = (v == "ab2");
      i++;
    } else if (key == "gap_update") {
      const std::string v = value(1);
      if (v != "log" && v != "none") error->all(FLERR, "fix fdm/couple: gap_update must be log or none");
      gapUpdate_ = (v == "log");
      i++;
    } else if (key == "contact_gaps") {
      const std::string v = value(1);
      if (v != "hold" && v != "free") error->all(FLERR, "fix fdm/couple: contact_gaps must be hold or free");
      holdContactGaps_ = (v == "hold");
      i++;
    } else if (key == "stresslets") {
      const std::string v = value(1);
      if (v != "yes" && v != "no") error->all(FLERR, "fix fdm/couple: stresslets must be yes or no");
      stresslets_ = (v == "yes");
      i++;
    } else if (key == "solver") {
      const std::string v = value(1);
      if (v != "cholmod" && v != "ldlt" && v != "cg")
        error->all(FLERR, "fix fdm/couple: solver must be cholmod, ldlt or cg");
      solver_ = v == "cholmod" ? fdm::ParticleVelocitySystem::cholmod
                               : v == "ldlt" ? fdm::ParticleVelocitySystem::ldlt : fdm::ParticleVelocitySystem::cg;
      i++;
    } else if (key == "checkpoint") {
      checkpointEvery_ = force->inumeric(FLERR, value(1));
      if (checkpointEvery_ < 0) error->all(FLERR, "fix fdm/couple: checkpoint N needs N >= 0 steps (0: none)");
      i++;
    } else if (key == "walls") {
      wallFile_ = value(1);
      if (wallFile_.empty()) error->all(FLERR, "fix fdm/couple: walls needs a file name");
      i++;
    } else if (key == "tolerance") {
      tolerance_ = force->numeric(FLERR, value(1));
      if (!(tolerance_ > 0 && tolerance_ < 1))
        error->all(FLERR, "fix fdm/couple: tolerance (relative residual of Eq. 31) must be in (0, 1)");
      i++;
    } else if (key == "contact_chord") {
      const std::string v = value(1);
      if (v != "yes" && v != "no") error->all(FLERR, "fix fdm/couple: contact_chord must be yes or no");
      contactChord_ = (v == "yes");
      i++;
    } else if (key == "background_shear") {
      backgroundShear_ = force->numeric(FLERR, value(1));
      if (!std::isfinite(backgroundShear_))
        error->all(FLERR, ("fix fdm/couple: background_shear needs a finite shear rate [1/s], got " +
                           std::string(value(1))).c_str());
      i++;
    } else if (key == "fluid_every") {
      fluidEvery_ = force->inumeric(FLERR, value(1));
      if (fluidEvery_ < 1)
        error->all(FLERR, ("fix fdm/couple: fluid_every K needs K >= 1 particle steps per fluid step, got " +
                           std::string(value(1))).c_str());
      i++;
    } else if (key == "held_drag") {
      const std::string v = value(1);
      if (v != "constant" && v != "extrapolated")
        error->all(FLERR, ("fix fdm/couple: held_drag must be constant or extrapolated, got " + v).c_str());
      heldExtrapolated_ = (v == "extrapolated");
      i++;
    } else if (key == "coulomb_tolerance") {
      coulombTolerance_ = force->numeric(FLERR, value(1));
      if (!(coulombTolerance_ > 0 && coulombTolerance_ < 1))
        error->all(FLERR, ("fix fdm/couple: coulomb_tolerance (of the sliding contacts' forces) must be in (0, 1), got " +
                           std::string(value(1))).c_str());
      i++;
    } else {
      error->all(FLERR, ("fix fdm/couple: unknown keyword " + key + " (see docs/dem.md)").c_str());
    }
  }
  perAtomColumns_ = stresslets_ ? 32 : 12;
  size_peratom_cols = perAtomColumns_;
  if (options.transport == "none" && (!(request.viscosity > 0) || !(request.meshSize > 0) || !(request.fluidDensity > 0)))
    error->all(FLERR, "fix fdm/couple transport none (DEM only, no fluid) needs viscosity eta [Pa s] and mesh Delta [m] "
                      "(the sub-grid model's mesh size), both positive; fluid_density (default 1000 kg/m3) too");
  if (options.transport != "none" && backgroundShear_ != 0)
    error->all(FLERR, "fix fdm/couple: background_shear goes with transport none (with the fluid solver the "
                      "walls drive the flow)");
  if (options.transport == "none" && fluidEvery_ > 1)
    error->all(FLERR, "fix fdm/couple: fluid_every goes with the fluid solver (transport none has no fluid step)");
  if (options.transport == "none" && stresslets_ && backgroundShear_ == 0)
    error->all(FLERR, "fix fdm/couple: stresslets need the fluid solver, or, with transport none, a "
                      "background_shear (the isolated sphere's stresslet in it)");
  if (options.transport == "socket" && (options.port <= 0 || options.port > 65535) && options.portFile.empty())
    error->all(FLERR, "fix fdm/couple: give the fluid solver's port (port P) or its port file (portfile F)");
  if (options.transport == "file" && options.directory.empty())
    error->all(FLERR, "fix fdm/couple: transport file needs directory D");
  if (!(options.connectTimeout > 0) || !(options.receiveTimeout > 0))
    error->all(FLERR, "fix fdm/couple: connect_timeout and timeout must be positive (seconds)");
  request.stresslets = stresslets_;
  request.checkpointEvery = checkpointEvery_;
  hasFluid_ = options.transport != "none";
  session_.attach(this, request);
  if (!session_.resumeFile().empty() && !session_.connected()) readResumeCheckpoint();
}

FixFdmCouple::~FixFdmCouple()
{
  session_.detach(this);
  memory->destroy(perAtom_);
  if (wallOut_) fclose(wallOut_);
}

int FixFdmCouple::setmask()
{
  // PRE_EXCHANGE: a resumed run restores its checkpoint in setup_pre_exchange
  return FixConst::INITIAL_INTEGRATE | FixConst::FINAL_INTEGRATE | FixConst::PRE_EXCHANGE;
}

void FixFdmCouple::init()
{
  session_.checkAtoms(lmp);
  atomsAtInit_ = int(atom->natoms);
  pair_ = dynamic_cast<PairFdmSubgrid *>(force->pair_match("fdm/subgrid", 1));
  if (pair_) pair_->requestContactStress(stresslets_);
  if (!wallFile_.empty() && (!pair_ || pair_->walls().empty()))
    error->all(FLERR, ("fix fdm/couple: walls " + wallFile_ + " needs pair_style fdm/subgrid with its walls "
                       "(wall FACE ux uy uz): there are no walls to write the loads of").c_str());
  if (force->newton_pair) error->all(FLERR, "fix fdm/couple requires newton off");
  if (std::strcmp(update->unit_style, "si") != 0)
    error->all(FLERR, (std::string("fix fdm/couple requires units si (the fluid solver works in SI), not units ") +
                       update->unit_style).c_str());
  if (!(update->dt > 0)) error->all(FLERR, "fix fdm/couple requires a positive timestep");
  // the contact springs' stability limit depends on the time step and on this fix's integrator
  if (pair_) pair_->checkTimeStep(update->dt, adamsBashforth_);
  for (int i = 0; i < modify->nfix; i++) {
    Fix *other = modify->fix[i];
    if (other == this) continue;
    if (std::strcmp(other->style, "fdm/couple") == 0)
      error->all(FLERR, "fix fdm/couple is defined twice: one coupled fluid, one fix");
    if (other->time_integrate)
      error->all(FLERR, (std::string("fix fdm/couple moves the particles itself (it replaces nve/sphere): remove fix ") +
                         other->id + " (" + other->style + ")").c_str());
    if (std::strcmp(other->style, "gravity") == 0)
      error->all(FLERR, (std::string("fix ") + other->id + " (gravity) adds the full weight m g without buoyancy: "
                         "use the gravity keyword of fix fdm/couple, which adds (rho_p - rho_f)/rho_p m g (Eq. 32)").c_str());
  }
  if (!comm->ghost_velocity && comm->me == 0)
    error->warning(FLERR, "fix fdm/couple: 'communicate single vel yes' is needed by the lubrication pair styles");
  // a resumed run continues the dumps of the interrupted one (fdmRun --resume cut them at the checkpoint)
  if (resume_)
    for (int i = 0; i < output->ndump; i++) {
      char append[] = "append", yes[] = "yes";
      char *args[] = {append, yes};
      output->dump[i]->modify_params(2, args);
    }
}

void FixFdmCouple::allAgree(const std::string &problemOnRank0)
{
  // The problem is known on rank 0 only; every rank must stop (and the fluid is told why).
  session_.stopIf(lmp, problemOnRank0);
}

void FixFdmCouple::fail(const std::string &message)
{
  // rank 0, in the middle of a step (the other ranks wait in MPI_Bcast): error->one aborts them all
  session_.abandon("fdmDEM: " + message);
  error->one(FLERR, ("fdm/couple: " + message).c_str());
}

void FixFdmCouple::gather(std::vector<Particle> &particles)
{
  const int nlocal = atom->nlocal;
  const bool withStress = stresslets_ && pair_;
  const int width = gatherWidth + (withStress ? gatherStressWidth : 0);
  std::vector<double> buf(size_t(width) * nlocal);
  for (int i = 0; i < nlocal; i++) {
    double *b = &buf[size_t(width) * i];
    *b++ = atom->tag[i];
    for (int d = 0; d < 3; d++) *b++ = atom->x[i][d];
    *b++ = atom->radius[i];
    for (int d = 0; d < 3; d++) *b++ = atom->v[i][d];
    for (int d = 0; d < 3; d++) *b++ = atom->omega[i][d];
    for (int d = 0; d < 3; d++) *b++ = atom->f[i][d];
    for (int d = 0; d < 3; d++) *b++ = atom->torque[i][d];
    *b++ = atom->rmass[i];
    *b++ = atom->density[i];
    if (withStress)
      for (int c = 0; c < 6; c++) *b++ = pair_->contactStress(i)[c];
  }
  const std::vector<double> all = fdm::gatherToRoot(buf, world);
  if (comm->me != 0) return;
  particles.assign(size_t(natoms_), Particle());
  std::vector<char> seen(size_t(natoms_), 0);
  for (size_t k = 0; k < all.size(); k += width) {
    const long tag = std::lround(all[k]);
    if (tag < 1 || tag > natoms_ || seen[tag - 1])
      fail("particle ID " + std::to_string(tag) + " is out of 1.." + std::to_string(natoms_) + " or twice in the system");
    seen[tag - 1] = 1;
    Particle &p = particles[tag - 1];
    const double *b = &all[k + 1];
    for (int d = 0; d < 3; d++) p.x[d] = *b++;
    p.radius = *b++;
    for (int d = 0; d < 3; d++) p.v[d] = *b++;
    for (int d = 0; d < 3; d++) p.omega[d] = *b++;
    for (int d = 0; d < 3; d++) p.f[d] = *b++;
    for (int d = 0; d < 3; d++) p.torque[d] = *b++;
    p.mass = *b++;
    p.density = *b++;
    for (int c = 0; c < 6; c++) p.contactStress[c] = withStress ? *b++ : 0.0;
  }
  for (int t = 0; t < natoms_; t++)
    if (!seen[t])
      fail("particle " + particleId(t) + " is missing: LIGGGHTS lost it (was it put or moved outside a non-periodic "
           "face of the box? " + std::to_string((long long) atom->natoms) + " atoms left of " + std::to_string(natoms_) +
           ")");
}

std::string FixFdmCouple::checkConfiguration(const std::vector<Particle> &particles, bool fromInput) const
{
  // rank 0. A particle through a wall, or two overlapping, would give a wrong flow silently.
  const char *axis = "xyz";
  for (size_t i = 0; i < particles.size(); i++) {
    const Particle &p = particles[i];
    const std::string who = "particle " + particleId(int(i)) + " at " + point(p.x) + " with radius " + number(p.radius);
    if (!(p.radius > 0) || !(p.density > 0) || !(p.mass > 0))
      return who + " has a non-positive radius, density (" + number(p.density) + ") or mass (" + number(p.mass) + ")";
    for (int d = 0; d < 3; d++) {
      const double lo = domain->boxlo[d], hi = domain->boxhi[d];
      if (!std::isfinite(p.x[d]) || p.x[d] < lo || p.x[d] > hi)
        return who + ": its centre lies outside the box in " + axis[d] + " (" + number(lo) + " .. " + number(hi) + ")";
      if (domain->periodicity[d]) {
        if (2 * p.radius > domain->prd[d])
          return who + " is larger than the periodic box in " + axis[d] + " (extent " + number(domain->prd[d]) +
                 "): it would overlap its own image";
      } else {
        // A configuration the input gave must be clear of the walls; a continuing or resumed run may
        // have a sphere pressed into one by its contact spring, as deep as both codes accept at any step.
        const bool low = p.x[d] - p.radius - lo < hi - p.x[d] - p.radius;
        const double gap = low ? p.x[d] - p.radius - lo : hi - p.x[d] - p.radius;
        const double allowed = fromInput ? 0.0 : cpl::contactOverlapTolerance * p.radius;
        if (gap < -allowed)
          return who + " crosses the wall " + axis[d] + " = " + number(low ? lo : hi) + " (non-periodic boundary; box " +
                 number(lo) + " .. " + number(hi) + "): gap " + number(gap) +
                 (fromInput ? std::string()
                            : " (" + number(-gap / p.radius) + " radii, more than the " +
                                  number(cpl::contactOverlapTolerance) + " radii accepted for a contact pressed into a wall)");
      }
    }
  }
  return fromInput ? findOverlap(particles) : std::string();
}

std::string FixFdmCouple::findOverlap(const std::vector<Particle> &p) const
{
  // Binned: bins at least 2 r_max wide, so overlapping pairs are in the same or adjacent bins;
  // sorting by bin and looking the 27 neighbours up is O(N log N).
  const long n = long(p.size());
  if (n < 2) return "";
  double rmax = 0;
  for (const Particle &q : p) rmax = std::max(rmax, q.radius);
  int bins[3];
  for (int d = 0; d < 3; d++) bins[d] = std::max(1, int(std::min(1e6, std::floor(domain->prd[d] / (2 * rmax)))));
  while (double(bins[0]) * bins[1] * bins[2] > 8.0 * n + 64)
    for (int d = 0; d < 3; d++) bins[d] = std::max(1, bins[d] / 2);
  auto binOf = [&](const double *x, int d) {
    double s = (x[d] - domain->boxlo[d]) / domain->prd[d];
    if (domain->periodicity[d]) s -= std::floor(s);
    return std::min(bins[d] - 1, std::max(0, int(s * bins[d])));
  };
  auto key = [&](int bx, int by, int bz) { return (long long)(bx * (long long) bins[1] + by) * bins[2] + bz; };
  std::vector<std::pair<long long, long> > sorted(n);
  for (long i = 0; i < n; i++) sorted[i] = std::make_pair(key(binOf(p[i].x, 0), binOf(p[i].x, 1), binOf(p[i].x, 2)), i);
  std::sort(sorted.begin(), sorted.end());

  long firstI = -1, firstJ = -1, pairs = 0;
  double firstGap = 0;
  std::vector<long long> neighbours;
  for (long i = 0; i < n; i++) {
    const int b[3] = {binOf(p[i].x, 0), binOf(p[i].x, 1), binOf(p[i].x, 2)};
    neighbours.clear();
    for (int dx = -1; dx <= 1; dx++)
      for (int dy = -1; dy <= 1; dy++)
        for (int dz = -1; dz <= 1; dz++) {
          int c[3] = {b[0] + dx, b[1] + dy, b[2] + dz};
          bool inside = true;
          for (int d = 0; d < 3; d++) {
            if (domain->periodicity[d]) c[d] = (c[d] + bins[d]) % bins[d];
            else if (c[d] < 0 || c[d] >= bins[d]) inside = false;
          }
          if (inside) neighbours.push_back(key(c[0], c[1], c[2]));
        }
    std::sort(neighbours.begin(), neighbours.end());
    neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
    for (long long k : neighbours) {
      auto range = std::equal_range(sorted.begin(), sorted.end(), std::make_pair(k, -1L),
          [](const std::pair<long long, long> &a, const std::pair<long long, long> &c) { return a.first < c.first; });
      for (auto it = range.first; it != range.second; ++it) {
        const long j = it->second;
        if (j <= i) continue;
        double r2 = 0;
        for (int d = 0; d < 3; d++) {
          double dx = p[j].x[d] - p[i].x[d];
          if (domain->periodicity[d]) dx -= domain->prd[d] * std::round(dx / domain->prd[d]);  // minimum image
          r2 += dx * dx;
        }
        const double gap = std::sqrt(r2) - p[i].radius - p[j].radius;
        if (gap < 0) {
          pairs++;
          if (firstI < 0 || i < firstI || (i == firstI && j < firstJ)) { firstI = i; firstJ = j; firstGap = gap; }
        }
      }
    }
  }
  if (pairs == 0) return "";
  return "particles " + particleId(int(firstI)) + " and " + particleId(int(firstJ)) + " overlap: centres " +
         point(p[firstI].x) + " and " + point(p[firstJ].x) + ", radii " + number(p[firstI].radius) + " and " +
         number(p[firstJ].radius) + ", surface gap " + number(firstGap) +
         (pairs > 1 ? " (" + std::to_string(pairs) + " overlapping pairs in all)" : std::string());
}

void FixFdmCouple::setup(int)
{
  // Called before every run (not with 'run N pre no'): connect once, then check the particles
  // wherever the input has put them since (set atom ... between runs).
  const bool firstSetup = !session_.connected();
  // `run N` instead of `run L upto` would run N steps more: the last step is checked against the
  // checkpoint's, or against -until's where the run was extended on purpose
  const long long until = session_.resumeUntil();
  if (resume_ && until > 0 && update->laststep != until)
    allAgree(comm->me != 0 ? std::string() :
             "resuming at step " + std::to_string(resume_->step) + " from " + resumeFile_ + " to step " +
             std::to_string(until) + " (-until) but this run command ends at step " +
             std::to_string((long long) update->laststep) + ": write it 'run " + std::to_string(until) +
             " upto' (fdmRun --resume --until does; docs/coupling.md)");
  if (resume_ && until == 0 && update->laststep != resume_->lastStep)
    allAgree(comm->me != 0 ? std::string() :
             "resuming at step " + std::to_string(resume_->step) + " from " + resumeFile_ + ": the run it belongs "
             "to ends at step " + std::to_string(resume_->lastStep) + " but this run command ends at step " +
             std::to_string((long long) update->laststep) + ": write it 'run " + std::to_string(resume_->lastStep) +
             " upto' (a resumed input runs to the same last step; fdmRun --resume --until L extends it to L; "
             "docs/coupling.md)");
  resume_.reset();
  // the count of init(): LIGGGHTS may have dropped an atom since, which gather() must name
  session_.ensureConnected(lmp, atomsAtInit_);
  natoms_ = session_.particles();
  // fewer atoms than announced: gather() names the particle LIGGGHTS lost
  if (atom->natoms > natoms_ || atom->map_tag_max > natoms_)
    allAgree("the particles changed since the coupling started: " + std::to_string((long long) atom->natoms) +
             " atoms with IDs up to " + std::to_string(atom->map_tag_max) + " where the fluid solver was told of " +
             std::to_string(natoms_) + " (particles cannot be inserted during a coupled session)");
  if (solution_.size() != size_t(6) * natoms_) {
    solution_.assign(size_t(6) * natoms_, 0.0);
    hydro_.assign(size_t(6) * natoms_, 0.0);
    fluidStress_.assign(size_t(7) * natoms_, 0.0);
    subgrid_.assign(size_t(6) * natoms_, 0.0);
    stress_.assign(size_t(20) * natoms_, 0.0);
  }
  std::vector<Particle> particles;
  gather(particles);
  // Overlaps and wall crossings are input errors in the configuration the input script gave (first
  // run, or positions set between runs of fixed particles); later runs, and a resumed session,
  // continue from where contacts (h_r > 0, finite kn) may legitimately have pressed particles a little
  // into each other or into a wall.
  allAgree(comm->me == 0 ? checkConfiguration(particles, (firstSetup && !resumed_) || !move_) : std::string());
  // A planned position update continues the previous run only from where that run left the
  // particles: if the input has moved them since (set, displace_atoms, read_restart ...), the next
  // step starts afresh (Euler from the current velocities, then Adams-Bashforth again).
  int keepPlan = havePlan_ ? 1 : 0;
  if (comm->me == 0 && keepPlan) {
    for (int p = 0; p < natoms_ && keepPlan; p++) {
      double d[3];
      for (int k = 0; k < 3; k++) d[k] = particles[p].x[k] - planPositions_[size_t(3) * p + k];
      domain->minimum_image(d);
      if (std::fabs(d[0]) + std::fabs(d[1]) + std::fabs(d[2]) > 1e-12 * (1.0 + std::fabs(particles[p].x[0]) +
                                                                      std::fabs(particles[p].x[1]) + std::fabs(particles[p].x[2])))
        keepPlan = 0;
    }
  }
  MPI_Bcast(&keepPlan, 1, MPI_INT, 0, world);
  if (!keepPlan) {
    havePlan_ = false;
    haveVelocities_ = false;
    previousVelocity_.clear();
    planPositions_.clear();
  }
  fillPerAtomArray();
  runStart_ = MPI_Wtime();
  run_ = Timing();
}

void FixFdmCouple::initial_integrate(int)
{
  // Step 1 of the algorithm (4.3): move the particles. Nothing else: there is no particle inertia
  // (Eqs. 28d-e). The displacement rates were planned at the end of the previous step
  // (planNextMove: Adams-Bashforth 2 with the log-gap correction of position_update.h); the very
  // first step moves with the velocities the input gave.
  if (!move_) return;
  const double dt = update->dt;
  for (int i = 0; i < atom->nlocal; i++) {
    if (havePlan_) {
      // v and omega become the rates of this move, so that the contact springs of the pair style
      // (tangential displacement += dt v_rel) follow the contact points exactly; the solve at the
      // end of the step sets them to U_{n+1} again
      const double *rate = &moveRate_[size_t(6) * (atom->tag[i] - 1)];
      for (int d = 0; d < 3; d++) {
        atom->v[i][d] = rate[d];
        atom->omega[i][d] = rate[3 + d];
      }
    }
    for (int d = 0; d < 3; d++) atom->x[i][d] += dt * atom->v[i][d];
  }
}

cpl::Step FixFdmCouple::makeStep(const std::vector<Particle> &particles) const
{
  cpl::Step step;
  step.step = update->ntimestep;
  // the fluid's step spans the particle steps since its last one (fluid_every K)
  step.dt = lastFluidStep_ >= 0 && update->ntimestep > lastFluidStep_ ? double(update->ntimestep - lastFluidStep_) * update->dt
                                                                      : update->dt;
  step.lastStep = update->laststep;
  step.checkpoint = checkpointDue();  // the fluid writes its own at the end of this step
  step.particles.resize(natoms_);
  const bool solved = currentVelocity_.size() == size_t(6) * natoms_;
  for (int p = 0; p < natoms_; p++) {
    const Particle &q = particles[p];
    cpl::StepParticle &out = step.particles[p];
    out.tag = p + 1;
    for (int d = 0; d < 3; d++) {
      // LIGGGHTS wraps periodic coordinates only when it re-neighbours: the fluid gets them in the box
      double x = q.x[d];
      if (domain->periodicity[d]) x -= domain->prd[d] * std::floor((x - domain->boxlo[d]) / domain->prd[d]);
      out.x[d] = x;
      // the last solved velocities U_n (v may hold this step's Adams-Bashforth displacement rate)
      out.velocity.U[d] = solved ? currentVelocity_[size_t(6) * p + d] : q.v[d];
      out.velocity.omega[d] = solved ? currentVelocity_[size_t(6) * p + 3 + d] : q.omega[d];
    }
    out.radius = q.radius;
  }
  return step;
}

void FixFdmCouple::assembleSystem(const std::vector<Particle> &particles)
{
  // Every rank builds the sub-grid blocks of its own pairs and wall gaps from its neighbour list;
  // rank 0 collects them and assembles Eq. (31) once for the step (paper section 4.4.2).
  std::vector<double> pairs, walls, allPairs, allWalls, wallIndex;
  long contacts = 0;
  if (pair_) {
    pair_->collectBlocks(stresslets_, pairs, walls, wallFile_.empty() ? nullptr : &wallIndex);
    contacts = pair_->contactsLast();
  }
  checkOverlaps();
  allPairs = fdm::gatherToRoot(pairs, world);
  allWalls = fdm::gatherToRoot(walls, world);
  // implicit contact springs (docs/contact.md 2b): c1 the weight of U_{n+1} in the next position
  // update (planNextMove: ab2 once a previous step exists), gamma = -c0/c1 the weight of U_n
  fdm::ParticleVelocitySystem::Springs springs;
  // decided on rank 0, which plans the position update (planPositions_ is rank 0's alone): every
  // rank must build its spring blocks with the same weight
  int multistepFlag = adamsBashforth_ && havePlan_ && haveVelocities_ && planPositions_.size() == size_t(3) * natoms_;
  MPI_Bcast(&multistepFlag, 1, MPI_INT, 0, world);
  const bool multistep = multistepFlag != 0;
  springWallBlockWall_.clear();
  if (pair_ && pair_->implicitContact() && move_) {
    std::vector<double> springPairs, springWalls;
    std::vector<double> springWallIndex;
    pair_->collectSpringBlocks(multistep ? 1.5 : 1.0, update->dt, springPairs, springWalls,
                               wallFile_.empty() ? nullptr : &springWallIndex);
    springs.pairs = fdm::gatherToRoot(springPairs, world);
    springs.walls = fdm::gatherToRoot(springWalls, world);
    if (!wallFile_.empty()) springWallBlockWall_ = fdm::gatherToRoot(springWallIndex, world);
    // Eq. (C5): the straight step's chord of a sliding or rolling pair, in its normal spring, from
    // U_n (kept in the checkpoints: a resumed run takes the same chord terms)
    const bool chord = contactChord_ && haveVelocities_ && currentVelocity_.size() == size_t(6) * natoms_;
    if (multistep) springs.gamma = 1.0 / 3.0;
    if (chord) springs.dt = update->dt;
    if (multistep || chord) springs.previous = currentVelocity_;
  }
  if (!wallFile_.empty()) {
    // the wall of each block, gathered in the same rank order as the blocks; the contact loads summed
    wallBlockWall_ = fdm::gatherToRoot(wallIndex, world);
    const std::vector<double> &local = pair_->wallContactLoads();
    std::vector<double> loads(3 * pair_->walls().size(), 0.0);
    for (size_t k = 0; k < loads.size() && k < local.size(); k++) loads[k] = local[k];
    wallContact_.assign(loads.size(), 0.0);
    MPI_Reduce(loads.data(), wallContact_.data(), int(loads.size()), MPI_DOUBLE, MPI_SUM, 0, world);
  }
  MPI_Reduce(&contacts, &contacts_, 1, MPI_LONG, MPI_SUM, 0, world);
  if (comm->me != 0) return;

  std::vector<fdm::ParticleVelocitySystem::Particle> loads(natoms_);
  for (int p = 0; p < natoms_; p++) {
    const Particle &q = particles[p];
    fdm::ParticleVelocitySystem::Particle &l = loads[p];
    for (int d = 0; d < 3; d++) {
      l.x[d] = q.x[d];
      l.force[d] = q.f[d];
      l.torque[d] = q.torque[d];
    }
    l.radius = q.radius;
    l.mass = q.mass;
    l.density = q.density;
  }
  if (move_ && session_.hasFluid() && domain->xperiodic && domain->yperiodic && domain->zperiodic)
    checkPeriodicBalance(particles);
  try {
    if (!system_) {
      fdm::ParticleVelocitySystem::Settings settings;
      settings.solver = solver_;
      settings.tolerance = tolerance_;
      settings.coulombTolerance = coulombTolerance_;
      settings.alphaLambda = session_.alphaLambda();
      settings.rhoFluid = session_.rhoFluid();
      for (int d = 0; d < 3; d++) settings.gravity[d] = gravity_[d];
      settings.stresslets = stresslets_;
      system_.reset(new fdm::ParticleVelocitySystem(settings));
    }
    system_->assemble(std::move(loads), std::move(allPairs), std::move(allWalls), std::move(springs));
  } catch (const fdm::ParticleVelocitySystem::Error &e) {
    fail(e.what());
  }
  pairBlocks_ = system_->pairBlocks();
  wallBlocks_ = system_->wallBlocks();
}

std::string FixFdmCouple::systemProblem(const fdm::ParticleVelocitySystem::Error &e, uint64_t step,
                                        uint32_t iteration) const
{
  // what the system cannot know: the mesh size, and when (iteration 0: the step's Volumes)
  if (e.kind == fdm::ParticleVelocitySystem::Error::noVolume)
    return std::string(e.what()) + ": is it smaller than a mesh cell (" + number(session_.meshSize()) + ")?";
  if (e.kind == fdm::ParticleVelocitySystem::Error::fluidValue)
    return std::string(e.what()) + " at step " + std::to_string(step) +
           (iteration > 0 ? ", inner iteration " + std::to_string(iteration) : std::string());
  return e.what();
}

void FixFdmCouple::setVolumes(const cpl::Volumes &volumes)
{
  // Eq. (31)'s rigid-body blocks and their factorisation, once per time step (they depend only on the
  // positions)
  std::vector<fdm::ParticleVelocitySystem::RigidVolume> rigid(natoms_);
  for (int p = 0; p < natoms_; p++) {
    const cpl::ParticleVolume &v = volumes.particles[p];
    rigid[p].Vu = v.Vu;
    std::copy(v.m1, v.m1 + 3, rigid[p].m1);
    std::copy(v.J, v.J + 6, rigid[p].J);
  }
  try {
    system_->setVolumes(rigid);
  } catch (const fdm::ParticleVelocitySystem::Error &e) {
    fail(systemProblem(e, volumes.step, 0));
  }
}

void FixFdmCouple::solveVelocities(const cpl::Integrals &integrals)
{
  // Eq. (31) for the integrals of one inner iteration (particle_velocity_system.h)
  std::vector<double> fluid(size_t(6) * natoms_);
  for (int p = 0; p < natoms_; p++)
    for (int d = 0; d < 3; d++) {
      fluid[size_t(6) * p + d] = integrals.particles[p].F[d];
      fluid[size_t(6) * p + 3 + d] = integrals.particles[p].T[d];
    }
  try {
    solution_ = system_->solve(fluid);
  } catch (const fdm::ParticleVelocitySystem::Error &e) {
    fail(systemProblem(e, integrals.step, integrals.iteration));
  }
  const long iterations = system_->lastIterations();
  run_.coulombRoundsMax = std::max(run_.coulombRoundsMax, system_->lastRounds());
  run_.solves++;
  run_.solverIterations += iterations;
  run_.solverIterationsMax = std::max(run_.solverIterationsMax, iterations);
  solverIterations_ = std::max(solverIterations_, iterations);
}

cpl::Volumes FixFdmCouple::noFluidVolumes(const std::vector<Particle> &particles) const
{
  // transport none: "volumes" of an isolated sphere in a fluid at rest, so that Eq. (31) reads
  // [diag(6 pi eta a, 8 pi eta a^3) + R^SG] u = F^c + F^ext + buoyant weight
  const double pi = 3.14159265358979323846;
  const double eta = session_.viscosity(), alpha = session_.alphaLambda(), rho = session_.rhoFluid();
  cpl::Volumes m;
  m.step = update->ntimestep;
  m.particles.resize(natoms_);
  for (int p = 0; p < natoms_; p++) {
    const double a = particles[p].radius;
    m.particles[p].Vu = 6 * pi * eta * a * alpha / rho;
    m.particles[p].J[0] = m.particles[p].J[3] = m.particles[p].J[5] = 8 * pi * eta * a * a * a * alpha / rho;
  }
  return m;
}

void FixFdmCouple::backgroundFlow(const std::vector<Particle> &particles, cpl::Integrals &integrals)
{
  // transport none with background_shear G: each isolated sphere's drag is taken relative to the simple
  // shear u = G (y - y_centre) e_x, whose vorticity turns it at Omega = -G/2 e_z, so the fluid's part of
  // Eq. (31) is 6 pi eta a u(x_p) and 8 pi eta a^3 Omega; with stresslets, the sphere's own stresslet
  // in it, (20/3) pi eta a^3 E with E_xy = G/2 (Kim & Karrila's S, docs/dem.md). Frame-invariant
  // sub-grid lubrication and the springs act on the velocities as with the fluid: the particle side of
  // a sheared suspension without the fluid solver (docs/benchmarks.md, "Without the fluid").
  const double pi = 3.14159265358979323846, eta = session_.viscosity(), G = backgroundShear_;
  const double yCentre = 0.5 * (domain->boxlo[1] + domain->boxhi[1]);
  for (int p = 0; p < natoms_; p++) {
    const double a = particles[p].radius;
    integrals.particles[p].F[0] = 6 * pi * eta * a * G * (particles[p].x[1] - yCentre);
    integrals.particles[p].T[2] = -8 * pi * eta * a * a * a * 0.5 * G;
    if (stresslets_) {   // order xx xy xz yy yz zz, then the trace
      std::fill(&fluidStress_[size_t(7) * p], &fluidStress_[size_t(7) * p] + 7, 0.0);
      fluidStress_[size_t(7) * p + 1] = (10.0 / 3.0) * pi * eta * a * a * a * G;
    }
  }
}

void FixFdmCouple::subgridResults(const std::vector<Particle> &particles)
{
  // rank 0, after the last inner iteration: the sub-grid force and torque (Eq. 21 and D.6) and,
  // when asked, the particle stresslets: S^h = S^FDM + S^SG, s^h = s^FDM + s^SG (Eq. 13), S^c (Eq. 52).
  subgrid_ = system_->subgridForces();
  run_.contactSlides += system_->slidingSwitches();
  run_.chordForceMax = std::max(run_.chordForceMax, system_->largestChordForce());
  run_.factorisations += system_->factorisations() - factorisationsCounted_;
  factorisationsCounted_ = system_->factorisations();
  run_.downdates += system_->downdates() - downdatesCounted_;
  downdatesCounted_ = system_->downdates();
  run_.backSubstitutions += system_->backSubstitutions() - backSubstitutionsCounted_;
  backSubstitutionsCounted_ = system_->backSubstitutions();
  // the implicit part of the contact forces (Eq. C2) and of their stresslet (Eq. 52)
  std::vector<double> springStress(size_t(6) * natoms_, 0.0);
  springs_ = system_->springForces(stresslets_ ? &springStress : nullptr,
                                   springWallBlockWall_.empty() ? nullptr : &springWallForces_);
  if (!stresslets_) return;
  std::vector<double> subgrid(size_t(7) * natoms_, 0.0);  // S^SG, s^SG: 7 per particle
  system_->addSubgridStresslets(subgrid);
  for (int p = 0; p < natoms_; p++) {
    double *out = &stress_[size_t(20) * p];
    for (int c = 0; c < 7; c++) out[c] = fluidStress_[size_t(7) * p + c] + subgrid[size_t(7) * p + c];
    for (int c = 0; c < 6; c++) out[7 + c] = particles[p].contactStress[c] + springStress[size_t(6) * p + c];
    for (int c = 0; c < 7; c++) out[13 + c] = subgrid[size_t(7) * p + c];
  }
}

void FixFdmCouple::storeStepDone(const cpl::StepDone &done)
{
  for (int p = 0; p < natoms_; p++) {
    for (int d = 0; d < 3; d++) {
      hydro_[size_t(6) * p + d] = done.forces[p].F[d];
      hydro_[size_t(6) * p + 3 + d] = done.forces[p].T[d];
    }
    if (stresslets_) {
      for (int c = 0; c < 6; c++) fluidStress_[size_t(7) * p + c] = done.stresslets[p].S[c];
      fluidStress_[size_t(7) * p + 6] = done.stresslets[p].trace;
    }
  }
  lastIterations_ = int(done.iterations);
  lastResidual_ = done.residual;
  if (!done.converged) notConverged_++;
}

void FixFdmCouple::final_integrate()
{
  // Steps 3-7 of the algorithm (4.3) seen from the particles: once per time step, after LIGGGHTS
  // has summed every force. Rank 0 talks to the fluid and solves; the result is broadcast.
  double t0 = MPI_Wtime();
  std::vector<Particle> particles;
  gather(particles);
  run_.gatherScatter += MPI_Wtime() - t0;
  t0 = MPI_Wtime();
  solverIterations_ = 0;
  assembleSystem(particles);
  run_.solve += MPI_Wtime() - t0;

  const bool fluidStep = hasFluid_ && fluidStepDue();
  if (comm->me == 0 && hasFluid_ && !fluidStep) {
    t0 = MPI_Wtime();
    frozenFluidStep(particles);
    run_.solve += MPI_Wtime() - t0;
  } else if (comm->me == 0 && !hasFluid_) {
    t0 = MPI_Wtime();
    setVolumes(noFluidVolumes(particles));
    cpl::Integrals atRest;  // no fluid: no fluid force
    atRest.step = update->ntimestep;
    atRest.iteration = 1;
    atRest.particles.assign(natoms_, cpl::ForceTorque());
    if (backgroundShear_ != 0) backgroundFlow(particles, atRest);
    solveVelocities(atRest);
    const std::vector<double> drag = system_->rigidBlocksTimes(solution_);
    for (int p = 0; p < natoms_; p++)  // the far-field (Stokes) force: F = 6 pi eta a (u_background - U)
      for (int d = 0; d < 3; d++) {
        hydro_[size_t(6) * p + d] = atRest.particles[p].F[d] - drag[size_t(6) * p + d];
        hydro_[size_t(6) * p + 3 + d] = atRest.particles[p].T[d] - drag[size_t(6) * p + 3 + d];
      }
    subgridResults(particles);
    lastIterations_ = 1;
    run_.solve += MPI_Wtime() - t0;
  } else if (comm->me == 0) {
    cpl::Transport *connection = session_.transport();
    if (!connection) fail("the connection to the fluid solver is closed");
    const bigint step = update->ntimestep;
    // the next message of this step from the fluid, of the expected type
    auto receive = [&](bool volumes) {
      const cpl::Message m = connection->receive();
      const bool expected = volumes ? m.type == cpl::MessageType::Volumes :
                            m.type == cpl::MessageType::Integrals || m.type == cpl::MessageType::StepDone;
      if (!expected)
        fail(std::string("coupling: expected ") + (volumes ? "Volumes" : "Integrals or StepDone") +
             " from the fluid solver, got " + cpl::messageTypeName(m.type) + " (step " +
             std::to_string((long long) step) + ")");
      if (m.step != uint64_t(step))
        fail(std::string("coupling: the fluid solver sent ") + cpl::messageTypeName(m.type) + " of step " +
             std::to_string(m.step) + " during step " + std::to_string((long long) step));
      return m;
    };
    try {
      t0 = MPI_Wtime();
      connection->send(makeStep(particles).toMessage());
      // Protocol 3: the volumes (Vu, m1, J since protocol 4) once per step, before the first Integrals
      const cpl::Message volumes = receive(true);
      double t1 = MPI_Wtime();
      run_.exchange += t1 - t0;
      setVolumes(cpl::Volumes::fromMessage(volumes, natoms_));
      t0 = MPI_Wtime();
      run_.solve += t0 - t1;
      while (true) {
        const cpl::Message m = receive(false);
        t1 = MPI_Wtime();
        run_.exchange += t1 - t0;
        if (m.type == cpl::MessageType::StepDone) {
          storeStepDone(cpl::StepDone::fromMessage(m, stresslets_, natoms_));
          subgridResults(particles);
          run_.solve += MPI_Wtime() - t1;
          break;
        }
        const cpl::Integrals integrals = cpl::Integrals::fromMessage(m, natoms_);
        solveVelocities(integrals);
        cpl::Velocities reply;
        reply.step = integrals.step;
        reply.iteration = integrals.iteration;
        reply.particles.resize(natoms_);
        for (int p = 0; p < natoms_; p++)
          for (int d = 0; d < 3; d++) {
            reply.particles[p].U[d] = solution_[size_t(6) * p + d];
            reply.particles[p].omega[d] = solution_[size_t(6) * p + 3 + d];
          }
        t0 = MPI_Wtime();
        run_.solve += t0 - t1;
        connection->send(reply.toMessage());
      }
    } catch (const std::exception &e) {
      fail(e.what());
    }
  }

  if (!wallFile_.empty() && comm->me == 0) writeWallLoads();
  if (move_ && comm->me == 0) {
    t0 = MPI_Wtime();
    planNextMove(particles);
    run_.solve += MPI_Wtime() - t0;
  }
  t0 = MPI_Wtime();
  scatter();
  run_.gatherScatter += MPI_Wtime() - t0;
  run_.steps++;
  if (fluidStep) {
    run_.fluidSteps++;
    lastFluidStep_ = update->ntimestep;
  }
  if (checkpointDue()) writeCheckpoint();
}

bool FixFdmCouple::fluidStepDue() const
{
  // fluid_every K: the fluid is solved at every K-th step, and always where the particle side has no
  // fluid solution to hold yet (a run's first step), at a checkpoint (the fluid writes its own at the
  // same step, so that a resumed run continues both from one step) and at the last step of a run
  if (fluidEvery_ <= 1 || lastFluidStep_ < 0 || !haveVelocities_ || hydro_.size() != size_t(6) * natoms_) return true;
  const bigint step = update->ntimestep;
  return step % fluidEvery_ == 0 || step == update->laststep || checkpointDue();
}

void FixFdmCouple::frozenFluidStep(const std::vector<Particle> &particles)
{
  // rank 0, a step between fluid steps (fluid_every K, docs/dem.md "Particle steps between fluid
  // steps"): the fluid's force on each particle is held as the Stokes drag of an isolated sphere toward
  // the velocity u_b it saw at the last fluid step, F = 6 pi eta a (U_b - U), T = 8 pi eta a^3
  // (Omega_b - Omega), with U_b = U + F^FDM/(6 pi eta a) from that step's converged U and F^FDM (and
  // the same for Omega), so that Eq. (31) at unchanged positions gives that step's velocities again (to
  // the inner iteration's tolerance).
  // R^SG, the contact springs and the position update follow the particles as in every step: they
  // change within a fluid step, where the far field does not. The sphere's drag D U_b = D U + F is the
  // same whichever step of the cycle it is taken from (between fluid steps F = D (U_b - U)), so U_b
  // needs no state of its own and a resumed run rebuilds it from U and F of its checkpoint.
  setVolumes(noFluidVolumes(particles));   // Eq. (31)'s rigid-body blocks become D
  const std::vector<double> dragTimesLastU = system_->rigidBlocksTimes(currentVelocity_);
  cpl::Integrals held;
  held.step = update->ntimestep;
  held.iteration = 1;
  held.particles.resize(natoms_);
  for (int p = 0; p < natoms_; p++)
    for (int d = 0; d < 3; d++) {   // D U_b = D U + F^FDM
      held.particles[p].F[d] = dragTimesLastU[size_t(6) * p + d] + hydro_[size_t(6) * p + d];
      held.particles[p].T[d] = dragTimesLastU[size_t(6) * p + 3 + d] + hydro_[size_t(6) * p + 3 + d];
    }
  if (heldExtrapolated_) extrapolateHeldDrag(held);
  solveVelocities(held);
  const std::vector<double> dragTimesU = system_->rigidBlocksTimes(solution_);
  for (int p = 0; p < natoms_; p++)
    for (int d = 0; d < 3; d++) {
      hydro_[size_t(6) * p + d] = held.particles[p].F[d] - dragTimesU[size_t(6) * p + d];
      hydro_[size_t(6) * p + 3 + d] = held.particles[p].T[d] - dragTimesU[size_t(6) * p + 3 + d];
    }
  // the fluid's stresslets (fluidStress_) stay those of the last fluid step; the sub-grid and contact
  // ones follow the particles
  subgridResults(particles);
  lastIterations_ = 0;
}

void FixFdmCouple::extrapolateHeldDrag(cpl::Integrals &held)
{
  // rank 0, held_drag extrapolated (docs/dem.md, "Particle steps between fluid steps"): the drag target
  // D U_b of a held step is extrapolated linearly in time from the last two fluid steps, s_n and s_{n-1}:
  // D U_b(s) = b_n + f (b_n - b_{n-1}), f = (s - s_n)/(s_n - s_{n-1}), at most 1. The fluid's force on a
  // particle changes along the step as the particles move (a pair turning about its contact sees the
  // normal load of the shear change sign): held constant that change is lost for K - 1 steps, first order
  // in the fluid's step; extrapolated it is lost to second order. b_n is D U + F^FDM of the fluid step,
  // which held carries at the first held step after it (the same at every held step for constant drag).
  if (heldDragStep_ != lastFluidStep_) {
    heldDragBefore_.swap(heldDrag_);
    heldDragStepBefore_ = heldDragStep_;
    heldDrag_.assign(size_t(6) * natoms_, 0.0);
    for (int p = 0; p < natoms_; p++)
      for (int d = 0; d < 3; d++) {
        heldDrag_[size_t(6) * p + d] = held.particles[p].F[d];
        heldDrag_[size_t(6) * p + 3 + d] = held.particles[p].T[d];
      }
    heldDragStep_ = lastFluidStep_;
  }
  // a fluid step forced between the regular ones (a run's end, a checkpoint) leaves a short interval:
  // f is capped at 1 so that its slope is not stretched over a longer one
  const bool twoSteps = heldDragStepBefore_ >= 0 && heldDragStepBefore_ < heldDragStep_ &&
                        heldDragBefore_.size() == heldDrag_.size();
  const double f = twoSteps ? std::min(1.0, double(update->ntimestep - heldDragStep_) /
                                                double(heldDragStep_ - heldDragStepBefore_)) : 0.0;
  for (int p = 0; p < natoms_; p++)
    for (int d = 0; d < 3; d++) {
      const size_t force = size_t(6) * p + d, torque = force + 3;
      held.particles[p].F[d] = heldDrag_[force] + (twoSteps ? f * (heldDrag_[force] - heldDragBefore_[force]) : 0.0);
      held.particles[p].T[d] = heldDrag_[torque] + (twoSteps ? f * (heldDrag_[torque] - heldDragBefore_[torque]) : 0.0);
    }
}

void FixFdmCouple::planNextMove(const std::vector<Particle> &particles)
{
  // rank 0, U_n just solved at the positions x_n the step started from (particles): the rates of
  // the next position update (position_update.h). currentVelocity_ still holds U_{n-1} here.
  namespace motion = fdm::motion;
  motion::Configuration c;
  c.n = natoms_;
  c.x.resize(size_t(3) * natoms_);
  c.radius.resize(natoms_);
  for (int p = 0; p < natoms_; p++) {
    for (int k = 0; k < 3; k++) c.x[size_t(3) * p + k] = particles[p].x[k];
    c.radius[p] = particles[p].radius;
  }
  c.u = solution_;
  if (havePlan_ && haveVelocities_ && planPositions_.size() == c.x.size()) {
    c.xPrevious = planPositions_;
    c.uPrevious = currentVelocity_;
  }
  for (int d = 0; d < 3; d++) c.period[d] = domain->periodicity[d] ? domain->prd[d] : 0.0;

  std::vector<int> closePairs;
  std::vector<motion::Wall> walls;
  if (gapUpdate_ && system_) closePairs = system_->closePairs();
  if (gapUpdate_ && pair_)
    for (const PairFdmSubgrid::Wall &w : pair_->walls())
      walls.push_back(motion::Wall{w.axis, w.side, w.side == 0 ? domain->boxlo[w.axis] : domain->boxhi[w.axis]});

  motion::Options options;
  options.adamsBashforth = adamsBashforth_;
  options.gapCorrection = gapUpdate_;
  options.holdContactGaps = holdContactGaps_;
  if (pair_ && pair_->contactActive()) options.contactGap = pair_->roughness();
  const motion::Statistics stats = motion::displacementRates(c, closePairs, walls, update->dt, options, moveRate_);
  run_.gapTargets += stats.pairGaps + stats.wallGaps;
  run_.gapLimited += stats.limited;
  run_.gapHeld += stats.heldGaps;
  run_.gapFallbacks += stats.fallback ? 1 : 0;
  run_.gapBoundWorst = std::max(run_.gapBoundWorst, stats.worstBound);
  if (stats.fallback && run_.gapFallbacks == 1 && comm->me == 0) {
    // said once per run (the count is in the timing line): in dense packings it is the rule
    char msg[400];
    std::snprintf(msg, sizeof msg, "fdm/couple: step " BIGINT_FORMAT ": the log-gap targets of %ld pairs and %ld wall "
                  "gaps contradict each other (a gap still %.2g of its target off after %d sweeps): such steps move "
                  "the particles straight, keeping every gap from closing below min(target, present gap) "
                  "(docs/dem.md, 'Position update'; counted in the timing line)",
                  update->ntimestep, stats.pairGaps, stats.wallGaps, stats.worst, stats.sweeps);
    error->warning(FLERR, msg);
  }
  run_.gapSweepsMax = std::max(run_.gapSweepsMax, stats.sweeps);
  planPositions_ = c.x;
  havePlan_ = true;
}

void FixFdmCouple::scatter()
{
  if (move_) {
    int planned = havePlan_ ? 1 : 0;
    MPI_Bcast(&planned, 1, MPI_INT, 0, world);
    havePlan_ = planned != 0;
    if (havePlan_) {
      moveRate_.resize(size_t(6) * natoms_);
      MPI_Bcast(moveRate_.data(), 6 * natoms_, MPI_DOUBLE, 0, world);
    }
  }
  // the velocities of the step now ending are the "previous" ones of the next position update
  if (haveVelocities_) previousVelocity_ = currentVelocity_;
  MPI_Bcast(solution_.data(), 6 * natoms_, MPI_DOUBLE, 0, world);
  currentVelocity_ = solution_;
  haveVelocities_ = true;
  MPI_Bcast(hydro_.data(), 6 * natoms_, MPI_DOUBLE, 0, world);
  MPI_Bcast(subgrid_.data(), 6 * natoms_, MPI_DOUBLE, 0, world);
  if (stresslets_) MPI_Bcast(stress_.data(), 20 * natoms_, MPI_DOUBLE, 0, world);
  long counters[4] = {solverIterations_, pairBlocks_, wallBlocks_, contacts_};
  MPI_Bcast(counters, 4, MPI_LONG, 0, world);
  solverIterations_ = counters[0];
  pairBlocks_ = counters[1];
  wallBlocks_ = counters[2];
  contacts_ = counters[3];
  MPI_Bcast(&lastIterations_, 1, MPI_INT, 0, world);
  MPI_Bcast(&lastResidual_, 1, MPI_DOUBLE, 0, world);
  // the implicit part of the contact forces: f and torque become the forces that moved the particles
  springs_.resize(size_t(6) * natoms_, 0.0);
  MPI_Bcast(springs_.data(), 6 * natoms_, MPI_DOUBLE, 0, world);
  // the velocities of the converged inner iteration are the particles' velocities of this step
  for (int i = 0; i < atom->nlocal; i++) {
    const size_t t = size_t(6) * (atom->tag[i] - 1);
    const double *u = &solution_[t];
    for (int d = 0; d < 3; d++) {
      atom->v[i][d] = u[d];
      atom->omega[i][d] = u[3 + d];
      atom->f[i][d] += springs_[t + d];
      atom->torque[i][d] += springs_[t + 3 + d];
    }
  }
  fillPerAtomArray();
}

void FixFdmCouple::checkOverlaps()
{
  // Every rank (collective). Two spheres overlapping by more than the fluid accepts of a sphere
  // pressed into a wall (cpl::contactOverlapTolerance of the smaller radius) are beyond what the
  // contact springs allow for any load they were chosen for: the run is no longer a suspension of
  // rigid spheres (measured: 0.08-0.21 a1 in dense scenes at large steps, docs/benchmarks.md
  // "Stability map"), so it stops rather than record it.
  const double maxOverlap = cpl::contactOverlapTolerance;
  if (!pair_ || !session_.hasFluid()) return;
  const PairFdmSubgrid::Overlap &mine = pair_->deepestOverlap();
  struct {
    double depth;
    int rank;
  } local = {mine.depth, comm->me}, worst;
  MPI_Allreduce(&local, &worst, 1, MPI_DOUBLE_INT, MPI_MAXLOC, world);
  if (!(worst.depth > maxOverlap)) return;
  double info[3] = {mine.gap, double(mine.tagI), double(mine.tagJ)};
  MPI_Bcast(info, 3, MPI_DOUBLE, worst.rank, world);
  char text[500];
  snprintf(text, sizeof text,
           "particles %ld and %ld overlap by %g m (%g of the smaller radius) at step " BIGINT_FORMAT
           ", more than the %g the fluid accepts: the contact springs did not hold them (a time step too large "
           "for this packing, or springs too soft for its loads: docs/benchmarks.md, 'Stability map', "
           "docs/contact.md, 'A recipe')",
           std::lround(info[1]), std::lround(info[2]), -info[0], worst.depth, update->ntimestep, maxOverlap);
  allAgree(comm->me == 0 ? std::string(text) : std::string());
}

void FixFdmCouple::checkPeriodicBalance(const std::vector<Particle> &particles)
{
  // rank 0. In a box periodic in every direction the steady Stokes flow exists only if the loads
  // on the free particles (the forces LIGGGHTS holds, whose contact parts cancel in pairs, plus the
  // buoyant weights of Eq. 31) balance the fluid's imposed pressure gradient: their sum is
  // V0 gradP0 (Eq. 43). Otherwise the mean flow grows without bound (2e12 m/s within the first
  // step of a force-free sphere under gradP0 = 0.01 Pa/m).
  const double pi = 3.14159265358979323846;
  const double *gradP0 = session_.gradP0();
  // only under an imposed gradient: the unit tests' stand-in fluids drive free particles in periodic
  // boxes by forces alone (a real fluid's mean flow would then grow too; docs/errors.md)
  if (gradP0[0] == 0 && gradP0[1] == 0 && gradP0[2] == 0) return;
  const double volume = domain->xprd * domain->yprd * domain->zprd;
  double sum[3] = {0, 0, 0}, scale = 0;
  for (const Particle &q : particles) {
    const double buoyantMass = q.mass - session_.rhoFluid() * 4.0 / 3.0 * pi * q.radius * q.radius * q.radius;
    for (int d = 0; d < 3; d++) {
      const double load = q.f[d] + buoyantMass * gravity_[d];
      sum[d] += load;
      scale += std::fabs(load);
    }
  }
  double imposed[3], mismatch = 0;
  for (int d = 0; d < 3; d++) {
    imposed[d] = volume * gradP0[d];
    scale += std::fabs(imposed[d]);
    mismatch = std::max(mismatch, std::fabs(sum[d] - imposed[d]));
  }
  if (mismatch <= 1e-6 * scale || scale == 0) return;
  char text[600];
  snprintf(text, sizeof text,
           "in a box periodic in every direction the loads on the free particles (forces beside contacts, "
           "buoyant weights) sum to (%g %g %g) N but the fluid's imposed pressure gradient gradP0 = (%g %g %g) "
           "Pa/m needs V0 gradP0 = (%g %g %g) N (Eq. 43; V0 = %g m3) at step " BIGINT_FORMAT
           ": no steady Stokes flow exists. Set gradP0 in the fluid's constant/fdmProperties, give the particles "
           "that external force (fix addforce), hold them (move no), or bound the flow with walls",
           sum[0], sum[1], sum[2], gradP0[0], gradP0[1], gradP0[2], imposed[0], imposed[1], imposed[2], volume,
           update->ntimestep);
  fail(text);
}

void FixFdmCouple::writeWallLoads()
{
  // rank 0, after the last inner iteration: per wall the force of the particles on it, sub-grid
  // lubrication (minus each wall block's force on its particle, Eq. D.6) and contact (minus the
  // wall contact forces of this step's force evaluation and of the implicit springs). A resumed run appends (fdmRun --resume
  // cut the file at the checkpoint, fdm/checkpoint.py).
  const std::vector<PairFdmSubgrid::Wall> &walls = pair_->walls();
  static const char *faceNames[6] = {"xlo", "xhi", "ylo", "yhi", "zlo", "zhi"};
  if (!wallOut_) {
    const bool append = !session_.resumeFile().empty();
    wallOut_ = fopen(wallFile_.c_str(), append ? "a" : "w");
    if (!wallOut_) fail("walls: cannot open " + wallFile_ + " for writing");
    if (!append) {
      fprintf(wallOut_, "# fix fdm/couple walls: force of the particles on each wall [N]: sub-grid lubrication "
                        "(Eq. D.6) and contact; timestep %.17g\n# step", update->dt);
      for (const PairFdmSubgrid::Wall &w : walls)
        for (const char *part : {"subgrid", "contact"})
          for (const char *c : {"X", "Y", "Z"}) fprintf(wallOut_, " %s:%s%s", faceNames[2 * w.axis + w.side], part, c);
      fprintf(wallOut_, "\n");
    }
  }
  std::vector<double> subgrid(3 * walls.size(), 0.0);
  if (system_ && !wallBlockWall_.empty()) {
    const std::vector<double> blocks = system_->wallBlockForces();
    if (blocks.size() != 6 * wallBlockWall_.size())
      fail("walls: " + std::to_string(blocks.size() / 6) + " wall blocks in Eq. (31) but " +
           std::to_string(wallBlockWall_.size()) + " wall indices");
    for (size_t b = 0; b < wallBlockWall_.size(); b++) {
      const size_t k = size_t(std::lround(wallBlockWall_[b]));
      for (int d = 0; d < 3; d++) subgrid[3 * k + d] -= blocks[6 * b + d];
    }
  }
  // contact: the forces of the step's force evaluation, plus the implicit springs' increment over
  // the step (Eq. C2), each spring block's share on its particle
  std::vector<double> contact(3 * walls.size(), 0.0);
  for (size_t k = 0; k < contact.size() && k < wallContact_.size(); k++) contact[k] = wallContact_[k];
  if (!springWallBlockWall_.empty()) {
    if (springWallForces_.size() != 6 * springWallBlockWall_.size())
      fail("walls: " + std::to_string(springWallForces_.size() / 6) + " implicit wall springs in Eq. (31) but " +
           std::to_string(springWallBlockWall_.size()) + " wall indices");
    for (size_t b = 0; b < springWallBlockWall_.size(); b++) {
      const size_t k = size_t(std::lround(springWallBlockWall_[b]));
      for (int d = 0; d < 3; d++) contact[3 * k + d] -= springWallForces_[6 * b + d];
    }
  }
  std::ostringstream line;
  line.precision(12);
  line << update->ntimestep;
  for (size_t k = 0; k < walls.size(); k++) {
    for (int d = 0; d < 3; d++) line << ' ' << subgrid[3 * k + d];
    for (int d = 0; d < 3; d++) line << ' ' << contact[3 * k + d];
  }
  line << '\n';
  const std::string text = line.str();
  if (fwrite(text.data(), 1, text.size(), wallOut_) != text.size() || fflush(wallOut_) != 0)
    fail("walls: could not write step " + std::to_string((long long) update->ntimestep) + " to " + wallFile_ +
         " (disk full or not writable?)");
}

void FixFdmCouple::fillPerAtomArray()
{
  if (atom->nmax > nmax_) {
    nmax_ = atom->nmax;
    memory->destroy(perAtom_);
    memory->create(perAtom_, nmax_, perAtomColumns_, "fdm/couple:hydrodynamic");
    array_atom = perAtom_;
  }
  for (int i = 0; i < atom->nlocal; i++) {
    const long t = atom->tag[i] - 1;
    const bool known = t >= 0 && t < natoms_ && hydro_.size() == size_t(6) * natoms_;
    for (int c = 0; c < 6; c++) {
      perAtom_[i][c] = known ? hydro_[size_t(6) * t + c] : 0.0;
      perAtom_[i][6 + c] = known ? subgrid_[size_t(6) * t + c] : 0.0;
    }
    if (stresslets_)
      for (int c = 0; c < 20; c++) perAtom_[i][12 + c] = known ? stress_[size_t(20) * t + c] : 0.0;
  }
}

void FixFdmCouple::printTiming(const char *what, const Timing &t, double wall, int runs) const
{
  if (comm->me != 0) return;
  const double percent = wall > 0 ? 100.0 / wall : 0.0;
  std::string gapStats = " (gap_update none)";
  if (gapUpdate_) {
    char g[300];
    std::snprintf(g, sizeof g, " with log gaps: %.3g gap targets and %.3g held contact gaps per step, at most %d "
                  "sweeps, %ld limited, %ld steps with contradictory targets (straight, gaps kept above their "
                  "bounds to %.2g)",
                  t.steps ? double(t.gapTargets) / t.steps : 0.0, t.steps ? double(t.gapHeld) / t.steps : 0.0,
                  t.gapSweepsMax, t.gapLimited, t.gapFallbacks, t.gapBoundWorst);
    gapStats = g;
  }
  std::string chordStats;
  if (contactChord_ && pair_ && pair_->implicitContact()) {
    char c[120];
    std::snprintf(c, sizeof c, ", pair springs' chord terms up to %.3g N", t.chordForceMax);
    chordStats = c;
  }
  char line[1500];
  std::snprintf(line, sizeof line,
                "fdm/couple timing %s (%d run%s, %ld steps, %.4g s): particle solve %.4g s (%.1f %%), "
                "exchange incl. fluid %.4g s (%.1f %%), gather/scatter %.4g s (%.1f %%); Eq. 31: %ld solves, "
                "%s iterations mean %.1f max %ld, %ld factorisations, %ld low-rank downdates, %ld back-substitutions (Coulomb rounds, at most %ld in a solve); last step %ld sub-grid pair blocks, %ld wall "
                "blocks, %ld contacts; "
                "%ld contacts began to slide within their step%s; position update %s%s%s%s\n",
                what, runs, runs == 1 ? "" : "s", t.steps, wall, t.solve, t.solve * percent, t.exchange,
                t.exchange * percent, t.gatherScatter, t.gatherScatter * percent, t.solves,
                fdm::ParticleVelocitySystem::solverName(solver_),
                t.solves ? double(t.solverIterations) / t.solves : 0.0, t.solverIterationsMax, t.factorisations, t.downdates, t.backSubstitutions, t.coulombRoundsMax,
                pairBlocks_, wallBlocks_, contacts_, t.contactSlides, chordStats.c_str(),
                adamsBashforth_ ? "ab2" : "euler", gapStats.c_str(),
                notConverged_ ? (", " + std::to_string(notConverged_) + " steps not converged").c_str() : "",
                fluidEvery_ > 1 ? ("; fluid_every " + std::to_string(fluidEvery_) + ": the fluid solved in " +
                                   std::to_string(t.fluidSteps) + " of the steps" +
                                   (heldExtrapolated_ ? ", the held drag extrapolated" : "")).c_str() : "");
  if (screen) fputs(line, screen);
  if (logfile) fputs(line, logfile);
}

void FixFdmCouple::post_run()
{
  const double now = MPI_Wtime();
  session_.addRun(run_.steps, run_.solve, run_.exchange, run_.gatherScatter);
  printTiming("of this run", run_, now - runStart_, 1);
  if (checkpointEvery_ > 0 && comm->me == 0 && screen)
    fprintf(screen, "fdm/couple checkpoints: every %lld steps and at the end of the run, %.4g s of writing so far\n",
            checkpointEvery_, checkpointSeconds_);
  notConverged_ = 0;
  // a following 'run N pre no' skips setup(): its timing starts here
  run_ = Timing();
  runStart_ = now;
}

double FixFdmCouple::compute_vector(int n)
{
  switch (n) {
    case 0: return lastIterations_;
    case 1: return lastResidual_;
    case 2: return session_.totalSolve() + run_.solve;
    case 3: return session_.totalExchange() + run_.exchange;
    case 4: return solverIterations_;
    case 5: return pairBlocks_;
    case 6: return wallBlocks_;
    case 7: return contacts_;
  }
  return 0.0;
}

double FixFdmCouple::memory_usage()
{
  return double(nmax_) * perAtomColumns_ * sizeof(double) + double(solution_.size() + hydro_.size()) * sizeof(double);
}

