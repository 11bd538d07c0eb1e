// Foam::fluidCheckpoint (fluid/fdmFoam/fluidCheckpoint): the marker of a fluid checkpoint, written and
// read back with every entry (the exact time to the last bit), the marker of a compact snapshot's
// restart (fromRest) and which session step is a first step (the first of a run, or the first after a
// restart from rest; never that of a plain resume), and a marker cut short refused by name.
#include "fluidCheckpoint.H"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

namespace {

std::string scratchFile(const std::string &name) {
  const char *dir = std::getenv("TMPDIR");
  return std::string(dir ? dir : "/tmp") + "/fdmFluidCheckpointTest." + std::to_string(::getpid()) + "." + name;
}

Foam::fluidCheckpoint marker(bool fromRest) {
  Foam::fluidCheckpoint c;
  c.step = 560;
  c.time = 56.000000000000007;   // not a round decimal: the 17 digits must give it back exactly
  c.timeIndex = 560;
  c.timeName = "56";
  c.stepsDone = 560;
  c.cells = 20736;
  c.processors = 2;
  c.particles = 56;
  c.fromRest = fromRest;
  return c;
}

}  // namespace

TEST(FluidCheckpoint, WrittenMarkerReadsBackEveryEntry) {
  for (bool fromRest : {false, true}) {
    const std::string file = scratchFile(fromRest ? "rest" : "plain");
    const Foam::fluidCheckpoint written = marker(fromRest);
    ASSERT_EQ(written.write(file), "");
    Foam::fluidCheckpoint read;
    ASSERT_EQ(read.read(file), "");
    EXPECT_EQ(read.step, written.step);
    EXPECT_EQ(read.time, written.time);   // bit for bit
    EXPECT_EQ(read.timeIndex, written.timeIndex);
    EXPECT_EQ(read.timeName, written.timeName);
    EXPECT_EQ(read.stepsDone, written.stepsDone);
    EXPECT_EQ(read.cells, written.cells);
    EXPECT_EQ(read.processors, written.processors);
    EXPECT_EQ(read.particles, written.particles);
    EXPECT_EQ(read.fromRest, fromRest);
    std::remove(file.c_str());
  }
}

TEST(FluidCheckpoint, MarkerWithoutFromRestIsAPlainCheckpoint) {
  // the markers fdmFoam wrote before the entry existed
  const std::string file = scratchFile("old");
  std::ofstream(file) << "step 45\ntime 2.25\ntimeIndex 45\ntimeName 2.25\nstepsDone 45\ncells 2304\n"
                         "processors 1\nparticles 3\nregularOutput 0\nend\n";
  Foam::fluidCheckpoint read;
  ASSERT_EQ(read.read(file), "");
  EXPECT_FALSE(read.fromRest);
  EXPECT_FALSE(read.firstStep(0));
  std::remove(file.c_str());
}

TEST(FluidCheckpoint, FirstStepOfARunOrAfterARestartFromRest) {
  const Foam::fluidCheckpoint start;               // no resume: a run from step 0
  EXPECT_TRUE(start.firstStep(0));
  EXPECT_FALSE(start.firstStep(1));
  const Foam::fluidCheckpoint resumed = marker(false);
  EXPECT_FALSE(resumed.firstStep(0));              // the fields of the step before: not a first step
  const Foam::fluidCheckpoint snapshot = marker(true);
  EXPECT_TRUE(snapshot.firstStep(0));              // the fluid from rest at step 560
  EXPECT_FALSE(snapshot.firstStep(1));
  EXPECT_EQ(snapshot.stepsDone, 560);              // while the count (particlesEvery) goes on
}

TEST(FluidCheckpoint, MarkerCutShortIsRefusedByName) {
  const std::string file = scratchFile("cut");
  std::ofstream(file) << "step 45\ntime 2.25\ntimeIndex 45\n";
  Foam::fluidCheckpoint read;
  const std::string problem = read.read(file);
  EXPECT_NE(problem.find(file + " is not a complete fdmFoam checkpoint marker"), std::string::npos) << problem;
  EXPECT_NE(problem.find("3 of its 8 entries and no end line"), std::string::npos) << problem;
  std::remove(file.c_str());
  EXPECT_NE(read.read(file).find("there is no checkpoint marker " + file), std::string::npos);
}
