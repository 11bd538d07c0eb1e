// Tests of the implicit contact-spring blocks (contact_springs.h, docs/contact.md 2b, Eqs. C1-C4) and
// of their place in Eq. (31) (particle_velocity_system.h): symmetric positive semi-definite,
// frame-invariant, no force for a rigid motion of the pair, the block times u equal to the spring
// force of the contact points' relative velocity as the contact law has it, and the overdamped
// spring stepped through Eq. (31) decaying by the factor of Eq. (C4) at any dt; the chord term of
// Eq. (C5) keeping a sliding pair's straight step where its spring assumed it.
#include "contact_springs.h"
#include "particle_velocity_system.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <random>

using fdm::ParticleVelocitySystem;
namespace contact = fdm::contact;
namespace springs = fdm::springs;

namespace {

typedef Eigen::Matrix<double, 12, 12, Eigen::RowMajor> Matrix12;
typedef Eigen::Matrix<double, 6, 6, Eigen::RowMajor> Matrix6;

Eigen::Vector3d randomUnit(std::mt19937 &rng)
{
  std::normal_distribution<double> g;
  Eigen::Vector3d n(g(rng), g(rng), g(rng));
  return n.normalized();
}

Eigen::Matrix3d randomRotation(std::mt19937 &rng)
{
  std::normal_distribution<double> g;
  Eigen::Matrix3d A;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) A(i, j) = g(rng);
  Eigen::HouseholderQR<Eigen::Matrix3d> qr(A);
  Eigen::Matrix3d Q = qr.householderQ();
  if (Q.determinant() < 0) Q.col(0) *= -1;
  return Q;
}

Matrix12 pairBlock(const Eigen::Vector3d &n, double li, double lj, double kn, double kt, double c1dt)
{
  Matrix12 R;
  contact::pairSpringBlock(n.data(), li, lj, kn, kt, c1dt, R.data());
  return R;
}

// the contact law's relative velocity of the contact points (pair_fdm_subgrid.cpp)
Eigen::Vector3d slip(const Eigen::Vector3d &n, double li, double lj, const Eigen::Matrix<double, 12, 1> &u)
{
  const Eigen::Vector3d Ui = u.segment<3>(0), Wi = u.segment<3>(3), Uj = u.segment<3>(6), Wj = u.segment<3>(9);
  return Ui - Uj - (li * Wi + lj * Wj).cross(n);
}

}  // namespace

TEST(ContactSprings, PairBlockIsSymmetricPositiveSemiDefiniteWithTheRankOfItsSprings)
{
  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; trial++) {
    const Eigen::Vector3d n = randomUnit(rng);
    for (double kt : {0.0, 700.0}) {
      const Matrix12 R = pairBlock(n, 1.0, 1.4, 2e4, kt, 0.015);
      EXPECT_EQ((R - R.transpose()).cwiseAbs().maxCoeff(), 0.0);
      Eigen::SelfAdjointEigenSolver<Matrix12> eig(R);
      const double largest = eig.eigenvalues().maxCoeff();
      EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-12 * largest);
      int rank = 0;
      for (int k = 0; k < 12; k++) rank += eig.eigenvalues()(k) > 1e-10 * largest;
      EXPECT_EQ(rank, kt > 0 ? 3 : 1);  // one spring per direction of the contact point's slip
    }
  }
}

TEST(ContactSprings, PairBlockIsFrameInvariant)
{
  std::mt19937 rng(5);
  for (int trial = 0; trial < 20; trial++) {
    const Eigen::Vector3d n = randomUnit(rng);
    const Eigen::Matrix3d Q = randomRotation(rng);
    Matrix12 P = Matrix12::Zero();
    for (int b = 0; b < 4; b++) P.block<3, 3>(3 * b, 3 * b) = Q;
    const Matrix12 R = pairBlock(n, 0.9, 1.3, 2e4, 300, 0.01), Rq = pairBlock(Q * n, 0.9, 1.3, 2e4, 300, 0.01);
    EXPECT_LT((Rq - P * R * P.transpose()).cwiseAbs().maxCoeff(), 1e-12 * R.cwiseAbs().maxCoeff());
  }
}

TEST(ContactSprings, RigidMotionOfThePairLoadsNoSpring)
{
  // contact points in the middle of the gap, l = a + h/2: for gaps inside the roughness layer and
  // overlaps alike, U = V + W x x, Omega = W gives no force at all
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (double h : {0.005, 1e-6, 0.0, -0.003}) {
    const double ai = 1.0, aj = 1.4;
    const Eigen::Vector3d n = randomUnit(rng), xj(u(rng), u(rng), u(rng));
    const Eigen::Vector3d xi = xj + (ai + aj + h) * n;  // n from j to i
    const Eigen::Vector3d V(u(rng), u(rng), u(rng)), W(u(rng), u(rng), u(rng));
    Eigen::Matrix<double, 12, 1> rigid;
    rigid << V + W.cross(xi), W, V + W.cross(xj), W;
    const Matrix12 R = pairBlock(n, ai + h / 2, aj + h / 2, 2e4, 2e4, 0.01);
    EXPECT_LT((R * rigid).cwiseAbs().maxCoeff(), 1e-12 * R.cwiseAbs().maxCoeff() * rigid.cwiseAbs().maxCoeff()) << h;
    // a relative motion does load it
    Eigen::Matrix<double, 12, 1> relative = rigid;
    relative.segment<3>(0) += 1e-3 * n;
    EXPECT_GT((R * relative).norm(), 1e-4 * R.cwiseAbs().maxCoeff());
  }
}

TEST(ContactSprings, BlockTimesVelocityIsTheSpringForceOfTheContactPointsSlip)
{
  // R u = c1 dt B^T K v_r (Eq. C3): on i the force c1 dt K v_r and the torque -l_i n x (that), on j
  // minus the force and -l_j n x (minus the force) -- the explicit law's force and torques
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> r(-1, 1);
  const double kn = 3e4, kt = 1e3, c1dt = 0.02, li = 1.002, lj = 1.402;
  for (int trial = 0; trial < 10; trial++) {
    const Eigen::Vector3d n = randomUnit(rng);
    Eigen::Matrix<double, 12, 1> u;
    for (int k = 0; k < 12; k++) u(k) = r(rng);
    const Eigen::Vector3d vr = slip(n, li, lj, u);
    const Eigen::Matrix3d K = kn * n * n.transpose() + kt * (Eigen::Matrix3d::Identity() - n * n.transpose());
    const Eigen::Vector3d f = -c1dt * K * vr;  // the change of the spring force on i over the step
    Eigen::Matrix<double, 12, 1> expected;
    expected << f, -li * n.cross(f), -f, -lj * n.cross(f);  // T_j = -l_j n x (force on i), as the law has it
    const Eigen::Matrix<double, 12, 1> got = -pairBlock(n, li, lj, kn, kt, c1dt) * u;
    EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-11 * expected.cwiseAbs().maxCoeff());
  }
}

TEST(ContactSprings, WallBlockAndWallVelocity)
{
  // symmetric PSD; a sphere sliding steadily with the wall (U_{n+1} = U_n = U_w, no rotation) and
  // a sphere spinning about the wall normal load no spring with ab2 (c1 = 3/2, gamma = 1/3) and euler
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> r(-1, 1);
  const double dt = 0.01;
  for (int trial = 0; trial < 10; trial++) {
    const Eigen::Vector3d n = randomUnit(rng);
    Eigen::Vector3d Uw(r(rng), r(rng), r(rng));
    Uw -= Uw.dot(n) * n;  // in the wall's plane
    for (double c1 : {1.5, 1.0}) {
      const double gamma = c1 == 1.5 ? 1.0 / 3.0 : 0.0;
      Matrix6 R;
      Eigen::Matrix<double, 6, 1> term;
      contact::wallSpringBlock(n.data(), 1.2, 2e4, 500, c1 * dt, dt, Uw.data(), R.data(), term.data());
      EXPECT_EQ((R - R.transpose()).cwiseAbs().maxCoeff(), 0.0);
      Eigen::SelfAdjointEigenSolver<Matrix6> eig(R);
      EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-12 * eig.eigenvalues().maxCoeff());
      Eigen::Matrix<double, 6, 1> u;
      u << Uw, 0.7 * n;
      const Eigen::Matrix<double, 6, 1> force = -R * (u - gamma * u) + term;  // Eq. (C2)
      EXPECT_LT(force.cwiseAbs().maxCoeff(), 1e-12 * R.cwiseAbs().maxCoeff()) << c1;
    }
  }
}

namespace {

// Two spheres (Stokes drag zeta each, no rotation) pressed together by F along x, the normal
// spring implicit, stepped as fix fdm/couple does: x_{n+1} = x_n + dt (c1 U_n + c0 U_{n-1}), the
// explicit force at x_{n+1}, then Eq. (31) with the spring blocks. Returns the gap history.
std::vector<double> pressedPair(double dt, double kn, double hr, double F, double zeta, int steps, bool ab2)
{
  ParticleVelocitySystem::Settings settings;
  settings.alphaLambda = 1;
  settings.rhoFluid = 1;
  ParticleVelocitySystem system(settings);
  double x[2] = {0, 2 + hr};  // radius 1, gap h_r: the contact starts
  std::vector<double> U(12, 0.0), Uprev;
  std::vector<double> gaps;
  for (int n = 0; n < steps; n++) {
    const bool multistep = ab2 && n >= 2;  // the first move (n = 1) is Euler, as the fix's
    if (n > 0)
      for (int p = 0; p < 2; p++) x[p] += dt * (multistep ? 1.5 * U[6 * p] - 0.5 * Uprev[6 * p] : U[6 * p]);
    const double gap = x[1] - x[0] - 2;
    gaps.push_back(gap);
    std::vector<ParticleVelocitySystem::Particle> particles(2);
    const double spring = gap < hr ? kn * (hr - gap) : 0.0;  // on 0 along -x
    particles[0].force[0] = F - spring;
    particles[1].force[0] = -F + spring;
    for (int p = 0; p < 2; p++) {
      particles[p].x[0] = x[p];
      particles[p].radius = 1;
      particles[p].mass = particles[p].density = 1;
    }
    ParticleVelocitySystem::Springs s;
    const bool nextMultistep = ab2 && n > 0;
    if (gap < hr) {
      const double nvec[3] = {-1, 0, 0};  // from 1 to 0
      double R[144];
      contact::pairSpringBlock(nvec, 1 + gap / 2, 1 + gap / 2, kn, 0, (nextMultistep ? 1.5 : 1.0) * dt, R);
      s.pairs = {1, 2};
      s.pairs.insert(s.pairs.end(), R, R + 144);
      s.pairs.insert(s.pairs.end(), {x[1] - x[0], 0, 0, 0.5});
      s.pairs.insert(s.pairs.end(), springs::pairRecord - springs::pairFriction, 0.0);  // frictionless
      if (nextMultistep) {
        s.gamma = 1.0 / 3.0;
        s.previous = U;
      }
    }
    system.assemble(particles, {}, {}, s);
    system.setVolumes({zeta, zeta}, {zeta, zeta});
    Uprev = U;
    U = system.solve(std::vector<double>(12, 0.0));
  }
  return gaps;
}

}  // namespace

TEST(ContactSprings, ImplicitSpringDecaysByTheFactorOfEqC4AtAnyTimeStep)
{
  // zeta (dh/dt)/2 = ... : the pair's normal mode has the resistance zeta/2, so r = dt kn/(zeta/2);
  // per step the gap error decays by (1 + r/2)/(1 + 3r/2) (ab2) or 1/(1 + r) (euler), without
  // oscillation, for r far beyond the explicit limits (1 and 2), to the gap h_r - F/kn
  const double kn = 2000, hr = 0.01, F = 10, zeta = 10;
  for (bool ab2 : {true, false})
    for (double r : {0.5, 10.0, 1000.0}) {
      const double dt = r * 0.5 * zeta / kn;
      const std::vector<double> gap = pressedPair(dt, kn, hr, F, zeta, 200, ab2);
      const double target = hr - F / kn;
      const double theory = ab2 ? (1 + r / 2) / (1 + 1.5 * r) : 1 / (1 + r);
      int checked = 0;
      for (int n = ab2 ? 2 : 1; n < 40; n++) {  // with ab2 after the first (Euler) move
        const double e0 = gap[n] - target, e1 = gap[n + 1] - target;
        if (!(std::fabs(e0) > 1e-7 * F / kn) || gap[n] >= hr) continue;  // in contact, above round-off
        EXPECT_NEAR(e1 / e0, theory, 1e-6) << "ab2 " << ab2 << " r " << r << " step " << n;
        checked++;
      }
      EXPECT_GE(checked, 2) << "ab2 " << ab2 << " r " << r;
      EXPECT_NEAR(gap.back(), target, 1e-12 * F / kn) << "ab2 " << ab2 << " r " << r;
    }
}

TEST(ContactSprings, SpringForcesAndStressletInEq31)
{
  // the system's implicit contact force equals -R_c (u - gamma U_n) + wall term, the sub-grid
  // force does not include it, and the pair's stresslets add up to sym(f x (x2 - x1))
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> r(-1, 1);
  ParticleVelocitySystem::Settings settings;
  settings.alphaLambda = 0.5;
  settings.rhoFluid = 1000;
  ParticleVelocitySystem system(settings);
  std::vector<ParticleVelocitySystem::Particle> particles(2);
  for (int p = 0; p < 2; p++) {
    particles[p].radius = 1;
    particles[p].mass = particles[p].density = 1000;
    for (int d = 0; d < 3; d++) particles[p].force[d] = r(rng);
  }
  const Eigen::Vector3d n = randomUnit(rng), branch = -2.004 * n;
  Matrix12 R = pairBlock(n, 1.002, 1.002, 2e4, 2e3, 0.015);
  ParticleVelocitySystem::Springs s;
  s.pairs = {1, 2};
  s.pairs.insert(s.pairs.end(), R.data(), R.data() + 144);
  s.pairs.insert(s.pairs.end(), {branch(0), branch(1), branch(2), 0.5});
  s.pairs.insert(s.pairs.end(), springs::pairRecord - springs::pairFriction, 0.0);  // no friction tail
  s.gamma = 1.0 / 3.0;
  for (int k = 0; k < 12; k++) s.previous.push_back(r(rng));
  const std::vector<double> previous = s.previous;
  system.assemble(particles, {}, {}, s);
  system.setVolumes({0.3, 0.4}, {0.2, 0.1});
  std::vector<double> fluid(12);
  for (double &f : fluid) f = r(rng);
  const std::vector<double> u = system.solve(fluid);
  std::vector<double> stress(12, 0.0);
  const std::vector<double> spring = system.springForces(&stress);
  Eigen::Map<const Eigen::Matrix<double, 12, 1> > U(u.data()), Un(previous.data());
  const Eigen::Matrix<double, 12, 1> expected = -R * (U - Un / 3.0);
  for (int k = 0; k < 12; k++) EXPECT_NEAR(spring[k], expected(k), 1e-12 * expected.cwiseAbs().maxCoeff());
  // Eq. (31): diagonal u = fluid + F^c + implicit part
  for (int k = 0; k < 12; k++) {
    const int p = k / 6, c = k % 6;
    const double load = fluid[k] + (c < 3 ? particles[p].force[c] : 0.0);
    EXPECT_NEAR(system.diagonal(k) * u[k], load + spring[k], 1e-10);
  }
  for (double f : system.subgridForces()) EXPECT_NEAR(f, 0.0, 1e-10);
  const Eigen::Vector3d f(spring[0], spring[1], spring[2]);
  static const int comp[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
  for (int c = 0; c < 6; c++) {
    const int a = comp[c][0], b = comp[c][1];
    EXPECT_NEAR(stress[c] + stress[6 + c], 0.5 * (f(a) * branch(b) + branch(a) * f(b)), 1e-12);
    EXPECT_NEAR(stress[c], stress[6 + c], 1e-12);  // equal spheres
  }
}

namespace {

// Two spheres touching along x (sphere 2 at +x), pulled apart along y by +F (on 1) and -F (on 2),
// their contact sticking at the start of the step with a stiff tangential spring (kt c1 dt / zeta =
// 1000), no explicit tangential force yet; Stokes drag zeta, rotational drag zetaR. Returns the
// system after one solve.
struct PullParameters {
  double zeta = 2, zetaR = 3, cap = 4, normal = 8, ktc1dt = 2000, lever = 1.0025;  // kn c1 dt 0: F_n constant
};

struct PulledPair : PullParameters {
  ParticleVelocitySystem system;
  std::vector<double> u;
  PulledPair(double F, bool ab2, double ftStart = 0, bool consistent = false) : system(settings(consistent))
  {
    std::vector<ParticleVelocitySystem::Particle> particles(2);
    for (int p = 0; p < 2; p++) {
      particles[p].radius = 1;
      particles[p].mass = particles[p].density = 1;
    }
    particles[0].force[1] = F;
    particles[1].force[1] = -F;
    const double n[3] = {-1, 0, 0};  // from 2 to 1
    double R[144];
    contact::pairSpringBlock(n, lever, lever, 1e4, ktc1dt, 1.0, R);  // kn c1 dt = 1e4, kt c1 dt = 2000
    ParticleVelocitySystem::Springs s;
    s.pairs = {1, 2};
    s.pairs.insert(s.pairs.end(), R, R + 144);
    s.pairs.insert(s.pairs.end(), {2 * lever, 0, 0, 0.5});
    s.pairs.insert(s.pairs.end(), {n[0], n[1], n[2], lever, lever, ktc1dt, cap / normal, normal, 0, 0, ftStart, 0});
    // F_t (start) and its moments are in the particles' loads, as the pair style adds them:
    // T = -l n x F_t on both spheres, (0, 0, l F_t,y) here
    particles[0].force[1] += ftStart;
    particles[1].force[1] -= ftStart;
    particles[0].torque[2] += lever * ftStart;
    particles[1].torque[2] += lever * ftStart;
    if (ab2) {
      s.gamma = 1.0 / 3.0;
      s.previous.assign(12, 0.0);
      s.previous[1] = 0.3;  // U_n of sphere 1 along y: the known part of the step's slip
    }
    system.assemble(particles, {}, {}, s);
    system.setVolumes({zeta, zeta}, {zetaR, zetaR});
    u = system.solve(std::vector<double>(12, 0.0));
  }
  static ParticleVelocitySystem::Settings settings(bool consistent = false)
  {
    ParticleVelocitySystem::Settings s;
    s.alphaLambda = 1;
    s.rhoFluid = 1;
    s.coulombConsistent = consistent;
    return s;
  }
};

}  // namespace

TEST(ContactSprings, CoulombLawHoldsAtTheEndOfTheStep)
{
  // docs/contact.md 2c: below the cap the stiff spring holds the pair (almost no slip, |F_t| < mu_s F_n);
  // beyond it the contact slides within the step with exactly mu_s F_n against the slip, the
  // spheres drift at (F - mu_s F_n)/zeta and turn under the moment of the friction force
  for (bool ab2 : {false, true}) {
    PulledPair held(3.0, ab2);
    EXPECT_EQ(held.system.slidingSwitches(), 0) << ab2;
    const std::vector<double> heldForce = held.system.springForces();
    EXPECT_LE(std::fabs(heldForce[1]), held.cap) << ab2;
    // the contact points hardly move apart in the step: rho_y = c1 [B (u - gamma U_n)]_y ~ F/(kt c1 dt)
    const double gamma = ab2 ? 1.0 / 3.0 : 0.0, Un1y = ab2 ? 0.3 : 0.0;
    const double slipY = (held.u[1] - gamma * Un1y) - held.u[7] + held.lever * (held.u[5] + held.u[11]);
    EXPECT_LT(std::fabs(slipY), 2 * 3.0 / held.ktc1dt) << ab2;

    PulledPair pulled(10.0, ab2);
    EXPECT_EQ(pulled.system.slidingSwitches(), 1) << ab2;
    // the contact's spring left the matrix: a rank-2 downdate of the step's factorisation, no new one
    EXPECT_EQ(pulled.system.factorisations(), 1) << ab2;
    EXPECT_EQ(pulled.system.downdates(), 1) << ab2;
    // (to 1e-11: the sliding spring leaves by a downdate of the factorisation, whose cancellation
    // costs a few digits at kt c1 dt / zeta = 1000)
    const double F = 10.0, cap = pulled.cap;
    EXPECT_NEAR(pulled.u[1], (F - cap) / pulled.zeta, 1e-11) << ab2;
    EXPECT_NEAR(pulled.u[7], -(F - cap) / pulled.zeta, 1e-11) << ab2;
    // the friction force -cap e_y on 1 at the contact point (lever l along -n = +x): torque l x (-cap e_y)
    EXPECT_NEAR(pulled.u[5], -pulled.lever * cap / pulled.zetaR, 1e-11) << ab2;
    const std::vector<double> force = pulled.system.springForces();
    EXPECT_NEAR(force[1], -cap, 1e-12) << ab2;
    EXPECT_NEAR(force[7], cap, 1e-12) << ab2;
    // the sub-grid force holds none of it (no sub-grid blocks here)
    for (double f : pulled.system.subgridForces()) EXPECT_NEAR(f, 0.0, 1e-12) << ab2;
  }
}

TEST(ContactSprings, CoulombLawOnAWall)
{
  // a sphere on the wall y = 0 (n = +y) moving at U_w along x, pushed along x by F: it slides on
  // the wall, carried by mu_s F_n of friction toward the wall's velocity
  // (frozen and consistent slides alike)
  const double zeta = 2, zetaR = 3, cap = 1.5, ktc1dt = 5000, ktdt = ktc1dt, dt = 1.0, lever = 1;
  for (bool consistent : {false, true})
  for (double F : {3.0, -6.0}) {  // sticking needs 0.6 of friction at F = 3, 6 at F = -6
    ParticleVelocitySystem system(PulledPair::settings(consistent));
    std::vector<ParticleVelocitySystem::Particle> particles(1);
    particles[0].radius = particles[0].mass = particles[0].density = 1;
    particles[0].force[0] = F;
    const double n[3] = {0, 1, 0}, Uw[3] = {2, 0, 0};
    double R[36], term[6];
    contact::wallSpringBlock(n, lever, 1e4, ktc1dt / dt, dt, dt, Uw, R, term);
    ParticleVelocitySystem::Springs s;
    s.walls = {1};
    s.walls.insert(s.walls.end(), R, R + 36);
    s.walls.insert(s.walls.end(), term, term + 6);
    s.walls.insert(s.walls.end(), {0, -1, 0});
    s.walls.insert(s.walls.end(), {n[0], n[1], n[2], lever, ktc1dt, ktdt, 0.5, 2 * cap, 0, 0, 0, 0, Uw[0], Uw[1], Uw[2]});
    system.assemble(particles, {}, {}, s);
    system.setVolumes({zeta}, {zetaR});
    const std::vector<double> u = system.solve(std::vector<double>(6, 0.0));
    // held: the contact point moves with the wall, U_x - l Omega_z... stuck or sliding, the friction
    // on the sphere is at most cap, along +x (the wall is faster than the sphere in both cases)
    const std::vector<double> force = system.springForces();
    EXPECT_LE(force[0], cap * (1 + 1e-9)) << F;
    if (F == -6.0) {
      EXPECT_EQ(system.slidingSwitches(), 1) << consistent;
      EXPECT_NEAR(force[0], cap, 1e-10) << consistent;
      EXPECT_NEAR(u[0], (F + cap) / zeta, 1e-10) << consistent;
      EXPECT_EQ(system.coulombConsistency().inconsistent, 0) << consistent;
    } else {
      EXPECT_EQ(system.slidingSwitches(), 0) << consistent;
    }
  }
}

TEST(ContactSprings, FrictionResistsAndNeverDrives)
{
  // a contact that slid in the last step (its spring at the cap: F_t = -cap e_y on 1) while the load
  // on it reverses to F = -2 e_y on 1 (below the cap): friction must not keep pushing along -y with
  // the full cap (that would drive sphere 1 at (-2 - cap)/zeta); it sticks, the pair hardly slips
  PulledPair reversed(-2.0, false, -4.0);
  EXPECT_EQ(reversed.system.slidingSwitches(), 0);
  const double slipY = reversed.u[1] - reversed.u[7] + reversed.lever * (reversed.u[5] + reversed.u[11]);
  EXPECT_LT(std::fabs(slipY), 2 * 4.0 / reversed.ktc1dt);
  const std::vector<double> force = reversed.system.springForces();
  // the tangential force f on 1 at the end, F_t(start) + the implicit part: under the cap, and what
  // rolling without slip needs: 2(-2 + f)/zeta + 2 l^2 f/zeta_R = 0
  const double l = reversed.lever, rolling = 2.0 / reversed.zeta / (1 / reversed.zeta + l * l / reversed.zetaR);
  EXPECT_LE(std::fabs(-4.0 + force[1]), 4.0 * (1 + 1e-9));
  EXPECT_NEAR(-4.0 + force[1], rolling, 0.01);
  // a contact whose F_t(start) points the wrong way (+cap along the pull) and whose load exceeds the
  // cap: it slides with the cap against the slip, the start direction forgotten
  PulledPair pulled(10.0, false, 4.0);
  EXPECT_EQ(pulled.system.slidingSwitches(), 1);
  EXPECT_NEAR(pulled.u[1], (10.0 - 4.0) / pulled.zeta, 1e-11);
  // the slide resists its slip: none slips along its friction force
  EXPECT_EQ(pulled.system.slidingAtEnd().sliding, 1);
  EXPECT_EQ(pulled.system.slidingAtEnd().alongFriction, 0);
  EXPECT_EQ(reversed.system.slidingAtEnd().sliding, 0);
}

namespace {

// K independent copies of PulledPair's contact (spheres 2k+1 and 2k+2 along x, each pair far from
// the others), pulled apart along y by the fluid forces +F_k and -F_k: a contact slides when
// F_k > cap. Returns the velocities of each solve for the pulls of each list.
std::vector<std::vector<double> > pulledPairs(ParticleVelocitySystem &system, int K,
                                              const std::vector<std::vector<double> > &pulls)
{
  const PullParameters q;
  std::vector<ParticleVelocitySystem::Particle> particles(2 * K);
  for (auto &p : particles) p.radius = p.mass = p.density = 1;
  ParticleVelocitySystem::Springs s;
  const double n[3] = {-1, 0, 0};
  double R[144];
  contact::pairSpringBlock(n, q.lever, q.lever, 1e4, q.ktc1dt, 1.0, R);
  for (int k = 0; k < K; k++) {
    s.pairs.insert(s.pairs.end(), {double(2 * k + 1), double(2 * k + 2)});
    s.pairs.insert(s.pairs.end(), R, R + 144);
    s.pairs.insert(s.pairs.end(), {2 * q.lever, 0, 0, 0.5});
    s.pairs.insert(s.pairs.end(), {n[0], n[1], n[2], q.lever, q.lever, q.ktc1dt, q.cap / q.normal, q.normal, 0, 0, 0, 0});
  }
  system.assemble(particles, {}, {}, s);
  system.setVolumes(std::vector<double>(2 * K, q.zeta), std::vector<double>(2 * K, q.zetaR));
  std::vector<std::vector<double> > solutions;
  for (const std::vector<double> &F : pulls) {
    std::vector<double> fluid(12 * K, 0.0);
    for (int k = 0; k < K; k++) {
      fluid[12 * k + 1] = F[k];
      fluid[12 * k + 6 + 1] = -F[k];
    }
    solutions.push_back(system.solve(fluid));
  }
  return solutions;
}

}  // namespace

TEST(ContactSprings, SlidingContactsDowndateTheFactorisation)
{
  // Contacts that begin to slide leave the matrix as rank-2 downdates of the step's factorisation
  // (Woodbury): the velocities of a new factorisation (CG here, the matrix as it stands), every
  // sliding pair drifting at (F - cap)/zeta; a later inner iteration adds its own downdate; beyond
  // 96 columns (48 contacts) the matrix is factorised again instead.
  const PullParameters q;
  const int K = 20;
  std::vector<double> first(K), second(K);
  // a pair pulled by F <= 6.5 rolls without sliding (its spring holds less than the cap of 4), one
  // pulled by F >= 7 slides: pairs 8.. slide in the first solve, pairs 4..7 join them in the second
  for (int k = 0; k < K; k++) {
    first[k] = k < 8 ? 2.0 : 7.0 + 0.25 * k;
    second[k] = k < 4 ? 2.0 : 7.0 + 0.25 * k;
  }
  ParticleVelocitySystem::Settings cgSettings = PulledPair::settings();
  cgSettings.solver = ParticleVelocitySystem::cg;
  cgSettings.tolerance = 1e-14;
  ParticleVelocitySystem reference(cgSettings);
  const auto expected = pulledPairs(reference, K, {first, second});
  for (ParticleVelocitySystem::Solver solver : {ParticleVelocitySystem::cholmod, ParticleVelocitySystem::ldlt}) {
    ParticleVelocitySystem::Settings settings = PulledPair::settings();
    settings.solver = solver;
    ParticleVelocitySystem system(settings);
    const auto got = pulledPairs(system, K, {first, second});
    EXPECT_EQ(system.factorisations(), 1) << solver;
    EXPECT_EQ(system.downdates(), 2) << solver;
    EXPECT_EQ(system.slidingSwitches(), K - 4) << solver;
    for (int solve = 0; solve < 2; solve++) {
      const std::vector<double> &F = solve == 0 ? first : second;
      for (size_t i = 0; i < got[solve].size(); i++)
        EXPECT_NEAR(got[solve][i], expected[solve][i], 1e-10) << solver << " solve " << solve << " unknown " << i;
      for (int k = 0; k < K; k++)
        if (F[k] >= 7) EXPECT_NEAR(got[solve][12 * k + 1], (F[k] - q.cap) / q.zeta, 1e-10) << solver << " pair " << k;
    }
  }
  ParticleVelocitySystem many(PulledPair::settings());
  const int manyPairs = 60;
  pulledPairs(many, manyPairs, {std::vector<double>(manyPairs, 10.0)});
  EXPECT_EQ(many.slidingSwitches(), manyPairs);
  EXPECT_EQ(many.factorisations(), 2);
  EXPECT_EQ(many.downdates(), 0);
  // both factorisations timed, the one inside the solve's Coulomb rounds too (the profile's factorisation row)
  EXPECT_GT(many.factorisationSeconds(), 0.0);
}

namespace {

// A zigzag chain of M spheres (sphere i at (1.8 i, 0.9 (i mod 2), 0.3 (i mod 3)), a contact between
// each neighbour pair), random loads that make most contacts slide and press or part them along
// their normals: each sliding contact's cap mu_s F_n(end) depends on the velocities, which the other
// caps change through the shared spheres. Returns the velocities of one solve.
// The chain's spring records and loads (its spheres have Vu = 2, Ju = 3: rigid blocks diag(2, 2, 2, 3, 3, 3)).
struct Chain {
  std::vector<ParticleVelocitySystem::Particle> particles;
  ParticleVelocitySystem::Springs springs;
  std::vector<double> fluid;
};

Chain chainProblem(int M, unsigned seed)
{
  const double knc1dt = 50, ktc1dt = 2000, mu = 0.5, lever = 1.0025;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> load(-10, 10), normal(4, 8);
  Chain c;
  std::vector<Eigen::Vector3d> x;
  c.particles.resize(size_t(M));
  x.resize(size_t(M));
  for (int i = 0; i < M; i++) {
    c.particles[size_t(i)].radius = c.particles[size_t(i)].mass = c.particles[size_t(i)].density = 1;
    x[size_t(i)] = Eigen::Vector3d(1.8 * i, 0.9 * (i % 2), 0.3 * (i % 3));
  }
  for (int i = 0; i + 1 < M; i++) {
    const Eigen::Vector3d branch = x[size_t(i) + 1] - x[size_t(i)], n = -branch.normalized();  // n from 2 to 1
    double R[144];
    contact::pairSpringBlock(n.data(), lever, lever, knc1dt, ktc1dt, 1.0, R);
    c.springs.pairs.insert(c.springs.pairs.end(), {double(i + 1), double(i + 2)});
    c.springs.pairs.insert(c.springs.pairs.end(), R, R + 144);
    c.springs.pairs.insert(c.springs.pairs.end(), {branch(0), branch(1), branch(2), 0.5});
    c.springs.pairs.insert(c.springs.pairs.end(), {n(0), n(1), n(2), lever, lever, ktc1dt, mu, normal(rng), knc1dt, 0, 0, 0});
  }
  c.fluid.assign(size_t(6) * M, 0.0);
  for (int i = 0; i < M; i++)
    for (int d = 0; d < 3; d++) c.fluid[size_t(6) * i + d] = load(rng);
  return c;
}

std::vector<double> loadedChain(ParticleVelocitySystem &system, int M, unsigned seed)
{
  const Chain c = chainProblem(M, seed);
  system.assemble(c.particles, {}, {}, c.springs);
  system.setVolumes(std::vector<double>(size_t(M), 2.0), std::vector<double>(size_t(M), 3.0));
  return system.solve(c.fluid);
}

// The chain's equations at u, written out from its records alone (not from the solver's state): the
// rigid blocks' force diag(2, 2, 2, 3, 3, 3) u less the fluid's and the contacts', each contact's normal
// spring implicit and its tangential force P(T), the projection of its trial force onto the disc of
// radius mu_s min(F_n(start), F_n(end)) (docs/contact.md 2c). Returns the largest residual over the
// largest load.
double chainResidual(const Chain &c, const std::vector<double> &u)
{
  std::vector<double> residual(u.size());
  for (size_t k = 0; k < u.size(); k++) residual[k] = (k % 6 < 3 ? 2.0 : 3.0) * u[k] - c.fluid[k];
  const int record = springs::pairRecord;
  for (size_t b = 0; b < c.springs.pairs.size(); b += size_t(record)) {
    const double *rec = &c.springs.pairs[b], *tail = rec + springs::pairFriction, *n = tail;
    const int base[2] = {6 * (int(rec[0]) - 1), 6 * (int(rec[1]) - 1)};
    double w[12], Rn[144], T[3], f[3], generalised[12];
    for (int k = 0; k < 12; k++) w[k] = u[size_t(base[k / 6] + k % 6)];
    contact::pairSpringBlock(n, tail[3], tail[4], tail[8], 0.0, 1.0, Rn);  // the normal spring (kn c1 dt, c1 dt = 1)
    contact::pairTangentialForceAtEnd(n, tail[3], tail[4], tail[5], tail + 9, w, T);
    const double approach = n[0] * (w[0] - w[6]) + n[1] * (w[1] - w[7]) + n[2] * (w[2] - w[8]);
    const double cap = tail[6] * std::min(tail[7], std::max(0.0, tail[7] - tail[8] * approach));
    const double size = std::sqrt(T[0] * T[0] + T[1] * T[1] + T[2] * T[2]);
    for (int a = 0; a < 3; a++) f[a] = size > cap ? cap * T[a] / size : T[a];
    contact::pairGeneralisedForce(n, tail[3], tail[4], f, generalised);
    for (int i = 0; i < 12; i++) {
      double normal = 0;
      for (int j = 0; j < 12; j++) normal -= Rn[12 * i + j] * w[j];
      residual[size_t(base[i / 6] + i % 6)] -= normal + generalised[i];
    }
  }
  double worst = 0, load = 0;
  for (size_t k = 0; k < u.size(); k++) {
    worst = std::max(worst, std::fabs(residual[k]));
    load = std::max(load, std::fabs(c.fluid[k]));
  }
  return worst / load;
}

}  // namespace

TEST(ContactSprings, ConsistentSlidesSolveCoulombsLawAtEveryContact)
{
  // coulomb_solve consistent (docs/contact.md 2c): the chain's equations, written out from its records
  // with every contact's force the projection of its trial force, hold at the solution to the rounds'
  // tolerance; no slide follows its friction. The frozen slides (the default) do not solve them: a
  // direction fixed in the round a contact began to slide, no contact sticking again.
  const int M = 16;
  long frozenOff = 0;
  for (unsigned seed : {1u, 2u, 3u}) {
    const Chain c = chainProblem(M, seed);
    ParticleVelocitySystem::Settings settings = PulledPair::settings(true);
    settings.coulombTolerance = 1e-10;
    ParticleVelocitySystem consistent(settings);
    const std::vector<double> u = loadedChain(consistent, M, seed);
    EXPECT_LT(chainResidual(c, u), 1e-8) << seed;
    EXPECT_GE(consistent.slidingAtEnd().sliding, M / 4) << seed;
    EXPECT_EQ(consistent.slidingAtEnd().alongFriction, 0) << seed;
    EXPECT_EQ(consistent.coulombConsistency().inconsistent, 0) << seed;
    EXPECT_LT(consistent.coulombConsistency().worst, 1e-8) << seed;
    EXPECT_LT(consistent.lastRounds(), 100) << seed;
    // the default tolerance, 1e-6 of the contact forces
    ParticleVelocitySystem byDefault(PulledPair::settings(true));
    EXPECT_LT(chainResidual(c, loadedChain(byDefault, M, seed)), 1e-4) << seed;
    ParticleVelocitySystem frozen(PulledPair::settings());
    const std::vector<double> frozenAnswer = loadedChain(frozen, M, seed);
    frozenOff += frozen.coulombConsistency().inconsistent;
    std::printf("seed %u: consistent %ld rounds, %ld factorisations, %ld downdates, %ld stuck again, residual %.2g; "
                "frozen %ld rounds, %ld contacts off the law, residual %.2g\n",
                seed, consistent.lastRounds(), consistent.factorisations(), consistent.downdates(),
                consistent.stickingSwitches(), chainResidual(c, u), frozen.lastRounds(),
                frozen.coulombConsistency().inconsistent, chainResidual(c, frozenAnswer));
  }
  EXPECT_GT(frozenOff, 0);
}

TEST(ContactSprings, ConsistentSlidesOfASimplePull)
{
  // one contact: the frozen and the consistent slides agree (its direction does not turn); under the cap
  // it sticks, a reversed load sticks it
  for (bool ab2 : {false, true}) {
    PulledPair pulled(10.0, ab2, 0, true);
    EXPECT_EQ(pulled.system.slidingSwitches(), 1) << ab2;
    EXPECT_EQ(pulled.system.factorisations(), 1) << ab2;
    EXPECT_NEAR(pulled.u[1], (10.0 - pulled.cap) / pulled.zeta, 1e-10) << ab2;
    EXPECT_NEAR(pulled.u[5], -pulled.lever * pulled.cap / pulled.zetaR, 1e-10) << ab2;
    EXPECT_NEAR(pulled.system.springForces()[1], -pulled.cap, 1e-10) << ab2;
    PulledPair held(3.0, ab2, 0, true);
    EXPECT_EQ(held.system.slidingSwitches(), 0) << ab2;
  }
  PulledPair reversed(-2.0, false, -4.0, true);
  EXPECT_EQ(reversed.system.slidingAtEnd().sliding, 0);
  EXPECT_EQ(reversed.system.coulombConsistency().inconsistent, 0);
}

TEST(ContactSprings, CoulombRoundsAreAcceleratedToTheSameAnswer)
{
  // The rounds of Coulomb's law (docs/contact.md 2c) are a fixed-point iteration on the caps of the
  // sliding contacts; Anderson mixing of the caps reaches the plain rounds' answer in fewer rounds,
  // and the default tolerance (1e-6 of the contact forces) stays that close to the converged answer
  const int M = 16;
  for (unsigned seed : {1u, 2u, 3u}) {
    ParticleVelocitySystem::Settings tight = PulledPair::settings();
    tight.coulombTolerance = 1e-10;
    tight.coulombAcceleration = false;
    ParticleVelocitySystem plain(tight);
    const std::vector<double> reference = loadedChain(plain, M, seed);
    tight.coulombAcceleration = true;
    ParticleVelocitySystem accelerated(tight);
    const std::vector<double> mixed = loadedChain(accelerated, M, seed);
    ParticleVelocitySystem::Settings byDefault = PulledPair::settings();
    ParticleVelocitySystem loose(byDefault);
    const std::vector<double> defaultAnswer = loadedChain(loose, M, seed);
    double scale = 0;
    for (double v : reference) scale = std::max(scale, std::fabs(v));
    EXPECT_GE(plain.slidingSwitches(), M / 2) << seed;  // most contacts slide
    EXPECT_EQ(accelerated.slidingSwitches(), plain.slidingSwitches()) << seed;
    for (size_t k = 0; k < reference.size(); k++) {
      EXPECT_NEAR(mixed[k], reference[k], 1e-10 * scale) << "seed " << seed << " unknown " << k;
      EXPECT_NEAR(defaultAnswer[k], reference[k], 1e-5 * scale) << "seed " << seed << " unknown " << k;
    }
    // measured: plain 18, 35, 44 rounds; mixed 10, 13, 10 (the default tolerance 8, 13, 9)
    EXPECT_LT(accelerated.backSubstitutions(), plain.backSubstitutions()) << seed;
    EXPECT_LE(loose.backSubstitutions(), accelerated.backSubstitutions()) << seed;
    EXPECT_EQ(loose.lastRounds(), loose.backSubstitutions()) << seed;  // one solve
  }
}

namespace {

// Two unit spheres in contact along x (sphere 2 at +x, gap h < h_r), pressed together by P and
// sliding past each other: F on sphere 2 along y (frictionless contact: kt = 0, the normal spring
// implicit), Stokes drag zeta. The step of fix fdm/couple with the given integrator weights, taken
// `steps` times from the same positions (a steady slide: U_n is the last step's solution, from which
// the chord term (C5) is estimated): the spring's explicit force at the start in the loads, Eq. (31)
// with the spring blocks. Keeps the last velocities and, in `gapAfter`, the gap the straight step
// x + dt (c1 U_{n+1} + c0 U_n) gives.
struct SlidingPair {
  double kn = 1e4, hr = 5e-3, h = 4e-3, P = 5, F = 10, zeta = 10, dt = 0.1;
  std::vector<double> u, previous;
  double springEnd = 0;   // the normal force on sphere 2 at the end of the step the solve applied
  double gapAfter = 0;
  SlidingPair(bool chord, bool ab2, int steps)
  {
    ParticleVelocitySystem::Settings settings;
    settings.alphaLambda = 1;
    settings.rhoFluid = 1;
    ParticleVelocitySystem system(settings);
    const double c1 = ab2 ? 1.5 : 1.0, gamma = ab2 ? 1.0 / 3.0 : 0.0;
    const double lever = 1 + h / 2, start = kn * (hr - h);
    std::vector<ParticleVelocitySystem::Particle> particles(2);
    for (int p = 0; p < 2; p++) {
      particles[p].radius = 1;
      particles[p].mass = particles[p].density = 1;
    }
    particles[0].x[0] = 0;
    particles[1].x[0] = 2 + h;
    particles[0].force[0] = P - start;   // the spring pushes 1 to -x, 2 to +x
    particles[1].force[0] = -P + start;
    particles[1].force[1] = F;
    const double n[3] = {-1, 0, 0};      // from 2 to 1
    double R[144];
    contact::pairSpringBlock(n, lever, lever, kn, 0, c1 * dt, R);
    u.assign(12, 0.0);
    for (int step = 0; step < steps; step++) {
      previous = u;
      ParticleVelocitySystem::Springs s;
      s.pairs = {1, 2};
      s.pairs.insert(s.pairs.end(), R, R + 144);
      s.pairs.insert(s.pairs.end(), {2 + h, 0, 0, 0.5});
      s.pairs.insert(s.pairs.end(), {n[0], n[1], n[2], lever, lever, 0, 0, start, kn * c1 * dt, 0, 0, 0});
      s.gamma = gamma;
      s.previous = previous;
      s.dt = chord ? dt : 0.0;
      system.assemble(particles, {}, {}, s);
      system.setVolumes({zeta, zeta}, {zeta, zeta});
      u = system.solve(std::vector<double>(12, 0.0));
    }
    // the straight step of the next position update
    double x[2][3] = {{0, 0, 0}, {2 + h, 0, 0}};
    for (int p = 0; p < 2; p++)
      for (int a = 0; a < 3; a++) x[p][a] += dt * (c1 * u[6 * p + a] - c1 * gamma * previous[6 * p + a]);
    gapAfter = std::sqrt(std::pow(x[1][0] - x[0][0], 2) + std::pow(x[1][1] - x[0][1], 2) +
                         std::pow(x[1][2] - x[0][2], 2)) - 2;
    // the force on sphere 2 along +x at the end of the step, as the solve applied it
    springEnd = start + system.springForces()[6];
  }
};

}  // namespace

TEST(ContactSprings, ChordTermKeepsTheStraightStepWhereTheSpringAssumedIt)
{
  // Eq. (C5): a pair sliding by dt |rho_t| of about 0.1 a per step opens by the chord
  // dt^2 |rho_t|^2/(2r) of 2.5e-3 a in a straight step, half of h_r. Without the chord term the explicit
  // force of the next step, k_n (h_r - h_{n+1}), falls short of the force the implicit spring
  // applied by k_n times the chord (here more than the spring's whole force: the contact breaks);
  // with it the two agree to the chord's own second order, and the gap stays in contact
  for (bool ab2 : {false, true}) {
    const SlidingPair without(false, ab2, 4), with(true, ab2, 4);
    const double chord = std::hypot(2.004, with.dt * (with.u[7] - with.u[1])) - 2.004;  // a steady slide
    ASSERT_GT(chord, 1e-3) << "ab2 " << ab2;
    const double nextWithout = without.kn * (without.hr - without.gapAfter);
    const double nextWith = with.kn * (with.hr - with.gapAfter);
    EXPECT_GT(std::fabs(nextWithout - without.springEnd), 0.9 * without.kn * chord) << "ab2 " << ab2;
    EXPECT_GT(without.gapAfter, without.hr) << "ab2 " << ab2 << ": the contact breaks without the chord term";
    EXPECT_LT(std::fabs(nextWith - with.springEnd), 0.02 * with.kn * chord) << "ab2 " << ab2;
    EXPECT_LT(with.gapAfter, with.hr) << "ab2 " << ab2 << ": the contact holds with it";
    // the pressing load is carried at the end of the step: the spring force balances P
    EXPECT_NEAR(with.springEnd, with.P, 0.02 * with.P) << "ab2 " << ab2;
  }
}
