// Tests of Eq. (31) on its own (particle_velocity_system.h; no LIGGGHTS): random small systems
// against a dense Eigen solve, both solvers, the factorisation kept while only the right-hand side
// changes, the sub-grid force and stresslet rows, and every error.
#include "particle_velocity_system.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <random>

using fdm::ParticleVelocitySystem;
namespace subgrid = fdm::subgrid;

namespace {

// A random scene: particles, sub-grid blocks in the records of pair_style fdm/subgrid, volumes,
// fluid forces, and the same system written out densely.
struct Scene {
  ParticleVelocitySystem::Settings settings;
  std::vector<ParticleVelocitySystem::Particle> particles;
  std::vector<double> pairs, walls, Vu, Ju, fluid;
  Eigen::MatrixXd R;        // R^SG, 6N x 6N
  Eigen::VectorXd wallRhs;  // sum of R_w[:, 0:3] U_w

  int n() const { return int(particles.size()); }

  // [(rho_f/rho_p) J/alpha + R^SG] and F^tot of Eq. (32)
  Eigen::MatrixXd matrix() const
  {
    Eigen::MatrixXd A = R;
    for (int p = 0; p < n(); p++)
      for (int d = 0; d < 3; d++) {
        A(6 * p + d, 6 * p + d) += settings.rhoFluid * Vu[p] / settings.alphaLambda;
        A(6 * p + 3 + d, 6 * p + 3 + d) += settings.rhoFluid * Ju[p] / settings.alphaLambda;
      }
    return A;
  }
  Eigen::VectorXd rhs() const
  {
    Eigen::VectorXd F = wallRhs;
    for (int p = 0; p < n(); p++) {
      const ParticleVelocitySystem::Particle &q = particles[p];
      for (int d = 0; d < 3; d++) {
        F(6 * p + d) += fluid[6 * p + d] + (q.density - settings.rhoFluid) / q.density * q.mass * settings.gravity[d] +
                        q.force[d];
        F(6 * p + 3 + d) += fluid[6 * p + 3 + d] + q.torque[d];
      }
    }
    return F;
  }
};

// A symmetric positive semi-definite block of size m (as the resistance blocks are), scaled.
Eigen::MatrixXd randomBlock(std::mt19937 &rng, int m, double scale)
{
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::MatrixXd B(m, m);
  for (int i = 0; i < m; i++)
    for (int j = 0; j < m; j++) B(i, j) = u(rng);
  return scale * B * B.transpose() / m;
}

Scene randomScene(unsigned seed, int n, int nPairs, int nWalls, bool stresslets,
                  ParticleVelocitySystem::Solver solver = ParticleVelocitySystem::cholmod)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), positive(0.5, 2);
  Scene s;
  s.settings.solver = solver;
  s.settings.tolerance = 1e-14;
  s.settings.alphaLambda = 0.25;
  s.settings.rhoFluid = 1000;
  s.settings.gravity[0] = 0.3;
  s.settings.gravity[2] = -9.81;
  s.settings.stresslets = stresslets;
  s.particles.resize(n);
  s.Vu.resize(n);
  s.Ju.resize(n);
  s.fluid.resize(6 * n);
  for (int p = 0; p < n; p++) {
    ParticleVelocitySystem::Particle &q = s.particles[p];
    q.radius = 0.1 * positive(rng);
    for (int d = 0; d < 3; d++) {
      q.x[d] = 5 + 4 * u(rng);
      q.force[d] = u(rng);
      q.torque[d] = 0.1 * u(rng);
    }
    q.density = 1000 * positive(rng);
    q.mass = q.density * 4.0 / 3.0 * M_PI * std::pow(q.radius, 3);
    s.Vu[p] = 4.0 / 3.0 * M_PI * std::pow(q.radius, 3) * positive(rng);
    s.Ju[p] = 0.4 * q.radius * q.radius * s.Vu[p];
    for (int c = 0; c < 6; c++) s.fluid[6 * p + c] = u(rng);
  }
  s.R = Eigen::MatrixXd::Zero(6 * n, 6 * n);
  s.wallRhs = Eigen::VectorXd::Zero(6 * n);
  const double scale = 1000 * 0.25 * 1e-3;  // of the order of the diagonal
  for (int b = 0; b < nPairs && n > 1; b++) {
    int i = int(rng() % n), j = int(rng() % n);
    if (i == j) j = (i + 1) % n;
    const Eigen::MatrixXd block = randomBlock(rng, 12, scale);
    s.pairs.push_back(i + 1);
    s.pairs.push_back(j + 1);
    for (int r = 0; r < 12; r++)
      for (int c = 0; c < 12; c++) s.pairs.push_back(block(r, c));
    const int base[2] = {6 * i, 6 * j};
    for (int r = 0; r < 12; r++)
      for (int c = 0; c < 12; c++) s.R(base[r / 6] + r % 6, base[c / 6] + c % 6) += block(r, c);
    if (stresslets)
      for (int k = 0; k < subgrid::pairStressRecord; k++) s.pairs.push_back(u(rng));
  }
  for (int b = 0; b < nWalls; b++) {
    const int p = int(rng() % n);
    const Eigen::MatrixXd block = randomBlock(rng, 6, scale);
    const double Uw[3] = {u(rng), 0, 0.5 * u(rng)};  // a wall moving in its plane y = const
    s.walls.push_back(p + 1);
    for (int r = 0; r < 6; r++)
      for (int c = 0; c < 6; c++) s.walls.push_back(block(r, c));
    for (int r = 0; r < 6; r++) {
      double rhs = 0;
      for (int c = 0; c < 3; c++) rhs += block(r, c) * Uw[c];
      s.walls.push_back(rhs);
      s.wallRhs(6 * p + r) += rhs;
    }
    s.R.block(6 * p, 6 * p, 6, 6) += block;
    if (stresslets)
      for (int k = 0; k < subgrid::wallStressRecord; k++) s.walls.push_back(u(rng));
  }
  return s;
}

void expectClose(const std::vector<double> &got, const Eigen::VectorXd &expected, double tolerance, const std::string &what)
{
  ASSERT_EQ(got.size(), size_t(expected.size())) << what;
  const double scale = expected.cwiseAbs().maxCoeff();
  for (int k = 0; k < expected.size(); k++)
    EXPECT_NEAR(got[k], expected(k), tolerance * scale) << what << ": unknown " << k << " (particle " << k / 6 + 1 << ")";
}

// Runs f and expects ParticleVelocitySystem::Error of this kind, about this particle, whose text
// contains every needle.
template <class F>
void expectError(F f, ParticleVelocitySystem::Error::Kind kind, int particle, std::initializer_list<std::string> needles)
{
  try {
    f();
    ADD_FAILURE() << "no error";
  } catch (const ParticleVelocitySystem::Error &e) {
    EXPECT_EQ(e.kind, kind) << e.what();
    EXPECT_EQ(e.particle, particle) << e.what();
    for (const std::string &n : needles) EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << "'" << n << "' not in: " << e.what();
  }
}

}  // namespace

TEST(ParticleVelocitySystem, RandomSystemsMatchADenseSolve)
{
  unsigned seed = 1;
  for (int n : {1, 2, 3, 7, 12, 20})
    for (int blocks = 0; blocks < 3; blocks++)  // none, pairs, pairs and walls
      for (ParticleVelocitySystem::Solver solver :
           {ParticleVelocitySystem::cholmod, ParticleVelocitySystem::ldlt, ParticleVelocitySystem::cg}) {
        const int nPairs = blocks > 0 ? 2 * n : 0, nWalls = blocks > 1 ? 1 + n / 3 : 0;
        Scene s = randomScene(seed++, n, nPairs, nWalls, false, solver);
        const Eigen::VectorXd expected = s.matrix().ldlt().solve(s.rhs());
        ParticleVelocitySystem system(s.settings);
        system.assemble(s.particles, s.pairs, s.walls);
        system.setVolumes(s.Vu, s.Ju);
        const std::string what = "N " + std::to_string(n) +
                                 (solver == ParticleVelocitySystem::cg ? " cg" : solver == ParticleVelocitySystem::ldlt ? " ldlt" : " cholmod") +
                                 ", " + std::to_string(system.pairBlocks()) + " pair and " +
                                 std::to_string(system.wallBlocks()) + " wall blocks";
        expectClose(system.solve(s.fluid), expected, 1e-10, what);
        EXPECT_EQ(system.velocities(), system.solve(s.fluid)) << what;
        if (solver != ParticleVelocitySystem::cg) EXPECT_EQ(system.lastIterations(), 1);
        EXPECT_EQ(system.pairBlocks(), n > 1 ? nPairs : 0);
        EXPECT_EQ(system.wallBlocks(), nWalls);
      }
}

TEST(ParticleVelocitySystem, FactorisationIsKeptWhileOnlyTheRightHandSideChanges)
{
  Scene s = randomScene(42, 6, 8, 2, false);
  ParticleVelocitySystem system(s.settings);
  system.assemble(s.particles, s.pairs, s.walls);
  system.setVolumes(s.Vu, s.Ju);
  EXPECT_EQ(system.factorisations(), 1);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int iteration = 0; iteration < 4; iteration++) {  // inner iterations: new fluid forces
    for (double &f : s.fluid) f = u(rng);
    expectClose(system.solve(s.fluid), s.matrix().ldlt().solve(s.rhs()), 1e-10, "iteration " + std::to_string(iteration));
  }
  EXPECT_EQ(system.factorisations(), 1);
  system.setVolumes(s.Vu, s.Ju);  // the same volumes: nothing to do
  EXPECT_EQ(system.factorisations(), 1);
  s.Vu[3] *= 1.5;                 // other volumes: a new diagonal
  system.setVolumes(s.Vu, s.Ju);
  EXPECT_EQ(system.factorisations(), 2);
  expectClose(system.solve(s.fluid), s.matrix().ldlt().solve(s.rhs()), 1e-10, "new volumes");
  system.assemble(s.particles, s.pairs, s.walls);  // the next step
  system.setVolumes(s.Vu, s.Ju);
  EXPECT_EQ(system.factorisations(), 3);
}

TEST(ParticleVelocitySystem, ConjugateGradientsStartFromThePreviousSolution)
{
  Scene s = randomScene(3, 10, 20, 3, false, ParticleVelocitySystem::cg);
  s.settings.tolerance = 1e-10;
  ParticleVelocitySystem system(s.settings);
  system.assemble(s.particles, s.pairs, s.walls);
  system.setVolumes(s.Vu, s.Ju);
  system.solve(s.fluid);
  EXPECT_GT(system.lastIterations(), 1);
  system.solve(s.fluid);  // the same right-hand side: already converged
  EXPECT_EQ(system.lastIterations(), 0);
  system.assemble(s.particles, s.pairs, s.walls);  // next step, same N: still the warm start
  system.setVolumes(s.Vu, s.Ju);
  system.solve(s.fluid);
  EXPECT_EQ(system.lastIterations(), 0);
  s.particles.pop_back();  // another N: from zero
  s.Vu.pop_back();
  s.Ju.pop_back();
  s.fluid.resize(6 * s.particles.size());
  system.assemble(s.particles, std::vector<double>(), std::vector<double>());
  EXPECT_EQ(system.velocities(), std::vector<double>(6 * s.particles.size(), 0.0));
}

TEST(ParticleVelocitySystem, SubgridForceIsMinusRTimesUPlusTheWallTerm)
{
  for (bool walls : {false, true}) {
    Scene s = randomScene(11, 8, 12, walls ? 4 : 0, false);
    ParticleVelocitySystem system(s.settings);
    system.assemble(s.particles, s.pairs, s.walls);
    system.setVolumes(s.Vu, s.Ju);
    const std::vector<double> &u = system.solve(s.fluid);
    const Eigen::Map<const Eigen::VectorXd> U(u.data(), u.size());
    const Eigen::VectorXd expected = -(s.R * U - s.wallRhs);
    expectClose(system.subgridForces(), expected, 1e-12, walls ? "with walls" : "pairs");
  }
}

TEST(ParticleVelocitySystem, WallBlockForcesAreEachBlocksShare)
{
  // Each wall block's force on its particle, R_w[:, 0:3] U_w - R_w u_p (Eq. D.6), by hand; without
  // pair blocks their sum per particle is subgridForces() (fix fdm/couple sums them per wall for the
  // momentum balance of a sheared suspension).
  for (bool stresslets : {false, true}) {
    Scene s = randomScene(17, 6, 0, 9, stresslets);
    ParticleVelocitySystem system(s.settings);
    system.assemble(s.particles, s.pairs, s.walls);
    system.setVolumes(s.Vu, s.Ju);
    const std::vector<double> u = system.solve(s.fluid);
    const std::vector<double> blocks = system.wallBlockForces();
    ASSERT_EQ(blocks.size(), size_t(6 * 9));
    const size_t record = subgrid::wallRecord + (stresslets ? subgrid::wallStressRecord : 0);
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(6 * s.n()), byHand(6 * 9);
    for (int b = 0; b < 9; b++) {
      const double *rec = &s.walls[b * record];
      const int p = int(rec[0]) - 1;
      for (int r = 0; r < 6; r++) {
        double f = rec[37 + r];
        for (int c = 0; c < 6; c++) f -= rec[1 + 6 * r + c] * u[6 * p + c];
        byHand(6 * b + r) = f;
        sum(6 * p + r) += blocks[6 * b + r];
      }
    }
    expectClose(blocks, byHand, 1e-14, "wall blocks");
    expectClose(system.subgridForces(), sum, 1e-12, "sum of the wall blocks");
  }
}

TEST(ParticleVelocitySystem, StressletRowsAreAppliedToTheirParticles)
{
  Scene s = randomScene(5, 5, 6, 3, true);
  ParticleVelocitySystem system(s.settings);
  system.assemble(s.particles, s.pairs, s.walls);
  system.setVolumes(s.Vu, s.Ju);
  const std::vector<double> u = system.solve(s.fluid);
  // the rows by hand: pair rows 0-5 particle 1's S, 6-11 particle 2's, 12 and 13 the traces s_1, s_2;
  // wall rows 0-5 S, 6 s, plus the wall-velocity term
  std::vector<double> expected(7 * s.n());
  for (int k = 0; k < 7 * s.n(); k++) expected[k] = 0.5 * k;  // the fluid's part
  std::vector<double> got = expected;
  const int pairWidth = subgrid::pairRecord + subgrid::pairStressRecord;
  for (size_t b = 0; b < s.pairs.size() / pairWidth; b++) {
    const double *rec = &s.pairs[b * pairWidth];
    const int p[2] = {int(rec[0]) - 1, int(rec[1]) - 1};
    const double *rows = rec + subgrid::pairRecord;
    for (int row = 0; row < 14; row++) {
      const int who = row < 12 ? row / 6 : row - 12, component = row < 12 ? row % 6 : 6;
      for (int k = 0; k < 12; k++) expected[7 * p[who] + component] -= rows[12 * row + k] * u[6 * p[k / 6] + k % 6];
    }
  }
  const int wallWidth = subgrid::wallRecord + subgrid::wallStressRecord;
  for (size_t b = 0; b < s.walls.size() / wallWidth; b++) {
    const double *rec = &s.walls[b * wallWidth];
    const int p = int(rec[0]) - 1;
    const double *rows = rec + subgrid::wallRecord;
    for (int row = 0; row < 7; row++) {
      expected[7 * p + row] += rows[42 + row];
      for (int k = 0; k < 6; k++) expected[7 * p + row] -= rows[6 * row + k] * u[6 * p + k];
    }
  }
  system.addSubgridStresslets(got);
  for (int k = 0; k < 7 * s.n(); k++)
    EXPECT_NEAR(got[k], expected[k], 1e-12 * (1 + std::fabs(expected[k]))) << "particle " << k / 7 + 1 << " component " << k % 7;
  // without stress rows there is nothing to add
  Scene plain = randomScene(5, 5, 6, 3, false);
  ParticleVelocitySystem noRows(plain.settings);
  noRows.assemble(plain.particles, plain.pairs, plain.walls);
  expectError([&] { noRows.addSubgridStresslets(got); }, ParticleVelocitySystem::Error::notSolved, -1,
              {"without stress rows"});
}

TEST(ParticleVelocitySystem, ClosePairsAreThoseWithABlock)
{
  Scene s = randomScene(9, 4, 3, 1, false);
  ParticleVelocitySystem system(s.settings);
  system.assemble(s.particles, s.pairs, s.walls);
  const std::vector<int> pairs = system.closePairs();
  ASSERT_EQ(pairs.size(), 6u);
  for (int b = 0; b < 3; b++) {
    EXPECT_EQ(pairs[2 * b], int(s.pairs[b * subgrid::pairRecord]) - 1);
    EXPECT_EQ(pairs[2 * b + 1], int(s.pairs[b * subgrid::pairRecord + 1]) - 1);
  }
}

TEST(ParticleVelocitySystem, ParticleWithoutVolumeIsNamed)
{
  Scene s = randomScene(13, 3, 2, 0, false);
  s.particles[1].x[0] = 6;
  s.particles[1].x[1] = 5;
  s.particles[1].x[2] = 3.5;
  s.particles[1].radius = 0.7;
  ParticleVelocitySystem system(s.settings);
  system.assemble(s.particles, s.pairs, s.walls);
  for (double bad : {0.0, -1e-3}) {
    std::vector<double> Vu = s.Vu, Ju = s.Ju;
    Vu[1] = bad;
    expectError([&] { system.setVolumes(Vu, Ju); }, ParticleVelocitySystem::Error::noVolume, 1,
                {"particle 2 at (6, 5, 3.5) with radius 0.7: the fluid's indicator function gives it no volume (Vu " +
                 std::string(bad == 0 ? "0," : "-0.001,")});
    Vu = s.Vu;
    Ju[1] = bad;
    expectError([&] { system.setVolumes(Vu, Ju); }, ParticleVelocitySystem::Error::noVolume, 1, {"particle 2", "no volume"});
  }
}

TEST(ParticleVelocitySystem, NonFiniteValuesAreNamed)
{
  Scene s = randomScene(17, 3, 2, 1, false);
  ParticleVelocitySystem system(s.settings);
  system.assemble(s.particles, s.pairs, s.walls);
  std::vector<double> Vu = s.Vu;
  Vu[2] = std::nan("");
  expectError([&] { system.setVolumes(Vu, s.Ju); }, ParticleVelocitySystem::Error::fluidValue, 2,
              {"non-finite volume for particle 3", "Vu nan"});
  expectError([&] { system.solve(s.fluid); }, ParticleVelocitySystem::Error::notSolved, -1, {"before the particle volumes"});
  system.setVolumes(s.Vu, s.Ju);
  std::vector<double> fluid = s.fluid;
  fluid[6 * 2 + 1] = HUGE_VAL;
  expectError([&] { system.solve(fluid); }, ParticleVelocitySystem::Error::fluidValue, 2,
              {"non-finite integral for particle 3", "(Fy = inf)"});
  // a non-finite force from the particle code: the velocity is not finite, naming its force
  s.particles[0].force[2] = std::nan("");
  system.assemble(s.particles, s.pairs, s.walls);
  system.setVolumes(s.Vu, s.Ju);
  expectError([&] { system.solve(s.fluid); }, ParticleVelocitySystem::Error::notSolved, 0,
              {"the velocity of particle 1", "is not finite (Eq. 31)", "nan)"});
  // blocks: a non-finite value, a tag out of range, a record cut short
  s.particles[0].force[2] = 0;
  std::vector<double> pairs = s.pairs;
  pairs[2 + 13] = std::nan("");
  expectError([&] { system.assemble(s.particles, pairs, s.walls); }, ParticleVelocitySystem::Error::badBlock,
              int(pairs[0]) - 1, {"non-finite sub-grid block for particles"});
  std::vector<double> walls = s.walls;
  walls[0] = 4;
  expectError([&] { system.assemble(s.particles, s.pairs, walls); }, ParticleVelocitySystem::Error::badBlock, -1,
              {"block for particle ID 4"});
  walls.pop_back();
  expectError([&] { system.assemble(s.particles, s.pairs, walls); }, ParticleVelocitySystem::Error::badBlock, -1,
              {"not whole records"});
  // the settings
  ParticleVelocitySystem::Settings settings = s.settings;
  settings.alphaLambda = 0;
  expectError([&] { ParticleVelocitySystem bad(settings); }, ParticleVelocitySystem::Error::notSolved, -1,
              {"positive alpha_lambda (0 s)"});
}

// Eq. (30) integrated over a discrete sphere: the fluid integrals of a rigid motion U0 + Omega0 x r
// sampled on any stencil (weights I_u V, offsets r; lambda = 0) give back exactly U0, Omega0 when
// the rigid-body block carries the stencil's own first moment and inertia tensor. With the paper's
// diagonal (m1 = 0, J = Ju 1) they do not: the particle turns in a uniform flow (docs/validation.md).
TEST(ParticleVelocitySystem, RigidBlockReturnsTheRigidMotionOfAnyStencil)
{
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(-1, 1), w(0.05, 1);
  Scene s = randomScene(37, 1, 0, 0, false);
  s.particles[0].density = s.settings.rhoFluid;  // neutrally buoyant, no other force
  for (int d = 0; d < 3; d++) s.particles[0].force[d] = s.particles[0].torque[d] = 0;
  const double scale = s.settings.rhoFluid / s.settings.alphaLambda;
  for (int trial = 0; trial < 20; trial++) {
    const Eigen::Vector3d U0(u(rng), u(rng), u(rng)), W0(u(rng), u(rng), u(rng)), shift(0.3 * u(rng), 0.3 * u(rng), 0);
    ParticleVelocitySystem::RigidVolume v;
    Eigen::Vector3d F = Eigen::Vector3d::Zero(), T = Eigen::Vector3d::Zero(), m1 = Eigen::Vector3d::Zero();
    Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
    double Vu = 0;
    for (int i = -2; i <= 2; i++)  // a lumpy sphere of cells, off-centre by `shift`, random weights
      for (int j = -2; j <= 2; j++)
        for (int k = -2; k <= 2; k++) {
          const Eigen::Vector3d r = Eigen::Vector3d(i, j, k) + shift;
          if (r.norm() > 2.2) continue;
          const double weight = w(rng);
          const Eigen::Vector3d ustar = U0 + W0.cross(r);
          Vu += weight;
          m1 += weight * r;
          J += weight * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
          F += scale * weight * ustar;
          T += scale * weight * r.cross(ustar);
        }
    v.Vu = Vu;
    for (int d = 0; d < 3; d++) v.m1[d] = m1(d);
    const double Jr[6] = {J(0, 0), J(0, 1), J(0, 2), J(1, 1), J(1, 2), J(2, 2)};
    std::copy(Jr, Jr + 6, v.J);
    const std::vector<double> fluid = {F(0), F(1), F(2), T(0), T(1), T(2)};
    ParticleVelocitySystem system(s.settings);
    system.assemble(s.particles, {}, {});
    system.setVolumes(std::vector<ParticleVelocitySystem::RigidVolume>{v});
    const std::vector<double> got = system.solve(fluid);
    for (int d = 0; d < 3; d++) {
      EXPECT_NEAR(got[d], U0(d), 1e-12) << "trial " << trial;
      EXPECT_NEAR(got[3 + d], W0(d), 1e-12) << "trial " << trial;
    }
    // the rigid-body blocks times u give the fluid integrals back (the hydrodynamic force is zero)
    const std::vector<double> back = system.rigidBlocksTimes(got);
    for (int k = 0; k < 6; k++) EXPECT_NEAR(back[k], fluid[k], 1e-10 * (1 + std::fabs(fluid[k])));
    // the paper's diagonal with the same volume and trace: the rotation is off when m1 != 0
    if (trial == 0) {
      ParticleVelocitySystem paper(s.settings);
      paper.assemble(s.particles, {}, {});
      paper.setVolumes({Vu}, {J.trace() / 3});
      const std::vector<double> off = paper.solve(fluid);
      EXPECT_GT(std::fabs(off[5] - W0(2)) + std::fabs(off[3] - W0(0)) + std::fabs(off[4] - W0(1)), 1e-3);
    }
  }
  // a block that is not positive definite is no volume, named
  ParticleVelocitySystem system(s.settings);
  system.assemble(s.particles, {}, {});
  ParticleVelocitySystem::RigidVolume bad;
  bad.Vu = 1;
  bad.m1[0] = 2;  // the first moment of a unit weight at distance 2 would need J >= 4
  bad.J[0] = bad.J[3] = bad.J[5] = 1;
  try {
    system.setVolumes(std::vector<ParticleVelocitySystem::RigidVolume>{bad});
    ADD_FAILURE() << "a block that is not positive definite was taken";
  } catch (const ParticleVelocitySystem::Error &e) {
    EXPECT_EQ(e.kind, ParticleVelocitySystem::Error::noVolume);
    EXPECT_NE(std::string(e.what()).find("m1 (2, 0, 0)"), std::string::npos) << e.what();
  }
}
