// Eq. (31) for the particle velocities: assembly, solution and sub-grid results (see the header).
#include "contact_springs.h"
#include "message_text.h"
#include "particle_velocity_system.h"
#include "fdm/anderson_mixing.h"

#include <Eigen/Cholesky>
#include <Eigen/CholmodSupport>
#include <Eigen/Eigenvalues>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/LU>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

namespace fdm {

namespace {
using fdm::text::number;
using fdm::text::particleId;
using fdm::text::point;

// A direct solver's factorisation of matrix, its pattern analysed once per step (sliding contacts
// change values only); false if it failed.
template <class Factorisation>
bool factoriseDirect(Factorisation &factorisation, const Eigen::SparseMatrix<double> &matrix, bool &analysed)
{
  if (!analysed) {
    factorisation.analyzePattern(matrix);
    analysed = true;
  }
  factorisation.factorize(matrix);
  return factorisation.info() == Eigen::Success;
}
}  // namespace

struct ParticleVelocitySystem::Matrices {
  Eigen::SparseMatrix<double> matrix;   // (rho_f/rho_p) J/alpha_lambda + R^SG
  std::vector<int> blockIndex;          // per particle, 36: position of entry (6p + i, 6p + j) in matrix.valuePtr()
  std::vector<double> subgridBlock;     // per particle, 36: those entries of R^SG (and the springs)
  Eigen::VectorXd wallRhs;              // sum over walls of R_w[:, 0:3] U_w (Eq. D.6)
  Eigen::VectorXd springRhs;            // known part of the implicit springs: gamma R_c U_n + dt B^T K U_w (Eq. C2)
  Eigen::VectorXd frictionRhs;          // what the contacts that slide within the step change in F^tot:
                                        // B^T (capped force - F_t), less a wall spring's tangential wall term
  Eigen::VectorXd chordRhs;             // the pair springs' chord term (Eq. C5), from U_n, once per step
  std::vector<double> rigidBlock;       // per particle, 36: (rho_f/rho_p) J/alpha_lambda of this step
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                           Eigen::DiagonalPreconditioner<double> > cg;  // Jacobi
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double> > ldlt;
  // the same factorisation in supernodes (dense blocks, BLAS): the one that scales to dense packings
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double> > cholmod;
  bool analysed = false;                // the direct solver's symbolic analysis of this step's pattern
  bool ready = false;                   // factorised (or preconditioned) for this step's rigid-body blocks

  // The tangential springs of the contacts that began to slide since the last factorisation left
  // the matrix: matrix = A - V V^T with A the factorised one, each such spring block V_c V_c^T of
  // rank 2 (columns of V scattered to the particles' rows). Solved by the Woodbury identity,
  // (A - V V^T)^-1 = A^-1 + A^-1 V C^-1 V^T A^-1 with the capacitance C = I - V^T A^-1 V: one
  // back-substitution per new column of V instead of a factorisation (docs/benchmarks.md,
  // "The particle solve of a dense suspension").
  Eigen::MatrixXd downdate;             // V (6N x r)
  Eigen::MatrixXd solvedDowndate;       // A^-1 V
  Eigen::LLT<Eigen::MatrixXd> capacitance;
  // Consistent slides also put springs back (a contact that sticks again, a slide's Jacobian renewed):
  // matrix = A - V S V^T with S = diag(+-1) (+1: out of the matrix), (A - V S V^T)^-1 = A^-1 +
  // A^-1 V (S - V^T A^-1 V)^-1 V^T A^-1; while every sign is +1 this is the LLT above
  std::vector<double> downdateSign;
  bool signedUpdate = false;
  Eigen::PartialPivLU<Eigen::MatrixXd> signedCapacitance;
  // The spring blocks that left the matrix in this round, kept as blocks: their columns of V (6N long
  // each) are built only if they are downdated, not when the step is factorised again anyway (in a
  // dense packing a thousand contacts begin to slide in one step: 2000 columns of 6N zeros)
  struct LeavingBlock {
    int base[2];
    int size;
    double R[144];
  };
  std::vector<LeavingBlock> leaving;

  // x = (the factorised matrix)^-1 b
  Eigen::VectorXd factorisedSolve(Solver solver, const Eigen::VectorXd &b) const
  {
    return solver == ParticleVelocitySystem::cholmod ? Eigen::VectorXd(cholmod.solve(b)) : Eigen::VectorXd(ldlt.solve(b));
  }
  Eigen::MatrixXd factorisedSolve(Solver solver, const Eigen::MatrixXd &b) const
  {
    return solver == ParticleVelocitySystem::cholmod ? Eigen::MatrixXd(cholmod.solve(b)) : Eigen::MatrixXd(ldlt.solve(b));
  }
  // x = matrix^-1 b: the factorisation, and the downdate of the contacts that slide since (Woodbury).
  // A stiff spring leaving the matrix (kt c1 dt much larger than the drag) costs the identity a few
  // digits by cancellation: about 1e-12 relative at kt c1 dt/zeta = 1000.
  Eigen::VectorXd directSolve(Solver solver, const Eigen::VectorXd &b) const
  {
    Eigen::VectorXd x = factorisedSolve(solver, b);
    if (downdate.cols() > 0) {
      const Eigen::VectorXd projected = downdate.transpose() * x;
      x += solvedDowndate * (signedUpdate ? Eigen::VectorXd(signedCapacitance.solve(projected))
                                          : Eigen::VectorXd(capacitance.solve(projected)));
    }
    return x;
  }
};

ParticleVelocitySystem::ParticleVelocitySystem(const Settings &settings) :
  settings_(settings), n_(0), springGamma_(0), slidingSwitches_(0), pairRecord_(subgrid::pairRecord), wallRecord_(subgrid::wallRecord), pairBlocks_(0),
  wallBlocks_(0), iterations_(0), factorisations_(0), downdates_(0), m_(new Matrices),
  coulombMixing_(new AndersonMixing(coulombMixingDepth))
{
  if (!(settings_.coulombTolerance > 0 && settings_.coulombTolerance < 1))
    throw Error(Error::notSolved, -1, "Eq. (31): the tolerance of Coulomb's law must be in (0, 1), got " +
                                      number(settings_.coulombTolerance));
  if (!(settings_.alphaLambda > 0) || !(settings_.rhoFluid > 0) || !(settings_.tolerance > 0))
    throw Error(Error::notSolved, -1, "Eq. (31) needs a positive alpha_lambda (" + number(settings_.alphaLambda) +
                                      " s), fluid density (" + number(settings_.rhoFluid) + " kg/m3) and CG tolerance (" +
                                      number(settings_.tolerance) + ")");
  if (settings_.stresslets) {
    pairRecord_ += subgrid::pairStressRecord;
    wallRecord_ += subgrid::wallStressRecord;
  }
}

ParticleVelocitySystem::~ParticleVelocitySystem() {}

int ParticleVelocitySystem::tagIndex(double tag) const
{
  const long t = std::lround(tag);
  if (!(t >= 1 && t <= n_)) throw Error(Error::badBlock, -1, "pair fdm/subgrid sent a block for particle ID " + number(tag));
  return int(t - 1);
}

void ParticleVelocitySystem::assemble(std::vector<Particle> particles, std::vector<double> pairs,
                                      std::vector<double> walls)
{
  assemble(std::move(particles), std::move(pairs), std::move(walls), Springs());
}

void ParticleVelocitySystem::assemble(std::vector<Particle> particles, std::vector<double> pairs,
                                      std::vector<double> walls, Springs springs)
{
  // R^SG once per time step (paper section 4.4.2): the positions do not move during the inner iterations
  const int N = int(particles.size());
  if (N != n_) u_.assign(size_t(6) * N, 0.0);
  n_ = N;
  particles_.swap(particles);
  pairs_.swap(pairs);
  walls_.swap(walls);
  springPairs_.swap(springs.pairs);
  springWalls_.swap(springs.walls);
  springPrevious_.swap(springs.previous);
  springGamma_ = springs.gamma;
  springDt_ = springs.dt;
  if (springPairs_.size() % springs::pairRecord != 0 || springWalls_.size() % springs::wallRecord != 0)
    throw Error(Error::badBlock, -1, "pair fdm/subgrid sent " + std::to_string(springPairs_.size()) + " pair and " +
                                     std::to_string(springWalls_.size()) + " wall contact-spring values, not whole "
                                     "records of " + std::to_string(springs::pairRecord) + " and " +
                                     std::to_string(springs::wallRecord));
  if ((springGamma_ != 0 || springDt_ > 0) && springPrevious_.size() != size_t(6) * N)
    throw Error(Error::badBlock, -1, "the implicit contact springs need U_n of " + std::to_string(N) +
                                     " particles, got " + std::to_string(springPrevious_.size()) + " values");
  if (pairs_.size() % pairRecord_ != 0 || walls_.size() % wallRecord_ != 0)
    throw Error(Error::badBlock, -1, "pair fdm/subgrid sent " + std::to_string(pairs_.size()) + " pair and " +
                                     std::to_string(walls_.size()) + " wall block values, not whole records of " +
                                     std::to_string(pairRecord_) + " and " + std::to_string(wallRecord_));
  pairBlocks_ = long(pairs_.size() / pairRecord_);
  wallBlocks_ = long(walls_.size() / wallRecord_);
  volumes_.clear();

  Matrices &m = *m_;
  std::vector<Eigen::Triplet<double> > triplets;
  triplets.reserve(size_t(36) * N + size_t(144) * pairBlocks_ + size_t(36) * wallBlocks_);
  for (int p = 0; p < N; p++)  // every particle's rigid-body block, always
    for (int i = 0; i < 6; i++)
      for (int j = 0; j < 6; j++) triplets.push_back(Eigen::Triplet<double>(6 * p + i, 6 * p + j, 0.0));
  m.wallRhs = Eigen::VectorXd::Zero(6 * N);
  for (long b = 0; b < pairBlocks_; b++) {
    const double *rec = &pairs_[size_t(b) * pairRecord_];
    const int i1 = tagIndex(rec[0]), i2 = tagIndex(rec[1]);
    const int base[2] = {6 * i1, 6 * i2};
    const double *R = rec + 2;
    for (int k = 0; k < pairRecord_ - 2; k++)
      if (!std::isfinite(R[k]))
        throw Error(Error::badBlock, i1, "pair fdm/subgrid sent a non-finite sub-grid block for particles " +
                                         particleId(i1) + " and " + particleId(i2) + " at " + point(particles_[i1].x) +
                                         " and " + point(particles_[i2].x));
    for (int i = 0; i < 12; i++)
      for (int j = 0; j < 12; j++)
        triplets.push_back(Eigen::Triplet<double>(base[i / 6] + i % 6, base[j / 6] + j % 6, R[12 * i + j]));
  }
  for (long b = 0; b < wallBlocks_; b++) {
    const double *rec = &walls_[size_t(b) * wallRecord_];
    const int p = tagIndex(rec[0]), base = 6 * p;
    const double *R = rec + 1, *rhs = rec + 37;
    for (int k = 0; k < wallRecord_ - 1; k++)
      if (!std::isfinite(R[k]))
        throw Error(Error::badBlock, p, "pair fdm/subgrid sent a non-finite sub-grid wall block for particle " +
                                        particleId(p) + " at " + point(particles_[p].x));
    for (int i = 0; i < 6; i++) {
      for (int j = 0; j < 6; j++) triplets.push_back(Eigen::Triplet<double>(base + i, base + j, R[6 * i + j]));
      m.wallRhs(base + i) += rhs[i];  // F = -R_w (U - U_w, Omega): the wall velocity is a force
    }
  }
  // the implicit contact springs (Eqs. C2, C3): R_c into the matrix, gamma R_c U_n + wall term into F^tot
  m.springRhs = Eigen::VectorXd::Zero(6 * N);
  m.frictionRhs = Eigen::VectorXd::Zero(6 * N);
  m.chordRhs = Eigen::VectorXd::Zero(6 * N);
  chordForce_.assign(springPairs_.size() / springs::pairRecord, 0.0);
  largestChordForce_ = 0;
  const size_t springRecords = springPairs_.size() / springs::pairRecord + springWalls_.size() / springs::wallRecord;
  springSlides_.assign(springRecords, 0);
  slideForce_.assign(3 * springRecords, 0.0);
  slideDirection_.assign(3 * springRecords, 0.0);
  slideCap_.assign(springRecords, 0.0);
  slideKeep_.assign(springRecords, 0.0);
  coulombFlips_.assign(springRecords, 0);
  coulombRenewals_.assign(springRecords, 0);
  coulombFrozen_.assign(springRecords, 0);
  slidingSwitches_ = 0;
  stickingSwitches_ = 0;
  for (size_t b = 0; b < springPairs_.size(); b += springs::pairRecord) {
    const double *rec = &springPairs_[b];
    const int i1 = tagIndex(rec[0]), i2 = tagIndex(rec[1]);
    const int base[2] = {6 * i1, 6 * i2};
    const double *R = rec + 2;
    for (int k = 0; k < springs::pairRecord - 2; k++)
      if (!std::isfinite(R[k]))
        throw Error(Error::badBlock, i1, "pair fdm/subgrid sent a non-finite contact-spring block for particles " +
                                         particleId(i1) + " and " + particleId(i2) + " at " + point(particles_[i1].x) +
                                         " and " + point(particles_[i2].x));
    for (int i = 0; i < 12; i++)
      for (int j = 0; j < 12; j++) {
        const double r = R[12 * i + j];
        triplets.push_back(Eigen::Triplet<double>(base[i / 6] + i % 6, base[j / 6] + j % 6, r));
        if (springGamma_ != 0)
          m.springRhs(base[i / 6] + i % 6) += springGamma_ * r * springPrevious_[size_t(base[j / 6] + j % 6)];
      }
  }
  for (size_t b = 0; b < springWalls_.size(); b += springs::wallRecord) {
    const double *rec = &springWalls_[b];
    const int p = tagIndex(rec[0]), base = 6 * p;
    const double *R = rec + 1, *term = rec + 37;
    for (int k = 0; k < springs::wallRecord - 1; k++)
      if (!std::isfinite(R[k]))
        throw Error(Error::badBlock, p, "pair fdm/subgrid sent a non-finite contact-spring wall block for particle " +
                                        particleId(p) + " at " + point(particles_[p].x));
    for (int i = 0; i < 6; i++) {
      for (int j = 0; j < 6; j++) {
        triplets.push_back(Eigen::Triplet<double>(base + i, base + j, R[6 * i + j]));
        if (springGamma_ != 0) m.springRhs(base + i) += springGamma_ * R[6 * i + j] * springPrevious_[size_t(base + j)];
      }
      m.springRhs(base + i) += term[i];
    }
  }
  m.matrix.resize(6 * N, 6 * N);
  m.matrix.setFromTriplets(triplets.begin(), triplets.end());
  m.matrix.makeCompressed();
  m.blockIndex.assign(size_t(36) * N, -1);
  m.subgridBlock.assign(size_t(36) * N, 0.0);
  for (int k = 0; k < 6 * N; k++)  // column k
    for (Eigen::SparseMatrix<double>::InnerIterator it(m.matrix, k); it; ++it)
      if (it.row() / 6 == k / 6) {
        const size_t e = size_t(36) * (k / 6) + 6 * (it.row() % 6) + k % 6;
        m.blockIndex[e] = int(&it.valueRef() - m.matrix.valuePtr());
        m.subgridBlock[e] = it.value();
      }
  m.rigidBlock.assign(size_t(36) * N, 0.0);
  m.analysed = false;
  m.ready = false;
  setChordForces();  // Eq. (C5), from U_n (the last solution) for the whole step
}

void ParticleVelocitySystem::setVolumes(const std::vector<double> &Vu, const std::vector<double> &Ju)
{
  if (Vu.size() != Ju.size())
    throw Error(Error::fluidValue, -1, "Eq. (31) got the volumes of " + std::to_string(Vu.size()) + " and " +
                                       std::to_string(Ju.size()) + " particles");
  std::vector<RigidVolume> volumes(Vu.size());
  for (size_t p = 0; p < Vu.size(); p++) {
    volumes[p].Vu = Vu[p];
    volumes[p].J[0] = volumes[p].J[3] = volumes[p].J[5] = Ju[p];
  }
  setVolumes(volumes);
}

void ParticleVelocitySystem::setVolumes(const std::vector<RigidVolume> &volumes)
{
  const int N = n_;
  if (volumes.size() != size_t(N))
    throw Error(Error::fluidValue, -1, "Eq. (31) got the volumes of " + std::to_string(volumes.size()) +
                                       " particles for " + std::to_string(N));
  Matrices &m = *m_;
  const double scale = settings_.rhoFluid / settings_.alphaLambda;
  std::vector<double> blocks(size_t(36) * N, 0.0);
  for (int p = 0; p < N; p++) {
    const Particle &q = particles_[p];
    const RigidVolume &v = volumes[size_t(p)];
    bool finite = std::isfinite(v.Vu);
    for (int k = 0; k < 3; k++) finite = finite && std::isfinite(v.m1[k]);
    for (int k = 0; k < 6; k++) finite = finite && std::isfinite(v.J[k]);
    // the values for a message (built only when a check fails: this runs for every particle every step)
    auto values = [&v]() {
      return "Vu " + number(v.Vu) + ", m1 " + point(v.m1) + ", J " + number(v.J[0]) + " " + number(v.J[1]) + " " +
             number(v.J[2]) + " " + number(v.J[3]) + " " + number(v.J[4]) + " " + number(v.J[5]);
    };
    if (!finite)
      throw Error(Error::fluidValue, p, "the fluid solver sent a non-finite volume for particle " + particleId(p) +
                                        " at " + point(q.x) + " (" + values() + ")");
    // r x (Omega x r) summed: J = [[xx xy xz], [xy yy yz], [xz yz zz]] of the record
    const double J[3][3] = {{v.J[0], v.J[1], v.J[2]}, {v.J[1], v.J[3], v.J[4]}, {v.J[2], v.J[4], v.J[5]}};
    // [m1]x w = m1 x w
    const double c[3][3] = {{0, -v.m1[2], v.m1[1]}, {v.m1[2], 0, -v.m1[0]}, {-v.m1[1], v.m1[0], 0}};
    // sum over the stencil of I_u [1, -[r]x]^T [1, -[r]x]: symmetric, positive definite for a real sphere
    Eigen::Matrix<double, 6, 6> B;
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        B(i, j) = i == j ? v.Vu : 0.0;
        B(i, 3 + j) = -c[i][j];      // force from Omega: sum I_u Omega x r = -m1 x Omega
        B(3 + i, j) = c[i][j];       // torque from U: sum I_u r x U = m1 x U
        B(3 + i, 3 + j) = J[i][j];   // torque from Omega: sum I_u r x (Omega x r) = J Omega
      }
    if (!(v.Vu > 0) || Eigen::LLT<Eigen::Matrix<double, 6, 6> >(B).info() != Eigen::Success)
      throw Error(Error::noVolume, p, "particle " + particleId(p) + " at " + point(q.x) + " with radius " +
                                      number(q.radius) + ": the fluid's indicator function gives it no volume (" +
                                      values() + ")");
    for (int i = 0; i < 6; i++)
      for (int j = 0; j < 6; j++) blocks[size_t(36) * p + 6 * i + j] = scale * B(i, j);
  }
  volumes_ = volumes;
  if (m.ready && blocks == m.rigidBlock) return;  // the same volumes again: keep the factorisation
  m.rigidBlock = blocks;
  double *entries = m.matrix.valuePtr();
  for (size_t e = 0; e < blocks.size(); e++) entries[m.blockIndex[e]] = m.subgridBlock[e] + blocks[e];
  factorise(": is the sub-grid matrix indefinite?");
  m.ready = true;
}

const char *ParticleVelocitySystem::solverName(Solver solver)
{
  switch (solver) {
    case cholmod: return "CHOLMOD";
    case ldlt: return "LDLT";
    case cg: return "CG";
  }
  return "?";
}

void ParticleVelocitySystem::factorise(const std::string &when)
{
  const std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  Matrices &m = *m_;
  m.downdate.resize(6 * n_, 0);
  m.solvedDowndate.resize(6 * n_, 0);
  m.downdateSign.clear();
  m.signedUpdate = false;
  bool factorised = true;
  if (settings_.solver != cg) {
    factorised = settings_.solver == cholmod ? factoriseDirect(m.cholmod, m.matrix, m.analysed)
                                             : factoriseDirect(m.ldlt, m.matrix, m.analysed);
    factorisations_++;
  } else {
    m.cg.setTolerance(settings_.tolerance);
    m.cg.setMaxIterations(std::max(1000, 6 * n_));
    m.cg.compute(m.matrix);
  }
  factorisationSeconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!factorised)
    throw Error(Error::notSolved, -1, std::string("the particle velocity system (Eq. 31) could not be factorised (") +
                                          solverName(settings_.solver) + ")" + when);
}

const std::vector<double> &ParticleVelocitySystem::solve(const std::vector<double> &fluidForces)
{
  const int N = n_;
  Matrices &m = *m_;
  if (!m.ready) throw Error(Error::notSolved, -1, "Eq. (31) solved before the particle volumes were given");
  if (fluidForces.size() != size_t(6) * N)
    throw Error(Error::fluidValue, -1, "Eq. (31) got " + std::to_string(fluidForces.size()) +
                                       " fluid force and torque values for " + std::to_string(N) + " particles");
  static const char *component[6] = {"Fx", "Fy", "Fz", "Tx", "Ty", "Tz"};
  Eigen::VectorXd rhs(6 * N);
  for (int p = 0; p < N; p++) {
    const Particle &q = particles_[p];
    for (int c = 0; c < 6; c++)
      if (!std::isfinite(fluidForces[size_t(6) * p + c]))
        throw Error(Error::fluidValue, p, "the fluid solver sent a non-finite integral for particle " + particleId(p) +
                                          " at " + point(q.x) + " (" + component[c] + " = " +
                                          number(fluidForces[size_t(6) * p + c]) + ")");
    const double buoyantFraction = 1.0 - settings_.rhoFluid / q.density;  // (rho_p - rho_f)/rho_p
    for (int d = 0; d < 3; d++) {
      rhs(6 * p + d) = fluidForces[size_t(6) * p + d] + buoyantFraction * q.mass * settings_.gravity[d] + q.force[d];
      rhs(6 * p + 3 + d) = fluidForces[size_t(6) * p + 3 + d] + q.torque[d];
    }
  }
  rhs += m.wallRhs;

  // one solve of the linear system for the right-hand side `total`, into u_
  auto solveLinear = [&](const Eigen::VectorXd &total) {
    Eigen::VectorXd u;
    if (settings_.solver != cg) {
      u = m.directSolve(settings_.solver, total);  // the factorisation of this step
      iterations_ = 1;
    } else {
      const Eigen::Map<const Eigen::VectorXd> guess(u_.data(), 6 * N);  // warm start: the previous solution
      u = m.cg.solveWithGuess(total, guess);
      iterations_ = std::max(iterations_, long(m.cg.iterations()));  // the hardest of the Coulomb rounds
      if (m.cg.info() != Eigen::Success && !(m.cg.error() < 1e-6))
        throw Error(Error::notSolved, -1, "the particle velocity system (Eq. 31) did not converge: relative residual " +
                                          number(m.cg.error()) + " after " + std::to_string(m.cg.iterations()) +
                                          " conjugate-gradient iterations (" + std::to_string(pairBlocks_) +
                                          " sub-grid pair blocks, " + std::to_string(wallBlocks_) + " wall blocks)");
    }
    for (int k = 0; k < 6 * N; k++) {
      if (!std::isfinite(u(k))) {
        const int p = k / 6;
        const Particle &q = particles_[p];
        throw Error(Error::notSolved, p, "the velocity of particle " + particleId(p) + " at " + point(q.x) +
                                         " is not finite (Eq. 31): its force " + point(q.force) + ", torque " +
                                         point(q.torque) + ", fluid integrals Vu " + number(volumes_[size_t(p)].Vu) +
                                         ", m1 " + point(volumes_[size_t(p)].m1));
      }
      u_[k] = u(k);
    }
  };
  // Coulomb's law at the end of the step: solve, let the overloaded sticking contacts slide and set
  // the sliding ones' caps at the solution, solve again, until the caps settle (docs/contact.md 2c)
  iterations_ = 0;
  coulombMixing_->reset();  // a new right-hand side: a new map of the caps
  lastCoulombResidual_ = HUGE_VAL;
  rounds_ = 0;
  std::fill(coulombFlips_.begin(), coulombFlips_.end(), 0);
  std::fill(coulombRenewals_.begin(), coulombRenewals_.end(), 0);
  std::fill(coulombFrozen_.begin(), coulombFrozen_.end(), 0);
  const int maxCoulombRounds = 100;  // each round a back-substitution (a downdate if contacts began to slide)
  for (int round = 0;; round++) {
    solveLinear(rhs + m.springRhs + m.frictionRhs + m.chordRhs);
    backSubstitutions_++;
    rounds_++;
    if (round == maxCoulombRounds) break;
    if (!(settings_.coulombConsistent ? consistentCoulombRound() : slideOverloadedContacts())) break;
  }
  return u_;
}

template <class Visit>
void ParticleVelocitySystem::forEachSpring(Visit &&visit) const
{
  size_t record = 0;
  for (size_t b = 0; b < springPairs_.size(); b += springs::pairRecord, record++) {
    const double *rec = &springPairs_[b];
    const int base[2] = {6 * tagIndex(rec[0]), 6 * tagIndex(rec[1])};
    visit(record, rec + springs::pairFriction, base, 12, false);
  }
  for (size_t b = 0; b < springWalls_.size(); b += springs::wallRecord, record++) {
    const double *rec = &springWalls_[b];
    const int base[1] = {6 * tagIndex(rec[0])};
    visit(record, rec + springs::wallFriction, base, 6, true);
  }
}

void ParticleVelocitySystem::setChordForces()
{
  // Eq. (C5) of docs/contact.md. The next position update moves the centres of a pair in contact by
  // dt rho_c, rho_c = c1 (U_i - U_j)_{n+1} + c0 (U_i - U_j)_n, and the straight step opens the gap by
  // its normal part and, to second order, by the chord dt^2 |rho_c,t|^2/(2r) of the tangential part
  // (r = l_i + l_j). The implicit normal spring (C2) sees the normal part only; at
  // a large dt the chord is as large as the few per cent of h_r by which a stiff spring holds its
  // gap below h_r (docs/benchmarks.md, "Where the contacts go at dt 0.08"), and the explicit force of
  // the next step lost k_n times it: contacts broke. The force the spring will lose, k_n times the
  // chord, enters F^tot (pulling the pair together along n), estimated from U_n (rho_c = (U_i - U_j)_n,
  // the rate of a steady slide) and kept for the step. Not from the step's own solution:
  // the chord depends on the tangential velocities, which the normal forces move, with a gain of
  // k_n dt^2 |rho_t|/(r zeta) >> 1 at a large dt (iterating it diverged).
  Matrices &m = *m_;
  m.chordRhs.setZero();
  largestChordForce_ = 0;
  if (!(springDt_ > 0)) return;
  const double c1 = 1.0 / (1.0 - springGamma_);
  forEachSpring([&](size_t record, const double *tail, const int *base, int, bool wall) {
    if (wall) return;  // a wall is flat: no chord
    const double *n = tail, r = tail[3] + tail[4], knc1dt = tail[8];
    double rho[3], normal = 0, tangential2 = 0;
    for (int a = 0; a < 3; a++) {
      rho[a] = springPrevious_[size_t(base[0] + a)] - springPrevious_[size_t(base[1] + a)];  // U_n
      normal += n[a] * rho[a];
    }
    for (int a = 0; a < 3; a++) tangential2 += (rho[a] - normal * n[a]) * (rho[a] - normal * n[a]);
    // k_n dt^2 |rho_t|^2/(2r) with k_n = knc1dt/(c1 dt)
    const double force = r > 0 ? knc1dt * springDt_ * tangential2 / (2 * c1 * r) : 0.0;
    chordForce_[record] = force;
    largestChordForce_ = std::max(largestChordForce_, force);
    for (int a = 0; a < 3; a++) {  // on i along -n (towards j), on j along +n
      m.chordRhs(base[0] + a) -= force * n[a];
      m.chordRhs(base[1] + a) += force * n[a];
    }
  });
}

double ParticleVelocitySystem::springVelocity(int k) const
{
  return u_[size_t(k)] - (springGamma_ != 0 ? springGamma_ * springPrevious_[size_t(k)] : 0.0);
}

void ParticleVelocitySystem::stickingForce(const double *tail, const double *w, bool wall, double end[3]) const
{
  const double *n = tail, *ft = tail + 9;
  if (wall)
    contact::wallTangentialForceAtEnd(n, tail[3], tail[4], tail[5], ft, tail + 12, w, end);
  else
    contact::pairTangentialForceAtEnd(n, tail[3], tail[4], tail[5], ft, w, end);
}

bool ParticleVelocitySystem::slideOverloadedContacts()
{
  // Coulomb's law at the end of the step (docs/contact.md 2c), a return mapping: a sticking
  // contact's implicit spring holds whatever tangential force the step needs (in a dense packing
  // far beyond mu_s F_n once kt dt/zeta_t is large); such a contact slides within the step, with the
  // cap along the direction of the overloaded force. The cap is mu_s times the smaller of the normal
  // force at the start and at the end of the step (the implicit normal spring): friction never
  // exceeds what the contact holds at either end, and a contact that opens within the step loses it.
  // The end's normal force depends on the velocities, which depend on the caps: the rounds are a
  // fixed-point iteration x -> G(x) on the caps, Anderson-mixed while no contact begins to slide.
  Matrices &m = *m_;
  bool matrixChanged = false, rhsChanged = false;
  m.leaving.clear();
  const size_t records = springSlides_.size();
  std::vector<double> caps(records, 0.0), capBounds(records, 0.0);  // G(x) of the sliding contacts; mu_s F_n(start)
  bool converged = true;
  auto setSlideForce = [&](size_t record, const double target[3], const double *ft, const int *base, int size,
                           const double *tail, bool wall) {
    const double term[3] = {target[0] - ft[0], target[1] - ft[1], target[2] - ft[2]};
    rhsChanged = setSlideTerm(record, term, tail, base, size, wall) || rhsChanged;
  };
  // one contact: w = u - gamma U_n of its particles, normalRate = n . (the contact points' approach rate)
  auto coulomb = [&](size_t record, const double *tail, const int *base, int size, bool wall) {
    const double ktc1dt = wall ? tail[4] : tail[5];
    const double mu = tail[6], normalStart = tail[7], *ft = tail + 9;
    if (!(mu > 0) || !(ktc1dt > 0)) return;  // no tangential spring: no friction (F_t = 0)
    double w[12], end[3];
    for (int k = 0; k < size; k++) w[k] = springVelocity(base[k / 6] + k % 6);
    const double cap = coulombCap(record, tail, w, wall);
    if (!springSlides_[record]) {  // sticking: does its implicit force stay under the cap?
      stickingForce(tail, w, wall, end);
      const double norm = std::sqrt(end[0] * end[0] + end[1] * end[1] + end[2] * end[2]);
      if (!(norm > cap * (1 + 1e-9)) || !(norm > 0)) return;
      springSlides_[record] = 1;
      slidingSwitches_++;
      for (int a = 0; a < 3; a++) slideDirection_[3 * record + a] = end[a] / norm;
      double Rt[144], term[6];
      removedSpring(record, tail, wall, Rt, term);
      if (wall)
        for (int k = 0; k < 6; k++) m.frictionRhs(base[0] + k) -= term[k];  // its wall term leaves F^tot
      takeOutOfMatrix(base, size, Rt);
      matrixChanged = true;
    }
    caps[record] = cap;
    capBounds[record] = mu * normalStart;
    // converged while no sliding contact's force at G(x) differs from its force at x (the cap of the
    // last solve) by more than coulombTolerance of its size (and of its F_t at the start)
    for (int a = 0; a < 3; a++) {
      const double next = cap * slideDirection_[3 * record + a], now = slideCap_[record] * slideDirection_[3 * record + a];
      if (std::fabs(next - now) > settings_.coulombTolerance * (std::fabs(next) + std::fabs(ft[a])) + 1e-300) converged = false;
    }
  };
  forEachSpring(coulomb);
  if (converged && !matrixChanged) return false;
  // the next caps: G(x), or its Anderson mixture with the last rounds' (kept within [0, mu_s F_n(start)]).
  // The history restarts when a contact began to slide (its spring left the matrix: a new map) and
  // when the caps moved more than in the round before (the clamps of G made the mixture overshoot)
  double residual = 0;
  for (size_t r = 0; r < records; r++) residual = std::max(residual, std::fabs(caps[r] - slideCap_[r]));
  const bool restart = matrixChanged || !settings_.coulombAcceleration || !(residual < lastCoulombResidual_);
  lastCoulombResidual_ = matrixChanged ? HUGE_VAL : residual;
  if (restart) {
    coulombMixing_->reset();
    if (!matrixChanged && settings_.coulombAcceleration) coulombMixing_->mix(slideCap_.data(), caps.data(), records);
  } else if (coulombMixing_->mix(slideCap_.data(), caps.data(), records)) {
    for (size_t r = 0; r < records; r++) caps[r] = springSlides_[r] ? std::min(std::max(caps[r], 0.0), capBounds[r]) : 0.0;
  }
  forEachSpring([&](size_t r, const double *tail, const int *base, int size, bool wall) {
    if (!springSlides_[r]) return;
    double target[3];
    for (int a = 0; a < 3; a++) target[a] = caps[r] * slideDirection_[3 * r + a];
    slideCap_[r] = caps[r];
    setSlideForce(r, target, tail + 9, base, size, tail, wall);
  });
  if (matrixChanged) downdateOrFactorise();
  return matrixChanged || rhsChanged;
}

void ParticleVelocitySystem::takeOutOfMatrix(const int *base, int size, const double *R)
{
  // R leaves the matrix (its entries exist: R_c had them), and gamma R U_n the known part
  Matrices &m = *m_;
  if (settings_.solver != cg) {
    Matrices::LeavingBlock block;
    block.base[0] = base[0];
    block.base[1] = size > 6 ? base[1] : base[0];
    block.size = size;
    std::copy(R, R + size * size, block.R);
    m.leaving.push_back(block);
  }
  for (int i = 0; i < size; i++) {
    const int row = base[i / 6] + i % 6;
    for (int j = 0; j < size; j++) {
      const int col = base[j / 6] + j % 6;
      m.matrix.coeffRef(row, col) -= R[size * i + j];
      if (row / 6 == col / 6) m.subgridBlock[size_t(36) * (row / 6) + 6 * (row % 6) + col % 6] -= R[size * i + j];
      if (springGamma_ != 0) m.springRhs(row) -= springGamma_ * R[size * i + j] * springPrevious_[size_t(col)];
    }
  }
}

bool ParticleVelocitySystem::setSlideTerm(size_t record, const double term[3], const double *tail, const int *base,
                                          int size, bool wall)
{
  // F^tot gets B^T of the change (the rhs term of a sliding contact: what replaces its F_t)
  double change[3], f[12];
  bool differs = false;
  for (int a = 0; a < 3; a++) {
    change[a] = term[a] - slideForce_[3 * record + a];
    differs = differs || change[a] != 0;
  }
  if (!differs) return false;
  for (int a = 0; a < 3; a++) slideForce_[3 * record + a] += change[a];
  if (wall)
    contact::wallGeneralisedForce(tail, tail[3], change, f);
  else
    contact::pairGeneralisedForce(tail, tail[3], tail[4], change, f);
  for (int k = 0; k < size; k++) m_->frictionRhs(base[k / 6] + k % 6) += f[k];
  return true;
}

void ParticleVelocitySystem::removedSpring(size_t record, const double *tail, bool wall, double *R, double *wallTerm) const
{
  double term[6];
  if (!settings_.coulombConsistent) {  // the whole tangential spring
    if (wall)
      contact::wallSpringBlock(tail, tail[3], 0.0, 1.0, tail[4], tail[5], tail + 12, R, wallTerm ? wallTerm : term);
    else
      contact::pairSpringBlock(tail, tail[3], tail[4], 0.0, 1.0, tail[5], R);
    return;
  }
  slidePart(tail, wall, &slideDirection_[3 * record], slideKeep_[record], R, wallTerm ? wallTerm : term);
}

void ParticleVelocitySystem::slidePart(const double *tail, bool wall, const double *t, double keep, double *R,
                                       double *wallTerm)
{
  if (wall)
    contact::wallSlideBlock(tail, tail[3], t, keep, tail[4], tail[5], tail + 12, R, wallTerm);
  else
    contact::pairSlideBlock(tail, tail[3], tail[4], t, keep, tail[5], R);
}

void ParticleVelocitySystem::slidingForce(size_t record, const double *tail, const double *w, bool wall,
                                          double force[3]) const
{
  // F_t + g + keep (I - n n^T - t t^T)(T - F_t): the rhs term and what the matrix still holds of the spring
  const double *n = tail, *ft = tail + 9, *g = &slideForce_[3 * record], *t = &slideDirection_[3 * record];
  const double keep = slideKeep_[record];
  double T[3];
  stickingForce(tail, w, wall, T);
  const double d[3] = {T[0] - ft[0], T[1] - ft[1], T[2] - ft[2]};
  const double dn = n[0] * d[0] + n[1] * d[1] + n[2] * d[2], dt = t[0] * d[0] + t[1] * d[1] + t[2] * d[2];
  for (int a = 0; a < 3; a++) force[a] = ft[a] + g[a] + keep * (d[a] - dn * n[a] - dt * t[a]);
}

double ParticleVelocitySystem::coulombCap(size_t record, const double *tail, const double *w, bool wall) const
{
  const double *n = tail, mu = tail[6], normalStart = tail[7], knc1dt = tail[8];
  const double rel[3] = {w[0] - (wall ? 0.0 : w[6]), w[1] - (wall ? 0.0 : w[7]), w[2] - (wall ? 0.0 : w[8])};
  const double chord = wall ? 0.0 : chordForce_[record];  // Eq. (C5): pairs only
  const double normalEnd = std::max(0.0, normalStart - knc1dt * (n[0] * rel[0] + n[1] * rel[1] + n[2] * rel[2]) - chord);
  return mu * std::min(normalStart, normalEnd);
}

bool ParticleVelocitySystem::consistentCoulombRound()
{
  // Coulomb's law at the end of the step kept at every contact (docs/contact.md 2c): the tangential force
  // is P(T), the projection of the trial force T (the sticking spring's force at the end of the step) onto
  // the disc of radius cap. A contact that sticks has its spring in the matrix; one that slides along t
  // has the spring along t out and keep = cap/|T| of it across t in: the Jacobian of cap T/|T|, so that
  // each round is a step of semismooth Newton, its right-hand side term g = P(T) - F_t - keep (I - n n^T -
  // t t^T)(T - F_t) at the last solution. A contact whose state changes, or whose slide turned or whose
  // |T| moved by more than `stretch` since its Jacobian was set, changes the matrix (a low-rank update of
  // the factorisation, signed: a spring may return); otherwise the rounds iterate g, Anderson-mixed.
  // A contact changes state at most maxFlips times in a solve, then slides on (at the cap along T).
  const int maxFlips = 3, maxRenewals = 2, freezeAfter = 20;
  const double turn = 0.95, stretch = 2.0;
  Matrices &m = *m_;
  m.leaving.clear();
  std::vector<double> next(slideForce_);  // G(x): the rhs terms at this solution
  bool matrixChanged = false, converged = true;
  forEachSpring([&](size_t r, const double *tail, const int *base, int size, bool wall) {
    const double *n = tail, *ft = tail + 9;
    const double ktc1dt = wall ? tail[4] : tail[5], mu = tail[6];
    if (!(mu > 0) || !(ktc1dt > 0)) return;  // no tangential spring: no friction (F_t = 0)
    double w[12], T[3];
    for (int k = 0; k < size; k++) w[k] = springVelocity(base[k / 6] + k % 6);
    const double cap = coulombCap(r, tail, w, wall);
    stickingForce(tail, w, wall, T);
    const double norm = std::sqrt(T[0] * T[0] + T[1] * T[1] + T[2] * T[2]);
    const bool over = norm > cap * (1 + 1e-9) && norm > 0;
    double *t0 = &slideDirection_[3 * r];
    // the part of its spring out of the matrix goes from (t0, keep of slideKeep_; none if it sticks) to
    // (t, keep; none: it sticks again): the difference leaves the matrix, its wall term F^tot
    auto changeOut = [&](bool slides, const double *t, double keep) {
      double R[144] = {0}, term[6] = {0}, before[144] = {0}, termBefore[6] = {0};
      if (springSlides_[r]) slidePart(tail, wall, t0, slideKeep_[r], before, termBefore);
      if (slides) slidePart(tail, wall, t, keep, R, term);
      for (int k = 0; k < size * size; k++) R[k] -= before[k];
      takeOutOfMatrix(base, size, R);
      if (wall)
        for (int k = 0; k < 6; k++) m.frictionRhs(base[0] + k) -= term[k] - termBefore[k];
      if (slides) {
        for (int a = 0; a < 3; a++) t0[a] = t[a];
        slideKeep_[r] = keep;
      }
      springSlides_[r] = slides;
      matrixChanged = true;
    };
    if (!springSlides_[r]) {
      if (!over) return;  // sticks: exactly in the matrix
      const double t[3] = {T[0] / norm, T[1] / norm, T[2] / norm};
      changeOut(true, t, cap / norm);
      slidingSwitches_++;
      coulombFlips_[r]++;
    } else if (coulombFrozen_[r]) {
      // slides along t0 for the rest of the solve (below)
    } else if ((!over || T[0] * t0[0] + T[1] * t0[1] + T[2] * t0[2] < cap) && coulombFlips_[r] < maxFlips) {
      // sticks again: under the cap, or its slip turned against the way it slid (T . t < cap: with the spring
      // out along t, a contact the friction can hold shows a slip that flips back and forth); the spring
      // back, the rhs term gone
      changeOut(false, t0, 0.0);
      stickingSwitches_++;
      coulombFlips_[r]++;
      for (int a = 0; a < 3; a++) next[3 * r + a] = 0;
      return;
    } else if (over) {
      const double t[3] = {T[0] / norm, T[1] / norm, T[2] / norm}, keep = cap / norm, keep0 = slideKeep_[r];
      // (at most maxRenewals in a solve: a contact whose Jacobian would swing between two states every round
      // keeps the last, its slide then converging as a chord step, Anderson-mixed)
      const bool renew = coulombRenewals_[r] < maxRenewals &&
                         (t[0] * t0[0] + t[1] * t0[1] + t[2] * t0[2] < turn || keep > stretch * keep0 || keep0 > stretch * keep);
      if (renew) {  // the Jacobian at this solution
        coulombRenewals_[r]++;
        changeOut(true, t, keep);
      }
    }
    // the rhs term at this solution (a contact past its flips slides at the cap along T even under it; a
    // frozen one along t0)
    auto rhsTerm = [&](double *g) {
      const double keep = slideKeep_[r];
      const double d[3] = {T[0] - ft[0], T[1] - ft[1], T[2] - ft[2]};
      const double dn = n[0] * d[0] + n[1] * d[1] + n[2] * d[2], dt = t0[0] * d[0] + t0[1] * d[1] + t0[2] * d[2];
      double fSize = 0, ftSize = 0, change = 0;
      for (int a = 0; a < 3; a++) {
        const double f = coulombFrozen_[r] ? cap * t0[a] : norm > 0 ? cap * T[a] / norm : 0.0;
        g[a] = f - ft[a] - keep * (d[a] - dn * n[a] - dt * t0[a]);
        fSize += f * f;
        ftSize += ft[a] * ft[a];
        change = std::max(change, std::fabs(g[a] - slideForce_[3 * r + a]));
      }
      return change > settings_.coulombTolerance * (std::sqrt(fSize) + std::sqrt(ftSize)) + 1e-300;
    };
    bool moves = rhsTerm(&next[3 * r]);
    if (moves && !coulombFrozen_[r] && coulombRenewals_[r] >= maxRenewals && rounds_ >= freezeAfter) {
      // still moving with its Jacobian renewed as often as allowed: it slides on along t0, its whole
      // spring out (the frozen slide of coulomb_solve frozen, for this contact and this solve)
      if (slideKeep_[r] != 0) {
        const double t[3] = {t0[0], t0[1], t0[2]};
        changeOut(true, t, 0.0);
      }
      coulombFrozen_[r] = 1;
      moves = rhsTerm(&next[3 * r]);
    }
    if (moves) converged = false;
  });
  double residual = 0;
  for (size_t k = 0; k < next.size(); k++) residual = std::max(residual, std::fabs(next[k] - slideForce_[k]));
  if (converged && !matrixChanged) return false;
  // the next rhs terms: G(x), or its Anderson mixture with the last rounds' (restarted as the caps' are:
  // when the matrix changed, a new map, and when the terms moved more than in the round before)
  const bool restart = matrixChanged || !settings_.coulombAcceleration || !(residual < lastCoulombResidual_);
  lastCoulombResidual_ = matrixChanged ? HUGE_VAL : residual;
  if (restart) {
    coulombMixing_->reset();
    if (!matrixChanged && settings_.coulombAcceleration) coulombMixing_->mix(slideForce_.data(), next.data(), next.size());
  } else {
    coulombMixing_->mix(slideForce_.data(), next.data(), next.size());
  }
  forEachSpring([&](size_t r, const double *tail, const int *base, int size, bool wall) {
    setSlideTerm(r, &next[3 * r], tail, base, size, wall);
  });
  if (matrixChanged) downdateOrFactorise();
  return true;
}

ParticleVelocitySystem::CoulombConsistency ParticleVelocitySystem::coulombConsistency() const
{
  CoulombConsistency c;
  forEachSpring([&](size_t r, const double *tail, const int *base, int size, bool wall) {
    const double ktc1dt = wall ? tail[4] : tail[5], mu = tail[6], *ft = tail + 9;
    if (!(mu > 0) || !(ktc1dt > 0)) return;
    double w[12], T[3], f[3], law[3];
    for (int k = 0; k < size; k++) w[k] = springVelocity(base[k / 6] + k % 6);
    const double cap = coulombCap(r, tail, w, wall);
    stickingForce(tail, w, wall, T);
    const double norm = std::sqrt(T[0] * T[0] + T[1] * T[1] + T[2] * T[2]);
    for (int a = 0; a < 3; a++) law[a] = norm > cap ? cap * T[a] / norm : T[a];
    if (springSlides_[r])
      slidingForce(r, tail, w, wall, f);
    else
      std::copy(T, T + 3, f);
    double error = 0, size2 = 0, ft2 = 0;
    for (int a = 0; a < 3; a++) {
      error += (f[a] - law[a]) * (f[a] - law[a]);
      size2 += law[a] * law[a];
      ft2 += ft[a] * ft[a];
    }
    const double relative = std::sqrt(error) / (std::sqrt(size2) + std::sqrt(ft2) + 1e-300);
    c.contacts++;
    if (relative > 1e-3) c.inconsistent++;
    c.worst = std::max(c.worst, relative);
  });
  return c;
}

void ParticleVelocitySystem::downdateOrFactorise()
{
  // Beyond maxDowndateColumns the column solves cost about as much as a factorisation of the
  // phi 0.47 Table 8 system (5742 unknowns, 2.1e6 non-zeros in its factor: 1.2e9 flops against
  // about 1e7 per column), and the capacitance grows; CG has no factorisation to downdate.
  const int maxDowndateColumns = 96;
  Matrices &m = *m_;
  // R_t = sum_k lambda_k v_k v_k^T (rank 2: the tangential plane) gives the columns sqrt(lambda_k) v_k of V,
  // at least one per block: more blocks than the room left means a factorisation, without them
  const std::vector<Matrices::LeavingBlock> &leaving = m.leaving;
  const long r0 = long(m.downdate.cols());
  if (settings_.solver == cg || r0 + long(leaving.size()) > maxDowndateColumns) {
    factorise(" after contacts started to slide");
    return;
  }
  // (a block that returns to the matrix, consistent slides, has negative eigenvalues: columns of sign -1)
  std::vector<Eigen::VectorXd> columns;
  std::vector<double> signs;
  for (const Matrices::LeavingBlock &leavingBlock : leaving) {
    const int size = leavingBlock.size;
    const Eigen::MatrixXd block = Eigen::Map<const Eigen::MatrixXd>(leavingBlock.R, size, size);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(block);
    const double largest = eigen.eigenvalues().cwiseAbs().maxCoeff();
    for (int k = 0; k < size; k++) {
      const double lambda = eigen.eigenvalues()(k);
      if (!(std::fabs(lambda) > 1e-12 * largest)) continue;
      Eigen::VectorXd column = Eigen::VectorXd::Zero(6 * n_);
      for (int i = 0; i < size; i++)
        column(leavingBlock.base[i / 6] + i % 6) = std::sqrt(std::fabs(lambda)) * eigen.eigenvectors()(i, k);
      columns.push_back(column);
      signs.push_back(lambda > 0 ? 1.0 : -1.0);
    }
  }
  const long r = r0 + long(columns.size());
  if (r > maxDowndateColumns) {
    factorise(" after contacts started to slide");
    return;
  }
  // blocks that change nothing (a consistent slide frozen with its spring already all out): no column, no
  // solve (CHOLMOD refuses a right-hand side of no columns)
  if (columns.empty()) return;
  Eigen::MatrixXd added(6 * n_, long(columns.size()));
  for (size_t k = 0; k < columns.size(); k++) added.col(long(k)) = columns[k];
  const Eigen::MatrixXd solvedAdded = m.factorisedSolve(settings_.solver, added);
  m.downdate.conservativeResize(Eigen::NoChange, r);
  m.downdate.rightCols(r - r0) = added;
  m.solvedDowndate.conservativeResize(Eigen::NoChange, r);
  m.solvedDowndate.rightCols(r - r0) = solvedAdded;
  m.downdateSign.insert(m.downdateSign.end(), signs.begin(), signs.end());
  const bool allOut = std::all_of(m.downdateSign.begin(), m.downdateSign.end(), [](double sign) { return sign > 0; });
  Eigen::MatrixXd capacitance = -m.downdate.transpose() * m.solvedDowndate;
  if (allOut) {
    capacitance.diagonal().array() += 1.0;
    m.signedUpdate = false;
    m.capacitance.compute(capacitance);
  } else {
    for (long k = 0; k < r; k++) capacitance(k, k) += m.downdateSign[size_t(k)];
    m.signedUpdate = true;
    m.signedCapacitance.compute(capacitance);
  }
  // A - V V^T stays positive definite while the particles keep their drag; if the capacitance says
  // otherwise (round-off near a singular system), the matrix is factorised as it stands
  if (allOut ? m.capacitance.info() != Eigen::Success : !(m.signedCapacitance.rcond() > 1e-12))
    factorise(" after contacts started to slide");
  else
    downdates_++;
}

double ParticleVelocitySystem::diagonal(int k) const { return m_->rigidBlock[size_t(36) * (k / 6) + 7 * (k % 6)]; }

std::vector<double> ParticleVelocitySystem::rigidBlocksTimes(const std::vector<double> &u) const
{
  const Matrices &m = *m_;
  std::vector<double> y(size_t(6) * n_, 0.0);
  for (int p = 0; p < n_; p++)
    for (int i = 0; i < 6; i++)
      for (int j = 0; j < 6; j++) y[size_t(6) * p + i] += m.rigidBlock[size_t(36) * p + 6 * i + j] * u[size_t(6) * p + j];
  return y;
}

std::vector<int> ParticleVelocitySystem::closePairs() const
{
  std::vector<int> pairs;
  pairs.reserve(size_t(2) * pairBlocks_);
  for (long b = 0; b < pairBlocks_; b++) {
    pairs.push_back(int(std::lround(pairs_[size_t(b) * pairRecord_])) - 1);
    pairs.push_back(int(std::lround(pairs_[size_t(b) * pairRecord_ + 1])) - 1);
  }
  return pairs;
}

std::vector<double> ParticleVelocitySystem::subgridForces() const
{
  // -(R^SG u - wall term): the whole matrix times u, less its rigid-body blocks
  const Matrices &m = *m_;
  const Eigen::Map<const Eigen::VectorXd> u(u_.data(), 6 * n_);
  const std::vector<double> rigid = rigidBlocksTimes(u_);
  Eigen::VectorXd forces = m.wallRhs - m.matrix * u + Eigen::Map<const Eigen::VectorXd>(rigid.data(), 6 * n_);
  // less the implicit springs' part of the matrix (contact forces, not sub-grid ones)
  const std::vector<double> springs = springForces();
  for (int k = 0; k < 6 * n_; k++) forces(k) -= springs[size_t(k)] - m.springRhs(k) - m.frictionRhs(k) - m.chordRhs(k);
  return std::vector<double>(forces.data(), forces.data() + forces.size());
}

std::vector<double> ParticleVelocitySystem::springForces(std::vector<double> *stresslets,
                                                         std::vector<double> *wallBlockForces) const
{
  // Eq. (C2): -R_c (u - gamma U_n) + dt B^T K U_w per contact; the stresslet of Eq. (52) of that force
  std::vector<double> out(size_t(6) * n_, 0.0);
  if (stresslets && stresslets->size() != size_t(6) * n_)
    throw Error(Error::notSolved, -1, "contact stresslets: " + std::to_string(stresslets->size()) + " values for " +
                                      std::to_string(n_) + " particles (6 each)");
  static const int comp[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
  auto addStress = [&](int p, const double *force, const double *branch, double weight) {
    if (!stresslets) return;
    for (int c = 0; c < 6; c++) {
      const int a = comp[c][0], b = comp[c][1];
      (*stresslets)[size_t(6) * p + c] += 0.5 * weight * (force[a] * branch[b] + branch[a] * force[b]);
    }
  };
  size_t record = 0;
  for (size_t b = 0; b < springPairs_.size(); b += springs::pairRecord, record++) {
    const double *rec = &springPairs_[b], *tail = rec + springs::pairFriction;
    const int p[2] = {int(std::lround(rec[0])) - 1, int(std::lround(rec[1])) - 1};
    const double *R = rec + 2, *branch = rec + 146, weight = rec[149];
    double w[12], f[12], Rt[144], slid[12] = {0};
    const bool slides = springSlides_[record];
    if (slides) {  // the tangential spring (or its part, consistent slides) left the matrix, the rhs term replaced F_t
      removedSpring(record, tail, false, Rt, nullptr);
      contact::pairGeneralisedForce(tail, tail[3], tail[4], &slideForce_[3 * record], slid);
    }
    for (int k = 0; k < 12; k++) w[k] = springVelocity(6 * p[k / 6] + k % 6);
    for (int i = 0; i < 12; i++) {
      f[i] = slid[i];
      if (i % 6 < 3) f[i] += (i < 6 ? -1.0 : 1.0) * chordForce_[record] * tail[i % 6];  // Eq. (C5)
      for (int j = 0; j < 12; j++) f[i] -= (R[12 * i + j] - (slides ? Rt[12 * i + j] : 0.0)) * w[j];
      out[size_t(6) * p[i / 6] + i % 6] += f[i];
    }
    // x_j - x_i from particle 1; from particle 2 the branch and the force both change sign
    addStress(p[0], f, branch, weight);
    addStress(p[1], f, branch, 1.0 - weight);
  }
  if (wallBlockForces) wallBlockForces->clear();
  for (size_t b = 0; b < springWalls_.size(); b += springs::wallRecord, record++) {
    const double *rec = &springWalls_[b], *tail = rec + springs::wallFriction;
    const int p = int(std::lround(rec[0])) - 1;
    const double *R = rec + 1, *term = rec + 37, *branch = rec + 43;
    double f[6], Rt[36], termT[6], slid[6] = {0};
    const bool slides = springSlides_[record];
    if (slides) {
      removedSpring(record, tail, true, Rt, termT);
      contact::wallGeneralisedForce(tail, tail[3], &slideForce_[3 * record], slid);
    }
    for (int i = 0; i < 6; i++) {
      f[i] = term[i] + slid[i] - (slides ? termT[i] : 0.0);
      for (int j = 0; j < 6; j++) f[i] -= (R[6 * i + j] - (slides ? Rt[6 * i + j] : 0.0)) * springVelocity(6 * p + j);
      out[size_t(6) * p + i] += f[i];
    }
    if (wallBlockForces) wallBlockForces->insert(wallBlockForces->end(), f, f + 6);
    addStress(p, f, branch, 1.0);
  }
  return out;
}

ParticleVelocitySystem::SlidingCount ParticleVelocitySystem::slidingAtEnd() const
{
  SlidingCount count;
  forEachSpring([&](size_t record, const double *tail, const int *base, int size, bool wall) {
    if (!springSlides_[record]) return;
    count.sliding++;
    // F_t - F_t,end (the sticking force at the solution) is the slip over the step in units of force,
    // k_t c1 dt rho_t
    const double *ft = tail + 9, *t = &slideDirection_[3 * record];
    double w[12], end[3];
    for (int k = 0; k < size; k++) w[k] = springVelocity(base[k / 6] + k % 6);
    stickingForce(tail, w, wall, end);
    if (settings_.coulombConsistent) {  // the force it applies, its direction and size
      double f[3];
      slidingForce(record, tail, w, wall, f);
      const double size = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
      const double slipAlong = size > 0 ? ((ft[0] - end[0]) * f[0] + (ft[1] - end[1]) * f[1] + (ft[2] - end[2]) * f[2]) / size : 0.0;
      if (slipAlong > size && size > 0) count.alongFriction++;
      return;
    }
    const double slipAlong = (ft[0] - end[0]) * t[0] + (ft[1] - end[1]) * t[1] + (ft[2] - end[2]) * t[2];
    if (slipAlong > slideCap_[record] && slideCap_[record] > 0) count.alongFriction++;
  });
  return count;
}

std::vector<double> ParticleVelocitySystem::wallBlockForces() const
{
  std::vector<double> forces(size_t(6) * wallBlocks_, 0.0);
  for (long b = 0; b < wallBlocks_; b++) {
    const double *rec = &walls_[size_t(b) * wallRecord_];
    const int p = int(std::lround(rec[0])) - 1;
    const double *R = rec + 1, *wallTerm = rec + 37;  // 6 x 6, then R_w[:, 0:3] U_w (6)
    for (int row = 0; row < 6; row++) {
      double value = wallTerm[row];
      for (int k = 0; k < 6; k++) value -= R[6 * row + k] * u_[size_t(6) * p + k];
      forces[size_t(6) * b + row] = value;
    }
  }
  return forces;
}

void ParticleVelocitySystem::addSubgridStresslets(std::vector<double> &stresslets) const
{
  if (!settings_.stresslets)
    throw Error(Error::notSolved, -1, "sub-grid stresslets asked of a system assembled without stress rows");
  if (stresslets.size() != size_t(7) * n_)
    throw Error(Error::notSolved, -1, "sub-grid stresslets: " + std::to_string(stresslets.size()) + " values for " +
                                      std::to_string(n_) + " particles (7 each)");
  for (long b = 0; b < pairBlocks_; b++) {
    const double *rec = &pairs_[size_t(b) * pairRecord_];
    const int p[2] = {int(std::lround(rec[0])) - 1, int(std::lround(rec[1])) - 1};
    const double *rows = rec + subgrid::pairRecord;  // 14 x 12: S_1 (6), S_2 (6), s_1, s_2
    double velocity[12];
    for (int k = 0; k < 6; k++) {
      velocity[k] = u_[size_t(6) * p[0] + k];
      velocity[6 + k] = u_[size_t(6) * p[1] + k];
    }
    for (int row = 0; row < 14; row++) {
      double value = 0;
      for (int k = 0; k < 12; k++) value -= rows[12 * row + k] * velocity[k];
      const int who = row < 12 ? row / 6 : row - 12;
      const int component = row < 12 ? row % 6 : 6;
      stresslets[size_t(7) * p[who] + component] += value;
    }
  }
  for (long b = 0; b < wallBlocks_; b++) {
    const double *rec = &walls_[size_t(b) * wallRecord_];
    const int p = int(std::lround(rec[0])) - 1;
    const double *rows = rec + subgrid::wallRecord, *wallTerm = rows + 42;  // 7 x 6, then 7
    for (int row = 0; row < 7; row++) {
      double value = wallTerm[row];
      for (int k = 0; k < 6; k++) value -= rows[6 * row + k] * u_[size_t(6) * p + k];
      stresslets[size_t(7) * p + row] += value;
    }
  }
}

}  // namespace fdm
