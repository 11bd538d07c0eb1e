// The collectives of fix fdm/couple's step (dem/step_collectives.h) on two MPI ranks (mpirun -np 2, CTest
// dem.StepCollectives), without LIGGGHTS: rank 0's plan, results and counters reach every rank bit for bit,
// the deepest overlap of whichever rank holds it is named on every rank, and the wall contact loads are
// summed on rank 0; the ranks waiting for rank 0 sleep.
#include "step_collectives.h"

#include <gtest/gtest.h>
#include <mpi.h>
#include <time.h>

#include <chrono>
#include <thread>

namespace {

int rank() { int r = 0; MPI_Comm_rank(MPI_COMM_WORLD, &r); return r; }
int size() { int s = 1; MPI_Comm_size(MPI_COMM_WORLD, &s); return s; }

// a value only rank 0 knows: distinct per index, never a round number
double value(size_t k, double scale) { return scale * (1.0 + 1.0 / 3.0 * double(k)); }

double threadCpuSeconds()
{
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace

TEST(StepCollectives, RunsOnTwoRanks) { EXPECT_EQ(size(), 2) << "run with mpirun -np 2"; }

TEST(StepCollectives, RankZerosStepReachesEveryRankAndBecomesThePlansVelocities)
{
  const int n = 3;
  for (bool stresslets : {false, true}) {
    fdm::CouplingTiming counts;
    fdm::CoupledVelocitySolve solve(fdm::ParticleVelocitySystem::Settings(), counts);
    solve.resize(n);
    fdm::MovePlan plan{fdm::motion::Options()};
    fdm::BlockCounts blocks;
    fdm::CoupledVelocitySolve::Results &r = solve.results();
    if (rank() == 0) {
      plan.planned = true;
      plan.rates.assign(6 * n, 0.0);
      for (size_t k = 0; k < plan.rates.size(); k++) plan.rates[k] = value(k, 0.1);
      for (size_t k = 0; k < r.solution.size(); k++) {
        r.solution[k] = value(k, 1.1);
        r.hydro[k] = value(k, -2.3);
        r.subgrid[k] = value(k, 3.7);
      }
      for (size_t k = 0; k < r.stress.size(); k++) r.stress[k] = value(k, 0.7);
      r.springs.assign(6 * n, 0.0);
      r.springs[4] = 9.5;
      solve.solverIterations = 17;
      solve.lastIterations = 4;
      solve.lastResidual = 3.25e-7;
      blocks.pairBlocks = 5;
      blocks.wallBlocks = 2;
      blocks.contacts = 1;
    }
    fdm::broadcastStep(plan, true, solve, blocks, n, stresslets, MPI_COMM_WORLD);
    ASSERT_TRUE(plan.planned);
    ASSERT_EQ(plan.rates.size(), size_t(6 * n));
    for (size_t k = 0; k < 6 * n; k++) {
      EXPECT_EQ(plan.rates[k], value(k, 0.1));
      EXPECT_EQ(r.solution[k], value(k, 1.1));
      EXPECT_EQ(r.hydro[k], value(k, -2.3));
      EXPECT_EQ(r.subgrid[k], value(k, 3.7));
      EXPECT_EQ(r.springs[k], k == 4 ? 9.5 : 0.0);
    }
    for (size_t k = 0; k < r.stress.size(); k++) EXPECT_EQ(r.stress[k], rank() == 0 || stresslets ? value(k, 0.7) : 0.0);
    EXPECT_EQ(plan.current, r.solution);
    EXPECT_TRUE(plan.haveVelocities);
    EXPECT_EQ(solve.solverIterations, 17);
    EXPECT_EQ(solve.lastIterations, 4);
    EXPECT_EQ(solve.lastResidual, 3.25e-7);
    EXPECT_EQ(blocks.pairBlocks, 5);
    EXPECT_EQ(blocks.wallBlocks, 2);
    EXPECT_EQ(blocks.contacts, 1);
  }
}

TEST(StepCollectives, WithoutMoveThePlanStaysEachRanksOwn)
{
  fdm::CouplingTiming counts;
  fdm::CoupledVelocitySolve solve(fdm::ParticleVelocitySystem::Settings(), counts);
  solve.resize(1);
  fdm::MovePlan plan{fdm::motion::Options()};
  fdm::BlockCounts blocks;
  plan.planned = rank() == 0;
  fdm::broadcastStep(plan, false, solve, blocks, 1, false, MPI_COMM_WORLD);
  EXPECT_EQ(plan.planned, rank() == 0);
  EXPECT_TRUE(plan.rates.empty());
}

TEST(StepCollectives, TheDeepestOverlapOfAnyRankIsNamedOnEveryRankBeyondTheReportDepth)
{
  // rank 1 holds the deeper pair
  fdm::Overlap mine;
  mine.depth = rank() == 1 ? 0.2 : 0.05;
  mine.gap = rank() == 1 ? -0.2 : -0.05;
  mine.tagI = rank() == 1 ? 7 : 1;
  mine.tagJ = rank() == 1 ? 12 : 2;
  const fdm::Overlap worst = fdm::deepestOverlap(mine, 0.1, MPI_COMM_WORLD);
  EXPECT_EQ(worst.depth, 0.2);
  EXPECT_EQ(worst.gap, -0.2);
  EXPECT_EQ(worst.tagI, 7);
  EXPECT_EQ(worst.tagJ, 12);
  // within the report depth only the depth is shared
  const fdm::Overlap shallow = fdm::deepestOverlap(mine, 0.5, MPI_COMM_WORLD);
  EXPECT_EQ(shallow.depth, 0.2);
  EXPECT_EQ(shallow.tagI, mine.tagI);
  // no pair on any rank: the sentinel depth, below any report depth
  const fdm::Overlap none = fdm::deepestOverlap(fdm::Overlap(), 0.0, MPI_COMM_WORLD);
  EXPECT_FALSE(none.depth > 0.0);
}

TEST(StepCollectives, WallContactLoadsAreSummedOnRankZero)
{
  // rank 0 knows one wall's loads, rank 1 two walls' and one value too many: cut to the 6 of two walls
  const std::vector<double> local =
      rank() == 0 ? std::vector<double>{1.5, -2, 0.25} : std::vector<double>{0.5, 1, 0.25, 3, 4, 5, 99};
  const std::vector<double> sum = fdm::sumOnRoot(local, 6, MPI_COMM_WORLD);
  ASSERT_EQ(sum.size(), 6u);
  const std::vector<double> expected =
      rank() == 0 ? std::vector<double>{2, -1, 0.5, 3, 4, 5} : std::vector<double>(6, 0.0);
  EXPECT_EQ(sum, expected);
}

// While rank 0 works (here it sleeps 0.6 s, so that the test takes no core from the other rank), the other
// rank waits for it under a fifth of a core: a blocking MPI_Bcast or MPI_Barrier polls, about a whole core
// where one is free (measured: 0.6 s of CPU in 0.6 s). Nor does it return before rank 0 has called.
TEST(StepCollectives, TheRanksWaitingForRankZeroSleep)
{
  const double work = 0.6;
  MPI_Barrier(MPI_COMM_WORLD);
  const auto start = std::chrono::steady_clock::now();
  const double cpuStart = threadCpuSeconds();
  if (rank() == 0) std::this_thread::sleep_for(std::chrono::duration<double>(work));
  fdm::waitAsleepForRoot(MPI_COMM_WORLD);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double cpu = threadCpuSeconds() - cpuStart;
  if (rank() == 0) return;
  EXPECT_GE(wall, 0.9 * work) << "returned before rank 0 called";
  EXPECT_LT(cpu, 0.2 * wall) << "waited " << wall << " s using " << cpu << " s of CPU";
}

int main(int argc, char **argv)
{
  MPI_Init(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  // both ranks report; a failure on either counts in the exit code
  const int failed = RUN_ALL_TESTS();
  int anyFailed = 0;
  MPI_Allreduce(&failed, &anyFailed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return anyFailed;
}
