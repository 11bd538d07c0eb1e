/* The collectives of fix fdm/couple's step besides the gathers of gather_to_root.h: what rank 0 found
   broadcast to every rank (the plan of the next move, Eq. 31's results by tag and the step's counters),
   the deepest overlap of any rank, and the contact loads on the walls summed on rank 0. Every rank calls
   each of them (collective). MPI, no LIGGGHTS. */

#ifndef FDM_STEP_COLLECTIVES_H
#define FDM_STEP_COLLECTIVES_H

#include "configuration_checks.h"
#include "coupled_velocity_solve.h"
#include "move_plan.h"

#include <mpi.h>

#include <vector>

namespace fdm {

// The step's counts of the sub-grid blocks and contacts (rank 0's after assembly), for fix fdm/couple's
// global vector.
struct BlockCounts {
  long pairBlocks = 0, wallBlocks = 0, contacts = 0;
};

// Returns on every rank once every rank has called it; the ranks that wait sleep between tests instead of
// polling (rank 0's coupled solve, the fluid's included, takes the step: the other ranks wait through it).
void waitAsleepForRoot(MPI_Comm comm);

// Rank 0's plan (with move: whether it is planned and its rates), Eq. (31)'s results for n particles
// (solution, hydro, subgrid, springs, and stress with stresslets), the solver's counters and counts, on
// every rank, which waits for them asleep (waitAsleepForRoot); the solution becomes the plan's current
// velocities (MovePlan::solved) on every rank. The results must be sized for n
// (CoupledVelocitySolve::resize) on every rank.
void broadcastStep(MovePlan &plan, bool move, CoupledVelocitySolve &solve, BlockCounts &counts, int n, bool stresslets,
                   MPI_Comm comm);

// The deepest of the ranks' (ties: the lowest rank's) on every rank: its depth always; its gap and tags
// only when the depth is beyond `report` (else those of `mine`).
Overlap deepestOverlap(const Overlap &mine, double report, MPI_Comm comm);

// The sum over the ranks of `local`, cut or padded with zeros to `size` values, on rank 0 (zeros elsewhere).
std::vector<double> sumOnRoot(const std::vector<double> &local, size_t size, MPI_Comm comm);

}  // namespace fdm

#endif
