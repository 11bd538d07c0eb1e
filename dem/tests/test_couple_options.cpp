// fix fdm/couple's keywords (dem/couple_options.h, dem/keyword_table.h) without LIGGGHTS: every keyword
// parsed once from the table, numbers read as LIGGGHTS reads them, each problem named with the value it got.
#include "couple_options.h"

#include "keyword_lines.h"

#include <gtest/gtest.h>

namespace {

using fdm::testing::words;

fdm::CoupleOptions parse(const std::string &line) { return fdm::parseCoupleOptions(words(line)); }

std::string problem(const std::string &line) { return fdm::testing::keywordProblem(fdm::parseCoupleOptions, line); }

}  // namespace

TEST(CoupleOptions, DefaultsAreTheDocumentedOnes)
{
  const fdm::CoupleOptions o = parse("port 4000");
  EXPECT_EQ(o.connection.transport, "socket");
  EXPECT_EQ(o.connection.port, 4000);
  EXPECT_EQ(o.connection.name, "fluid solver fdmFoam");
  EXPECT_TRUE(o.move && o.adamsBashforth && o.gapUpdate && o.holdContactGaps && o.contactChord);
  EXPECT_FALSE(o.stresslets || o.heldExtrapolated);
  EXPECT_EQ(o.solver, fdm::ParticleVelocitySystem::cholmod);
  EXPECT_EQ(o.tolerance, 1e-10);
  EXPECT_EQ(o.coulombTolerance, fdm::ParticleVelocitySystem::Settings().coulombTolerance);
  EXPECT_EQ(o.fluidEvery, 1);
  EXPECT_EQ(o.checkpointEvery, 0);
  EXPECT_TRUE(o.wallFile.empty());
  EXPECT_TRUE(o.hasFluid());
}

TEST(CoupleOptions, EveryKeywordReachesItsOption)
{
  const fdm::CoupleOptions o =
      parse("transport file directory dir connect_timeout 5 timeout 7.5 record rec gravity 0 -9.81 1e-3 move no "
            "stresslets yes solver ldlt tolerance 1e-8 coulomb_tolerance 1e-7 integrator euler gap_update none "
            "contact_gaps free contact_chord no checkpoint 10 walls walls.dat fluid_every 3 held_drag extrapolated");
  EXPECT_EQ(o.connection.transport, "file");
  EXPECT_EQ(o.connection.directory, "dir");
  EXPECT_EQ(o.connection.connectTimeout, 5);
  EXPECT_EQ(o.connection.receiveTimeout, 7.5);
  EXPECT_EQ(o.connection.recordFile, "rec");
  EXPECT_EQ(o.gravity[0], 0);
  EXPECT_EQ(o.gravity[1], -9.81);
  EXPECT_EQ(o.gravity[2], 1e-3);
  EXPECT_FALSE(o.move || o.adamsBashforth || o.gapUpdate || o.holdContactGaps || o.contactChord);
  EXPECT_TRUE(o.stresslets && o.heldExtrapolated);
  EXPECT_EQ(o.solver, fdm::ParticleVelocitySystem::ldlt);
  EXPECT_EQ(o.tolerance, 1e-8);
  EXPECT_EQ(o.coulombTolerance, 1e-7);
  EXPECT_EQ(o.checkpointEvery, 10);
  EXPECT_EQ(o.wallFile, "walls.dat");
  EXPECT_EQ(o.fluidEvery, 3);
  // what the units and the session are given
  EXPECT_EQ(o.systemSettings().solver, fdm::ParticleVelocitySystem::ldlt);
  EXPECT_EQ(o.systemSettings().gravity[1], -9.81);
  EXPECT_TRUE(o.systemSettings().stresslets);
  EXPECT_FALSE(o.moveOptions().adamsBashforth || o.moveOptions().gapCorrection || o.moveOptions().holdContactGaps);
  EXPECT_EQ(o.sessionRequest().checkpointEvery, 10);
  EXPECT_EQ(o.sessionRequest().options.directory, "dir");
}

TEST(CoupleOptions, DemOnlyTakesTheFluidsValues)
{
  const fdm::CoupleOptions o = parse("transport none viscosity 0.5 mesh 0.25 fluid_density 1200 background_shear 2 "
                                     "stresslets yes");
  EXPECT_FALSE(o.hasFluid());
  EXPECT_EQ(o.viscosity, 0.5);
  EXPECT_EQ(o.meshSize, 0.25);
  EXPECT_EQ(o.fluidDensity, 1200);
  EXPECT_EQ(o.backgroundShear, 2);
  EXPECT_EQ(o.sessionRequest().viscosity, 0.5);
}

TEST(CoupleOptions, NumbersAreReadAsLiggghtsReadsThem)
{
  // the same conversion as force->numeric (atof): the same double for the same text
  EXPECT_EQ(parse("port 1 tolerance 3.3e-9").tolerance, 3.3e-9);
  EXPECT_EQ(parse("port 1 tolerance .25").tolerance, 0.25);
  EXPECT_EQ(problem("port 1 tolerance 1e-9x"), "fix fdm/couple: tolerance needs a number, got 1e-9x");
  EXPECT_EQ(problem("port 1 tolerance 0x10"), "fix fdm/couple: tolerance needs a number, got 0x10");
  EXPECT_EQ(problem("port 1 checkpoint 2.5"), "fix fdm/couple: checkpoint needs an integer, got 2.5");
  EXPECT_EQ(problem("port 1 gravity 0 0 g"), "fix fdm/couple: gravity needs a number, got g");
}

TEST(CoupleOptions, EachProblemIsNamedWithTheValueItGot)
{
  EXPECT_EQ(problem("port 1 gravitation 1"), "fix fdm/couple: unknown keyword gravitation (see docs/dem.md)");
  EXPECT_EQ(problem("port 1 move"), "fix fdm/couple: keyword move needs a value");
  EXPECT_EQ(problem("port 1 gravity 0 0"), "fix fdm/couple: keyword gravity needs 3 values");
  EXPECT_EQ(problem("port 1 move maybe"), "fix fdm/couple: move must be yes or no, got maybe");
  EXPECT_EQ(problem("port 1 contact_chord 1"), "fix fdm/couple: contact_chord must be yes or no, got 1");
  EXPECT_EQ(problem("port 1 solver lu"), "fix fdm/couple: solver must be cholmod, ldlt or cg, got lu");
  EXPECT_EQ(problem("transport mpi"), "fix fdm/couple: transport must be socket, file or none, got mpi");
  EXPECT_EQ(problem("port 1 held_drag linear"), "fix fdm/couple: held_drag must be constant or extrapolated, got linear");
  EXPECT_EQ(problem("port 1 coulomb_tolerance 2"),
            "fix fdm/couple: coulomb_tolerance (of the sliding contacts' forces) must be in (0, 1), got 2");
  EXPECT_EQ(problem("port 1 tolerance 0"), "fix fdm/couple: tolerance (relative residual of Eq. 31) must be in (0, 1), got 0");
  EXPECT_EQ(problem("port 1 fluid_every 0"),
            "fix fdm/couple: fluid_every K needs K >= 1 particle steps per fluid step, got 0");
  EXPECT_EQ(problem("port 1 checkpoint -1"), "fix fdm/couple: checkpoint N needs N >= 0 steps (0: none), got -1");
}

TEST(CoupleOptions, KeywordsThatGoWithOrWithoutTheFluidAreChecked)
{
  EXPECT_NE(problem("transport none viscosity 1").find("transport none (DEM only, no fluid) needs viscosity"),
            std::string::npos);
  EXPECT_NE(problem("port 1 background_shear 1").find("background_shear goes with transport none"), std::string::npos);
  EXPECT_NE(problem("transport none viscosity 1 mesh 1 fluid_every 2").find("fluid_every goes with the fluid solver"),
            std::string::npos);
  EXPECT_NE(problem("transport none viscosity 1 mesh 1 stresslets yes").find("stresslets need the fluid solver"),
            std::string::npos);
  EXPECT_NE(problem("").find("give the fluid solver's port"), std::string::npos);
  EXPECT_EQ(problem("portfile p"), "");
  EXPECT_EQ(problem("transport file"), "fix fdm/couple: transport file needs directory D");
  EXPECT_NE(problem("port 1 timeout 0").find("must be positive (seconds)"), std::string::npos);
}

TEST(KeywordTable, AlternativesReadAsASentence)
{
  EXPECT_EQ(fdm::KeywordTable::alternatives({"a"}), "a");
  EXPECT_EQ(fdm::KeywordTable::alternatives({"a", "b"}), "a or b");
  EXPECT_EQ(fdm::KeywordTable::alternatives({"a", "b", "c"}), "a, b or c");
}
