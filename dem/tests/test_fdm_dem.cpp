// Tests of fdmDEM and fix fdm/couple: the real fdmDEM (real LIGGGHTS, real MPI) runs as a child
// process against a scripted fluid peer that speaks the coupling protocol (a test harness, not a
// fluid solver): it sends fixed integrals and checks that the velocities returned are the analytic
// solution of Eq. (31) for a diagonal system, and it misbehaves on purpose to test error handling.
#include "harness.h"

namespace {

// A "fluid" that is not an fdm coupler at all: accepts, then writes bytes that are no message.
void garbageServer(const std::string& portFile, std::string& problem)
{
    const int fd = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a;
    std::memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    if (bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 || ::listen(fd, 1) != 0) {
        problem = "bind";
        return;
    }
    socklen_t len = sizeof a;
    getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
    std::ofstream(portFile.c_str()) << ntohs(a.sin_port) << "\n";
    const int c = accept(fd, nullptr, nullptr);
    char buf[1024];
    recv(c, buf, sizeof buf, 0);  // the DEM's Hello
    const char junk[] = "HTTP/1.1 400 Bad Request\r\n\r\nnot a coupler";
    send(c, junk, sizeof junk, MSG_NOSIGNAL);
    std::this_thread::sleep_for(std::chrono::seconds(2));
    close(c);
    close(fd);
}

// U = alpha (F + (rho_p - rho_f)/rho_p m g + f_ext) / (rho_f Vu), Omega = alpha T / (rho_f Ju): Eq. (31)
// with R^SG = 0 is diagonal, particle by particle.
void expectAnalyticVelocities(const FakeFluid& fluid, const Scene& scene, const double g[3], const double fext[3])
{
    ASSERT_EQ(fluid.velocities.size(), fluid.integrals.size());
    ASSERT_FALSE(fluid.velocities.empty());
    for (size_t m = 0; m < fluid.velocities.size(); ++m) {
        const cpl::Integrals& in = fluid.integrals[m];
        const cpl::Velocities& out = fluid.velocities[m];
        EXPECT_EQ(out.step, in.step);
        EXPECT_EQ(out.iteration, in.iteration);
        ASSERT_EQ(out.particles.size(), scene.spheres.size());
        for (uint32_t p = 0; p < out.particles.size(); ++p) {
            const Sphere& s = scene.spheres[p];
            const double mass = s.density * FakeFluid::volume(s.radius);
            const double buoyant = (s.density - fluid.rhoFluid) / s.density * mass;
            const cpl::ForceTorque& q = in.particles[p];
            const cpl::ParticleVolume& v = fluid.volumeOf(in.step, p);
            const cpl::RigidVelocity& u = out.particles[p];
            // Eq. (31) of a free particle: its rigid-body block times (U, Omega) = F^tot
            Eigen::Matrix<double, 6, 1> load;
            for (int d = 0; d < 3; ++d) {
                load(d) = q.F[d] + buoyant * g[d] + fext[d];
                load(3 + d) = q.T[d];
            }
            const Eigen::Matrix<double, 6, 1> expected = rigidBlock(v, fluid.rhoFluid, fluid.alphaLambda).ldlt().solve(load);
            for (int d = 0; d < 3; ++d) {
                const double U = expected(d), W = expected(3 + d);
                EXPECT_LT(relativeDifference(u.U[d], U), 1e-12)
                    << "particle " << p + 1 << " U" << "xyz"[d] << " step " << out.step << " iteration " << out.iteration
                    << ": " << u.U[d] << " vs " << U;
                EXPECT_LT(relativeDifference(u.omega[d], W), 1e-12)
                    << "particle " << p + 1 << " Omega" << "xyz"[d] << ": " << u.omega[d] << " vs " << W;
            }
        }
    }
}

// The whole scene of the physics tests: gravity, an external force, three particles of different
// radius and density, moving.
Scene physicsScene()
{
    Scene s;
    s.beforeFix = "fix             pull all addforce 0.5 -0.25 0.125";
    s.fixOptions = "gravity 0 0 -9.81";
    s.runs = "dump            hydro all custom 1 hydro.dump id f_couple[1] f_couple[2] f_couple[3] f_couple[4] "
             "f_couple[5] f_couple[6]\n"
             "dump_modify     hydro sort id format \"%d %.17g %.17g %.17g %.17g %.17g %.17g\"\n"
             "thermo_style    custom step f_couple[1] f_couple[2]\n"
             "thermo          1\n"
             "run             2\n"
             "variable        it equal f_couple[1]\n"
             "variable        res equal f_couple[2]\n"
             "print           \"COUPLE iterations ${it} residual ${res}\"";
    return s;
}

}  // namespace

// ---- physics of the particle side -------------------------------------------------------------------

TEST(FdmDEM, VelocitiesAreTheAnalyticSolutionOfEq31)
{
    const std::string dir = workDir("analytic");
    const Scene scene = physicsScene();
    FakeFluid fluid(dir);
    const DemRun run = runWithFluid(dir, scene, fluid);
    ASSERT_EQ(run.status, 0) << run.output;
    EXPECT_EQ(fluid.error, "");
    EXPECT_TRUE(fluid.finished) << "no Finish after the input";

    const double g[3] = {0, 0, -9.81}, fext[3] = {0.5, -0.25, 0.125};
    expectAnalyticVelocities(fluid, scene, g, fext);
    ASSERT_EQ(fluid.steps.size(), 2u);
    EXPECT_EQ(fluid.volumes.size(), 2u);     // once per step
    EXPECT_EQ(fluid.velocities.size(), 6u);  // 2 steps x 3 inner iterations

    // Hello: N, box, periodicity, dt
    EXPECT_EQ(fluid.demHello.nParticles, 3);
    EXPECT_EQ(fluid.demHello.hi[0], 8.0);
    EXPECT_TRUE(fluid.demHello.periodic[0]);
    EXPECT_DOUBLE_EQ(fluid.demHello.dt, 0.01);
    EXPECT_EQ(fluid.demHello.lastStep, 2);

    // Step 1: particles by tag, with their radius; step 2: moved by dt * (U of the last inner
    // iteration of step 1), and U, Omega in the record are those velocities.
    const cpl::Step &s1 = fluid.steps[0], &s2 = fluid.steps[1];
    EXPECT_EQ(s1.step, 1u);
    EXPECT_EQ(s2.step, 2u);
    const cpl::Velocities& last1 = fluid.velocities[2];
    for (uint32_t p = 0; p < 3; ++p) {
        EXPECT_EQ(s1.particles[p].tag, p + 1);
        EXPECT_DOUBLE_EQ(s1.particles[p].radius, scene.spheres[p].radius);
        const double x0[3] = {scene.spheres[p].x, scene.spheres[p].y, scene.spheres[p].z};
        for (int d = 0; d < 3; ++d) {
            EXPECT_DOUBLE_EQ(s1.particles[p].x[d], x0[d]) << "moved before any velocity was solved";
            EXPECT_NEAR(s2.particles[p].x[d], x0[d] + scene.dt * last1.particles[p].U[d], 1e-12);
            EXPECT_EQ(s2.particles[p].velocity.U[d], last1.particles[p].U[d]);
            EXPECT_EQ(s2.particles[p].velocity.omega[d], last1.particles[p].omega[d]);
        }
    }

    // Per-atom output: the hydrodynamic force and torque of the last StepDone of each step
    std::ifstream dump((dir + "/hydro.dump").c_str());
    std::string line;
    int timestep = -1, checked = 0;
    while (std::getline(dump, line)) {
        if (line == "ITEM: TIMESTEP") { dump >> timestep; continue; }
        if (line.compare(0, 11, "ITEM: ATOMS") != 0) continue;
        for (int p = 0; p < 3; ++p) {
            int id;
            double v[6];
            dump >> id >> v[0] >> v[1] >> v[2] >> v[3] >> v[4] >> v[5];
            for (int c = 0; c < 6; ++c)
                EXPECT_EQ(v[c], timestep == 0 ? 0.0 : FakeFluid::hydro(id - 1, c, timestep))
                    << "step " << timestep << " particle " << id << " column " << c + 1;
            ++checked;
        }
    }
    EXPECT_EQ(checked, 9);  // steps 0, 1, 2

    // Global outputs and the timing report
    expectContains(run.output, "COUPLE iterations 3 residual 1.25e-07");
    expectContains(run.output, "fdm/couple timing of this run (1 run, 2 steps");
    expectContains(run.output, "particle solve");
    expectContains(run.output, "fdm/couple timing total (1 run, 2 steps");
    // the breakdown of the particle step, after each run and for the session (rank 0's)
    expectContains(run.output, "fdm/couple particle step by part (this run; one rank; 2 steps, 2 with the fluid");
    expectContains(run.output, "fdm/couple particle step by part (total, coupled; one rank; 2 steps");
    expectContains(run.output, "    Eq. 31 solves");
    expectContains(run.output, "    exchange incl. fluid (waiting)");
    expectContains(run.output, "      of which neighbour lists");
}

TEST(FdmDEM, MoveNoHoldsTheParticlesAndTheConnectionOutlivesARun)
{
    const std::string dir = workDir("runs");
    Scene scene;
    scene.fixOptions = "move no";
    scene.runs = "run 2\nset atom 1 x 3.25\nrun 1\nrun 1";
    FakeFluid fluid(dir);
    fluid.iterations = 2;
    const DemRun run = runWithFluid(dir, scene, fluid);
    ASSERT_EQ(run.status, 0) << run.output;
    ASSERT_EQ(fluid.steps.size(), 4u);  // one connection for three runs
    EXPECT_TRUE(fluid.finished);
    EXPECT_EQ(fluid.steps[1].particles[0].x[0], 2.0);   // not moved although U != 0
    EXPECT_EQ(fluid.steps[2].particles[0].x[0], 3.25);  // where the input put it
    EXPECT_EQ(fluid.steps[3].particles[0].x[0], 3.25);
    EXPECT_EQ(fluid.steps[3].step, 4u);
    expectContains(run.output, "fdm/couple timing total (3 runs, 4 steps");
    expectContains(run.output, "fdm/couple particle step by part (total, coupled; one rank; 4 steps, 4 with the fluid");
}

TEST(FdmDEM, TwoRanksGiveTheSameVelocitiesAsOne)
{
    // both ranks own particles
    expectSameRunOnOneAndTwoRanks("mpi", physicsScene(), "Nlocal:    1.5 ave 2 max 1 min", 1e-12, 0.0);
}

TEST(FdmDEM, FileTransportAndRecordGiveTheSameRun)
{
    const std::string dir = workDir("file");
    Scene scene = physicsScene();
    scene.transport = "transport file directory coupling";
    scene.fixOptions += " record coupling.record";
    FakeFluid fluid(dir);
    fluid.options.transport = "file";
    fluid.options.directory = dir + "/coupling";
    const DemRun run = runWithFluid(dir, scene, fluid);
    ASSERT_EQ(run.status, 0) << run.output;
    const double g[3] = {0, 0, -9.81}, fext[3] = {0.5, -0.25, 0.125};
    expectAnalyticVelocities(fluid, scene, g, fext);
    // the record holds the whole conversation: 2 Hello, 2 Step, 2 Volumes, 6 Integrals, 6 Velocities,
    // 2 StepDone, Finish
    std::ifstream in((dir + "/coupling.record").c_str(), std::ios::binary);
    std::vector<unsigned char> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    size_t at = 0, n = 0;
    while (at + cpl::headerSize <= b.size()) { at += cpl::encodedSize(&b[at]); ++n; }
    EXPECT_EQ(n, 21u);
}

// ---- bad input: a clear error naming the particle or value, a non-zero exit, within seconds ----------


TEST(FdmDEMErrors, ParticleCrossingAWall)
{
    Scene scene;
    scene.boundary = "p f p";
    scene.spheres[1].y = 7.6;  // radius 0.7: through the wall y = 8
    expectFailure("wall", scene, [](FakeFluid& f) { f.periodic[1] = 0; },
                  "particle 2 at (6, 7.6, 3.5) with radius 0.7 crosses the wall y = 8");
}

TEST(FdmDEMErrors, ParticleCentreOutsideTheBox)
{
    Scene scene;
    scene.boundary = "p p f";
    scene.runs = "set atom 3 z 8.5\nrun 1";  // LIGGGHTS loses an atom beyond a non-periodic face
    expectFailure("outside", scene, [](FakeFluid& f) { f.periodic[2] = 0; },
                  "particle 3 is missing: LIGGGHTS lost it (was it put or moved outside a non-periodic face of the box?");
}

TEST(FdmDEMErrors, OverlappingParticles)
{
    Scene scene;
    scene.spheres.push_back({6.0, 5.0, 4.6, 0.5, 1000.0});  // 1.1 above particle 2 (radius 0.7): gap -0.1
    expectFailure("overlap", scene, nullptr,
                  "particles 2 and 4 overlap: centres (6, 5, 3.5) and (6, 5, 4.6), radii 0.7 and 0.5, surface gap -0.1");
}

TEST(FdmDEMErrors, OverlapThroughAPeriodicFace)
{
    Scene scene;
    scene.spheres[0].x = 0.2;
    scene.spheres.push_back({7.5, 3.0, 4.0, 0.5, 1000.0});  // minimum image distance 0.7 < 1.0
    expectFailure("overlapPeriodic", scene, nullptr, "particles 1 and 4 overlap");
}

TEST(FdmDEMErrors, ManyParticlesAreCheckedQuickly)
{
    // 8000 particles on a lattice (the binned check is O(N log N)), the last one placed on another
    Scene scene;
    scene.spheres.clear();
    for (int i = 0; i < 20; ++i)
        for (int j = 0; j < 20; ++j)
            for (int k = 0; k < 20; ++k) scene.spheres.push_back({0.2 + 0.4 * i, 0.2 + 0.4 * j, 0.2 + 0.4 * k, 0.15, 1000.0});
    scene.spheres.back().x = 7.45;  // against particle 7600 at 7.4: gap -0.25
    const DemRun run = expectFailure("many", scene, nullptr, "particles 7600 and 8000 overlap", true, 30.0);
    (void)run;
}

TEST(FdmDEMErrors, ParticleInsertedDuringTheSession)
{
    Scene scene;
    scene.runs = "run 1\ncreate_atoms 1 single 1 7 1 units box\nrun 1";
    expectFailure("inserted", scene, nullptr,
                  "the particles changed since the coupling started: 4 atoms with IDs up to 4 where the fluid solver "
                  "was told of 3");
}

TEST(FdmDEMErrors, ParticleCountMismatch)
{
    Scene scene;
    scene.spheres.pop_back();
    expectFailure("count", scene, [](FakeFluid& f) { f.nExpected = 3; },
                  "the fluid case expects 3 particles (constant/fdmProperties nParticles) but the LIGGGHTS input has 2");
}

TEST(FdmDEMErrors, BoxMismatch)
{
    Scene scene;
    expectFailure("box", scene, [](FakeFluid& f) { f.box[1] = 10; }, "x extent: LIGGGHTS box 0 .. 8 but OpenFOAM mesh 0 .. 10");
}

TEST(FdmDEMErrors, PeriodicityMismatch)
{
    Scene scene;
    expectFailure("periodic", scene, [](FakeFluid& f) { f.periodic[2] = 0; },
                  "z boundary: LIGGGHTS periodic (p) but the OpenFOAM mesh has no cyclic patches in z");
}

TEST(FdmDEMErrors, FluidNeverStarts)
{
    Scene scene;
    scene.fixOptions = "connect_timeout 2";
    const DemRun run = expectFailure("never", scene, nullptr, "could not connect to the fluid solver fdmFoam within 2 s",
                                  false, 6.0);
    EXPECT_GT(run.seconds, 1.9);
}

TEST(FdmDEMErrors, FluidDiesMidStep)
{
    Scene scene;
    scene.runs = "run 100";
    expectFailure("dies", scene, [](FakeFluid& f) { f.mode = FakeFluid::DieAfterStep; },
                  "the fluid solver fdmFoam closed the connection (did it crash? see its log)", true, 5.0);
}

TEST(FdmDEMErrors, FluidDiesMidStepWithTwoRanks)
{
    // rank 0 alone talks to the fluid: its error must still end every rank at once
    Scene scene;
    scene.runs = "run 100";
    expectFailure("dies2", scene, [](FakeFluid& f) { f.mode = FakeFluid::DieAfterStep; },
                  "the fluid solver fdmFoam closed the connection (did it crash? see its log)", true, 8.0, 2);
}

TEST(FdmDEMErrors, OverlapWithTwoRanks)
{
    Scene scene;
    scene.spheres.push_back({6.0, 5.0, 4.6, 0.5, 1000.0});
    expectFailure("overlap2", scene, nullptr, "particles 2 and 4 overlap", true, 8.0, 2);
}

TEST(FdmDEMErrors, LiggghtsErrorAfterARunIsToldToTheFluid)
{
    const std::string dir = workDir("liggghtsError");
    Scene scene;
    scene.runs = "run 1\nthis_is_not_a_command";
    FakeFluid fluid(dir);
    const DemRun run = runWithFluid(dir, scene, fluid);
    EXPECT_NE(run.status, 0);
    expectContains(run.output, "Unknown command: this_is_not_a_command");
    expectContains(fluid.error, "fdmDEM stopped before the end of its input");
    EXPECT_FALSE(fluid.finished);
}

TEST(FdmDEMErrors, FluidSendsError)
{
    Scene scene;
    expectFailure("error", scene, [](FakeFluid& f) { f.mode = FakeFluid::ErrorAfterStep; },
                  "the fluid solver fdmFoam stopped: fdmFoam: the pressure solver diverged at step 1");
}

TEST(FdmDEMErrors, FluidSendsAnUnexpectedMessage)
{
    Scene scene;
    expectFailure("wrongType", scene, [](FakeFluid& f) { f.mode = FakeFluid::WrongTypeAfterStep; },
                  "expected Volumes from the fluid solver, got Velocities (step 1)");
}

TEST(FdmDEMErrors, FluidSendsGarbage)
{
    const std::string dir = workDir("garbage");
    Scene scene;
    writeInput(dir, scene);
    std::string problem;
    std::remove((dir + "/coupling.port").c_str());
    std::thread server([&] { garbageServer(dir + "/coupling.port", problem); });
    const DemRun run = runDEM(dir);
    server.join();
    EXPECT_NE(run.status, 0);
    expectContains(run.output, "bad magic");
    EXPECT_LT(run.seconds, 10.0);
}

TEST(FdmDEMErrors, ParticleWithNoFluidVolume)
{
    Scene scene;
    expectFailure("zeroVolume", scene, [](FakeFluid& f) { f.mode = FakeFluid::ZeroVolume; },
                  "particle 2 at (6, 5, 3.5) with radius 0.7: the fluid's indicator function gives it no volume (Vu 0");
}

TEST(FdmDEMErrors, VolumesOfTheWrongSize)
{
    Scene scene;
    expectFailure("shortVolumes", scene, [](FakeFluid& f) { f.mode = FakeFluid::ShortVolumes; },
                  "Volumes (step 1) has 2 records of 10 values (20 in all) where 3 records of 10 were expected");
}

TEST(FdmDEMErrors, NonFiniteIntegral)
{
    Scene scene;
    expectFailure("nan", scene, [](FakeFluid& f) { f.mode = FakeFluid::NaNIntegral; },
                  "non-finite integral for particle 3");
}

TEST(FdmDEMErrors, NveSphereWithTheCouplingFix)
{
    Scene scene;
    scene.beforeFix = "fix             integrate all nve/sphere";
    expectFailure("nve", scene, nullptr, "remove fix integrate (nve/sphere)", false);
}

TEST(FdmDEMErrors, MapArrayIsRequired)
{
    const std::string dir = workDir("map");
    Scene scene;
    writeInput(dir, scene);
    // rewrite the atom_modify line
    std::ifstream in((dir + "/in.dem").c_str());
    std::stringstream text;
    text << in.rdbuf();
    std::string s = text.str();
    s.replace(s.find("map array"), 9, "map hash");
    std::ofstream((dir + "/in.dem").c_str()) << s;
    const DemRun run = runDEM(dir);
    EXPECT_NE(run.status, 0);
    expectContains(run.output, "fix fdm/couple requires atom_modify map array");
}

TEST(FdmDEMErrors, UnknownKeyword)
{
    Scene scene;
    scene.fixOptions = "gravitation 0 0 -9.81";
    expectFailure("keyword", scene, nullptr, "fix fdm/couple: unknown keyword gravitation", false);
}

TEST(FdmDEMErrors, CoulombToleranceOutOfRange)
{
    Scene scene;
    scene.fixOptions = "coulomb_tolerance 2";
    expectFailure("coulomb-tolerance", scene, nullptr,
                  "fix fdm/couple: coulomb_tolerance (of the sliding contacts' forces) must be in (0, 1), got 2", false);
}

TEST(FdmDEMErrors, FluidEveryBelowOne)
{
    Scene scene;
    scene.fixOptions = "fluid_every 0";
    expectFailure("fluid-every", scene, nullptr,
                  "fix fdm/couple: fluid_every K needs K >= 1 particle steps per fluid step, got 0", false);
}

TEST(FdmDEMErrors, HeldDragUnknown)
{
    Scene scene;
    scene.fixOptions = "fluid_every 2 held_drag linear";
    expectFailure("held-drag", scene, nullptr,
                  "fix fdm/couple: held_drag must be constant or extrapolated, got linear", false);
}

TEST(FdmDEMErrors, BackgroundShearWithTheFluid)
{
    Scene scene;
    scene.fixOptions = "background_shear 1";
    expectFailure("background-shear", scene, nullptr, "fix fdm/couple: background_shear goes with transport none",
                  false);
}

TEST(FdmDEMErrors, ContactChordNotYesOrNo)
{
    Scene scene;
    scene.fixOptions = "contact_chord maybe";
    expectFailure("contact-chord", scene, nullptr, "fix fdm/couple: contact_chord must be yes or no", false);
}

TEST(FdmDEMErrors, FixOutputBadInput)
{
    // fix fdm/output (fix_fdm_output.h): the keywords, checked when the fix is defined
    Scene scene;
    scene.runs = "fix out all fdm/output records 10 p.records vtk 5\nrun 1";
    expectFailure("output-missing", scene, nullptr, "fix fdm/output: keyword vtk needs 2 values", false);
    scene.runs = "fix out all fdm/output records 0 p.records\nrun 1";
    expectFailure("output-zero", scene, nullptr, "fix fdm/output: records every 0 steps: must be 1 or more", false);
    scene.runs = "fix out all fdm/output\nrun 1";
    expectFailure("output-nothing", scene, nullptr, "fix fdm/output: nothing to write", false);
    scene.runs = "fix out all fdm/output records 1 p.records dump yes\nrun 1";
    expectFailure("output-keyword", scene, nullptr, "fix fdm/output: unknown keyword dump", false);
    scene.runs = "unfix couple\nfix out all fdm/output records 1 p.records\nrun 1";
    expectFailure("output-alone", scene, nullptr, "fix fdm/output needs fix fdm/couple", false);
    // a records file that cannot be created: named, and the fluid is told
    scene.runs = "fix out all fdm/output records 1 no-such-folder/p.records\nrun 1";
    expectFailure("output-unwritable", scene, nullptr, "cannot create the records file no-such-folder/p.records");
}

FDM_SCRATCH_CLEANUP("fdmDEMTest");

int main(int argc, char** argv)
{
    // mpirun refuses root unless told
    setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
    setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    ::testing::InitGoogleTest(&argc, argv);
    return RUN_ALL_TESTS();
}
