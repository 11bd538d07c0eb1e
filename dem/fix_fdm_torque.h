/* fix fdm/torque -- a constant external torque on every particle of a group (docs/dem.md).

   Syntax:
     fix ID group fdm/torque Tx Ty Tz

   Tx, Ty, Tz: the torque [N m] added to each particle of the group at every force evaluation
   (post_force), beside the contact torques of the pair style. fix fdm/couple takes it into the
   particle's external torque of Eq. (31) (T^ext of Eq. 32), as it takes fix addforce's force.

   LIGGGHTS 3.8 has no per-particle torque fix (LAMMPS's fix addtorque spreads a torque over a
   group's atoms as forces about its centre of mass, which is nothing for one sphere). The
   mobility calibration (scripts/fdmsubgrid/calibration.py) drives a sphere by a torque with it. */

#ifndef FDM_FIX_FDM_TORQUE_H
#define FDM_FIX_FDM_TORQUE_H

#include "fix.h"

namespace LAMMPS_NS {

class FixFdmTorque : public Fix {
 public:
  FixFdmTorque(class LAMMPS *, int, char **);
  int setmask();
  void init();
  void setup(int);
  void post_force(int);

 private:
  double torque_[3];
};

}  // namespace LAMMPS_NS

#endif
