// The keywords of pair_style fdm/subgrid (subgrid_options.h).
#include "subgrid_options.h"

#include "fdm/resistance/subgrid.hpp"

namespace fdm {

namespace {
const char *faceNames[6] = {"xlo", "xhi", "ylo", "yhi", "zlo", "zhi"};
bool positive(double x) { return x > 0; }
}  // namespace

const char *faceName(int face) { return face >= 0 && face < 6 ? faceNames[face] : "?"; }

SubgridOptions::SubgridOptions() :
  cutoffCells(resistance::defaultPairCutoffCells), wallCutoffCells(resistance::defaultWallCutoffCells)
{
}

SubgridOptions parseSubgridOptions(const std::vector<std::string> &args)
{
  SubgridOptions o;
  KeywordTable table("pair_style fdm/subgrid");
  // the sub-grid lubrication model
  table.yesNo("lubrication", o.lubrication)
      .choice<bool>("model", {{"cutoff", false}, {"calibrated", true}}, o.calibrated)
      .values("calibration", 1, [&o](const std::string *v) {
        o.calibrationFile = v[0];
        o.calibrated = true;
      })
      .number("cutoff", o.cutoffCells, {positive, "cutoff (the cut-off gap in mesh cells) must be positive"})
      .number("wall_cutoff", o.wallCutoffCells,
              {positive, "wall_cutoff (the wall cut-off gap in mesh cells) must be positive"});
  // frictional contact and its springs' integration
  table.values("contact", 4, [&o, &table](const std::string *v) {
    o.kn = table.toNumber("contact", v[0]);
    o.kt = table.toNumber("contact", v[1]);
    o.mu = table.toNumber("contact", v[2]);
    o.hr = table.toNumber("contact", v[3]);
    if (!(o.kn > 0) || !(o.kt >= 0) || !(o.mu >= 0) || !(o.hr >= 0))
      table.fail("contact kn " + v[0] + " kt " + v[1] + " mu_s " + v[2] + " h_r " + v[3] +
                 ": kn must be positive, kt, mu_s and h_r non-negative");
  });
  table.choice<bool>("contact_integration", {{"implicit", true}, {"explicit", false}}, o.implicitContact)
      .choice<bool>("unstable_step", {{"error", true}, {"warn", false}}, o.unstableStepIsError);
  // the walls, one keyword each
  table.values("wall", 4, [&o, &table](const std::string *v) {
    int face = 0;
    while (face < 6 && v[0] != faceNames[face]) face++;
    if (face == 6) table.fail("wall " + v[0] + ": the face must be one of xlo xhi ylo yhi zlo zhi");
    SubgridWall w;
    w.axis = face / 2;
    w.side = face % 2;
    for (int d = 0; d < 3; d++) w.velocity[d] = table.toNumber("wall", v[1 + d]);
    if (w.velocity[w.axis] != 0)
      table.fail("wall " + v[0] + " moves through itself (velocity component " + v[1 + w.axis] +
                 " along its normal): a wall moves in its own plane");
    for (const SubgridWall &other : o.walls)
      if (other.axis == w.axis && other.side == w.side) table.fail("wall " + v[0] + " is declared twice");
    o.walls.push_back(w);
  });
  table.parse(args, "see docs/commands/pair_fdm_subgrid.md");
  return o;
}

}  // namespace fdm
