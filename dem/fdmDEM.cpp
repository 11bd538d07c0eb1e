// fdmDEM -- LIGGGHTS (Debian's libliggghts 3.8) with the project's styles registered at run time.
//   fdmDEM -in input [-var name value ...] [-echo screen] [other LIGGGHTS options]   (serial or mpirun)
// The styles are added to LIGGGHTS's style maps before the input is read, so no LIGGGHTS rebuild
// is needed (docs/dem.md). After the input script, the fluid solver is told to finish.
#include "coupling_session.h"
#include "fix_contact_history_fdm.h"
#include "fix_fdm_couple.h"
#include "fix_fdm_output.h"
#include "fix_fdm_torque.h"
#include "pair_fdm_subgrid.h"
#include "style_registry.h"

#include "input.h"
#include "lammps.h"

#include <mpi.h>
#include <omp.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace {
const char usage[] =
    "usage: fdmDEM -in INPUT [-var NAME VALUE ...] [-echo screen] [-log FILE] [other LIGGGHTS options]\n"
    "       mpirun -np N fdmDEM -in INPUT ...\n"
    "       fdmDEM -in INPUT -resume CHECKPOINT   continue from a checkpoint of fix fdm/couple (fdmRun --resume)\n"
    "       fdmDEM -in INPUT -resume CHECKPOINT -until L   ... to step L, where the input's 'run L upto' was\n"
    "                                             changed from the checkpoint's last step (fdmRun --resume --until L)\n"
    "LIGGGHTS 3.8 with fix fdm/couple (coupling to the fluid solver fdmFoam) and pair_style fdm/subgrid\n"
    "(sub-grid lubrication and frictional contact); see docs/dem.md.\n";
}

int main(int argc, char **argv)
{
  // Unbuffered: an error message printed just before MPI_Abort must not be lost.
  setvbuf(stdout, nullptr, _IONBF, 0);
  setvbuf(stderr, nullptr, _IONBF, 0);
  for (int i = 1; i < argc; i++)
    if (!std::strcmp(argv[i], "-h") || !std::strcmp(argv[i], "-help") || !std::strcmp(argv[i], "--help")) {
      std::fputs(usage, stdout);
      return 0;
    }
  // CHOLMOD's supernodal factorisation of Eq. (31) copies each supernode in OpenMP loops of a fixed 4
  // threads (CHOLMOD_OMP_NUM_THREADS, compiled into Debian's libcholmod): on a machine whose cores the
  // fluid ranks and other runs share, they wait on each other for more than the copies take (the
  // factorisation of the dense Table 8 row 1.5-2.5x slower, docs/benchmarks.md "Where a dense row's
  // particle step goes"). Dynamic threads let OpenMP give those loops no more threads than the load
  // leaves free. The loops only copy and scatter: the factors, hence the results, do not depend on it.
  // OMP_DYNAMIC in the environment decides instead.
  if (!std::getenv("OMP_DYNAMIC")) omp_set_dynamic(1);
  MPI_Init(&argc, &argv);

  // LIGGGHTS writes log.liggghts unless told otherwise: off by default, -log FILE to have one
  // -resume FILE and -until L are fdmDEM's own (fix fdm/couple restores the particles from FILE, and
  // accepts an input that runs to L rather than to the checkpoint's last step); the rest is LIGGGHTS's
  std::vector<char *> args(argv, argv + 1);
  bool haveLog = false;
  for (int i = 1; i < argc; i++) {
    if (!std::strcmp(argv[i], "-resume")) {
      if (i + 1 >= argc) {
        std::fputs("fdmDEM: -resume needs the checkpoint file (fdmRun --resume finds it)\n", stderr);
        MPI_Abort(MPI_COMM_WORLD, 2);
      }
      LAMMPS_NS::CouplingSession::instance().setResumeFile(argv[++i]);
      continue;
    }
    if (!std::strcmp(argv[i], "-until")) {
      char *end = nullptr;
      const long long last = i + 1 < argc ? std::strtoll(argv[i + 1], &end, 10) : 0;
      if (i + 1 >= argc || *end != '\0' || last <= 0) {
        std::fputs("fdmDEM: -until needs the last step of the resumed run, a positive integer (fdmRun --resume --until L)\n",
                   stderr);
        MPI_Abort(MPI_COMM_WORLD, 2);
      }
      LAMMPS_NS::CouplingSession::instance().setResumeUntil(last);
      i++;
      continue;
    }
    if (!std::strcmp(argv[i], "-log") || !std::strcmp(argv[i], "-l")) haveLog = true;
    args.push_back(argv[i]);
  }
  static char logFlag[] = "-log", logNone[] = "none";
  if (!haveLog) {
    args.push_back(logFlag);
    args.push_back(logNone);
  }
  args.push_back(nullptr);

  LAMMPS_NS::LAMMPS *lmp = new LAMMPS_NS::LAMMPS(int(args.size()) - 1, args.data(), MPI_COMM_WORLD);
  fdm::registerFix<LAMMPS_NS::FixFdmCouple>(lmp, "fdm/couple");
  fdm::registerFix<LAMMPS_NS::FixFdmOutput>(lmp, "fdm/output");
  fdm::registerFix<LAMMPS_NS::FixFdmTorque>(lmp, "fdm/torque");
  fdm::registerPair<LAMMPS_NS::PairFdmSubgrid>(lmp, "fdm/subgrid");
  // LIGGGHTS's contact history, made to serve pair fdm/subgrid too (Neighbor finds it by this name)
  fdm::registerFix<LAMMPS_NS::FixContactHistoryFdm>(lmp, "contacthistory");
  lmp->input->file();
  LAMMPS_NS::CouplingSession::instance().finishAll(lmp);
  delete lmp;
  MPI_Finalize();
  return 0;
}
