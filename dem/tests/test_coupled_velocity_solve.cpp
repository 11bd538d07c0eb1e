// Eq. (31) within a coupled step (dem/coupled_velocity_solve.h) without LIGGGHTS, on isolated spheres
// whose answers are Stokes's: the DEM-only step (a fluid at rest, or a simple shear), a fluid step with
// the fluid's volumes and integrals, and the held step between fluid steps, which at unchanged positions
// gives the fluid step's velocities back.
#include "coupled_velocity_solve.h"

#include <gtest/gtest.h>

#include <cmath>

namespace cpl = fdm::coupler;

namespace {

const double pi = 3.14159265358979323846, eta = 2.0, alpha = 0.01, rho = 1000.0;

fdm::GatheredParticle sphere(double y, double a, double fx)
{
  fdm::GatheredParticle p = fdm::GatheredParticle();
  p.x[0] = 5;
  p.x[1] = y;
  p.x[2] = 5;
  p.radius = a;
  p.density = rho;   // neutrally buoyant
  p.mass = rho * 4.0 / 3.0 * pi * a * a * a;
  p.f[0] = fx;
  return p;
}

struct Solve {
  fdm::CouplingTiming counts;
  fdm::CoupledVelocitySolve solve;
  explicit Solve(int n, bool stresslets = false) : solve(settings(stresslets), counts)
  {
    solve.setFluid(alpha, rho, eta, 0.25);
    solve.resize(n);
  }
  static fdm::ParticleVelocitySystem::Settings settings(bool stresslets)
  {
    fdm::ParticleVelocitySystem::Settings s;
    s.solver = fdm::ParticleVelocitySystem::ldlt;
    s.stresslets = stresslets;
    return s;
  }
  void assemble(const std::vector<fdm::GatheredParticle> &p) { solve.assemble(p, {}, {}, {}); }
};

}  // namespace

TEST(CoupledVelocitySolve, WithoutAFluidASphereMovesAtItsStokesVelocity)
{
  const std::vector<fdm::GatheredParticle> p = {sphere(5, 1.0, 3.0), sphere(9, 1.5, 0.0)};
  Solve s(2);
  s.assemble(p);
  s.solve.noFluidStep(p, 1, 6.0, 0.0);
  const fdm::CoupledVelocitySolve::Results &r = s.solve.results();
  EXPECT_NEAR(r.solution[0], 3.0 / (6 * pi * eta * 1.0), 1e-14);
  EXPECT_NEAR(r.solution[6], 0.0, 1e-15);
  EXPECT_NEAR(r.hydro[0], -3.0, 1e-12);   // the drag balances the force
  EXPECT_EQ(s.solve.lastIterations, 1);
  EXPECT_EQ(s.counts.solves, 1);
}

TEST(CoupledVelocitySolve, InABackgroundShearAFreeSphereFollowsTheFlowWithItsStresslet)
{
  const double G = 1.5, a = 1.4, y = 8.0, yCentre = 6.0;
  const std::vector<fdm::GatheredParticle> p = {sphere(y, a, 0.0)};
  Solve s(1, true);
  s.assemble(p);
  s.solve.noFluidStep(p, 1, yCentre, G);
  const fdm::CoupledVelocitySolve::Results &r = s.solve.results();
  EXPECT_NEAR(r.solution[0], G * (y - yCentre), 1e-12);
  EXPECT_NEAR(r.solution[5], -G / 2, 1e-12);
  EXPECT_NEAR(r.hydro[0], 0.0, 1e-10);
  // S^h = S^FDM + S^SG (Eq. 13): the isolated sphere's (20/3) pi eta a^3 E_xy, order xx xy xz yy yz zz
  EXPECT_NEAR(r.stress[1], 10.0 / 3.0 * pi * eta * a * a * a * G, 1e-10);
}

TEST(CoupledVelocitySolve, AHeldStepAtUnchangedPositionsGivesTheFluidStepsVelocities)
{
  const std::vector<fdm::GatheredParticle> p = {sphere(5, 1.0, 2.0)};
  Solve s(1);
  s.assemble(p);
  // a fluid step: volumes of the discrete sphere, the fluid's integral of its inner iteration
  cpl::Volumes v;
  v.step = 1;
  v.particles.resize(1);
  v.particles[0].Vu = 4.0;
  v.particles[0].J[0] = v.particles[0].J[3] = v.particles[0].J[5] = 1.5;
  s.solve.setVolumes(v);
  cpl::Integrals in;
  in.step = 1;
  in.iteration = 1;
  in.particles.assign(1, cpl::ForceTorque());
  in.particles[0].F[1] = 0.5;
  const std::vector<double> fluidStepU = s.solve.solve(in);
  // the fluid step's converged balance, no inertia (Eqs. 28d-e): F^FDM + F^c = 0
  cpl::StepDone done;
  done.step = 1;
  done.iterations = 5;
  done.converged = true;
  done.forces.assign(1, cpl::ForceTorque());
  done.forces[0].F[0] = -2.0;
  s.solve.storeStepDone(done);
  s.solve.finishStep(p);
  EXPECT_EQ(s.solve.lastIterations, 5);
  // the held step: Eq. (31) with the drag D in place of the fluid, D U = (D U_fluid + F^FDM) + F^c
  fdm::HeldDrag held(false);
  s.assemble(p);
  s.solve.heldStep(p, 2, 1, fluidStepU, held);
  const std::vector<double> &U = s.solve.results().solution;
  for (int k = 0; k < 6; k++) EXPECT_NEAR(U[k], fluidStepU[k], 1e-15) << k;
  EXPECT_EQ(s.solve.lastIterations, 0);
  // the fluid's force of the held step, D (u_b - U), is the fluid step's again
  EXPECT_NEAR(s.solve.results().hydro[0], -2.0, 1e-12);
}

TEST(CoupledVelocitySolve, AParticleWithNoFluidVolumeIsNamedWithTheMeshSize)
{
  const std::vector<fdm::GatheredParticle> p = {sphere(5, 0.1, 0.0)};
  Solve s(1);
  s.assemble(p);
  cpl::Volumes v;
  v.step = 3;
  v.particles.resize(1);
  try {
    s.solve.setVolumes(v);
    FAIL() << "no error";
  } catch (const std::runtime_error &e) {
    EXPECT_NE(std::string(e.what()).find("is it smaller than a mesh cell (0.25)?"), std::string::npos) << e.what();
  }
}

TEST(CoupledVelocitySolve, PerAtomRowsAreTheFixsColumnsAndZeroForAnUnknownParticle)
{
  // one sphere pushed along x without a fluid: its row is the drag F^FDM = -F (6), F^SG = 0 (6) and,
  // with stresslets, the 20 stress columns in order
  const std::vector<fdm::GatheredParticle> p = {sphere(5, 1.0, 3.0), sphere(9, 1.5, 0.0)};
  Solve s(2);
  s.assemble(p);
  s.solve.noFluidStep(p, 1, 6.0, 0.0);
  fdm::CoupledVelocitySolve::Results &r = s.solve.results();
  ASSERT_EQ(fdm::CoupledVelocitySolve::Results::perAtomColumns(false), 12);
  ASSERT_EQ(fdm::CoupledVelocitySolve::Results::perAtomColumns(true), 32);
  for (size_t k = 0; k < r.stress.size(); k++) r.stress[k] = double(k);
  double row[32];
  r.perAtomRow(0, 2, true, row);
  EXPECT_EQ(row[0], r.hydro[0]);
  EXPECT_NEAR(row[0], -3.0, 1e-12);
  for (int c = 0; c < 6; c++) EXPECT_EQ(row[6 + c], r.subgrid[c]);
  r.perAtomRow(1, 2, true, row);
  for (int c = 0; c < 20; c++) EXPECT_EQ(row[12 + c], 20.0 + c);
  // a tag beyond the particles the fluid was told of, or results not sized for them: zeros
  for (long index : {-1L, 2L}) {
    r.perAtomRow(index, 2, true, row);
    for (int c = 0; c < 32; c++) EXPECT_EQ(row[c], 0.0) << index << " " << c;
  }
  row[12] = 7.0;
  r.perAtomRow(0, 3, false, row);
  for (int c = 0; c < 12; c++) EXPECT_EQ(row[c], 0.0);
  EXPECT_EQ(row[12], 7.0);   // without stresslets the row is 12 columns: nothing beyond is written
}
