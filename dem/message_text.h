// How the particle side writes numbers, points and particles into its messages (errors, the
// coupling's text fields): 10 significant digits, "(x, y, z)", particles by their LIGGGHTS ID.
// One place for fix fdm/couple, the coupling session and the Eq. (31) unit; no LIGGGHTS.
#ifndef FDM_MESSAGE_TEXT_H
#define FDM_MESSAGE_TEXT_H

#include <sstream>
#include <string>

namespace fdm {
namespace text {

inline std::string number(double x)
{
  std::ostringstream os;
  os.precision(10);
  os << x;
  return os.str();
}

inline std::string point(const double *x)
{
  return "(" + number(x[0]) + ", " + number(x[1]) + ", " + number(x[2]) + ")";
}

// particles are stored by tag - 1
inline std::string particleId(int index) { return std::to_string(index + 1); }

}  // namespace text
}  // namespace fdm

#endif
