// The configuration checks of fix fdm/couple (dem/configuration_checks.h) as functions of particles
// and box, without LIGGGHTS: walls, box, periodic images, overlaps (also through a periodic face and
// among many particles), the periodic box's force balance (Eq. 43) and the deep overlap of a run.
#include "configuration_checks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace {

fdm::GatheredParticle sphere(double x, double y, double z, double a)
{
  fdm::GatheredParticle p = fdm::GatheredParticle();
  p.x[0] = x;
  p.x[1] = y;
  p.x[2] = z;
  p.radius = a;
  p.density = 1000;
  p.mass = 1000 * 4.0 / 3.0 * 3.14159265358979323846 * a * a * a;
  return p;
}

// [0, 10]^3, periodic in x and z, walls in y
fdm::ParticleBox channel()
{
  fdm::ParticleBox b;
  for (int d = 0; d < 3; d++) {
    b.lo[d] = 0;
    b.hi[d] = 10;
    b.length[d] = 10;
    b.periodic[d] = d != 1;
  }
  return b;
}

bool contains(const std::string &text, const std::string &part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST(ConfigurationChecks, ASphereClearOfEverythingPasses)
{
  EXPECT_EQ(fdm::configurationProblem({sphere(5, 5, 5, 1), sphere(8, 5, 5, 1)}, channel(), true), "");
}

TEST(ConfigurationChecks, ASphereThroughAWallIsNamed)
{
  const std::string p = fdm::configurationProblem({sphere(5, 5, 5, 1), sphere(5, 0.99, 5, 1)}, channel(), true);
  EXPECT_TRUE(contains(p, "particle 2 at (5, 0.99, 5) with radius 1 crosses the wall y = 0")) << p;
  // a continuing run accepts a sphere pressed into a wall by its spring, up to the coupler's tolerance
  EXPECT_EQ(fdm::configurationProblem({sphere(5, 0.99, 5, 1)}, channel(), false), "");
  const std::string deep = fdm::configurationProblem({sphere(5, 0.9, 5, 1)}, channel(), false);
  EXPECT_TRUE(contains(deep, "radii accepted for a contact pressed into a wall")) << deep;
}

TEST(ConfigurationChecks, ACentreOutsideTheBoxOrASphereLargerThanThePeriodIsNamed)
{
  EXPECT_TRUE(contains(fdm::configurationProblem({sphere(11, 5, 5, 1)}, channel(), true),
                       "its centre lies outside the box in x"));
  EXPECT_TRUE(contains(fdm::configurationProblem({sphere(5, 5, 5, 5.5)}, channel(), false),
                       "is larger than the periodic box in x"));
  fdm::GatheredParticle massless = sphere(5, 5, 5, 1);
  massless.mass = 0;
  EXPECT_TRUE(contains(fdm::configurationProblem({massless}, channel(), true), "non-positive radius, density"));
}

TEST(ConfigurationChecks, OverlapsAreFoundThroughAPeriodicFace)
{
  const std::string p = fdm::firstOverlap({sphere(5, 5, 5, 1), sphere(0.5, 5, 5, 1), sphere(9.6, 5, 5, 1)}, channel());
  EXPECT_TRUE(contains(p, "particles 2 and 3 overlap")) << p;
  EXPECT_TRUE(contains(p, "surface gap -1.1")) << p;
  // only a configuration the input gave is checked for overlaps
  EXPECT_EQ(fdm::configurationProblem({sphere(5, 5, 5, 1), sphere(6.5, 5, 5, 1)}, channel(), false), "");
  EXPECT_TRUE(contains(fdm::configurationProblem({sphere(5, 5, 5, 1), sphere(6.5, 5, 5, 1)}, channel(), true),
                       "particles 1 and 2 overlap"));
}

TEST(ConfigurationChecks, TheBinnedSearchFindsWhatEveryPairFinds)
{
  // 2000 random spheres in a periodic box: the first pair and the count agree with the O(N^2) search
  std::mt19937 random(7);
  std::uniform_real_distribution<double> u(0, 10);
  fdm::ParticleBox box = channel();
  box.periodic[1] = true;
  std::vector<fdm::GatheredParticle> p;
  for (int i = 0; i < 2000; i++) p.push_back(sphere(u(random), u(random), u(random), 0.05));
  long pairs = 0, firstI = -1, firstJ = -1;
  for (long i = 0; i < long(p.size()); i++)
    for (long j = i + 1; j < long(p.size()); j++) {
      double r2 = 0;
      for (int d = 0; d < 3; d++) {
        double dx = p[j].x[d] - p[i].x[d];
        dx -= 10 * std::round(dx / 10);
        r2 += dx * dx;
      }
      if (std::sqrt(r2) < 0.1) {
        if (pairs++ == 0) firstI = i, firstJ = j;
      }
    }
  ASSERT_GT(pairs, 1);
  const std::string found = fdm::firstOverlap(p, box);
  EXPECT_TRUE(contains(found, "particles " + std::to_string(firstI + 1) + " and " + std::to_string(firstJ + 1) + " ")) << found;
  EXPECT_TRUE(contains(found, "(" + std::to_string(pairs) + " overlapping pairs in all)")) << found;
}

TEST(ConfigurationChecks, APeriodicBoxNeedsItsLoadsToBalanceTheImposedGradient)
{
  fdm::ParticleBox box = channel();
  box.periodic[1] = true;
  const double gradP0[3] = {0.01, 0, 0}, noGradient[3] = {0, 0, 0}, gravity[3] = {0, 0, 0};
  fdm::GatheredParticle p = sphere(5, 5, 5, 1);
  EXPECT_EQ(fdm::periodicBalanceProblem({p}, box, noGradient, 1000, gravity, 3), "");
  const std::string unbalanced = fdm::periodicBalanceProblem({p}, box, gradP0, 1000, gravity, 3);
  EXPECT_TRUE(contains(unbalanced, "needs V0 gradP0 = (10 0 0) N (Eq. 43; V0 = 1000 m3) at step 3")) << unbalanced;
  p.f[0] = 10;   // the external force V0 gradP0
  EXPECT_EQ(fdm::periodicBalanceProblem({p}, box, gradP0, 1000, gravity, 3), "");
}

TEST(ConfigurationChecks, ADeepOverlapDuringARunStopsIt)
{
  EXPECT_EQ(fdm::deepOverlapProblem(1, 2, -0.01, 0.01, 5), "");
  const std::string p = fdm::deepOverlapProblem(3, 7, -0.1, 0.1, 42);
  EXPECT_TRUE(contains(p, "particles 3 and 7 overlap by 0.1 m (0.1 of the smaller radius) at step 42")) << p;
}

TEST(ConfigurationChecks, TheInputsSetUpNeedsNewtonOffUnitsSiAndAPositiveStep)
{
  EXPECT_EQ(fdm::couplingSetupProblem(false, "si", 1e-3), "");
  EXPECT_EQ(fdm::couplingSetupProblem(true, "si", 1e-3), "fix fdm/couple requires newton off");
  EXPECT_EQ(fdm::couplingSetupProblem(false, "lj", 1e-3),
            "fix fdm/couple requires units si (the fluid solver works in SI), not units lj");
  EXPECT_EQ(fdm::couplingSetupProblem(false, "si", 0), "fix fdm/couple requires a positive timestep");
  EXPECT_EQ(fdm::couplingSetupProblem(false, "si", std::nan("")), "fix fdm/couple requires a positive timestep");
}

TEST(ConfigurationChecks, OtherFixesThatMoveOrWeighTheParticlesAreRefusedByName)
{
  EXPECT_EQ(fdm::otherFixProblem("fdm/output", "out", false), "");
  EXPECT_EQ(fdm::otherFixProblem("fdm/couple", "c2", true), "fix fdm/couple is defined twice: one coupled fluid, one fix");
  EXPECT_EQ(fdm::otherFixProblem("nve/sphere", "integr", true),
            "fix fdm/couple moves the particles itself (it replaces nve/sphere): remove fix integr (nve/sphere)");
  const std::string g = fdm::otherFixProblem("gravity", "grav", false);
  EXPECT_TRUE(contains(g, "fix grav (gravity) adds the full weight m g without buoyancy")) << g;
  EXPECT_TRUE(contains(g, "use the gravity keyword of fix fdm/couple")) << g;
}
