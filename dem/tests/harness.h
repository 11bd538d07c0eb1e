// The test harness of the particle side: writes a LIGGGHTS input, runs the real fdmDEM (serial or
// mpirun) as a child process, and plays the fluid solver's part of the coupling protocol with
// scripted volumes and integrals (a harness for the particle side, not a fluid solver).
#ifndef FDM_DEM_TEST_HARNESS_H
#define FDM_DEM_TEST_HARNESS_H

#include "fdm/coupler.h"
#include "scratch.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <memory>
#include <netinet/in.h>
#include <sstream>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace cpl = fdm::coupler;

namespace {


const double pi = 3.14159265358979323846;

std::string workDir(const std::string& name)
{
    const std::string dir = fdm::testing::scratchPath("fdmDEMTest", name);
    ::mkdir(dir.c_str(), 0755);
    return dir;
}

// ---- the LIGGGHTS input ---------------------------------------------------------------------------

// Eq. (31)'s rigid-body block of a particle, (rho_f/alpha) [[Vu 1, -[m1]x], [[m1]x, J]]
// (particle_velocity_system.h, RigidVolume)
inline Eigen::Matrix<double, 6, 6> rigidBlock(const cpl::ParticleVolume& v, double rhoFluid, double alpha)
{
    const double J[3][3] = {{v.J[0], v.J[1], v.J[2]}, {v.J[1], v.J[3], v.J[4]}, {v.J[2], v.J[4], v.J[5]}};
    const double c[3][3] = {{0, -v.m1[2], v.m1[1]}, {v.m1[2], 0, -v.m1[0]}, {-v.m1[1], v.m1[0], 0}};
    Eigen::Matrix<double, 6, 6> B;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            B(i, j) = i == j ? v.Vu : 0.0;
            B(i, 3 + j) = -c[i][j];
            B(3 + i, j) = c[i][j];
            B(3 + i, 3 + j) = J[i][j];
        }
    return rhoFluid / alpha * B;
}

struct Sphere {
    double x, y, z, radius, density;
};

struct Scene {
    std::string boundary = "p p p";
    double lo[3] = {0, 0, 0}, hi[3] = {8, 8, 8};
    std::vector<Sphere> spheres = {{2.0, 3.0, 4.0, 0.5, 2500.0}, {6.0, 5.0, 3.5, 0.7, 1500.0},
                                   {5.5, 1.5, 6.5, 0.4, 4000.0}};
    double dt = 0.01;
    std::string beforeFix;   // lines before the fix (fix addforce, dump, ...)
    std::string fixOptions;  // extra fdm/couple keywords
    std::string runs = "run 2";
    std::string pairStyle = "none";  // e.g. "fdm/subgrid contact 100 80 0.5 0.01"
    std::string transport = "portfile coupling.port";
};

void writeInput(const std::string& dir, const Scene& s)
{
    std::ofstream in((dir + "/in.dem").c_str());
    in.precision(17);
    in << "atom_style      sphere\n"
          "atom_modify     map array sort 0 0.0\n"
          "boundary        " << s.boundary << "\n"
          "newton          off\n"
          "communicate     single vel yes\n"
          "units           si\n"
          "region          box block " << s.lo[0] << " " << s.hi[0] << " " << s.lo[1] << " " << s.hi[1] << " "
       << s.lo[2] << " " << s.hi[2] << " units box\n"
          "create_box      1 box\n";
    for (const Sphere& p : s.spheres) in << "create_atoms    1 single " << p.x << " " << p.y << " " << p.z << " units box\n";
    for (size_t i = 0; i < s.spheres.size(); ++i)
        in << "set             atom " << i + 1 << " diameter " << 2 * s.spheres[i].radius << " density "
           << s.spheres[i].density << "\n";
    in << "pair_style      " << s.pairStyle << "\n"
       << (s.pairStyle == "none" ? "" : "pair_coeff      * *\n")
       << "neighbor        0.1 bin\n"
          "timestep        " << s.dt << "\n"
       << s.beforeFix << "\n"
       << "fix             couple all fdm/couple " << s.transport << " connect_timeout 5 timeout 10 " << s.fixOptions
       << "\n" << s.runs << "\n";
}

// ---- running fdmDEM ---------------------------------------------------------------------------------

struct DemRun {
    int status;
    std::string output;
    double seconds;
};

DemRun runDEM(const std::string& dir, int ranks = 1)
{
    std::string command = "cd '" + dir + "' && timeout -k 5 60 ";
    if (ranks > 1) command += std::string(FDM_MPIEXEC) + " -np " + std::to_string(ranks) + " --oversubscribe ";
    command += std::string(FDM_DEM_EXE) + " -in in.dem 2>&1";
    const auto t0 = std::chrono::steady_clock::now();
    FILE* p = popen(command.c_str(), "r");
    std::string out;
    char buf[4096];
    while (p && std::fgets(buf, sizeof buf, p)) out += buf;
    const int status = p ? pclose(p) : -1;
    DemRun r;
    r.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.output = out;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
}

// ---- the scripted fluid peer ------------------------------------------------------------------------

struct FakeFluid {
    enum Mode { Normal, DieAfterStep, ErrorAfterStep, WrongTypeAfterStep, ZeroVolume, NaNIntegral, ShortVolumes };
    Mode mode = Normal;
    cpl::Options options;
    long nExpected = -1;
    double alphaLambda = 0.25, rhoFluid = 1000.0, delta = 0.2, viscosity = 0.16;
    double box[6] = {0, 8, 0, 8, 0, 8};
    int periodic[3] = {1, 1, 1};
    // Each non-periodic face: kind (1 = no-slip wall, 2 = slip, 3 = other) and wall velocity.
    int faceKind[6] = {1, 1, 1, 1, 1, 1};
    double faceVelocity[6][3] = {{0}};
    uint32_t iterations = 3;

    // what happened
    cpl::DemHello demHello;
    std::vector<cpl::Step> steps;
    std::vector<cpl::Volumes> volumes;       // one per step
    std::vector<cpl::Integrals> integrals;   // one per inner iteration
    std::vector<cpl::Velocities> velocities;
    std::vector<cpl::StepDone> stepDones;
    bool finished = false;
    std::string error;
    std::thread thread;

    explicit FakeFluid(const std::string& dir)
    {
        options.portFile = dir + "/coupling.port";
        options.name = "particle code fdmDEM";
        options.connectTimeout = 15;
        options.receiveTimeout = 15;
        std::remove(options.portFile.c_str());
    }
    ~FakeFluid()
    {
        if (thread.joinable()) thread.join();
    }
    void start()
    {
        thread = std::thread([this] {
            try {
                run();
            } catch (const std::exception& e) {
                error = e.what();
            }
        });
    }
    void join() { thread.join(); }

    // Deterministic, particle- and step-dependent volumes and particle- and iteration-dependent
    // integrals (all SI).
    static double volume(double a) { return 4.0 / 3.0 * pi * a * a * a; }
    cpl::Volumes makeVolumes(const cpl::Step& step) const
    {
        cpl::Volumes m;
        m.step = step.step;
        m.particles.resize(step.particles.size());
        for (size_t p = 0; p < step.particles.size(); ++p) {
            const double a = step.particles[p].radius;
            // a discrete sphere off the mesh's symmetry points: a small first moment and an anisotropic
            // inertia tensor, so that Eq. (31)'s whole rigid-body block is exercised
            cpl::ParticleVolume& v = m.particles[p];
            v.Vu = volume(a) * (1.0 + 0.01 * double(step.step));
            const double m1[3] = {0.02, -0.01, 0.005}, J[6] = {0.41, 0.004, -0.002, 0.39, 0.003, 0.40};
            for (int d = 0; d < 3; ++d) v.m1[d] = m1[d] * a * v.Vu;
            for (int k = 0; k < 6; ++k) v.J[k] = J[k] * a * a * v.Vu;
        }
        if (mode == ZeroVolume) m.particles[1].Vu = 0.0;
        if (mode == ShortVolumes) m.particles.pop_back();
        return m;
    }
    cpl::Integrals makeIntegrals(const cpl::Step& step, uint32_t k) const
    {
        cpl::Integrals m;
        m.step = step.step;
        m.iteration = k;
        m.particles.resize(step.particles.size());
        for (size_t p = 0; p < step.particles.size(); ++p)
            for (int d = 0; d < 3; ++d) {
                m.particles[p].F[d] = 0.1 * (p + 1) * (d + 1) * k - 0.3 + 0.01 * double(step.step);
                m.particles[p].T[d] = 0.02 * (p + 2) * (3 - d) - 0.05 * k;
            }
        if (mode == NaNIntegral && k == 2) m.particles[2].F[1] = std::nan("");
        return m;
    }
    // The Volumes of the step an Integrals or Velocities message belongs to.
    const cpl::ParticleVolume& volumeOf(uint64_t step, size_t particle) const
    {
        for (const cpl::Volumes& v : volumes)
            if (v.step == step) return v.particles.at(particle);
        throw std::runtime_error("harness: no Volumes of step " + std::to_string(step));
    }
    static double hydro(uint32_t p, int c, uint64_t step) { return 10.0 * (p + 1) + c + 0.5 * double(step); }

    void run()
    {
        std::unique_ptr<cpl::Transport> t = cpl::listen(options);
        demHello = cpl::DemHello::fromMessage(t->receive(cpl::MessageType::Hello));
        cpl::FluidHello hello;
        hello.nParticlesExpected = nExpected;
        hello.alphaLambda = alphaLambda;
        hello.rhoFluid = rhoFluid;
        hello.delta = delta;
        hello.viscosity = viscosity;
        for (int d = 0; d < 3; ++d) {
            hello.lo[d] = box[2 * d];
            hello.hi[d] = box[2 * d + 1];
            hello.periodic[d] = periodic[d] != 0;
        }
        for (int f = 0; f < 6; ++f) {
            hello.faces[f].kind = periodic[f / 2] ? cpl::layout::bPeriodic : faceKind[f];
            for (int d = 0; d < 3; ++d) hello.faces[f].velocity[d] = periodic[f / 2] ? 0.0 : faceVelocity[f][d];
        }
        t->send(hello.toMessage());
        while (true) {
            cpl::Message m = t->receive();
            if (m.type == cpl::MessageType::Finish) {
                finished = true;
                return;
            }
            if (m.type != cpl::MessageType::Step) throw cpl::CouplerError("harness: got " + std::string(cpl::messageTypeName(m.type)));
            steps.push_back(cpl::Step::fromMessage(m));
            const cpl::Step& step = steps.back();
            if (mode == DieAfterStep) return;  // t goes out of scope: the socket closes as on a crash
            if (mode == ErrorAfterStep) {
                t->sendError("fdmFoam: the pressure solver diverged at step " + std::to_string(step.step));
                return;
            }
            if (mode == WrongTypeAfterStep) {
                t->send(cpl::makeMessage(cpl::MessageType::Velocities, step.step, 1, m.count, 6));
                t->receive();  // the DEM's Error
                return;
            }
            volumes.push_back(makeVolumes(step));  // protocol 3: once per step, before the first Integrals
            t->send(volumes.back().toMessage());
            if (mode == ShortVolumes) {
                t->receive();  // the DEM's Error
                return;
            }
            for (uint32_t k = 1; k <= iterations; ++k) {
                integrals.push_back(makeIntegrals(step, k));
                t->send(integrals.back().toMessage());
                velocities.push_back(cpl::Velocities::fromMessage(t->receive(cpl::MessageType::Velocities)));
            }
            cpl::StepDone done;
            done.step = step.step;
            done.iterations = iterations;
            done.residual = 1.25e-07;
            done.converged = true;
            done.forces.resize(step.particles.size());
            if (demHello.stresslets) done.stresslets.resize(step.particles.size());
            for (uint32_t p = 0; p < step.particles.size(); ++p) {
                for (int d = 0; d < 3; ++d) {
                    done.forces[p].F[d] = hydro(p, d, step.step);
                    done.forces[p].T[d] = hydro(p, 3 + d, step.step);
                }
                if (!demHello.stresslets) continue;
                for (int c = 0; c < 6; ++c) done.stresslets[p].S[c] = hydro(p, 6 + c, step.step);
                done.stresslets[p].trace = hydro(p, 12, step.step);
            }
            stepDones.push_back(done);
            t->send(done.toMessage());
        }
    }
};

// The velocities of a message as one vector of 6N: (U, Omega) per particle.
std::vector<double> flat(const cpl::Velocities& v)
{
    std::vector<double> u;
    for (const cpl::RigidVelocity& p : v.particles) {
        u.insert(u.end(), p.U, p.U + 3);
        u.insert(u.end(), p.omega, p.omega + 3);
    }
    return u;
}

void expectContains(const std::string& text, const std::string& needle)
{
    EXPECT_NE(text.find(needle), std::string::npos) << "'" << needle << "' not in:\n" << text;
}

double relativeDifference(double a, double b) { return std::fabs(a - b) / std::max(1e-300, std::max(std::fabs(a), std::fabs(b))); }

// Writes the scene's input into dir, runs fdmDEM (serial or on `ranks` ranks) against `fluid`, set up
// by the caller, and waits for both.
DemRun runWithFluid(const std::string& dir, const Scene& scene, FakeFluid& fluid, int ranks = 1)
{
    writeInput(dir, scene);
    fluid.start();
    const DemRun run = runDEM(dir, ranks);
    fluid.join();
    return run;
}

// Runs a scene expected to fail; returns the run, checks status and duration, and that the fluid
// peer (if any) was told why.
DemRun expectFailure(const std::string& name, const Scene& scene, std::function<void(FakeFluid&)> setup,
                  const std::string& needle, bool withFluid = true, double within = 10.0, int ranks = 1)
{
    const std::string dir = workDir(name);
    std::unique_ptr<FakeFluid> fluid;
    DemRun run;
    if (withFluid) {
        fluid.reset(new FakeFluid(dir));
        if (setup) setup(*fluid);
        run = runWithFluid(dir, scene, *fluid, ranks);
    } else {
        writeInput(dir, scene);
        run = runDEM(dir, ranks);
    }
    EXPECT_NE(run.status, 0) << run.output;
    EXPECT_NE(run.status, 124) << "timed out:\n" << run.output;
    expectContains(run.output, "ERROR");
    expectContains(run.output, needle);
    EXPECT_LT(run.seconds, within) << run.output;
    if (fluid && fluid->mode == FakeFluid::Normal) expectContains(fluid->error, needle);  // the peer was told
    return run;
}

// Runs the scene serially and on two ranks against FakeFluid and expects every message the fluid
// received (velocities and step records) to agree within |a - b| <= relative max(|a|, |b|) + absolute;
// twoRankNeedle shows that the two-rank run split what it should.
void expectSameRunOnOneAndTwoRanks(const std::string& name, const Scene& scene, const std::string& twoRankNeedle,
                                   double relative, double absolute)
{
    std::vector<cpl::Message> results[2];
    for (int ranks = 1; ranks <= 2; ++ranks) {
        const std::string dir = workDir(name + "np" + std::to_string(ranks));
        FakeFluid fluid(dir);
        const DemRun run = runWithFluid(dir, scene, fluid, ranks);
        ASSERT_EQ(run.status, 0) << run.output;
        if (ranks == 2) expectContains(run.output, twoRankNeedle);
        for (const cpl::Velocities& v : fluid.velocities) results[ranks - 1].push_back(v.toMessage());
        for (const cpl::Step& s : fluid.steps) results[ranks - 1].push_back(s.toMessage());
    }
    ASSERT_EQ(results[0].size(), results[1].size());
    for (size_t m = 0; m < results[0].size(); ++m) {
        ASSERT_EQ(results[0][m].data.size(), results[1][m].data.size());
        for (size_t k = 0; k < results[0][m].data.size(); ++k) {
            const double a = results[0][m].data[k], b = results[1][m].data[k];
            EXPECT_LE(std::fabs(a - b), relative * std::max(std::fabs(a), std::fabs(b)) + absolute)
                << cpl::messageTypeName(results[0][m].type) << " " << m << " value " << k << ": " << a << " vs " << b;
        }
    }
}

}  // namespace

#endif
