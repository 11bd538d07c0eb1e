/* fix contacthistory, as LIGGGHTS's own, but also serving pair_style fdm/subgrid.

   LIGGGHTS keeps tangential contact history (the spring elongation of a contact) in per-neighbour
   arrays of its 'granhistory' neighbour list, saved into per-atom partner arrays by fix
   contacthistory before atoms migrate. Its init() only accepts a pair style named exactly 'gran',
   and Neighbor finds the fix by the exact style string 'contacthistory'; so this subclass is
   registered under that name and hands its pair pointer and compute flag to the base class when
   the pair style is fdm/subgrid. For pair gran it behaves exactly as the original. Not meant to be
   used in an input script: pair_style fdm/subgrid creates it. */
#ifndef FDM_FIX_CONTACT_HISTORY_FDM_H
#define FDM_FIX_CONTACT_HISTORY_FDM_H

#include "fix_contact_history.h"

namespace LAMMPS_NS {

class FixContactHistoryFdm : public FixContactHistory {
 public:
  FixContactHistoryFdm(class LAMMPS *lmp, int narg, char **arg) : FixContactHistory(lmp, narg, arg) {}
  void init();
};

}  // namespace LAMMPS_NS

#endif
