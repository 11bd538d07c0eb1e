// The command-line tool prints JSON with a normalisation field and rejects bad input.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <sys/wait.h>

namespace {
struct Result {
    int status;
    std::string output;
};
Result run(const std::string& arguments)
{
    const std::string command = std::string(FDM_RESISTANCE_TOOL) + " " + arguments + " 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    Result r = {-1, ""};
    if (!pipe) return r;
    char buffer[4096];
    std::size_t n;
    while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) r.output.append(buffer, n);
    const int status = pclose(pipe);
    r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}
}  // namespace

TEST(Cli, PairTheoryPrintsEveryFunction)
{
    const Result r = run("pair --a1 1 --a2 1 --xi 1e-5 --theory");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("\"normalisation\""), std::string::npos);
    EXPECT_NE(r.output.find("\"XA11\": 25003.5858"), std::string::npos) << r.output;
    for (const char* f : {"YA21", "YB22", "XC12", "YC11", "XG21", "YG12", "YH22", "XM11", "YM12", "ZM21", "XP12"})
        EXPECT_NE(r.output.find(std::string("\"") + f + "\""), std::string::npos) << f;
}

TEST(Cli, PairSubgridMatrixAndWall)
{
    Result r = run("pair --a1 1 --a2 1.4 --xi 0.01 --subgrid --delta 0.1");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("\"X21A\""), std::string::npos);
    EXPECT_NE(r.output.find("\"xi_cut\""), std::string::npos);
    r = run("matrix --x1 0 0 0 --x2 2.01 0 0 --a1 1 --a2 1 --delta 0.1 --eta 2");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("\"R\""), std::string::npos);
    EXPECT_NE(r.output.find("\"stress_rows\""), std::string::npos);
    EXPECT_NE(r.output.find("\"normalisation\""), std::string::npos);
    r = run("wall --a 1 --eps 0.001 --delta 0.1");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("\"XA\": 1002.35"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("\"subgrid_dimensional_over_eta\""), std::string::npos);
}

TEST(Cli, RejectsBadInput)
{
    EXPECT_EQ(run("pair --a1 -1 --a2 1 --xi 0.1").status, 2);
    EXPECT_EQ(run("pair --a1 1 --a2 1").status, 2);
    EXPECT_EQ(run("matrix --x1 0 0 --a1 1").status, 2);
    EXPECT_EQ(run("wall --a 1 --eps abc").status, 2);
    EXPECT_EQ(run("frobnicate").status, 2);
    EXPECT_EQ(run("pair --a1 1 --a2 1 --xi 0.1 --subgrid").status, 2);  // --delta required
}
