/* fix fdm/output -- per-particle records and ParaView files of a coupled run (docs/dem.md).

   Syntax:
     fix ID all fdm/output [records N FILE] [vtk M DIR] [append yes|no]

   records N FILE: every N steps, one block of per-particle records (tag, type, periodic image,
     position wrapped into the box, radius, U, Omega, the fluid's and the sub-grid force and torque,
     LIGGGHTS's own force and torque, and with fix fdm/couple ... stresslets yes the stresslets:
     fluid part, sub-grid part, contact) appended to the binary FILE (particle_records.h; read by
     scripts/fdmsubgrid/output.py read_particle_records), flushed after each block.
   vtk M DIR: every M steps (the fluid's writeInterval), and at the last step of every run, the
     particles as DIR/particles_<step>.vtp (VTK XML PolyData) and the series DIR/particles.pvd.
   append yes: continue the files of a previous run (a resumed run): the blocks and VTK entries
     up to the current step are kept, later ones dropped.

   Reads fix fdm/couple's per-atom array (which must exist) after every step's solve (end_of_step);
   the particles are gathered by tag on rank 0 (MPI_Gatherv), which writes. */

#ifndef FDM_FIX_FDM_OUTPUT_H
#define FDM_FIX_FDM_OUTPUT_H

#include "fix.h"
#include "particle_records.h"

#include <memory>
#include <string>
#include <vector>

namespace LAMMPS_NS {

class FixFdmOutput : public Fix {
 public:
  FixFdmOutput(class LAMMPS *, int, char **);
  ~FixFdmOutput();
  int setmask();
  void init();
  void setup(int);
  void end_of_step();
  void post_run();

 private:
  void open();
  bool appending() const;                     // append yes, or a resumed run
  bool gather(std::vector<double> &byTag);   // rank 0: natoms_ x width_ values by tag
  void writeRecords(const std::vector<double> &byTag);
  void writeVtk(const std::vector<double> &byTag);
  void write(bool record, bool vtk);
  void fail(const std::string &message);

  long recordEvery_, vtkEvery_;
  std::string recordPath_, vtkDir_;
  bool append_;
  class Fix *couple_;          // fix fdm/couple, whose per-atom array is read
  bool stresslets_;            // its array has the stresslet columns
  int coupleColumns_, width_;  // per-atom columns of fdm/couple, values gathered per particle
  long natoms_;
  bool opened_;
  fdm::records::Layout layout_;
  std::unique_ptr<fdm::records::Writer> records_;
  std::unique_ptr<fdm::vtk::Series> series_;
  long long lastVtkStep_;
  double seconds_;             // rank 0: gathering and writing, this run
  long recordsThisRun_, vtkThisRun_;
};

}  // namespace LAMMPS_NS

#endif
