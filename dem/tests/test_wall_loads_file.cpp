// The wall-loads file of fix fdm/couple walls FILE (dem/wall_loads_file.h) without LIGGGHTS: its header,
// each wall's sub-grid and contact loads summed from the blocks' forces on their particles (the force on
// the wall is minus theirs), appending for a resumed run, and a block count that does not match its walls.
#include "wall_loads_file.h"
#include "scratch.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace {

std::string read(const std::string &path)
{
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// walls ylo (0) and yhi (1): two sub-grid blocks on ylo, one on yhi; one implicit spring on yhi
fdm::WallLoadsFile::StepLoads loads()
{
  fdm::WallLoadsFile::StepLoads l;
  l.subgridBlockForces = {1, 2, 3, 9, 9, 9, 0.5, 0, 0, 9, 9, 9, 0, 0, -4, 9, 9, 9};
  l.subgridBlockWall = {0, 0, 1};
  l.contactLoads = {0, 0, 0, 0, 7, 0};
  l.springBlockForces = {0, 1, 0, 9, 9, 9};
  l.springBlockWall = {1};
  return l;
}

}  // namespace

TEST(WallLoadsFile, EachWallsLoadsAreMinusItsBlocksForces)
{
  const fdm::WallLoadsFile file("unused", {{1, 0}, {1, 1}});
  EXPECT_EQ(file.line(12, loads()), "12 -1.5 -2 -3 0 0 0 0 0 4 0 6 0\n");
}

TEST(WallLoadsFile, AHeaderThenALinePerStepAndAResumedRunAppends)
{
  const std::string path = fdm::testing::scratchPath("fdmWallLoadsTest", "walls.dat");
  {
    fdm::WallLoadsFile file(path, {{1, 0}, {1, 1}});
    file.write(1, 0.05, false, loads());
    file.write(2, 0.05, false, loads());
  }
  {
    fdm::WallLoadsFile resumed(path, {{1, 0}, {1, 1}});
    resumed.write(3, 0.05, true, loads());
  }
  const std::string text = read(path);
  EXPECT_EQ(text.find("# fix fdm/couple walls: force of the particles on each wall [N]: sub-grid lubrication "
                      "(Eq. D.6) and contact; timestep 0.050000000000000003\n# step ylo:subgridX ylo:subgridY "
                      "ylo:subgridZ ylo:contactX ylo:contactY ylo:contactZ yhi:subgridX"), 0u) << text;
  EXPECT_NE(text.find("\n1 -1.5"), std::string::npos);
  EXPECT_NE(text.find("\n3 -1.5"), std::string::npos);
  EXPECT_EQ(text.find("# fix", 1), std::string::npos);   // one header
  std::remove(path.c_str());
}

TEST(WallLoadsFile, AResumedRunWithoutTheFileStartsItWithTheHeader)
{
  // fdmRun --from-snapshot: a run resumed in a fresh case folder, where no earlier run wrote the file
  const std::string path = fdm::testing::scratchPath("fdmWallLoadsTest", "fresh-walls.dat");
  std::remove(path.c_str());
  {
    fdm::WallLoadsFile resumed(path, {{1, 0}, {1, 1}});
    resumed.write(401, 0.05, true, loads());
    resumed.write(402, 0.05, true, loads());
  }
  const std::string text = read(path);
  EXPECT_EQ(text.find("# fix fdm/couple walls: force of the particles on each wall [N]"), 0u) << text;
  EXPECT_NE(text.find("\n# step ylo:subgridX"), std::string::npos) << text;
  EXPECT_NE(text.find("\n401 -1.5"), std::string::npos) << text;
  EXPECT_NE(text.find("\n402 -1.5"), std::string::npos) << text;
  EXPECT_EQ(text.find("# fix", 1), std::string::npos);   // one header
  std::remove(path.c_str());
}

TEST(WallLoadsFile, BlocksAndWallIndicesMustAgree)
{
  const fdm::WallLoadsFile file("unused", {{1, 0}});
  fdm::WallLoadsFile::StepLoads l = loads();
  l.subgridBlockWall = {0, 0};
  try {
    file.line(1, l);
    FAIL() << "no error";
  } catch (const std::runtime_error &e) {
    EXPECT_STREQ(e.what(), "walls: 3 wall blocks in Eq. (31) but 2 wall indices");
  }
}
