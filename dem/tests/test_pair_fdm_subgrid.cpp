// Tests of pair_style fdm/subgrid inside fdmDEM (real LIGGGHTS, real MPI) against the scripted fluid
// peer of harness.h: the sub-grid blocks of the resistance library enter Eq. (31) exactly, the
// moving-wall term of Eq. (D.6), Newton's third law for unequal spheres, the stresslets of Eq. (13),
// the contact forces, MPI and the errors of an inconsistent wall declaration.
#include "harness.h"

#include "fdm/resistance/blocks.hpp"
#include "fdm/resistance/subgrid_calibration.hpp"

#include <Eigen/Dense>

namespace res = fdm::resistance;

namespace {

// Two close unequal spheres (a2/a1 = 1.4, xi = 0.02 along a slanted line) and a third far away, with the
// cut-off model (its radii and mesh, a1/Delta = 2.5, are outside the calibration table of the default model).
Scene pairScene(double xi = 0.02)
{
    Scene s;
    const double a1 = 0.5, a2 = 0.7, r = (a1 + a2) * (1 + xi / 2);
    const double n[3] = {0.6, 0.48, 0.64};  // unit vector
    s.spheres = {{3.0, 4.0, 4.0, a1, 2500.0},
                 {3.0 + r * n[0], 4.0 + r * n[1], 4.0 + r * n[2], a2, 1500.0},
                 {6.5, 1.5, 6.8, 0.4, 4000.0}};
    s.pairStyle = "fdm/subgrid model cutoff";
    s.fixOptions = "move no";
    return s;
}

struct Expected {
    Eigen::MatrixXd R;       // R^SG, 6N x 6N
    Eigen::VectorXd wallRhs;  // R_w[:, 0:3] U_w
    std::vector<res::PairBlock> pairBlocks;
    std::vector<std::pair<int, int> > pairs;
};

// R^SG built here, independently of the pair style, from the resistance library (the cut-off model, or the
// model given).
Expected subgridMatrix(const Scene& scene, const FakeFluid& fluid, const res::SubgridModel* given = nullptr)
{
    const int n = int(scene.spheres.size());
    Expected e;
    e.R = Eigen::MatrixXd::Zero(6 * n, 6 * n);
    e.wallRhs = Eigen::VectorXd::Zero(6 * n);
    const res::CutoffSubgridModel cutoff(fluid.delta, res::defaultPairCutoffCells);
    const res::SubgridModel& model = given ? *given : cutoff;
    for (int i = 0; i < n; ++i)
        for (int j = i + 1; j < n; ++j) {
            const Sphere &p = scene.spheres[i], &q = scene.spheres[j];
            const double x1[3] = {p.x, p.y, p.z}, x2[3] = {q.x, q.y, q.z};
            res::PairBlock b;
            if (!res::subgridPairBlock(model, x1, x2, p.radius, q.radius, fluid.viscosity, b)) continue;
            res::addPairBlockToDense(b, i, j, e.R.data(), 6 * n);  // row-major; R^SG is symmetric (A.2)
            e.pairBlocks.push_back(b);
            e.pairs.push_back(std::make_pair(i, j));
        }
    return e;
}

// The velocities of Eq. (31) with R^SG: [D + R] u = F, for every inner iteration the peer saw.
void expectSolution(const FakeFluid& fluid, const Scene& scene, const Expected& e, double tolerance)
{
    ASSERT_EQ(fluid.velocities.size(), fluid.integrals.size());
    ASSERT_FALSE(fluid.velocities.empty());
    const int n = int(scene.spheres.size());
    for (size_t m = 0; m < fluid.velocities.size(); ++m) {
        const cpl::Integrals& in = fluid.integrals[m];
        const cpl::Velocities& out = fluid.velocities[m];
        Eigen::MatrixXd A = e.R;
        Eigen::VectorXd F = e.wallRhs;
        for (int p = 0; p < n; ++p) {
            A.block<6, 6>(6 * p, 6 * p) += rigidBlock(fluid.volumeOf(in.step, p), fluid.rhoFluid, fluid.alphaLambda);
            for (int d = 0; d < 3; ++d) {
                F(6 * p + d) += in.particles[p].F[d];
                F(6 * p + 3 + d) += in.particles[p].T[d];
            }
        }
        const Eigen::VectorXd u = A.ldlt().solve(F);
        const std::vector<double> got = flat(out);
        for (int k = 0; k < 6 * n; ++k)
            EXPECT_NEAR(got[k], u(k), tolerance * u.cwiseAbs().maxCoeff())
                << "unknown " << k << " (particle " << k / 6 + 1 << ") step " << out.step << " iteration " << out.iteration;
    }
}

std::vector<std::vector<double> > readDump(const std::string& file, int columns)
{
    // the last snapshot: one line per atom, sorted by id
    std::ifstream in(file.c_str());
    std::string line;
    std::vector<std::vector<double> > rows;
    while (std::getline(in, line)) {
        if (line.find("ITEM: ATOMS") == 0) {
            rows.clear();
            continue;
        }
        std::istringstream is(line);
        std::vector<double> v;
        double x;
        while (is >> x) v.push_back(x);
        if (int(v.size()) == columns) rows.push_back(v);
    }
    return rows;
}

std::string dumpColumns(int n)
{
    std::string s;
    for (int c = 1; c <= n; ++c) s += " f_couple[" + std::to_string(c) + "]";
    return s;
}

// LIGGGHTS 3.8's dump_modify has no 'format float': one format for the id and `values` numbers
std::string dumpFormat(int values)
{
    std::string s = "\ndump_modify     d sort id format \"%d";
    for (int c = 0; c < values; ++c) s += " %.17g";
    return s + "\"";
}

}  // namespace

TEST(PairFdmSubgrid, SubgridBlocksEnterEq31AndObeyNewtonsThirdLaw)
{
    const std::string dir = workDir("pairblocks");
    Scene scene = pairScene();
    scene.runs = "dump            d all custom 1 sg.dump id" + dumpColumns(12) + dumpFormat(12) +
                 "\nthermo_style    custom step f_couple[5] f_couple[6]\n"
                 "thermo          1\nrun             2";
    FakeFluid fluid(dir);
    const DemRun run = runWithFluid(dir, scene, fluid);
    ASSERT_EQ(run.status, 0) << run.output;
    EXPECT_EQ(fluid.error, "");
    expectContains(run.output, "pair fdm/subgrid: sub-grid lubrication ON");
    expectContains(run.output, "no walls (no wall search)");
    expectContains(run.output, "contact OFF (h_r = 0: no contact search)");
    expectContains(run.output, "1 sub-grid pair blocks, 0 wall blocks");

    const Expected e = subgridMatrix(scene, fluid);
    ASSERT_EQ(e.pairs.size(), 1u);  // the far sphere is out of range
    expectSolution(fluid, scene, e, 1e-8);

    // the sub-grid force of the last step, F^SG = -R^SG u: equal and opposite on the two unequal spheres
    const auto rows = readDump(dir + "/sg.dump", 13);
    ASSERT_EQ(rows.size(), 3u);
    const std::vector<double> last = flat(fluid.velocities.back());
    Eigen::VectorXd u(18);
    for (int k = 0; k < 18; ++k) u(k) = last[k];
    const Eigen::VectorXd F = -e.R * u;
    double scale = 0;
    for (int d = 0; d < 3; ++d) {
        scale = std::max(scale, std::fabs(rows[0][7 + d]));
        EXPECT_NEAR(rows[0][7 + d], F(d), 1e-7 * F.cwiseAbs().maxCoeff());
        EXPECT_NEAR(rows[1][7 + d], F(6 + d), 1e-7 * F.cwiseAbs().maxCoeff());
        EXPECT_EQ(rows[2][7 + d], 0.0);  // no neighbour in range: no correction
    }
    ASSERT_GT(scale, 0);
    // round-off of the sum of terms R_ij u_j, each up to max|R| max|u|
    const double roundOff = 1e-12 * e.R.cwiseAbs().maxCoeff() * u.cwiseAbs().maxCoeff();
    for (int d = 0; d < 3; ++d)
        EXPECT_LT(std::fabs(rows[0][7 + d] + rows[1][7 + d]), roundOff) << "Newton's third law; force " << scale;
}

namespace {
// The pair scene at a1/Delta = 3 (the suspensions' mesh; set fluid.delta = calibratedDelta), a2/a1 = 1.4 and a
// third sphere of a1: every radius pair is in the shipped calibration table.
const double calibratedDelta = 0.5 / 3;
Scene calibratedScene(const std::string& pairStyle)
{
    Scene scene = pairScene(0.05);
    scene.pairStyle = pairStyle;
    scene.spheres[2].radius = 0.5;
    return scene;
}
// R^SG with the shipped table's CalibratedSubgridModel
Expected calibratedMatrix(const Scene& scene, const FakeFluid& fluid)
{
    static const res::SubgridCalibration table = res::SubgridCalibration::read(res::SubgridCalibration::defaultPath());
    const res::CalibratedSubgridModel calibrated(table, fluid.delta, res::defaultPairCutoffCells, res::defaultWallCutoffCells);
    return subgridMatrix(scene, fluid, &calibrated);
}
}  // namespace

TEST(PairFdmSubgrid, DefaultModelIsTheCalibrationTable)
{
    // `pair_style fdm/subgrid` with nothing asked uses the table; R^SG is CalibratedSubgridModel's
    const std::string dir = workDir("pairdefault");
    const Scene scene = calibratedScene("fdm/subgrid");
    FakeFluid fluid(dir);
    fluid.delta = calibratedDelta;
    const DemRun run = runWithFluid(dir, scene, fluid);
    ASSERT_EQ(run.status, 0) << run.output;
    EXPECT_EQ(fluid.error, "");
    expectContains(run.output, "calibrated (Appendix B");
    const Expected e = calibratedMatrix(scene, fluid);
    ASSERT_EQ(e.pairs.size(), 1u);
    expectSolution(fluid, scene, e, 1e-8);
    // not the cut-off model's matrix: the calibration changes the pair's block at xi = 0.05
    const Expected cut = subgridMatrix(scene, fluid);
    EXPECT_GT((cut.R - e.R).cwiseAbs().maxCoeff(), 0.05 * e.R.cwiseAbs().maxCoeff());
}

TEST(PairFdmSubgrid, PairStyleGivenAgainStartsFromTheDefaults)
{
    // the second pair_style line says nothing of the model or of contact: the run has the default model
    // (the calibration) and no contact, not the first line's cut-off model and springs
    const std::string dir = workDir("pairagain");
    Scene scene = calibratedScene("fdm/subgrid model cutoff contact 100 80 0.5 0.1 unstable_step warn");
    scene.runs = "pair_style      fdm/subgrid\npair_coeff      * *\nrun             1";
    FakeFluid fluid(dir);
    fluid.delta = calibratedDelta;
    const DemRun run = runWithFluid(dir, scene, fluid);
    ASSERT_EQ(run.status, 0) << run.output;
    expectContains(run.output, "calibrated (Appendix B");
    expectContains(run.output, "contact OFF");
    expectSolution(fluid, scene, calibratedMatrix(scene, fluid), 1e-8);
}

TEST(PairFdmSubgrid, LubricationNoGivesTheDiagonalSystem)
{
    const std::string dir = workDir("lubno");
    Scene scene = pairScene();
    scene.pairStyle = "fdm/subgrid lubrication no";
    FakeFluid fluid(dir);
    const DemRun run = runWithFluid(dir, scene, fluid);
    ASSERT_EQ(run.status, 0) << run.output;
    expectContains(run.output, "sub-grid lubrication OFF (lubrication no)");
    Expected e = subgridMatrix(scene, fluid);
    e.R.setZero();
    expectSolution(fluid, scene, e, 1e-12);
}

TEST(PairFdmSubgrid, TwoRanksGiveTheSameVelocitiesAsOne)
{
    // the pair straddles the boundary between the two ranks' sub-domains (z = 4)
    Scene scene = pairScene();
    const double shift = 4.0 - 0.5 * (scene.spheres[0].z + scene.spheres[1].z);
    scene.spheres[0].z += shift;
    scene.spheres[1].z += shift;
    expectSameRunOnOneAndTwoRanks("pair", scene, "1 by 1 by 2 MPI processor grid", 1e-9, 1e-9);  // split at z = 4
}

namespace {
// One sphere at eps = 0.1 from the wall y = 0, which moves at (0.3, 0, 0.1); the other walls at rest.
Scene wallScene()
{
    Scene s;
    s.boundary = "p f p";
    s.spheres = {{3.0, 0.55, 4.0, 0.5, 2500.0}, {6.0, 5.0, 3.5, 0.7, 1500.0}};
    s.pairStyle = "fdm/subgrid model cutoff wall ylo 0.3 0 0.1 wall yhi 0 0 0";
    s.fixOptions = "move no";
    return s;
}
void movingWall(FakeFluid& fluid)
{
    fluid.periodic[1] = 0;
    fluid.faceVelocity[2][0] = 0.3;
    fluid.faceVelocity[2][2] = 0.1;
}
}  // namespace

TEST(PairFdmSubgrid, MovingWallBlockEntersEq31)
{
    const std::string dir = workDir("wall");
    Scene scene = wallScene();
    scene.runs = "dump            d all custom 1 w.dump id" + dumpColumns(12) + dumpFormat(12) +
                 "\nrun             2";
    FakeFluid fluid(dir);
    movingWall(fluid);
    const DemRun run = runWithFluid(dir, scene, fluid);
    ASSERT_EQ(run.status, 0) << run.output;
    expectContains(run.output, "wall ylo at velocity (0.3 0 0.1)");
    expectContains(run.output, "0 sub-grid pair blocks, 1 wall blocks");

    Expected e = subgridMatrix(scene, fluid);
    res::CutoffSubgridModel model(fluid.delta, res::defaultWallCutoffCells);
    const double x[3] = {3.0, 0.55, 4.0}, point[3] = {0, 0, 0}, normal[3] = {0, -1, 0}, wallU[3] = {0.3, 0, 0.1};
    res::WallBlock b;
    ASSERT_TRUE(res::subgridWallBlock(model, x, 0.5, point, normal, fluid.viscosity, b));
    double rhs[6], stressRhs[7];
    res::wallVelocityTerm(b, wallU, rhs, stressRhs);
    for (int i = 0; i < 6; ++i) {
        e.wallRhs(i) = rhs[i];
        for (int j = 0; j < 6; ++j) e.R(i, j) += b.R[i][j];
    }
    expectSolution(fluid, scene, e, 1e-8);

    // F^SG = -R_w (U - U_w, Omega)
    const auto rows = readDump(dir + "/w.dump", 13);
    ASSERT_EQ(rows.size(), 2u);
    const std::vector<double> last = flat(fluid.velocities.back());
    double relative[6];
    for (int k = 0; k < 6; ++k) relative[k] = last[k] - (k < 3 ? wallU[k] : 0.0);
    for (int i = 0; i < 6; ++i) {
        double F = 0;
        for (int k = 0; k < 6; ++k) F -= b.R[i][k] * relative[k];
        EXPECT_NEAR(rows[0][7 + i], F, 1e-7 * std::fabs(b.R[1][1]) * 1e-3 + 1e-9 * std::fabs(F)) << "component " << i;
    }
}

TEST(PairFdmSubgrid, StressletsAreFluidPlusSubgridPlusContact)
{
    const std::string dir = workDir("stress");
    Scene scene = pairScene();
    scene.fixOptions += " stresslets yes";
    scene.runs = "dump            d all custom 1 s.dump id" + dumpColumns(25) + dumpFormat(25) +
                 "\nrun             2";
    FakeFluid fluid(dir);
    const DemRun run = runWithFluid(dir, scene, fluid);
    ASSERT_EQ(run.status, 0) << run.output;
    EXPECT_TRUE(fluid.demHello.stresslets);
    const Expected e = subgridMatrix(scene, fluid);
    ASSERT_EQ(e.pairBlocks.size(), 1u);
    const auto rows = readDump(dir + "/s.dump", 26);
    ASSERT_EQ(rows.size(), 3u);
    const std::vector<double> last = flat(fluid.velocities.back());
    const uint64_t step = fluid.stepDones.back().step;
    // S^SG_a = -(G u + H Omega): rows 0-5 particle 1, 6-11 particle 2, 12-13 the traces
    const res::PairBlock& b = e.pairBlocks[0];
    for (int row = 0; row < 14; ++row) {
        double sg = 0;
        for (int k = 0; k < 12; ++k) sg -= b.stress[row][k] * last[k];
        const int who = row < 12 ? row / 6 : row - 12, component = row < 12 ? row % 6 : 6;
        const double fluidPart = FakeFluid::hydro(who, 6 + component, step);
        EXPECT_NEAR(rows[who][1 + 12 + component], fluidPart + sg, 1e-7 * (std::fabs(sg) + std::fabs(fluidPart)))
            << "particle " << who + 1 << " stress component " << component;
    }
    // the far sphere: the fluid's stresslet alone; no contact anywhere: S^c = 0
    for (int c = 0; c < 7; ++c) EXPECT_DOUBLE_EQ(rows[2][13 + c], FakeFluid::hydro(2, 6 + c, step));
    for (int p = 0; p < 3; ++p)
        for (int c = 0; c < 6; ++c) EXPECT_EQ(rows[p][20 + c], 0.0);
}

TEST(PairFdmSubgrid, ContactForcesAreEqualOppositeAndEnterEq31)
{
    // gap 0.012 < h_r = 0.05: F_n = kn (h_r - gap) = 100 * 0.038 = 3.8 N along the line of centres
    const std::string dir = workDir("contact");
    Scene scene = pairScene();
    // one step of fixed particles: the springs' stability limit (dt < 0.0043 s here) does not matter
    scene.pairStyle = "fdm/subgrid lubrication no contact 100 80 0.5 0.05 unstable_step warn";
    scene.fixOptions = "move no stresslets yes";
    scene.runs = "dump            d all custom 1 c.dump id fx fy fz" + dumpColumns(25) + dumpFormat(28) +
                 "\nrun             1";
    FakeFluid fluid(dir);
    const DemRun run = runWithFluid(dir, scene, fluid);
    ASSERT_EQ(run.status, 0) << run.output;
    expectContains(run.output, "contact ON (kn 100 N/m, kt 80 N/m, mu_s 0.5, h_r 0.05 m; springs implicit in Eq. 31)");
    expectContains(run.output, "1 contacts");
    const auto rows = readDump(dir + "/c.dump", 29);
    ASSERT_EQ(rows.size(), 3u);
    const double n[3] = {0.6, 0.48, 0.64}, gap = 1.2 * 0.01;
    const double Fn = 100 * (0.05 - gap);
    for (int d = 0; d < 3; ++d) {
        EXPECT_NEAR(rows[0][1 + d], -Fn * n[d], 1e-9);  // sphere 1 pushed away from sphere 2
        EXPECT_NEAR(rows[1][1 + d], Fn * n[d], 1e-9);
        EXPECT_EQ(rows[2][1 + d], 0.0);
    }
    // Eq. (31) with R^SG = 0: each particle's rigid-body block times (U, Omega) = (F_fluid + F_c, T_fluid)
    const cpl::Integrals& in = fluid.integrals.back();
    const cpl::Velocities& out = fluid.velocities.back();
    for (int p = 0; p < 2; ++p) {
        Eigen::Matrix<double, 6, 1> load;
        for (int d = 0; d < 3; ++d) {
            load(d) = in.particles[p].F[d] + rows[p][1 + d];
            load(3 + d) = in.particles[p].T[d];
        }
        const Eigen::Matrix<double, 6, 1> expected =
            rigidBlock(fluid.volumeOf(in.step, p), fluid.rhoFluid, fluid.alphaLambda).ldlt().solve(load);
        for (int d = 0; d < 3; ++d)
            EXPECT_NEAR(out.particles[p].U[d], expected(d), 1e-10 * std::fabs(expected(d)) + 1e-14);
    }
    // contact stresslet, Eq. (52): S^c_p = 1/2 a_p/(a_1+a_2) (F ⊗ x + x ⊗ F), x = x_p' - x_p
    const double r = 1.2 * 1.01, weight[2] = {0.5 / 1.2, 0.7 / 1.2};
    const int comp[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
    for (int p = 0; p < 2; ++p) {
        // on 1: F = -Fn n, x = +r n; on 2: F = +Fn n, x = -r n: the same product
        for (int c = 0; c < 6; ++c) {
            const double expected = -weight[p] * Fn * r * n[comp[c][0]] * n[comp[c][1]];
            EXPECT_NEAR(rows[p][4 + 19 + c], expected, 1e-9) << "particle " << p + 1 << " component " << c;
        }
    }
}

TEST(PairFdmSubgrid, ASecondRunContinuesTheContactSpringsBitForBit)
{
    // A run split in two (run k, then run N upto) is the one run: the force evaluation of the second
    // run's setup reads the tangential springs but leaves them as they are (re-projecting a spring onto
    // the tangent plane, or capping it at mu_s |F_n| again, moves it by an ulp; a resumed run starts
    // with that evaluation too). Sliding contacts (mu_s small), one between two spheres, one with a
    // moving wall, so that both are capped at every step.
    Scene scene;
    scene.boundary = "p f p";
    const double r = 1.02, n[3] = {0.6, 0.48, 0.64};
    scene.spheres = {{3.0, 0.52, 4.0, 0.5, 2500.0}, {5.0, 4.0, 4.0, 0.5, 2500.0},
                     {5.0 + r * n[0], 4.0 + r * n[1], 4.0 + r * n[2], 0.5, 2500.0}};
    scene.pairStyle = "fdm/subgrid lubrication no contact 100 80 0.001 0.05 unstable_step warn "
                      "wall ylo 0.3 0 0.1 wall yhi 0 0 0";
    std::vector<std::vector<double> > runs;
    for (const std::string& split : {std::string(), std::string("4"), std::string("7")}) {
        const std::string dir = workDir("splitrun" + split);
        scene.runs = split.empty() ? "run             12" : "run             " + split + "\nrun             12 upto";
        FakeFluid fluid(dir);
        movingWall(fluid);
        const DemRun run = runWithFluid(dir, scene, fluid);
        ASSERT_EQ(run.status, 0) << run.output;
        ASSERT_TRUE(fluid.error.empty()) << fluid.error;
        expectContains(run.output, "2 contacts");
        std::vector<double> all;
        for (const cpl::Velocities& v : fluid.velocities) {
            const std::vector<double> u = flat(v);
            all.insert(all.end(), u.begin(), u.end());
        }
        ASSERT_EQ(all.size(), size_t(12 * 3 * 18));   // 12 steps of 3 inner iterations, 3 particles
        runs.push_back(all);
    }
    for (size_t s = 1; s < runs.size(); ++s)
        for (size_t k = 0; k < runs[0].size(); ++k)
            ASSERT_EQ(runs[s][k], runs[0][k]) << "split " << (s == 1 ? 4 : 7) << ": step " << k / 54 + 1
                                              << ", value " << k % 54 << " (bit for bit)";
}

TEST(PairFdmSubgridErrors, UndeclaredFluidWall)
{
    Scene scene = wallScene();
    scene.pairStyle = "fdm/subgrid wall yhi 0 0 0";
    expectFailure("undeclared", scene, movingWall,
                  "the fluid case has a no-slip wall on ylo moving at (0.3 0 0.1) m/s, not declared to pair_style "
                  "fdm/subgrid: add 'wall ylo 0.3 0 0.1'");
}

TEST(PairFdmSubgridErrors, WallVelocityMismatch)
{
    Scene scene = wallScene();
    scene.pairStyle = "fdm/subgrid wall ylo 0.2 0 0.1 wall yhi 0 0 0";
    expectFailure("mismatch", scene, movingWall,
                  "wall ylo: pair_style fdm/subgrid says it moves at (0.2 0 0.1) m/s but the fluid case (0/U) at (0.3 0 "
                  "0.1) m/s");
}

TEST(PairFdmSubgridErrors, WallWhereTheFluidHasASlipBoundary)
{
    expectFailure("slip", wallScene(),
                  [](FakeFluid& f) {
                      movingWall(f);
                      f.faceKind[3] = 2;
                  },
                  "pair_style fdm/subgrid declares a wall on yhi but the fluid case has a slip wall there");
}

TEST(PairFdmSubgridErrors, WallOnAPeriodicBoundaryAndBadKeywords)
{
    const std::string dir = workDir("periodicwall");
    Scene scene = pairScene();
    scene.pairStyle = "fdm/subgrid wall zlo 0 0 0";
    writeInput(dir, scene);
    DemRun run = runDEM(dir);
    EXPECT_NE(run.status, 0);
    expectContains(run.output, "pair_style fdm/subgrid: wall zlo on a periodic boundary");
    scene.pairStyle = "fdm/subgrid wall ylo 0 1 0";
    writeInput(dir, scene);
    run = runDEM(dir);
    EXPECT_NE(run.status, 0);
    expectContains(run.output, "wall ylo moves through itself");
    scene.pairStyle = "fdm/subgrid contact 0 80 0.5 0.01";
    writeInput(dir, scene);
    run = runDEM(dir);
    EXPECT_NE(run.status, 0);
    expectContains(run.output, "kn must be positive");
}
