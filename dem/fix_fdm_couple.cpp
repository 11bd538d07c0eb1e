#include "fix_fdm_couple.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "modify.h"
#include "update.h"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

using namespace LAMMPS_NS;
namespace cpl = fdm::coupler;

std::unique_ptr<cpl::Transport> FixFdmCouple::connection_;
double FixFdmCouple::alphaLambda_ = 0.0;
double FixFdmCouple::rhoFluid_ = 0.0;

namespace {
std::string fmt(double x)
{
  std::ostringstream os;
  os.precision(10);
  os << x;
  return os.str();
}
std::string point(const double *x) { return "(" + fmt(x[0]) + " " + fmt(x[1]) + " " + fmt(x[2]) + ")"; }
}  // namespace

FixFdmCouple::FixFdmCouple(LAMMPS *lmp, int narg, char **arg) :
  Fix(lmp, narg, arg), move_(true), lastIterations_(0), lastResidual_(0.0),
  solveTime_(0.0), exchangeTime_(0.0), gatherTime_(0.0), steps_(0)
{
  if (igroup != 0) error->all(FLERR, "fix fdm/couple must be applied to group all");
  time_integrate = 1;
  vector_flag = 1;
  size_vector = 4;
  global_freq = 1;
  extvector = 0;
  gravity_[0] = gravity_[1] = gravity_[2] = 0.0;
  options_.name = "fluid solver fdmFoam";
  options_.portFile = "";

  for (int i = 3; i < narg; i++) {
    const std::string key = arg[i];
    auto value = [&](int n) {
      if (i + n >= narg) error->all(FLERR, ("fix fdm/couple: keyword " + key + " needs a value").c_str());
      return std::string(arg[i + n]);
    };
    if (key == "transport") { options_.transport = value(1); i++; }
    else if (key == "host") { options_.host = value(1); i++; }
    else if (key == "port") { options_.port = force->inumeric(FLERR, value(1).c_str()); i++; }
    else if (key == "portfile") { options_.portFile = value(1); i++; }
    else if (key == "directory") { options_.directory = value(1); i++; }
    else if (key == "connect_timeout") { options_.connectTimeout = force->numeric(FLERR, value(1).c_str()); i++; }
    else if (key == "timeout") { options_.receiveTimeout = force->numeric(FLERR, value(1).c_str()); i++; }
    else if (key == "record") { options_.recordFile = value(1); i++; }
    else if (key == "gravity") {
      for (int d = 0; d < 3; d++) gravity_[d] = force->numeric(FLERR, value(d + 1).c_str());
      i += 3;
    } else if (key == "move") {
      const std::string v = value(1);
      if (v != "yes" && v != "no") error->all(FLERR, "fix fdm/couple: move must be yes or no");
      move_ = (v == "yes");
      i++;
    } else {
      error->all(FLERR, ("fix fdm/couple: unknown keyword " + key).c_str());
    }
  }
  if (options_.transport == "socket" && options_.port <= 0 && options_.portFile.empty())
    error->all(FLERR, "fix fdm/couple: give the fluid solver's port (port P) or its port file (portfile F)");
  if (options_.transport == "file" && options_.directory.empty())
    error->all(FLERR, "fix fdm/couple: transport file needs directory D");
}

FixFdmCouple::~FixFdmCouple() {}

int FixFdmCouple::setmask()
{
  return FixConst::INITIAL_INTEGRATE | FixConst::FINAL_INTEGRATE;
}

void FixFdmCouple::init()
{
  if (!atom->sphere_flag) error->all(FLERR, "fix fdm/couple requires atom_style sphere");
  if (atom->map_style != 1) error->all(FLERR, "fix fdm/couple requires atom_modify map array");
  if (force->newton_pair) error->all(FLERR, "fix fdm/couple requires newton off");
  if (atom->natoms > 0 && atom->map_tag_max != atom->natoms)
    error->all(FLERR, "fix fdm/couple requires atom tags 1..N without gaps");
  for (int i = 0; i < modify->nfix; i++)
    if (modify->fix[i] != this && modify->fix[i]->time_integrate)
      error->all(FLERR, (std::string("fix fdm/couple moves the particles itself: remove fix ") +
                         modify->fix[i]->id + " (" + modify->fix[i]->style + ")").c_str());
}

void FixFdmCouple::fail(const std::string &message)
{
  if (connection_) connection_->sendError("fdmDEM: " + message);
  error->one(FLERR, message.c_str());
}

void FixFdmCouple::connectAndHandshake()
{
  if (comm->me != 0 || connection_) return;
  const int N = int(atom->natoms);
  try {
    if (screen) fprintf(screen, "fdm/couple: connecting to fdmFoam (%s)\n", options_.transport.c_str());
    connection_ = cpl::connect(options_);
    cpl::Message hello = cpl::makeMessage(cpl::MessageType::Hello, 0, 0, 1, cpl::layout::helloDemWidth,
        "role=dem version=" + std::to_string(cpl::protocolVersion) + " dt=" + fmt(update->dt) +
        " lastStep=" + std::to_string((long long) update->laststep));
    double *r = &hello.data[0];
    r[0] = N;
    for (int d = 0; d < 3; d++) { r[1 + 2*d] = domain->boxlo[d]; r[2 + 2*d] = domain->boxhi[d]; }
    r[7] = domain->xperiodic; r[8] = domain->yperiodic; r[9] = domain->zperiodic;
    connection_->send(hello);
    const cpl::Message reply = connection_->receive(cpl::MessageType::Hello);
    alphaLambda_ = reply.at(0, 1);
    rhoFluid_ = reply.at(0, 2);
    if (!(alphaLambda_ > 0) || !(rhoFluid_ > 0)) fail("fdmFoam sent a non-positive alpha_lambda or rho_f");
    if (screen)
      fprintf(screen, "fdm/couple: connected (%s): %d particles, alpha_lambda %g s, rho_f %g kg/m3\n",
              connection_->describe().c_str(), N, alphaLambda_, rhoFluid_);
  } catch (const std::exception &e) {
    fail(e.what());
  }
}

void FixFdmCouple::gather(std::vector<Particle> &particles)
{
  const int nlocal = atom->nlocal;
  const int W = 1 + sizeof(Particle) / sizeof(double);
  std::vector<double> buf(size_t(W) * nlocal);
  for (int i = 0; i < nlocal; i++) {
    double *b = &buf[size_t(W) * i];
    b[0] = atom->tag[i];
    Particle p;
    for (int d = 0; d < 3; d++) {
      p.x[d] = atom->x[i][d]; p.v[d] = atom->v[i][d]; p.omega[d] = atom->omega[i][d];
      p.f[d] = atom->f[i][d]; p.torque[d] = atom->torque[i][d];
    }
    p.radius = atom->radius[i];
    p.mass = atom->rmass[i];
    p.density = atom->density[i];
    std::memcpy(b + 1, &p, sizeof p);
  }
  int count = int(buf.size());
  std::vector<int> counts(comm->nprocs), displs(comm->nprocs);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, world);
  std::vector<double> all;
  if (comm->me == 0) {
    int total = 0;
    for (int p = 0; p < comm->nprocs; p++) { displs[p] = total; total += counts[p]; }
    all.resize(total);
  }
  MPI_Gatherv(buf.data(), count, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, 0, world);
  if (comm->me == 0) {
    particles.assign(size_t(atom->natoms), Particle());
    for (size_t k = 0; k < all.size(); k += W)
      std::memcpy(&particles[size_t(all[k]) - 1], &all[k + 1], sizeof(Particle));
  }
}

void FixFdmCouple::checkConfiguration(const std::vector<Particle> &particles)
{
  // rank 0 only. A particle crossing a wall, or two overlapping, would give a wrong flow silently.
  const int periodic[3] = {domain->xperiodic, domain->yperiodic, domain->zperiodic};
  const char *axis = "xyz";
  for (size_t i = 0; i < particles.size(); i++) {
    const Particle &p = particles[i];
    for (int d = 0; d < 3; d++) {
      const double margin = periodic[d] ? 0.0 : p.radius;
      if (!std::isfinite(p.x[d]) || p.x[d] - margin < domain->boxlo[d] || p.x[d] + margin > domain->boxhi[d])
        fail("particle " + std::to_string(i + 1) + " at " + point(p.x) + " with radius " + fmt(p.radius) +
             " lies outside the domain in " + axis[d] + ": the box spans " + fmt(domain->boxlo[d]) + " .. " +
             fmt(domain->boxhi[d]) + (periodic[d] ? " (periodic)" : " (walls)"));
    }
  }
  // Overlaps: all pairs, minimum image (at setup only; O(N^2) is well under a second for 10^4)
  const double L[3] = {domain->xprd, domain->yprd, domain->zprd};
  for (size_t i = 0; i < particles.size(); i++)
    for (size_t j = i + 1; j < particles.size(); j++) {
      double r2 = 0;
      for (int d = 0; d < 3; d++) {
        double dx = particles[j].x[d] - particles[i].x[d];
        if (periodic[d]) dx -= L[d] * std::round(dx / L[d]);
        r2 += dx * dx;
      }
      const double gap = std::sqrt(r2) - particles[i].radius - particles[j].radius;
      if (gap < 0)
        fail("particles " + std::to_string(i + 1) + " and " + std::to_string(j + 1) + " overlap: centres " +
             point(particles[i].x) + " and " + point(particles[j].x) + ", radii " + fmt(particles[i].radius) +
             " and " + fmt(particles[j].radius) + ", surface gap " + fmt(gap));
    }
}

void FixFdmCouple::setup(int)
{
  connectAndHandshake();
  std::vector<Particle> particles;
  gather(particles);
  if (comm->me == 0) checkConfiguration(particles);
  if (solution_.size() != size_t(6 * atom->natoms)) solution_.assign(size_t(6 * atom->natoms), 0.0);
}

void FixFdmCouple::initial_integrate(int)
{
  // Step 1 of the algorithm (4.3): move the particles with the velocities of the previous step.
  if (!move_) return;
  const double dt = update->dt;
  for (int i = 0; i < atom->nlocal; i++)
    for (int d = 0; d < 3; d++) atom->x[i][d] += dt * atom->v[i][d];
}

void FixFdmCouple::solveVelocities(const std::vector<Particle> &particles, const cpl::Message &integrals,
                                   std::vector<double> &solution)
{
  // Eq. (31): [ (rho_f/rho_p) J / alpha_lambda + R^SG ] u = F_tot, with (rho_f/rho_p) M_p = rho_f Vu and
  // (rho_f/rho_p) J_p = rho_f Ju from the fluid's indicator function I_u. R^SG (sub-grid lubrication)
  // is empty until the pair style adds its blocks: the system is built as a sparse matrix already.
  const int N = int(particles.size());
  using namespace cpl::layout;
  std::vector<Eigen::Triplet<double> > triplets;
  triplets.reserve(size_t(6 * N));
  Eigen::VectorXd rhs(6 * N), guess(6 * N);
  for (int p = 0; p < N; p++) {
    const Particle &q = particles[p];
    const double Vu = integrals.at(p, iVu), Ju = integrals.at(p, iJu);
    if (!(Vu > 0) || !(Ju > 0))
      fail("particle " + std::to_string(p + 1) + " at " + point(q.x) + ": the fluid's indicator function covers no "
           "volume (Vu " + fmt(Vu) + "): is the particle smaller than a mesh cell?");
    // buoyant weight (rho_p - rho_f)/rho_p m g, Eq. (32)
    const double buoyancy = 1.0 - rhoFluid_ / q.density;
    for (int d = 0; d < 3; d++) {
      triplets.push_back(Eigen::Triplet<double>(6*p + d, 6*p + d, rhoFluid_ * Vu / alphaLambda_));
      triplets.push_back(Eigen::Triplet<double>(6*p + 3 + d, 6*p + 3 + d, rhoFluid_ * Ju / alphaLambda_));
      rhs(6*p + d) = integrals.at(p, iFx + d) + buoyancy * q.mass * gravity_[d] + q.f[d];
      rhs(6*p + 3 + d) = integrals.at(p, iTx + d) + q.torque[d];
    }
  }
  for (int k = 0; k < 6 * N; k++) guess(k) = solution[k];
  Eigen::SparseMatrix<double> A(6 * N, 6 * N);
  A.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> cg;  // Jacobi
  cg.setTolerance(1e-10);
  cg.compute(A);
  const Eigen::VectorXd u = cg.solveWithGuess(rhs, guess);
  for (int k = 0; k < 6 * N; k++) {
    if (!std::isfinite(u(k)))
      fail("the velocity of particle " + std::to_string(k / 6 + 1) + " is not finite (Eq. 31): check its forces "
           "and the fluid integrals");
    solution[k] = u(k);
  }
}

void FixFdmCouple::final_integrate()
{
  // Step 4 of the algorithm (4.3), every inner iteration, on rank 0; the result is broadcast.
  double t0 = MPI_Wtime();
  std::vector<Particle> particles;
  gather(particles);
  const int N = int(atom->natoms);
  gatherTime_ += MPI_Wtime() - t0;

  if (comm->me == 0) {
    try {
      double t1 = MPI_Wtime();
      cpl::Message step = cpl::makeMessage(cpl::MessageType::Step, update->ntimestep, 0, N, cpl::layout::stepWidth,
          "dt=" + fmt(update->dt) + " lastStep=" + std::to_string((long long) update->laststep));
      for (int p = 0; p < N; p++) {
        step.at(p, cpl::layout::sTag) = p + 1;
        for (int d = 0; d < 3; d++) {
          step.at(p, cpl::layout::sX + d) = particles[p].x[d];
          step.at(p, cpl::layout::sUx + d) = particles[p].v[d];
          step.at(p, cpl::layout::sWx + d) = particles[p].omega[d];
        }
        step.at(p, cpl::layout::sRadius) = particles[p].radius;
      }
      connection_->send(step);
      while (true) {
        cpl::Message m = connection_->receive();
        double t2 = MPI_Wtime();
        exchangeTime_ += t2 - t1;
        if (m.type == cpl::MessageType::StepDone) {
          lastIterations_ = int(m.iteration);
          lastResidual_ = m.textNumber("residual");
          break;
        }
        if (m.type != cpl::MessageType::Integrals)
          fail(std::string("coupling: expected Integrals or StepDone from fdmFoam, got ") +
               cpl::messageTypeName(m.type));
        if (int(m.count) != N || m.width != cpl::layout::integralsWidth)
          fail("coupling: fdmFoam sent integrals for " + std::to_string(m.count) + " particles, LIGGGHTS has " +
               std::to_string(N));
        solveVelocities(particles, m, solution_);
        t1 = MPI_Wtime();
        solveTime_ += t1 - t2;
        cpl::Message reply = cpl::makeMessage(cpl::MessageType::Velocities, m.step, m.iteration, N,
                                              cpl::layout::velocitiesWidth);
        reply.data = solution_;
        connection_->send(reply);
      }
    } catch (const std::exception &e) {
      fail(e.what());
    }
  }

  t0 = MPI_Wtime();
  MPI_Bcast(solution_.data(), 6 * N, MPI_DOUBLE, 0, world);
  MPI_Bcast(&lastIterations_, 1, MPI_INT, 0, world);
  MPI_Bcast(&lastResidual_, 1, MPI_DOUBLE, 0, world);
  for (int i = 0; i < atom->nlocal; i++) {
    const double *u = &solution_[size_t(6) * (atom->tag[i] - 1)];
    for (int d = 0; d < 3; d++) { atom->v[i][d] = u[d]; atom->omega[i][d] = u[3 + d]; }
  }
  gatherTime_ += MPI_Wtime() - t0;
  steps_++;
}

void FixFdmCouple::post_run()
{
  if (comm->me != 0 || !screen) return;
  const double total = solveTime_ + exchangeTime_ + gatherTime_;
  fprintf(screen,
          "fdm/couple timing (%ld steps): particle solve %.4g s, exchange (incl. fluid) %.4g s, "
          "gather/scatter %.4g s (%.4g s total)\n",
          steps_, solveTime_, exchangeTime_, gatherTime_, total);
}

double FixFdmCouple::compute_vector(int n)
{
  switch (n) {
    case 0: return lastIterations_;
    case 1: return lastResidual_;
    case 2: return solveTime_;
    case 3: return exchangeTime_;
  }
  return 0.0;
}

void FixFdmCouple::finishAll()
{
  if (!connection_) return;
  try {
    connection_->send(cpl::makeMessage(cpl::MessageType::Finish, 0, 0, 0, 0));
  } catch (const std::exception &) {
  }
  connection_->close();
  connection_.reset();
}
