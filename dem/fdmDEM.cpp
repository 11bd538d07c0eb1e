// fdmDEM -- LIGGGHTS (Debian's libliggghts 3.8) with the project's styles registered at run time.
//   fdmDEM -in input [-var name value ...] [other LIGGGHTS options]       (serial or mpirun)
// The styles are added to LIGGGHTS's style maps before the input is read, so no LIGGGHTS rebuild
// is needed (docs/dem.md). After the input script, the fluid solver is told to finish.
#include "fix_fdm_couple.h"
#include "style_registry.h"

#include "input.h"
#include "lammps.h"

#include <mpi.h>

#include <cstdio>
#include <cstring>
#include <vector>

int main(int argc, char **argv)
{
  // Unbuffered: an error message followed by MPI_Abort must not be lost.
  setvbuf(stdout, nullptr, _IONBF, 0);
  MPI_Init(&argc, &argv);

  std::vector<char *> args(argv, argv + argc);
  bool haveLog = false;
  for (int i = 1; i < argc; i++) if (std::strcmp(argv[i], "-log") == 0) haveLog = true;
  static char logFlag[] = "-log", logNone[] = "none";
  if (!haveLog) { args.push_back(logFlag); args.push_back(logNone); }

  LAMMPS_NS::LAMMPS *lmp = new LAMMPS_NS::LAMMPS(int(args.size()), args.data(), MPI_COMM_WORLD);
  fdm::registerFix<LAMMPS_NS::FixFdmCouple>(lmp, "fdm/couple");
  lmp->input->file();
  LAMMPS_NS::FixFdmCouple::finishAll();
  delete lmp;
  MPI_Finalize();
  return 0;
}
