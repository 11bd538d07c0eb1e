// fix fdm/couple: the particle side of the coupled FDM method (Orsi, Lobry & Peters 2023, 4.2-4.4).
// See fix_fdm_couple.h for what it does and docs/dem.md for its use.
#include "fix_fdm_couple.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "update.h"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

using namespace LAMMPS_NS;
namespace cpl = fdm::coupler;

std::unique_ptr<cpl::Transport> FixFdmCouple::connection_;
bool FixFdmCouple::connected_ = false;
int FixFdmCouple::sessionParticles_ = 0;
double FixFdmCouple::alphaLambda_ = 0.0;
double FixFdmCouple::rhoFluid_ = 0.0;
double FixFdmCouple::delta_ = 0.0;
FixFdmCouple::Timing FixFdmCouple::total_;
int FixFdmCouple::runs_ = 0;
double FixFdmCouple::sessionStart_ = 0.0;

namespace {

// Per-atom values gathered to rank 0: tag, then the fields of Particle.
const int gatherWidth = 19;

std::string fmt(double x)
{
  std::ostringstream os;
  os.precision(10);
  os << x;
  return os.str();
}
std::string point(const double *x) { return "(" + fmt(x[0]) + ", " + fmt(x[1]) + ", " + fmt(x[2]) + ")"; }
std::string tagName(int index) { return std::to_string(index + 1); }

// If LIGGGHTS stops on an error (error->all exits), tell the fluid solver why it lost its peer
// rather than leave it to guess from a closed socket.
void tellPeerWeStopped();

}  // namespace

void FixFdmCouple::Timing::add(const Timing &t)
{
  solve += t.solve;
  exchange += t.exchange;
  gatherScatter += t.gatherScatter;
  steps += t.steps;
}

FixFdmCouple::FixFdmCouple(LAMMPS *lmp, int narg, char **arg) :
  Fix(lmp, narg, arg), move_(true), atomsAtInit_(0), natoms_(0), lastIterations_(0), lastResidual_(0.0), notConverged_(0), runStart_(0.0),
  nmax_(0), perAtom_(nullptr)
{
  if (igroup != 0) error->all(FLERR, "fix fdm/couple must be applied to group all (every particle is in the fluid)");
  time_integrate = 1;
  vector_flag = 1;
  size_vector = 4;
  global_freq = 1;
  extvector = 0;
  peratom_flag = 1;
  size_peratom_cols = 6;
  peratom_freq = 1;
  gravity_[0] = gravity_[1] = gravity_[2] = 0.0;
  options_.name = "fluid solver fdmFoam";

  for (int i = 3; i < narg; i++) {
    const std::string key = arg[i];
    auto value = [&](int n) -> const char * {
      if (i + n >= narg) error->all(FLERR, ("fix fdm/couple: keyword " + key + " needs a value").c_str());
      return arg[i + n];
    };
    if (key == "transport") {
      options_.transport = value(1);
      if (options_.transport != "socket" && options_.transport != "file")
        error->all(FLERR, ("fix fdm/couple: transport " + options_.transport + " is not socket or file").c_str());
      i++;
    } else if (key == "host") { options_.host = value(1); i++; }
    else if (key == "port") { options_.port = force->inumeric(FLERR, value(1)); i++; }
    else if (key == "portfile") { options_.portFile = value(1); i++; }
    else if (key == "directory") { options_.directory = value(1); i++; }
    else if (key == "connect_timeout") { options_.connectTimeout = force->numeric(FLERR, value(1)); i++; }
    else if (key == "timeout") { options_.receiveTimeout = force->numeric(FLERR, value(1)); i++; }
    else if (key == "record") { options_.recordFile = value(1); i++; }
    else if (key == "gravity") {
      for (int d = 0; d < 3; d++) gravity_[d] = force->numeric(FLERR, value(d + 1));
      i += 3;
    } else if (key == "move") {
      const std::string v = value(1);
      if (v != "yes" && v != "no") error->all(FLERR, "fix fdm/couple: move must be yes or no");
      move_ = (v == "yes");
      i++;
    } else {
      error->all(FLERR, ("fix fdm/couple: unknown keyword " + key + " (see docs/dem.md)").c_str());
    }
  }
  if (options_.transport == "socket" && (options_.port <= 0 || options_.port > 65535) && options_.portFile.empty())
    error->all(FLERR, "fix fdm/couple: give the fluid solver's port (port P) or its port file (portfile F)");
  if (options_.transport == "file" && options_.directory.empty())
    error->all(FLERR, "fix fdm/couple: transport file needs directory D");
  if (!(options_.connectTimeout > 0) || !(options_.receiveTimeout > 0))
    error->all(FLERR, "fix fdm/couple: connect_timeout and timeout must be positive (seconds)");
}

FixFdmCouple::~FixFdmCouple()
{
  memory->destroy(perAtom_);
}

int FixFdmCouple::setmask()
{
  return FixConst::INITIAL_INTEGRATE | FixConst::FINAL_INTEGRATE;
}

void FixFdmCouple::init()
{
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
  atomsAtInit_ = int(atom->natoms);
  if (force->newton_pair) error->all(FLERR, "fix fdm/couple requires newton off");
  if (std::strcmp(update->unit_style, "si") != 0)
    error->all(FLERR, (std::string("fix fdm/couple requires units si (the fluid solver works in SI), not units ") +
                       update->unit_style).c_str());
  if (!(update->dt > 0)) error->all(FLERR, "fix fdm/couple requires a positive timestep");
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
}

void FixFdmCouple::allAgree(const std::string &problemOnRank0)
{
  // The problem is known on rank 0 only; every rank must call error->all.
  int length = int(problemOnRank0.size());
  MPI_Bcast(&length, 1, MPI_INT, 0, world);
  if (length == 0) return;
  std::vector<char> text(problemOnRank0.begin(), problemOnRank0.end());
  text.resize(size_t(length) + 1, '\0');
  MPI_Bcast(text.data(), length, MPI_CHAR, 0, world);
  if (comm->me == 0 && connection_) {
    connection_->sendError("fdmDEM: " + problemOnRank0);
    connection_.reset();
  }
  error->all(FLERR, (std::string("fdm/couple: ") + text.data()).c_str());
}

void FixFdmCouple::fail(const std::string &message)
{
  // rank 0, in the middle of a step (the other ranks wait in MPI_Bcast): error->one aborts them all
  if (connection_) {
    connection_->sendError("fdmDEM: " + message);
    connection_.reset();
  }
  error->one(FLERR, ("fdm/couple: " + message).c_str());
}

std::string FixFdmCouple::checkFluidHello(const cpl::Message &hello) const
{
  using cpl::protocolVersion;
  if (hello.count != 1 || hello.width < cpl::layout::helloFluidWidth)
    return "malformed Hello from the fluid solver (" + std::to_string(hello.count) + " records of " +
           std::to_string(hello.width) + " values)";
  const long version = std::lround(hello.textNumber("version"));
  if (version != protocolVersion)
    return "coupling protocol version mismatch: fdmFoam speaks " + std::to_string(version) + ", fdmDEM speaks " +
           std::to_string(protocolVersion);
  const double *r = &hello.data[0];
  const long long nExpected = std::llround(r[0]);
  if (nExpected >= 0 && nExpected != natoms_)
    return "the fluid case expects " + std::to_string(nExpected) + " particles (constant/fdmProperties nParticles) "
           "but the LIGGGHTS input has " + std::to_string(natoms_);
  if (!(r[1] > 0) || !(r[2] > 0) || !(r[3] > 0))
    return "the fluid solver sent a non-positive alpha_lambda (" + fmt(r[1]) + " s), rho_f (" + fmt(r[2]) +
           " kg/m3) or mesh size (" + fmt(r[3]) + " m)";
  const char *axis = "xyz";
  for (int d = 0; d < 3; d++) {
    const double lo = r[4 + 2*d], hi = r[5 + 2*d];
    const double tolerance = 1e-9 * std::max(std::fabs(domain->prd[d]), std::fabs(hi - lo));
    if (!(std::fabs(lo - domain->boxlo[d]) <= tolerance) || !(std::fabs(hi - domain->boxhi[d]) <= tolerance))
      return std::string(1, axis[d]) + " extent: LIGGGHTS box " + fmt(domain->boxlo[d]) + " .. " +
             fmt(domain->boxhi[d]) + " but OpenFOAM mesh " + fmt(lo) + " .. " + fmt(hi);
    const bool fluidPeriodic = r[10 + d] != 0;
    if (fluidPeriodic != (domain->periodicity[d] != 0))
      return std::string(1, axis[d]) + " boundary: LIGGGHTS " + (domain->periodicity[d] ? "periodic (p)" :
             "not periodic") + " but the OpenFOAM mesh " + (fluidPeriodic ? "has cyclic patches" : "has no cyclic patches") +
             " in " + axis[d];
  }
  return "";
}

void FixFdmCouple::connectAndHandshake()
{
  std::string problem;
  if (comm->me == 0) {
    try {
      if (screen)
        fprintf(screen, "fdm/couple: connecting to fdmFoam (%s%s)\n", options_.transport.c_str(),
                options_.transport == "file" ? (" in " + options_.directory).c_str() :
                (" " + options_.host + (options_.portFile.empty() ? ":" + std::to_string(options_.port) :
                                        ", port file " + options_.portFile)).c_str());
      connection_ = cpl::connect(options_);
      std::atexit(tellPeerWeStopped);
      cpl::Message hello = cpl::makeMessage(cpl::MessageType::Hello, 0, 0, 1, cpl::layout::helloDemWidth,
          "role=dem version=" + std::to_string(cpl::protocolVersion) + " dt=" + fmt(update->dt) +
          " lastStep=" + std::to_string((long long) update->laststep));
      double *r = &hello.data[0];
      r[0] = natoms_;
      for (int d = 0; d < 3; d++) {
        r[1 + 2*d] = domain->boxlo[d];
        r[2 + 2*d] = domain->boxhi[d];
        r[7 + d] = domain->periodicity[d];
      }
      connection_->send(hello);
      const cpl::Message reply = connection_->receive(cpl::MessageType::Hello);
      problem = checkFluidHello(reply);
      if (problem.empty()) {
        alphaLambda_ = reply.at(0, 1);
        rhoFluid_ = reply.at(0, 2);
        delta_ = reply.at(0, 3);
        if (screen)
          fprintf(screen, "fdm/couple: connected (%s): %d particles, alpha_lambda %g s, rho_f %g kg/m3, "
                  "mesh size %g m\n", connection_->describe().c_str(), natoms_, alphaLambda_, rhoFluid_, delta_);
      }
    } catch (const std::exception &e) {
      problem = e.what();
    }
  }
  allAgree(problem);
  MPI_Bcast(&alphaLambda_, 1, MPI_DOUBLE, 0, world);
  MPI_Bcast(&rhoFluid_, 1, MPI_DOUBLE, 0, world);
  MPI_Bcast(&delta_, 1, MPI_DOUBLE, 0, world);
  sessionStart_ = MPI_Wtime();
}

void FixFdmCouple::gather(std::vector<Particle> &particles)
{
  const int nlocal = atom->nlocal;
  std::vector<double> buf(size_t(gatherWidth) * nlocal);
  for (int i = 0; i < nlocal; i++) {
    double *b = &buf[size_t(gatherWidth) * i];
    *b++ = atom->tag[i];
    for (int d = 0; d < 3; d++) *b++ = atom->x[i][d];
    *b++ = atom->radius[i];
    for (int d = 0; d < 3; d++) *b++ = atom->v[i][d];
    for (int d = 0; d < 3; d++) *b++ = atom->omega[i][d];
    for (int d = 0; d < 3; d++) *b++ = atom->f[i][d];
    for (int d = 0; d < 3; d++) *b++ = atom->torque[i][d];
    *b++ = atom->rmass[i];
    *b++ = atom->density[i];
  }
  const int count = int(buf.size());
  std::vector<int> counts(comm->nprocs), displs(comm->nprocs);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, world);
  std::vector<double> all;
  if (comm->me == 0) {
    int total = 0;
    for (int p = 0; p < comm->nprocs; p++) { displs[p] = total; total += counts[p]; }
    all.resize(total);
  }
  MPI_Gatherv(buf.data(), count, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, 0, world);
  if (comm->me != 0) return;
  particles.assign(size_t(natoms_), Particle());
  std::vector<char> seen(size_t(natoms_), 0);
  for (size_t k = 0; k < all.size(); k += gatherWidth) {
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
  }
  for (int t = 0; t < natoms_; t++)
    if (!seen[t])
      fail("particle " + tagName(t) + " is missing: LIGGGHTS lost it (was it put or moved outside a non-periodic "
           "face of the box? " + std::to_string((long long) atom->natoms) + " atoms left of " + std::to_string(natoms_) +
           ")");
}

std::string FixFdmCouple::checkConfiguration(const std::vector<Particle> &particles) const
{
  // rank 0. A particle through a wall, or two overlapping, would give a wrong flow silently.
  const char *axis = "xyz";
  for (size_t i = 0; i < particles.size(); i++) {
    const Particle &p = particles[i];
    const std::string who = "particle " + tagName(int(i)) + " at " + point(p.x) + " with radius " + fmt(p.radius);
    if (!(p.radius > 0) || !(p.density > 0) || !(p.mass > 0))
      return who + " has a non-positive radius, density (" + fmt(p.density) + ") or mass (" + fmt(p.mass) + ")";
    for (int d = 0; d < 3; d++) {
      const double lo = domain->boxlo[d], hi = domain->boxhi[d];
      if (!std::isfinite(p.x[d]) || p.x[d] < lo || p.x[d] > hi)
        return who + ": its centre lies outside the box in " + axis[d] + " (" + fmt(lo) + " .. " + fmt(hi) + ")";
      if (domain->periodicity[d]) {
        if (2 * p.radius > domain->prd[d])
          return who + " is larger than the periodic box in " + axis[d] + " (extent " + fmt(domain->prd[d]) +
                 "): it would overlap its own image";
      } else if (p.x[d] - p.radius < lo || p.x[d] + p.radius > hi) {
        const bool low = p.x[d] - p.radius < lo;
        const double gap = low ? p.x[d] - p.radius - lo : hi - p.x[d] - p.radius;
        return who + " crosses the wall " + axis[d] + " = " + fmt(low ? lo : hi) + " (non-periodic boundary; box " +
               fmt(lo) + " .. " + fmt(hi) + "): gap " + fmt(gap);
      }
    }
  }
  return findOverlap(particles);
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
  return "particles " + tagName(int(firstI)) + " and " + tagName(int(firstJ)) + " overlap: centres " +
         point(p[firstI].x) + " and " + point(p[firstJ].x) + ", radii " + fmt(p[firstI].radius) + " and " +
         fmt(p[firstJ].radius) + ", surface gap " + fmt(firstGap) +
         (pairs > 1 ? " (" + std::to_string(pairs) + " overlapping pairs in all)" : std::string());
}

void FixFdmCouple::setup(int)
{
  // Called before every run (not with 'run N pre no'): connect once, then check the particles
  // wherever the input has put them since (set atom ... between runs).
  if (!connected_) {
    // Counted at init(), before this setup's re-partitioning: LIGGGHTS silently drops an atom put
    // outside a non-periodic face, and gather() must be able to name it.
    sessionParticles_ = atomsAtInit_;  // what the fluid is told at the handshake, for the session
    natoms_ = sessionParticles_;
    connectAndHandshake();
    connected_ = true;
  }
  natoms_ = sessionParticles_;
  // fewer atoms than announced: gather() names the particle LIGGGHTS lost
  if (atom->natoms > natoms_ || atom->map_tag_max > natoms_)
    allAgree("the particles changed since the coupling started: " + std::to_string((long long) atom->natoms) +
             " atoms with IDs up to " + std::to_string(atom->map_tag_max) + " where the fluid solver was told of " +
             std::to_string(natoms_) + " (particles cannot be inserted during a coupled session)");
  if (solution_.size() != size_t(6) * natoms_) {
    solution_.assign(size_t(6) * natoms_, 0.0);
    hydro_.assign(size_t(6) * natoms_, 0.0);
  }
  std::vector<Particle> particles;
  gather(particles);
  allAgree(comm->me == 0 ? checkConfiguration(particles) : std::string());
  fillPerAtomArray();
  runStart_ = MPI_Wtime();
  run_ = Timing();
}

void FixFdmCouple::initial_integrate(int)
{
  // Step 1 of the algorithm (4.3): move the particles with the velocities solved at the previous
  // step. Nothing else: there is no particle inertia (Eq. 28d-e).
  if (!move_) return;
  const double dt = update->dt;
  for (int i = 0; i < atom->nlocal; i++)
    for (int d = 0; d < 3; d++) atom->x[i][d] += dt * atom->v[i][d];
}

cpl::Message FixFdmCouple::makeStep(const std::vector<Particle> &particles) const
{
  using namespace cpl::layout;
  cpl::Message step = cpl::makeMessage(cpl::MessageType::Step, update->ntimestep, 0, natoms_, stepWidth,
      "dt=" + fmt(update->dt) + " lastStep=" + std::to_string((long long) update->laststep));
  for (int p = 0; p < natoms_; p++) {
    const Particle &q = particles[p];
    step.at(p, sTag) = p + 1;
    for (int d = 0; d < 3; d++) {
      // LIGGGHTS wraps periodic coordinates only when it re-neighbours: the fluid gets them in the box
      double x = q.x[d];
      if (domain->periodicity[d]) x -= domain->prd[d] * std::floor((x - domain->boxlo[d]) / domain->prd[d]);
      step.at(p, sX + d) = x;
      step.at(p, sUx + d) = q.v[d];
      step.at(p, sWx + d) = q.omega[d];
    }
    step.at(p, sRadius) = q.radius;
  }
  return step;
}

void FixFdmCouple::solveVelocities(const std::vector<Particle> &particles, const cpl::Message &integrals)
{
  // Eq. (31): [ (rho_f/rho_p) J / alpha_lambda + R^SG ] u = F_tot, unknowns (U, Omega) per particle
  // by tag. (rho_f/rho_p) M_p = rho_f Vu and (rho_f/rho_p) J_p = rho_f Ju come from the fluid's
  // indicator function I_u; F_tot (Eq. 32) = the fluid integral + buoyant weight + everything
  // LIGGGHTS put in f and torque (contacts, fix addforce, ...: F^c + F^ext).
  using namespace cpl::layout;
  const int N = natoms_;
  std::vector<Eigen::Triplet<double> > triplets;
  triplets.reserve(size_t(6) * N);
  Eigen::VectorXd rhs(6 * N), guess(6 * N);
  for (int p = 0; p < N; p++) {
    const Particle &q = particles[p];
    const double Vu = integrals.at(p, iVu), Ju = integrals.at(p, iJu);
    for (int f = 0; f < integralsWidth; f++)
      if (!std::isfinite(integrals.at(p, f)))
        fail("the fluid solver sent a non-finite integral for particle " + tagName(p) + " at " + point(q.x) +
             " (field " + std::to_string(f) + " of [Vu, Ju, F, T]) at step " + std::to_string(integrals.step) +
             ", inner iteration " + std::to_string(integrals.iteration));
    if (!(Vu > 0) || !(Ju > 0))
      fail("particle " + tagName(p) + " at " + point(q.x) + " with radius " + fmt(q.radius) +
           ": the fluid's indicator function gives it no volume (Vu " + fmt(Vu) + ", Ju " + fmt(Ju) +
           "): is it smaller than a mesh cell (" + fmt(delta_) + ")?");
    const double buoyantFraction = 1.0 - rhoFluid_ / q.density;  // (rho_p - rho_f)/rho_p
    for (int d = 0; d < 3; d++) {
      triplets.push_back(Eigen::Triplet<double>(6*p + d, 6*p + d, rhoFluid_ * Vu / alphaLambda_));
      triplets.push_back(Eigen::Triplet<double>(6*p + 3 + d, 6*p + 3 + d, rhoFluid_ * Ju / alphaLambda_));
      rhs(6*p + d) = integrals.at(p, iFx + d) + buoyantFraction * q.mass * gravity_[d] + q.f[d];
      rhs(6*p + 3 + d) = integrals.at(p, iTx + d) + q.torque[d];
    }
  }
  // R^SG: the sub-grid lubrication blocks (pair and wall) will be appended to `triplets` here.
  for (int k = 0; k < 6 * N; k++) guess(k) = solution_[k];

  Eigen::SparseMatrix<double> A(6 * N, 6 * N);
  A.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                           Eigen::DiagonalPreconditioner<double> > cg;  // Jacobi
  cg.setTolerance(1e-10);
  cg.setMaxIterations(std::max(1000, 6 * N));
  cg.compute(A);
  const Eigen::VectorXd u = cg.solveWithGuess(rhs, guess);  // warm start: previous inner iteration
  if (cg.info() != Eigen::Success && !(cg.error() < 1e-6))
    fail("the particle velocity system (Eq. 31) did not converge: relative residual " + fmt(cg.error()) + " after " +
         std::to_string(cg.iterations()) + " conjugate-gradient iterations");
  for (int k = 0; k < 6 * N; k++) {
    if (!std::isfinite(u(k))) {
      const int p = k / 6;
      fail("the velocity of particle " + tagName(p) + " at " + point(particles[p].x) + " is not finite (Eq. 31): "
           "its force " + point(particles[p].f) + ", torque " + point(particles[p].torque) + ", fluid integrals Vu " +
           fmt(integrals.at(p, iVu)) + " Ju " + fmt(integrals.at(p, iJu)));
    }
    solution_[k] = u(k);
  }
}

void FixFdmCouple::storeStepDone(const cpl::Message &done)
{
  if (int(done.count) != natoms_ || done.width != cpl::layout::stepDoneWidth)
    fail("the fluid solver ended step " + std::to_string(done.step) + " with forces for " + std::to_string(done.count) +
         " particles (" + std::to_string(done.width) + " values each) where " + std::to_string(natoms_) +
         " particles (6 values) were expected");
  hydro_ = done.data;
  lastIterations_ = int(std::lround(done.textNumber("iterations")));
  lastResidual_ = done.textNumber("residual");
  if (done.textValue("converged") != "1") notConverged_++;
}

void FixFdmCouple::final_integrate()
{
  // Steps 3-7 of the algorithm (4.3) seen from the particles: once per time step, after LIGGGHTS
  // has summed every force. Rank 0 talks to the fluid and solves; the result is broadcast.
  double t0 = MPI_Wtime();
  std::vector<Particle> particles;
  gather(particles);
  run_.gatherScatter += MPI_Wtime() - t0;

  if (comm->me == 0) {
    if (!connection_) fail("the connection to the fluid solver is closed");
    const bigint step = update->ntimestep;
    try {
      t0 = MPI_Wtime();
      connection_->send(makeStep(particles));
      while (true) {
        const cpl::Message m = connection_->receive();
        double t1 = MPI_Wtime();
        run_.exchange += t1 - t0;
        if (m.type != cpl::MessageType::Integrals && m.type != cpl::MessageType::StepDone)
          fail(std::string("coupling: expected Integrals or StepDone from the fluid solver, got ") +
               cpl::messageTypeName(m.type) + " (step " + std::to_string((long long) step) + ")");
        if (m.step != uint64_t(step))
          fail(std::string("coupling: the fluid solver sent ") + cpl::messageTypeName(m.type) + " of step " +
               std::to_string(m.step) + " during step " + std::to_string((long long) step));
        if (m.type == cpl::MessageType::StepDone) {
          storeStepDone(m);
          break;
        }
        if (int(m.count) != natoms_ || m.width != cpl::layout::integralsWidth)
          fail("coupling: the fluid solver sent integrals for " + std::to_string(m.count) + " particles (" +
               std::to_string(m.width) + " values each), LIGGGHTS has " + std::to_string(natoms_) + " (8 values)");
        solveVelocities(particles, m);
        cpl::Message reply = cpl::makeMessage(cpl::MessageType::Velocities, m.step, m.iteration, natoms_,
                                              cpl::layout::velocitiesWidth);
        reply.data = solution_;
        t0 = MPI_Wtime();
        run_.solve += t0 - t1;
        connection_->send(reply);
      }
    } catch (const std::exception &e) {
      fail(e.what());
    }
  }

  t0 = MPI_Wtime();
  scatter();
  run_.gatherScatter += MPI_Wtime() - t0;
  run_.steps++;
}

void FixFdmCouple::scatter()
{
  MPI_Bcast(solution_.data(), 6 * natoms_, MPI_DOUBLE, 0, world);
  MPI_Bcast(hydro_.data(), 6 * natoms_, MPI_DOUBLE, 0, world);
  MPI_Bcast(&lastIterations_, 1, MPI_INT, 0, world);
  MPI_Bcast(&lastResidual_, 1, MPI_DOUBLE, 0, world);
  // the velocities of the converged inner iteration are the particles' velocities of this step
  for (int i = 0; i < atom->nlocal; i++) {
    const double *u = &solution_[size_t(6) * (atom->tag[i] - 1)];
    for (int d = 0; d < 3; d++) {
      atom->v[i][d] = u[d];
      atom->omega[i][d] = u[3 + d];
    }
  }
  fillPerAtomArray();
}

void FixFdmCouple::fillPerAtomArray()
{
  if (atom->nmax > nmax_) {
    nmax_ = atom->nmax;
    memory->destroy(perAtom_);
    memory->create(perAtom_, nmax_, 6, "fdm/couple:hydrodynamic");
    array_atom = perAtom_;
  }
  for (int i = 0; i < atom->nlocal; i++) {
    const long t = atom->tag[i] - 1;
    for (int c = 0; c < 6; c++) perAtom_[i][c] = (t >= 0 && t < natoms_) ? hydro_[size_t(6) * t + c] : 0.0;
  }
}

void FixFdmCouple::printTiming(const char *what, const Timing &t, double wall, int runs) const
{
  if (comm->me != 0) return;
  const double percent = wall > 0 ? 100.0 / wall : 0.0;
  char line[512];
  std::snprintf(line, sizeof line,
                "fdm/couple timing %s (%d run%s, %ld steps, %.4g s): particle solve %.4g s (%.1f %%), "
                "exchange incl. fluid %.4g s (%.1f %%), gather/scatter %.4g s (%.1f %%)%s\n",
                what, runs, runs == 1 ? "" : "s", t.steps, wall, t.solve, t.solve * percent, t.exchange,
                t.exchange * percent, t.gatherScatter, t.gatherScatter * percent,
                notConverged_ ? (", " + std::to_string(notConverged_) + " steps not converged").c_str() : "");
  if (screen) fputs(line, screen);
  if (logfile) fputs(line, logfile);
}

void FixFdmCouple::post_run()
{
  const double now = MPI_Wtime();
  total_.add(run_);
  runs_++;
  printTiming("of this run", run_, now - runStart_, 1);
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
    case 2: return total_.solve + run_.solve;
    case 3: return total_.exchange + run_.exchange;
  }
  return 0.0;
}

double FixFdmCouple::memory_usage()
{
  return double(nmax_) * 6 * sizeof(double) + double(solution_.size() + hydro_.size()) * sizeof(double);
}

void FixFdmCouple::finishAll(LAMMPS *lmp)
{
  if (lmp->comm->me != 0 || !connection_) return;
  try {
    connection_->send(cpl::makeMessage(cpl::MessageType::Finish, lmp->update->ntimestep, 0, 0, 0));
  } catch (const std::exception &e) {
    if (lmp->screen) fprintf(lmp->screen, "fdm/couple: WARNING: could not tell the fluid solver to finish: %s\n",
                             e.what());
  }
  connection_->close();
  connection_.reset();
  const double wall = MPI_Wtime() - sessionStart_, percent = wall > 0 ? 100.0 / wall : 0.0;
  char line[512];
  std::snprintf(line, sizeof line,
                "fdm/couple timing total (%d run%s, %ld steps, %.4g s coupled): particle solve %.4g s (%.1f %%), "
                "exchange incl. fluid %.4g s (%.1f %%), gather/scatter %.4g s (%.1f %%)\n",
                runs_, runs_ == 1 ? "" : "s", total_.steps, wall, total_.solve, total_.solve * percent,
                total_.exchange, total_.exchange * percent, total_.gatherScatter, total_.gatherScatter * percent);
  if (lmp->screen) fputs(line, lmp->screen);
  if (lmp->logfile) fputs(line, lmp->logfile);
}

namespace {
void tellPeerWeStopped()
{
  FixFdmCouple::abandon("fdmDEM stopped before the end of its input (a LIGGGHTS error? see the fdmDEM log)");
}
}  // namespace

void FixFdmCouple::abandon(const std::string &why)
{
  if (!connection_) return;
  connection_->sendError(why);
  connection_->close();
  connection_.reset();
}
