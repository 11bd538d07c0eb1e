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

std::vector<double> FixContactHistoryFdm::packAtom(int i)
{
  std::vector<double> record(size_t(1 + npartner_[i] * (1 + dnum_)));
  record.resize(size_t(pack_exchange(i, record.data())));
  return record;
}

void FixContactHistoryFdm::restoreAtom(int i, const double *record)
{
  unpack_exchange(i, const_cast<double *>(record));
}
