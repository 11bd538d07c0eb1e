// fix fdm/torque: a constant external torque on every particle of a group (fix_fdm_torque.h, docs/dem.md).
#include "fix_fdm_torque.h"

#include "atom.h"
#include "error.h"
#include "force.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>

using namespace LAMMPS_NS;
using namespace FixConst;

namespace {

// a finite number, or an error naming the fix's argument
double torqueComponent(Error *error, const char *text, const char *name)
{
  char *end = nullptr;
  errno = 0;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || errno != 0 || !std::isfinite(v))
    error->all(FLERR, (std::string("fix fdm/torque: ") + name + " must be a finite number, got '" + text + "'").c_str());
  return v;
}

}  // namespace

FixFdmTorque::FixFdmTorque(LAMMPS *lmp, int narg, char **arg) : Fix(lmp, narg, arg)
{
  if (narg != 6) error->all(FLERR, "fix fdm/torque: syntax is 'fix ID group fdm/torque Tx Ty Tz'");
  const char *names[3] = {"Tx", "Ty", "Tz"};
  for (int d = 0; d < 3; d++) torque_[d] = torqueComponent(error, arg[3 + d], names[d]);
}

int FixFdmTorque::setmask() { return POST_FORCE; }

void FixFdmTorque::init()
{
  if (!atom->torque_flag) error->all(FLERR, "fix fdm/torque needs per-particle torques (atom_style sphere or granular)");
}

void FixFdmTorque::setup(int vflag) { post_force(vflag); }

void FixFdmTorque::post_force(int)
{
  double **torque = atom->torque;
  const int *mask = atom->mask;
  for (int i = 0; i < atom->nlocal; i++)
    if (mask[i] & groupbit)
      for (int d = 0; d < 3; d++) torque[i][d] += torque_[d];
}
