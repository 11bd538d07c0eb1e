// The collectives of fix fdm/couple's step (step_collectives.h).
#include "step_collectives.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

namespace fdm {

void waitAsleepForRoot(MPI_Comm comm)
{
  // Open MPI polls in a blocking collective, even when it yields: a rank waiting in MPI_Bcast through
  // rank 0's coupled solve would hold a core the fluid's ranks need. A non-blocking barrier, tested
  // between naps of 10 us doubling to 1 ms (the latency added to a wait of 0.1-10 s).
  MPI_Request request;
  MPI_Ibarrier(comm, &request);
  std::chrono::microseconds nap(10);
  const std::chrono::microseconds longestNap(1000);
  for (int done = 0;;) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) return;
    std::this_thread::sleep_for(nap);
    nap = std::min(2 * nap, longestNap);
  }
}

void broadcastStep(MovePlan &plan, bool move, CoupledVelocitySolve &solve, BlockCounts &counts, int n, bool stresslets,
                   MPI_Comm comm)
{
  waitAsleepForRoot(comm);
  if (move) {
    int planned = plan.planned ? 1 : 0;
    MPI_Bcast(&planned, 1, MPI_INT, 0, comm);
    plan.planned = planned != 0;
    if (plan.planned) {
      plan.rates.resize(size_t(6) * n);
      MPI_Bcast(plan.rates.data(), 6 * n, MPI_DOUBLE, 0, comm);
    }
  }
  CoupledVelocitySolve::Results &r = solve.results();
  MPI_Bcast(r.solution.data(), 6 * n, MPI_DOUBLE, 0, comm);
  plan.solved(r.solution);
  MPI_Bcast(r.hydro.data(), 6 * n, MPI_DOUBLE, 0, comm);
  MPI_Bcast(r.subgrid.data(), 6 * n, MPI_DOUBLE, 0, comm);
  if (stresslets) MPI_Bcast(r.stress.data(), 20 * n, MPI_DOUBLE, 0, comm);
  long counters[4] = {solve.solverIterations, counts.pairBlocks, counts.wallBlocks, counts.contacts};
  MPI_Bcast(counters, 4, MPI_LONG, 0, comm);
  solve.solverIterations = counters[0];
  counts.pairBlocks = counters[1];
  counts.wallBlocks = counters[2];
  counts.contacts = counters[3];
  MPI_Bcast(&solve.lastIterations, 1, MPI_INT, 0, comm);
  MPI_Bcast(&solve.lastResidual, 1, MPI_DOUBLE, 0, comm);
  // the implicit part of the contact forces (sized here: the other ranks never assemble)
  r.springs.resize(size_t(6) * n, 0.0);
  MPI_Bcast(r.springs.data(), 6 * n, MPI_DOUBLE, 0, comm);
}

Overlap deepestOverlap(const Overlap &mine, double report, MPI_Comm comm)
{
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  struct { double depth; int rank; } local = {mine.depth, rank}, worst;
  MPI_Allreduce(&local, &worst, 1, MPI_DOUBLE_INT, MPI_MAXLOC, comm);
  Overlap out = mine;
  out.depth = worst.depth;
  if (!(worst.depth > report)) return out;
  double info[3] = {mine.gap, double(mine.tagI), double(mine.tagJ)};
  MPI_Bcast(info, 3, MPI_DOUBLE, worst.rank, comm);
  out.gap = info[0];
  out.tagI = std::lround(info[1]);
  out.tagJ = std::lround(info[2]);
  return out;
}

std::vector<double> sumOnRoot(const std::vector<double> &local, size_t size, MPI_Comm comm)
{
  std::vector<double> mine(size, 0.0), sum(size, 0.0);
  for (size_t k = 0; k < size && k < local.size(); k++) mine[k] = local[k];
  MPI_Reduce(mine.data(), sum.data(), int(size), MPI_DOUBLE, MPI_SUM, 0, comm);
  return sum;
}

}  // namespace fdm
