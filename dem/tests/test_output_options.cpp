// fix fdm/output's keywords (dem/output_options.h, dem/keyword_table.h) without LIGGGHTS: every keyword
// reaching its option and each problem named with the keyword and the value it got.
#include "output_options.h"

#include "keyword_lines.h"

#include <gtest/gtest.h>

namespace {

using fdm::testing::words;

std::string problem(const std::string &line) { return fdm::testing::keywordProblem(fdm::parseOutputOptions, line); }

}  // namespace

TEST(OutputOptions, EveryKeywordReachesItsOption)
{
  const fdm::OutputOptions o = fdm::parseOutputOptions(words("records 100 p.records vtk 1000 vtk append yes"));
  EXPECT_EQ(o.recordEvery, 100);
  EXPECT_EQ(o.recordPath, "p.records");
  EXPECT_EQ(o.vtkEvery, 1000);
  EXPECT_EQ(o.vtkDir, "vtk");
  EXPECT_TRUE(o.append);
  const fdm::OutputOptions records = fdm::parseOutputOptions(words("records 1 r"));
  EXPECT_EQ(records.vtkEvery, 0);
  EXPECT_FALSE(records.append);
  EXPECT_EQ(fdm::parseOutputOptions(words("vtk 5 d")).recordEvery, 0);
}

TEST(OutputOptions, EachProblemIsNamedWithTheKeywordAndTheValueItGot)
{
  EXPECT_EQ(problem("records 100 p.records vtk 10"), "fix fdm/output: keyword vtk needs 2 values");
  EXPECT_EQ(problem("records 0 p.records"), "fix fdm/output: records every 0 steps: must be 1 or more");
  EXPECT_EQ(problem("vtk -3 d"), "fix fdm/output: vtk every -3 steps: must be 1 or more");
  EXPECT_EQ(problem("records 1.5 p"), "fix fdm/output: records needs an integer, got 1.5");
  EXPECT_EQ(problem("records 1 p append maybe"), "fix fdm/output: append must be yes or no, got maybe");
  EXPECT_EQ(problem("append yes"), "fix fdm/output: nothing to write: give records N FILE and/or vtk M DIR");
  EXPECT_EQ(problem("dump 1 p").find("fix fdm/output: unknown keyword dump (records N FILE, vtk M DIR"), 0u);
}
