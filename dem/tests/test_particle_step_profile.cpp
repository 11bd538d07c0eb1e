// The breakdown of the particle step (dem/particle_step_profile.h) without LIGGGHTS: the parts add up,
// the rest is what the wall time leaves, LIGGGHTS's timers split it, runs add into a session's total.
#include "particle_step_profile.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

using Profile = fdm::ParticleStepProfile;

// the row of the report named `name` (after its indentation): seconds, percent, ms per step
struct Row {
  bool found = false;
  double seconds = 0, percent = 0, msPerStep = 0;
};

Row row(const std::string &report, const std::string &name)
{
  std::istringstream in(report);
  std::string line;
  Row r;
  while (std::getline(in, line)) {
    const size_t at = line.find_first_not_of(' ');
    if (at < 4 || line.compare(at, name.size(), name) != 0) continue;
    if (line.size() > at + name.size() && line[at + name.size()] != ' ') continue;  // a longer name
    r.found = std::sscanf(line.c_str() + at + name.size(), " %lf s %lf %% %lf ms/step", &r.seconds, &r.percent,
                          &r.msPerStep) == 3;
    return r;
  }
  return r;
}

Profile example()
{
  Profile p;
  p.add(Profile::subgridBlocks, 1.0);
  p.add(Profile::systemAssembly, 0.25);
  p.add(Profile::systemFactorisation, 0.25);
  p.add(Profile::systemSolves, 2.0);
  p.add(Profile::systemResults, 0.25);
  p.add(Profile::contact, 0.75);
  p.add(Profile::positionUpdate, 0.5);
  p.add(Profile::fluidExchange, 3.0);
  p.add(Profile::gatherScatter, 0.5);
  return p;
}

}  // namespace

TEST(ParticleStepProfile, RowsAreSecondsSharesOfTheWallAndMillisecondsPerStep)
{
  const std::string report = example().report("this run", "one rank", 10.0, 4, 1);
  EXPECT_EQ(report.substr(0, report.find('\n')),
            "fdm/couple particle step by part (this run; one rank; 4 steps, 1 with the fluid, 10 s):");
  const Row subgrid = row(report, Profile::name(Profile::subgridBlocks));
  ASSERT_TRUE(subgrid.found) << report;
  EXPECT_DOUBLE_EQ(subgrid.seconds, 1.0);
  EXPECT_DOUBLE_EQ(subgrid.percent, 10.0);
  EXPECT_DOUBLE_EQ(subgrid.msPerStep, 250.0);
  const Row exchange = row(report, Profile::name(Profile::fluidExchange));
  EXPECT_DOUBLE_EQ(exchange.percent, 30.0);
  EXPECT_DOUBLE_EQ(exchange.msPerStep, 750.0);
}

TEST(ParticleStepProfile, TheRestIsWhatTheWallLeavesAndTheRowsAddUpToIt)
{
  const Profile p = example();
  EXPECT_DOUBLE_EQ(p.timed(), 8.5);
  const std::string report = p.report("this run", "one rank", 10.0, 4, 1);
  const Row rest = row(report, "rest of the step");
  ASSERT_TRUE(rest.found) << report;
  EXPECT_DOUBLE_EQ(rest.seconds, 1.5);
  double sum = 0, percent = 0;
  for (int k = 0; k < Profile::timedParts; k++) {
    const Row r = row(report, Profile::name(Profile::Part(k)));
    ASSERT_TRUE(r.found) << Profile::name(Profile::Part(k)) << "\n" << report;
    sum += r.seconds;
    percent += r.percent;
  }
  EXPECT_NEAR(sum + rest.seconds, 10.0, 1e-9);
  EXPECT_NEAR(percent + rest.percent, 100.0, 1e-6);
  // without LIGGGHTS's timers the rest is not split
  EXPECT_EQ(report.find("of which"), std::string::npos);
  // a wall shorter than the parts (clocks read at different places) leaves no negative rest
  EXPECT_DOUBLE_EQ(row(p.report("this run", "one rank", 8.0, 4, 1), "rest of the step").seconds, 0.0);
}

TEST(ParticleStepProfile, LiggghtsTimersSplitTheRest)
{
  Profile p = example();
  Profile::LiggghtsTimers l;
  l.neighbour = 0.5;
  l.communication = 0.25;
  l.output = 0.125;
  p.addLiggghts(l);
  const std::string report = p.report("this run", "rank 0's of 2 ranks", 10.0, 4, 1);
  EXPECT_DOUBLE_EQ(row(report, "of which neighbour lists").seconds, 0.5) << report;
  EXPECT_DOUBLE_EQ(row(report, "of which communication").seconds, 0.25);
  EXPECT_DOUBLE_EQ(row(report, "of which output").seconds, 0.125);
  EXPECT_DOUBLE_EQ(row(report, "of which other").seconds, 1.5 - 0.875);
  EXPECT_NE(report.find("(this run; rank 0's of 2 ranks; 4 steps"), std::string::npos);
  // timers longer than the rest leave "other" at 0, not below
  l.neighbour = 5;
  Profile q = example();
  q.addLiggghts(l);
  EXPECT_DOUBLE_EQ(row(q.report("this run", "one rank", 10.0, 4, 1), "of which other").seconds, 0.0);
}

TEST(ParticleStepProfile, RunsAddIntoTheSessionsTotal)
{
  Profile total;
  Profile::LiggghtsTimers l;
  l.neighbour = 1;
  l.communication = 2;
  l.output = 3;
  for (int run = 0; run < 3; run++) {
    Profile p = example();
    p.addLiggghts(l);
    total.add(p);
  }
  EXPECT_DOUBLE_EQ(total.seconds(Profile::systemSolves), 6.0);
  EXPECT_DOUBLE_EQ(total.timed(), 3 * 8.5);
  EXPECT_DOUBLE_EQ(total.liggghts().neighbour, 3.0);
  EXPECT_DOUBLE_EQ(total.liggghts().communication, 6.0);
  EXPECT_DOUBLE_EQ(total.liggghts().output, 9.0);
  // a run without them adds nothing to them
  total.add(example());
  EXPECT_DOUBLE_EQ(total.liggghts().neighbour, 3.0);
  EXPECT_DOUBLE_EQ(total.seconds(Profile::systemSolves), 8.0);
}

TEST(ParticleStepProfile, LapAddsTheElapsedTimeAndStartsTheNext)
{
  Profile p;
  const Profile::Clock::time_point start = Profile::now();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const Profile::Clock::time_point next = p.lap(Profile::contact, start);
  EXPECT_GE(p.seconds(Profile::contact), 0.019);
  EXPECT_LT(p.seconds(Profile::contact), 1.0);
  EXPECT_DOUBLE_EQ(p.seconds(Profile::contact), std::chrono::duration<double>(next - start).count());
  EXPECT_DOUBLE_EQ(p.timed(), p.seconds(Profile::contact));
}

TEST(ParticleStepProfile, AStretchAddsWhatItsTimedPartsDoNotHold)
{
  Profile p;
  p.add(Profile::contact, 0.5);
  const double before = p.timed();
  p.add(Profile::systemAssembly, 0.25);   // timed within the stretch
  p.add(Profile::systemFactorisation, 0.125);
  p.addUntimed(Profile::systemSolves, 1.0, before);
  EXPECT_EQ(p.seconds(Profile::systemSolves), 0.625);
  EXPECT_EQ(p.timed(), 1.5);
  // the timed parts hold more than the stretch (clocks read apart): nothing is added, never a negative
  const double again = p.timed();
  p.add(Profile::systemResults, 0.5);
  p.addUntimed(Profile::systemSolves, 0.25, again);
  EXPECT_EQ(p.seconds(Profile::systemSolves), 0.625);
}

TEST(ParticleStepProfile, EveryPartHasItsOwnName)
{
  std::vector<std::string> names;
  for (int k = 0; k < Profile::timedParts; k++) {
    const std::string n = Profile::name(Profile::Part(k));
    EXPECT_NE(n, "?");
    for (const std::string &m : names) EXPECT_NE(n, m);
    names.push_back(n);
  }
}
