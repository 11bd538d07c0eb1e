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

#include <vector>

namespace LAMMPS_NS {

class FixContactHistoryFdm : public FixContactHistory {
 public:
  FixContactHistoryFdm(class LAMMPS *lmp, int narg, char **arg) : FixContactHistory(lmp, narg, arg) {}
  void init();

  // Checkpoint and resume (fix fdm/couple): the contact history of owned atom i as LIGGGHTS
  // migrates it between ranks (pack_exchange: partner count, then per partner its tag and the
  // spring elongation), after copying the current history from the neighbour list to the atoms
  // (syncFromNeighbourList, LIGGGHTS's own pre_exchange); and the reverse for a restored atom,
  // before the neighbour list is built (it copies the atoms' history into the list).
  void syncFromNeighbourList() { pre_exchange(); }
  std::vector<double> packAtom(int i);
  void restoreAtom(int i, const double *record);
};

}  // namespace LAMMPS_NS

#endif
