// The position update's plan and history (dem/move_plan.h) without LIGGGHTS: Euler on the first step,
// Adams-Bashforth 2 once a previous step exists, the velocities' history, and whether the particles are
// where the plan starts from.
#include "move_plan.h"

#include <gtest/gtest.h>

#include <cmath>

namespace {

fdm::GatheredParticle at(double x)
{
  fdm::GatheredParticle p = fdm::GatheredParticle();
  p.x[0] = x;
  p.x[1] = p.x[2] = 5;
  p.radius = 1;
  return p;
}

fdm::ParticleBox box()
{
  fdm::ParticleBox b;
  for (int d = 0; d < 3; d++) {
    b.lo[d] = 0;
    b.hi[d] = b.length[d] = 10;
    b.periodic[d] = true;
  }
  return b;
}

fdm::motion::Options options()
{
  fdm::motion::Options o;
  o.adamsBashforth = true;
  o.gapCorrection = false;
  return o;
}

}  // namespace

TEST(MovePlan, EulerFirstThenAdamsBashforthWithTheHistory)
{
  fdm::MovePlan plan(options());
  const std::vector<double> u1 = {1, 0, 0, 0, 0, 0}, u2 = {2, 0, 0, 0, 0, 0};
  EXPECT_FALSE(plan.multistep(1));
  plan.plan({at(1)}, box(), u1, {}, {}, 0.1, 0.0);
  EXPECT_TRUE(plan.planned);
  EXPECT_EQ(plan.rates[0], 1.0);             // Euler: no previous step
  plan.solved(u1);
  EXPECT_TRUE(plan.multistep(1));
  plan.plan({at(1.1)}, box(), u2, {}, {}, 0.1, 0.0);
  EXPECT_EQ(plan.rates[0], 1.5 * 2 - 0.5 * 1);   // AB2: 3/2 U_n - 1/2 U_{n-1}
  plan.solved(u2);
  EXPECT_EQ(plan.previous, u1);
  EXPECT_EQ(plan.current, u2);
}

TEST(MovePlan, APlanContinuesOnlyFromWhereItStarts)
{
  fdm::MovePlan plan(options());
  plan.plan({at(1)}, box(), {1, 0, 0, 0, 0, 0}, {}, {}, 0.1, 0.0);
  auto periodic = [](double *d) {
    for (int k = 0; k < 3; k++) d[k] -= 10 * std::round(d[k] / 10);
  };
  EXPECT_TRUE(plan.continuesFrom({at(1)}, periodic));
  EXPECT_TRUE(plan.continuesFrom({at(11)}, periodic));   // its periodic image
  EXPECT_FALSE(plan.continuesFrom({at(1.5)}, periodic));
  plan.solved({1, 0, 0, 0, 0, 0});
  plan.forget();
  EXPECT_FALSE(plan.planned || plan.haveVelocities || plan.multistep(1));
  EXPECT_TRUE(plan.previous.empty() && plan.positions.empty());
}

TEST(MovePlan, TheFallbackIsSaidWithItsCounts)
{
  fdm::motion::Statistics s;
  s.pairGaps = 12;
  s.wallGaps = 3;
  s.worst = 0.7;
  s.sweeps = 30;
  const std::string w = fdm::MovePlan::fallbackWarning(40, s);
  EXPECT_EQ(w.find("fdm/couple: step 40: the log-gap targets of 12 pairs and 3 wall gaps contradict each other "
                   "(a gap still 0.7 of its target off after 30 sweeps)"), 0u) << w;
}

TEST(MovePlan, TheImplicitSpringsTakeUnOnlyWhenTheStepOrTheChordNeedsIt)
{
  fdm::MovePlan plan(options());
  fdm::ParticleVelocitySystem::Springs none;
  plan.springHistory(false, true, 1, 0.1, none);   // no velocities yet: no chord term
  EXPECT_EQ(none.gamma, 0.0);
  EXPECT_EQ(none.dt, 0.0);
  EXPECT_TRUE(none.previous.empty());
  const std::vector<double> u = {1, 2, 3, 4, 5, 6};
  plan.solved(u);
  fdm::ParticleVelocitySystem::Springs chord, multistep, both, off, otherCount;
  plan.springHistory(false, true, 1, 0.1, chord);
  EXPECT_EQ(chord.gamma, 0.0);
  EXPECT_EQ(chord.dt, 0.1);
  EXPECT_EQ(chord.previous, u);
  plan.springHistory(true, false, 1, 0.1, multistep);
  EXPECT_EQ(multistep.gamma, 1.0 / 3.0);
  EXPECT_EQ(multistep.dt, 0.0);
  EXPECT_EQ(multistep.previous, u);
  plan.springHistory(true, true, 1, 0.1, both);
  EXPECT_EQ(both.gamma, 1.0 / 3.0);
  EXPECT_EQ(both.dt, 0.1);
  plan.springHistory(false, false, 1, 0.1, off);
  EXPECT_TRUE(off.previous.empty());
  plan.springHistory(false, true, 2, 0.1, otherCount);   // U_n of another particle count: no chord term
  EXPECT_EQ(otherCount.dt, 0.0);
  EXPECT_TRUE(otherCount.previous.empty());
}
