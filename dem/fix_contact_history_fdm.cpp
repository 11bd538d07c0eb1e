// fix contacthistory serving pair_style fdm/subgrid (see fix_contact_history_fdm.h).
#include "fix_contact_history_fdm.h"

#include "atom.h"
#include "error.h"
#include "force.h"
#include "pair_fdm_subgrid.h"

using namespace LAMMPS_NS;

void FixContactHistoryFdm::init()
{
  PairFdmSubgrid *pair = dynamic_cast<PairFdmSubgrid *>(force->pair_match("fdm/subgrid", 1));
  if (!pair) {
    FixContactHistory::init();  // pair gran: the stock behaviour
    return;
  }
  if (!atom->tag_enable) error->all(FLERR, "contact history requires atom IDs");
  // pre_exchange() only uses the pair's neighbour lists and its compute flag
  pair_gran_ = pair;
  computeflag_ = &pair->computeflag;
  allocate_pages();
}
