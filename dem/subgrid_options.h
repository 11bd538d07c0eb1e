/* The keywords of pair_style fdm/subgrid (docs/commands/pair_fdm_subgrid.md), parsed by one keyword table
   (keyword_table.h) and checked: every message starts with the style's name and names the keyword and the
   value it got. No LIGGGHTS: the pair style hands its arguments and turns a KeywordError into error->all. */

#ifndef FDM_SUBGRID_OPTIONS_H
#define FDM_SUBGRID_OPTIONS_H

#include "keyword_table.h"

#include <string>
#include <vector>

namespace fdm {

// A planar wall on a non-periodic face of the box, moving in its own plane.
struct SubgridWall {
  int axis, side;       // face = 2*axis + side (xlo, xhi, ylo, yhi, zlo, zhi)
  double velocity[3];
};

// "xlo", "xhi", "ylo", "yhi", "zlo", "zhi" for face 0..5
const char *faceName(int face);

struct SubgridOptions {
  bool lubrication = true;
  bool calibrated = true;            // model calibrated (Appendix B's table), or cutoff
  std::string calibrationFile;       // its table (empty: SubgridCalibration::defaultPath())
  double cutoffCells, wallCutoffCells;  // the cut-off model's gaps in mesh cells (resistance/subgrid.hpp's defaults)
  double kn = 0, kt = 0, mu = 0, hr = 0;   // contact kn kt mu_s h_r (h_r 0: no contact)
  std::vector<SubgridWall> walls;
  bool unstableStepIsError = true;   // unstable_step error | warn
  bool implicitContact = true;       // contact_integration implicit | explicit
  SubgridOptions();
};

// The options of `args` (the keywords and their values), or KeywordError naming the first problem.
SubgridOptions parseSubgridOptions(const std::vector<std::string> &args);

}  // namespace fdm

#endif
