/* Gather variable-length blocks of doubles from every rank onto rank 0 (MPI_Gather of the counts,
   then MPI_Gatherv), in rank order. Every gather of the particle side goes through it: fix
   fdm/couple's particles and sub-grid and spring blocks (Eq. 31 is assembled on rank 0), its
   checkpoint, and fix fdm/output's records. */

#ifndef FDM_GATHER_TO_ROOT_H
#define FDM_GATHER_TO_ROOT_H

#include <mpi.h>

#include <vector>

namespace fdm {

// Every rank's `mine`, concatenated in rank order on rank 0 (empty on the others).
inline std::vector<double> gatherToRoot(const std::vector<double> &mine, MPI_Comm comm)
{
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int count = int(mine.size());
  std::vector<int> counts(size), displs(size);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  std::vector<double> all;
  if (rank == 0) {
    int total = 0;
    for (int p = 0; p < size; p++) { displs[p] = total; total += counts[p]; }
    all.resize(total);
  }
  MPI_Gatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, 0, comm);
  return all;
}

}  // namespace fdm

#endif
