// Registers the project's styles in an installed (unmodified) LIGGGHTS 3.8 library.
// Force::pair_map is public; Modify::fix_map is private, reached through the rule that access
// checking does not apply to names in explicit template instantiations ([temp.explicit]).
#ifndef FDM_STYLE_REGISTRY_H
#define FDM_STYLE_REGISTRY_H

#include "force.h"
#include "lammps.h"
#include "modify.h"

#include <map>
#include <string>

namespace fdm {

typedef LAMMPS_NS::Fix *(*FixCreator)(LAMMPS_NS::LAMMPS *, int, char **);
typedef std::map<std::string, FixCreator> FixMap;

template <typename Tag, typename Tag::type Member> struct PrivateAccess {
  friend typename Tag::type get(Tag) { return Member; }
};
struct FixMapTag {
  typedef FixMap *LAMMPS_NS::Modify::*type;
  friend type get(FixMapTag);
};
template struct PrivateAccess<FixMapTag, &LAMMPS_NS::Modify::fix_map>;

template <class T> LAMMPS_NS::Fix *createFix(LAMMPS_NS::LAMMPS *lmp, int narg, char **arg)
{
  return new T(lmp, narg, arg);
}
template <class T> void registerFix(LAMMPS_NS::LAMMPS *lmp, const char *name)
{
  (*(lmp->modify->*get(FixMapTag())))[name] = &createFix<T>;
}
template <class T> LAMMPS_NS::Pair *createPair(LAMMPS_NS::LAMMPS *lmp) { return new T(lmp); }
template <class T> void registerPair(LAMMPS_NS::LAMMPS *lmp, const char *name)
{
  (*lmp->force->pair_map)[name] = &createPair<T>;
}

}  // namespace fdm
#endif
