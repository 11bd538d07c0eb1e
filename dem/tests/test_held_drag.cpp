// The particle steps between fluid steps (fluid_every K) without LIGGGHTS: which steps the fluid solves
// (dem/fluid_step_schedule.h) and the drag target a held step takes (dem/held_drag.h), constant or
// extrapolated linearly from the last two fluid steps, capped at one interval, and restored from a
// checkpoint's state.
#include "fluid_step_schedule.h"
#include "held_drag.h"

#include <gtest/gtest.h>

TEST(FluidStepSchedule, TheFluidSolvesEveryKthStepTheFirstTheLastAndTheCheckpoints)
{
  fdm::FluidStepSchedule every1;
  EXPECT_TRUE(every1.due(3, 10, false, true));
  fdm::FluidStepSchedule s(3);
  EXPECT_TRUE(s.due(1, 10, false, false));   // nothing to hold yet
  s.solved(1);
  EXPECT_FALSE(s.due(2, 10, false, true));
  EXPECT_TRUE(s.due(3, 10, false, true));
  EXPECT_TRUE(s.due(4, 10, true, true));     // a checkpoint
  EXPECT_TRUE(s.due(10, 10, false, true));   // the run's last step
  EXPECT_TRUE(s.due(5, 10, false, false));   // no fluid solution to hold (a new run's start)
}

TEST(FluidStepSchedule, AFluidStepSpansTheParticleStepsSinceTheLastOne)
{
  fdm::FluidStepSchedule s(4);
  EXPECT_EQ(s.span(1, 0.5), 0.5);
  s.solved(4);
  EXPECT_EQ(s.span(8, 0.5), 2.0);
  EXPECT_EQ(s.lastFluidStep(), 4);
}

TEST(HeldDrag, ConstantHoldsTheLastFluidStepsTarget)
{
  fdm::HeldDrag held(false);
  const std::vector<double> b = {1, 2, 3, 4, 5, 6};
  EXPECT_EQ(held.target(b, 5, 4), b);
  EXPECT_EQ(held.target(b, 7, 4), b);
  EXPECT_EQ(held.state().lastStep, -1);   // nothing kept
}

TEST(HeldDrag, ExtrapolatedFollowsTheLineThroughTheLastTwoFluidSteps)
{
  fdm::HeldDrag held(true);
  // the first fluid step has no predecessor: held constant
  EXPECT_EQ(held.target({1, 0, 0, 0, 0, 0}, 2, 1), std::vector<double>({1, 0, 0, 0, 0, 0}));
  // fluid steps 1 (b = 1) and 4 (b = 4): b(s) = 4 + (s - 4)/3 * 3
  EXPECT_EQ(held.target({4, 0, 0, 0, 0, 0}, 5, 4)[0], 5.0);
  // the target of later held steps of the same cycle comes from the kept b_n, whatever is passed
  EXPECT_EQ(held.target({99, 0, 0, 0, 0, 0}, 6, 4)[0], 6.0);
  // beyond one interval the slope is not stretched: f at most 1
  EXPECT_EQ(held.target({99, 0, 0, 0, 0, 0}, 9, 4)[0], 7.0);
  EXPECT_EQ(held.state().lastStep, 4);
  EXPECT_EQ(held.state().beforeStep, 1);
}

TEST(HeldDrag, ARestoredStateExtrapolatesAsTheRunItContinues)
{
  fdm::HeldDrag run(true);
  run.target({2, 0, 0, 0, 0, 1}, 3, 2);
  const double before = run.target({4, 0, 0, 0, 0, 3}, 5, 4)[5];
  fdm::HeldDrag resumed(true);
  resumed.restore(run.state());
  EXPECT_EQ(resumed.target({0, 0, 0, 0, 0, 0}, 5, 4)[5], before);
  EXPECT_EQ(before, 4.0);
}
