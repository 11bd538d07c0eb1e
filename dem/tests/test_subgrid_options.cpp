// pair_style fdm/subgrid's keywords (dem/subgrid_options.h, dem/keyword_table.h) without LIGGGHTS: the
// documented defaults, every keyword reaching its option, repeated walls, each problem named with the
// keyword and the value it got.
#include "subgrid_options.h"

#include "keyword_lines.h"

#include <gtest/gtest.h>

namespace {

using fdm::testing::words;

fdm::SubgridOptions parse(const std::string &line) { return fdm::parseSubgridOptions(words(line)); }

std::string problem(const std::string &line) { return fdm::testing::keywordProblem(fdm::parseSubgridOptions, line); }

}  // namespace

TEST(SubgridOptions, DefaultsAreTheDocumentedOnes)
{
  // docs/commands/pair_fdm_subgrid.md, Default (the cut-offs: the resistance library's)
  const fdm::SubgridOptions o = parse("");
  EXPECT_TRUE(o.lubrication && o.calibrated && o.unstableStepIsError && o.implicitContact);
  EXPECT_TRUE(o.calibrationFile.empty());
  EXPECT_EQ(o.cutoffCells, 0.65);
  EXPECT_EQ(o.wallCutoffCells, 0.75);
  EXPECT_EQ(o.kn, 0.0);
  EXPECT_EQ(o.hr, 0.0);   // no contact
  EXPECT_TRUE(o.walls.empty());
}

TEST(SubgridOptions, EveryKeywordReachesItsOption)
{
  const fdm::SubgridOptions o =
      parse("lubrication no model cutoff cutoff 0.5 wall_cutoff 1e-1 contact 20000 200 0.5 0.005 "
            "wall ylo -1 0 0.25 wall yhi 1 0 0 unstable_step warn contact_integration explicit");
  EXPECT_FALSE(o.lubrication || o.calibrated || o.unstableStepIsError || o.implicitContact);
  EXPECT_EQ(o.cutoffCells, 0.5);
  EXPECT_EQ(o.wallCutoffCells, 0.1);
  EXPECT_EQ(o.kn, 20000.0);
  EXPECT_EQ(o.kt, 200.0);
  EXPECT_EQ(o.mu, 0.5);
  EXPECT_EQ(o.hr, 0.005);
  ASSERT_EQ(o.walls.size(), 2u);
  EXPECT_EQ(o.walls[0].axis, 1);
  EXPECT_EQ(o.walls[0].side, 0);
  EXPECT_EQ(o.walls[0].velocity[0], -1.0);
  EXPECT_EQ(o.walls[0].velocity[2], 0.25);
  EXPECT_EQ(o.walls[1].side, 1);
  EXPECT_EQ(std::string(fdm::faceName(2 * o.walls[1].axis + o.walls[1].side)), "yhi");
  // a table file chooses the calibrated model; a later "model cutoff" still wins, as the line reads
  const fdm::SubgridOptions table = parse("model cutoff calibration my.table");
  EXPECT_TRUE(table.calibrated);
  EXPECT_EQ(table.calibrationFile, "my.table");
  EXPECT_FALSE(parse("calibration my.table model cutoff").calibrated);
}

TEST(SubgridOptions, EachProblemIsNamedWithTheKeywordAndTheValueItGot)
{
  EXPECT_EQ(problem("lubrication maybe"), "pair_style fdm/subgrid: lubrication must be yes or no, got maybe");
  EXPECT_EQ(problem("model exact"), "pair_style fdm/subgrid: model must be cutoff or calibrated, got exact");
  EXPECT_EQ(problem("cutoff -0.5"),
            "pair_style fdm/subgrid: cutoff (the cut-off gap in mesh cells) must be positive, got -0.5");
  EXPECT_EQ(problem("wall_cutoff 0"),
            "pair_style fdm/subgrid: wall_cutoff (the wall cut-off gap in mesh cells) must be positive, got 0");
  EXPECT_EQ(problem("cutoff 1x"), "pair_style fdm/subgrid: cutoff needs a number, got 1x");
  EXPECT_EQ(problem("contact 0 80 0.5 0.01"),
            "pair_style fdm/subgrid: contact kn 0 kt 80 mu_s 0.5 h_r 0.01: kn must be positive, kt, mu_s and h_r "
            "non-negative");
  EXPECT_EQ(problem("contact 100 80 -0.5 0.01").find("pair_style fdm/subgrid: contact kn 100 kt 80 mu_s -0.5 h_r"), 0u);
  EXPECT_EQ(problem("contact 100 80 0.5"), "pair_style fdm/subgrid: keyword contact needs 4 values");
  EXPECT_EQ(problem("wall top 0 0 0"), "pair_style fdm/subgrid: wall top: the face must be one of xlo xhi ylo yhi zlo zhi");
  EXPECT_EQ(problem("wall ylo 0 1 0"), "pair_style fdm/subgrid: wall ylo moves through itself (velocity component 1 "
                                       "along its normal): a wall moves in its own plane");
  EXPECT_EQ(problem("wall ylo 0 0 0 wall ylo 1 0 0"), "pair_style fdm/subgrid: wall ylo is declared twice");
  EXPECT_EQ(problem("wall ylo fast 0 0"), "pair_style fdm/subgrid: wall needs a number, got fast");
  EXPECT_EQ(problem("unstable_step ignore"), "pair_style fdm/subgrid: unstable_step must be error or warn, got ignore");
  EXPECT_EQ(problem("contact_integration semi"),
            "pair_style fdm/subgrid: contact_integration must be implicit or explicit, got semi");
  EXPECT_EQ(problem("friction 0.5"),
            "pair_style fdm/subgrid: unknown keyword friction (see docs/commands/pair_fdm_subgrid.md)");
}
