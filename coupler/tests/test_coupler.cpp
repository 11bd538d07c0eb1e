// Unit tests of the coupler: wire format, both transports, and every failure a user can meet.
#include "fdm/coupler.h"
#include "scratch.h"

#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

using namespace fdm::coupler;

namespace {

typedef std::chrono::steady_clock Clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string hostName()
{
    char host[256] = {0};
    gethostname(host, sizeof host - 1);
    return host;
}

std::string tempPath(const std::string& name)
{
    return fdm::testing::scratchPath("fdmCouplerTest", name);
}

FDM_SCRATCH_CLEANUP("fdmCouplerTest");

Message sample(uint64_t step = 12, uint32_t iteration = 3)
{
    Message m = makeMessage(MessageType::Integrals, step, iteration, 2, layout::integralsWidth, "dt=0.5 lastStep=9");
    for (size_t i = 0; i < m.data.size(); ++i) m.data[i] = 1.0 / (i + 1) - 0.25;
    return m;
}

// Expects `f` to throw a CouplerError whose text contains every one of `needles`.
template <class F> void expectCouplerError(F f, std::initializer_list<std::string> needles)
{
    try {
        f();
        ADD_FAILURE() << "no CouplerError";
    } catch (const CouplerError& e) {
        for (const std::string& n : needles)
            EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << "'" << n << "' not in: " << e.what();
    }
}

void put32(std::vector<unsigned char>& b, size_t at, uint32_t v)
{
    for (int i = 0; i < 4; ++i) b[at + i] = (v >> (8 * i)) & 0xff;
}
void put64(std::vector<unsigned char>& b, size_t at, uint64_t v)
{
    for (int i = 0; i < 8; ++i) b[at + i] = (v >> (8 * i)) & 0xff;
}

// A connected (fluid, dem) pair over a socket, the listener in a thread.
struct SocketPair {
    std::unique_ptr<Transport> fluid, dem;
    explicit SocketPair(Options o = Options(), const std::string& demRecord = "")
    {
        if (o.portFile.empty()) o.portFile = tempPath("port");
        Options f = o, d = o;
        d.recordFile = demRecord;
        f.name = "particle code";
        d.name = "fluid solver";
        std::thread t([&] { fluid = listen(f); });
        dem = connect(d);
        t.join();
    }
};

}  // namespace

// ---- message format ---------------------------------------------------------------------------------

TEST(Message, RoundTripIsBitExact)
{
    Message m = sample();
    m.data[1] = std::numeric_limits<double>::quiet_NaN();
    m.data[2] = -0.0;
    m.data[3] = std::numeric_limits<double>::denorm_min();
    const std::vector<unsigned char> bytes = encode(m);
    ASSERT_EQ(bytes.size(), headerSize + m.text.size() + 8 * m.data.size());
    EXPECT_EQ(0, std::memcmp(bytes.data(), "FDMC", 4));
    EXPECT_EQ(encodedSize(bytes.data()), bytes.size());
    const Message back = decode(bytes.data(), bytes.size());
    EXPECT_EQ(back.type, m.type);
    EXPECT_EQ(back.step, 12u);
    EXPECT_EQ(back.iteration, 3u);
    EXPECT_EQ(back.count, 2u);
    EXPECT_EQ(back.width, uint32_t(layout::integralsWidth));
    EXPECT_EQ(back.text, m.text);
    ASSERT_EQ(back.data.size(), m.data.size());
    EXPECT_EQ(0, std::memcmp(back.data.data(), m.data.data(), 8 * m.data.size()));
    EXPECT_DOUBLE_EQ(back.at(1, layout::iFx), m.at(1, layout::iFx));
}

TEST(Message, IsLittleEndianOnTheWire)
{
    Message m = makeMessage(MessageType::Step, 0x0102030405060708ULL, 7, 1, 1);
    m.data[0] = 1.0;  // 0x3ff0000000000000
    const std::vector<unsigned char> b = encode(m);
    EXPECT_EQ(b[4], protocolVersion & 0xff);
    EXPECT_EQ(b[6], 2);     // Step
    EXPECT_EQ(b[8], 0x08);  // step, least significant byte first
    EXPECT_EQ(b[15], 0x01);
    EXPECT_EQ(b[16], 7);    // iteration
    EXPECT_EQ(b[headerSize + 7], 0x3f);
    EXPECT_EQ(b[headerSize + 6], 0xf0);
}

TEST(Message, EmptyMessageRoundTrips)
{
    const Message m = makeMessage(MessageType::Finish, 5, 0, 0, 0);
    const std::vector<unsigned char> bytes = encode(m);
    EXPECT_EQ(bytes.size(), headerSize);
    const Message back = decode(bytes.data(), bytes.size());
    EXPECT_EQ(back.type, MessageType::Finish);
    EXPECT_TRUE(back.data.empty() && back.text.empty());
}

TEST(Message, TextValues)
{
    const Message m = makeMessage(MessageType::StepDone, 1, 4, 0, 0, "iterations=4 residual=1.5e-07 converged=1");
    EXPECT_EQ(m.textValue("converged"), "1");
    EXPECT_DOUBLE_EQ(m.textNumber("residual"), 1.5e-7);
    expectCouplerError([&] { m.textValue("iter"); }, {"StepDone", "'iter='"});
    const Message bad = makeMessage(MessageType::Step, 1, 0, 0, 0, "dt=abc");
    expectCouplerError([&] { bad.textNumber("dt"); }, {"dt=abc", "not a number"});
}

TEST(Message, LayoutOfProtocol4)
{
    EXPECT_EQ(protocolVersion, 4);
    EXPECT_EQ(layout::volumesWidth, 10);  // protocol 4: Vu, m1, J once per step ...
    EXPECT_EQ(layout::integralsWidth, 6);  // ... F, T every inner iteration
    EXPECT_EQ(uint16_t(MessageType::Volumes), 8);
    EXPECT_EQ(layout::helloDemWidth, 10u);
    EXPECT_EQ(layout::helloFluidWidth, 38u);
    EXPECT_EQ(layout::hfViscosity, 13);
    EXPECT_EQ(layout::hfFaceBase, 14);
    EXPECT_EQ(layout::faceWidth, 4u);
    EXPECT_EQ(layout::hfFaceBase + layout::nFaces * layout::faceWidth, layout::helloFluidWidth);
    EXPECT_EQ(layout::stepDoneWidth, 6);
    EXPECT_EQ(layout::dSxx, 6);
    EXPECT_EQ(layout::dSzz, 11);
    EXPECT_EQ(layout::dTrace, 12);
    EXPECT_EQ(layout::stepDoneStressWidth, 13);
}

TEST(Message, FluidHelloOfProtocol2RoundTrips)
{
    // Shear cell: cyclic in x and z, walls moving along x at ylo and yhi
    Message m = makeMessage(MessageType::Hello, 0, 0, 1, layout::helloFluidWidth,
                            "role=fluid version=" + std::to_string(protocolVersion));
    const double head[13] = {2, 0.0625, 1000, 0.25, 0, 6, 0, 4, 0, 4, 1, 0, 1};
    for (int i = 0; i < 13; ++i) m.data[i] = head[i];
    m.at(0, layout::hfViscosity) = 1e-3;
    const double wall[6][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}, {1, -0.5, 0, 0},
                               {1, 0.5, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}};
    for (uint32_t f = 0; f < layout::nFaces; ++f)
        for (uint32_t k = 0; k < layout::faceWidth; ++k)
            m.at(0, layout::hfFaceBase + layout::faceWidth * f + k) = wall[f][k];

    const std::vector<unsigned char> bytes = encode(m);
    ASSERT_EQ(bytes.size(), headerSize + m.text.size() + 8 * 38);
    EXPECT_EQ(bytes[24], 38);  // width, little-endian
    const Message back = decode(bytes.data(), bytes.size());
    EXPECT_EQ(back.type, MessageType::Hello);
    EXPECT_EQ(back.count, 1u);
    EXPECT_EQ(back.width, 38u);
    EXPECT_EQ(back.textNumber("version"), protocolVersion);
    EXPECT_EQ(back.data, m.data);
    EXPECT_EQ(back.at(0, 2), 1000);                      // the first 13 fields unchanged
    EXPECT_EQ(back.at(0, 12), 1);
    EXPECT_EQ(back.at(0, layout::hfViscosity), 1e-3);
    const uint32_t ylo = layout::hfFaceBase + 2 * layout::faceWidth;
    const uint32_t yhi = layout::hfFaceBase + 3 * layout::faceWidth;
    EXPECT_EQ(back.at(0, layout::hfFaceBase + layout::fKind), layout::bPeriodic);
    EXPECT_EQ(back.at(0, ylo + layout::fKind), layout::bWall);
    EXPECT_EQ(back.at(0, ylo + layout::fUx), -0.5);
    EXPECT_EQ(back.at(0, yhi + layout::fUx), 0.5);
    EXPECT_EQ(back.at(0, 37), 0);                        // zhi Uz, the last field
}

TEST(Message, StepDoneWithStressletsRoundTrips)
{
    Message m = makeMessage(MessageType::StepDone, 7, 12, 3, layout::stepDoneStressWidth,
                            "iterations=12 residual=1e-05 converged=1");
    for (size_t i = 0; i < m.data.size(); ++i) m.data[i] = 0.5 * i - 3;
    const std::vector<unsigned char> bytes = encode(m);
    const Message back = decode(bytes.data(), bytes.size());
    EXPECT_EQ(back.width, 13u);
    EXPECT_EQ(back.data, m.data);
    EXPECT_EQ(back.at(2, layout::dFx), 0.5 * 26 - 3);
    EXPECT_EQ(back.at(2, layout::dTrace), 0.5 * 38 - 3);
}

TEST(Message, BadMagicIsRejected)
{
    std::vector<unsigned char> bytes = encode(sample());
    bytes[0] = 'X';
    expectCouplerError([&] { decode(bytes.data(), bytes.size()); }, {"bad magic"});
}

TEST(Message, OtherProtocolVersionNamesBothVersions)
{
    std::vector<unsigned char> bytes = encode(sample());
    bytes[4] = protocolVersion + 1;
    expectCouplerError([&] { decode(bytes.data(), bytes.size()); },
                       {"version " + std::to_string(protocolVersion + 1), "version " + std::to_string(protocolVersion)});
}

TEST(Message, UnknownTypeIsRejected)
{
    std::vector<unsigned char> bytes = encode(sample());
    bytes[6] = 99;
    expectCouplerError([&] { decode(bytes.data(), bytes.size()); }, {"unknown type 99"});
}

TEST(Message, EveryTruncationIsRejected)
{
    const std::vector<unsigned char> bytes = encode(sample());
    for (size_t size = 0; size < bytes.size(); ++size)
        EXPECT_THROW(decode(bytes.data(), size), CouplerError) << size << " bytes";
    std::vector<unsigned char> longer = bytes;
    longer.push_back(0);
    EXPECT_THROW(decode(longer.data(), longer.size()), CouplerError);
}

TEST(Message, AbsurdSizesAreRejectedFromTheHeaderAlone)
{
    const std::vector<unsigned char> good = encode(sample());
    std::vector<unsigned char> h(good.begin(), good.begin() + headerSize);
    // self-consistent header announcing 2^31 records of 13 values (200 GiB)
    put32(h, 20, 1u << 31);
    put32(h, 24, 13);
    put64(h, 32, (uint64_t(1) << 31) * 13);
    expectCouplerError([&] { encodedSize(h.data()); }, {"absurd"});
    // inconsistent payload
    h.assign(good.begin(), good.begin() + headerSize);
    put64(h, 32, 17);
    EXPECT_THROW(encodedSize(h.data()), CouplerError);
    // absurd width, absurd text
    h.assign(good.begin(), good.begin() + headerSize);
    put32(h, 24, 100000);
    EXPECT_THROW(encodedSize(h.data()), CouplerError);
    h.assign(good.begin(), good.begin() + headerSize);
    put32(h, 28, 0xffffffffu);
    EXPECT_THROW(encodedSize(h.data()), CouplerError);
}

TEST(Message, InconsistentMessageIsNotEncoded)
{
    Message m = sample();
    m.data.pop_back();
    EXPECT_THROW(encode(m), CouplerError);
}

// ---- typed messages ---------------------------------------------------------------------------------

namespace {
// pack -> encode -> decode: what the peer gets
template <class T> Message overTheWire(const T& typed)
{
    const std::vector<unsigned char> bytes = encode(typed.toMessage());
    return decode(bytes.data(), bytes.size());
}
double value(int i) { return 1.0 / (i + 3) - 0.125 * i; }  // distinct, not round
}  // namespace

TEST(TypedMessages, DemHelloRoundTrips)
{
    DemHello h;
    h.dt = 0.0125;
    h.lastStep = 1234567;
    h.stresslets = true;
    h.nParticles = 8000;
    for (int d = 0; d < 3; ++d) {
        h.lo[d] = value(d);
        h.hi[d] = 10 + value(d + 3);
        h.periodic[d] = d != 1;
    }
    const Message m = overTheWire(h);
    EXPECT_EQ(m.type, MessageType::Hello);
    EXPECT_EQ(m.width, layout::helloDemWidth);
    EXPECT_EQ(m.textValue("role"), "dem");
    const DemHello b = DemHello::fromMessage(m);
    EXPECT_EQ(b.version, protocolVersion);
    EXPECT_EQ(b.dt, 0.0125);
    EXPECT_EQ(b.lastStep, 1234567);
    EXPECT_TRUE(b.stresslets);
    EXPECT_EQ(b.nParticles, 8000);
    for (int d = 0; d < 3; ++d) {
        EXPECT_EQ(b.lo[d], h.lo[d]);
        EXPECT_EQ(b.hi[d], h.hi[d]);
        EXPECT_EQ(b.periodic[d], h.periodic[d]);
    }
    h.stresslets = false;
    EXPECT_FALSE(DemHello::fromMessage(overTheWire(h)).stresslets);
}

TEST(TypedMessages, DemHelloReadsStressletsTolerantlyAndRequiresIt)
{
    Message m = DemHello().toMessage();
    for (const char* yes : {"1", "1.0", "yes", "TRUE", "on"}) {
        m.text = "role=dem version=" + std::to_string(protocolVersion) + " dt=1 lastStep=1 stresslets=" + yes;
        EXPECT_TRUE(DemHello::fromMessage(m).stresslets) << yes;
    }
    m.text = "role=dem version=" + std::to_string(protocolVersion) + " dt=1 lastStep=1 stresslets=off";
    EXPECT_FALSE(DemHello::fromMessage(m).stresslets);
    m.text = "role=dem version=" + std::to_string(protocolVersion) + " dt=1 lastStep=1";
    expectCouplerError([&] { DemHello::fromMessage(m); }, {"no stresslets= entry", "dt=1 lastStep=1"});
    m.text += " stresslets=2";
    expectCouplerError([&] { DemHello::fromMessage(m); }, {"stresslets=2", "not 0 or 1"});
    m.text = "role=dem version=1 dt=1 lastStep=1 stresslets=0";
    expectCouplerError([&] { DemHello::fromMessage(m); },
                       {"version mismatch", "version 1", "version " + std::to_string(protocolVersion)});
}

TEST(TypedMessages, FluidHelloRoundTrips)
{
    FluidHello h;
    h.nParticlesExpected = -1;
    h.alphaLambda = 0.0625;
    h.rhoFluid = 1000;
    h.delta = 0.25;
    h.viscosity = 1e-3;
    for (int d = 0; d < 3; ++d) {
        h.lo[d] = -value(d);
        h.hi[d] = 6 + value(d);
        h.periodic[d] = d != 1;
    }
    for (int f = 0; f < 6; ++f) {
        h.faces[f].kind = f / 2 == 1 ? layout::bWall : layout::bPeriodic;
        for (int d = 0; d < 3; ++d) h.faces[f].velocity[d] = f / 2 == 1 && d == 0 ? (f == 2 ? -0.5 : 0.5) : 0.0;
    }
    const Message m = overTheWire(h);
    EXPECT_EQ(m.width, layout::helloFluidWidth);
    EXPECT_EQ(m.at(0, layout::hfViscosity), 1e-3);                                          // the documented offsets
    EXPECT_EQ(m.at(0, layout::hfFaceBase + 3 * layout::faceWidth + layout::fUx), 0.5);    // yhi Ux
    const FluidHello b = FluidHello::fromMessage(m);
    EXPECT_EQ(b.nParticlesExpected, -1);
    EXPECT_EQ(b.alphaLambda, 0.0625);
    EXPECT_EQ(b.rhoFluid, 1000);
    EXPECT_EQ(b.delta, 0.25);
    EXPECT_EQ(b.viscosity, 1e-3);
    for (int d = 0; d < 3; ++d) {
        EXPECT_EQ(b.lo[d], h.lo[d]);
        EXPECT_EQ(b.hi[d], h.hi[d]);
        EXPECT_EQ(b.periodic[d], h.periodic[d]);
    }
    for (int f = 0; f < 6; ++f) {
        EXPECT_EQ(b.faces[f].kind, h.faces[f].kind);
        for (int d = 0; d < 3; ++d) EXPECT_EQ(b.faces[f].velocity[d], h.faces[f].velocity[d]);
    }
    Message bad = m;
    bad.at(0, layout::hfFaceBase + 4 * layout::faceWidth + layout::fKind) = 7;
    expectCouplerError([&] { FluidHello::fromMessage(bad); }, {"face zlo", "boundary kind 7"});
}

TEST(TypedMessages, StepRoundTrips)
{
    Step s;
    s.step = 42;
    s.dt = 0.05;
    s.lastStep = 100;
    for (int p = 0; p < 3; ++p) {
        StepParticle q;
        q.tag = p + 1;
        for (int d = 0; d < 3; ++d) {
            q.x[d] = value(10 * p + d);
            q.velocity.U[d] = value(10 * p + 3 + d);
            q.velocity.omega[d] = value(10 * p + 6 + d);
        }
        q.radius = 0.5 + p;
        s.particles.push_back(q);
    }
    const Message m = overTheWire(s);
    EXPECT_EQ(m.width, uint32_t(layout::stepWidth));
    EXPECT_EQ(m.at(2, layout::sRadius), 2.5);
    const Step b = Step::fromMessage(m, 3);
    EXPECT_EQ(b.step, 42u);
    EXPECT_EQ(b.dt, 0.05);
    EXPECT_EQ(b.lastStep, 100);
    ASSERT_EQ(b.particles.size(), 3u);
    for (int p = 0; p < 3; ++p) {
        EXPECT_EQ(b.particles[p].tag, p + 1);
        EXPECT_EQ(b.particles[p].radius, s.particles[p].radius);
        for (int d = 0; d < 3; ++d) {
            EXPECT_EQ(b.particles[p].x[d], s.particles[p].x[d]);
            EXPECT_EQ(b.particles[p].velocity.U[d], s.particles[p].velocity.U[d]);
            EXPECT_EQ(b.particles[p].velocity.omega[d], s.particles[p].velocity.omega[d]);
        }
    }
    // dt goes with 10 significant digits (as it always did)
    s.dt = 1.0 / 3.0;
    EXPECT_EQ(Step::fromMessage(overTheWire(s)).dt, 0.3333333333);
}

TEST(TypedMessages, VolumesRoundTrip)
{
    Volumes v;
    v.step = 7;
    for (int p = 0; p < 3; ++p) {
        ParticleVolume q;
        q.Vu = value(10 * p);
        for (int d = 0; d < 3; ++d) q.m1[d] = value(10 * p + 1 + d);
        for (int k = 0; k < 6; ++k) q.J[k] = value(10 * p + 4 + k);
        v.particles.push_back(q);
    }
    const Message m = overTheWire(v);
    EXPECT_EQ(m.type, MessageType::Volumes);
    EXPECT_EQ(m.width, uint32_t(layout::volumesWidth));
    EXPECT_EQ(m.at(2, layout::volM1y), value(22));
    EXPECT_EQ(m.at(2, layout::volJzz), value(29));
    const Volumes b = Volumes::fromMessage(m, 3);
    EXPECT_EQ(b.step, 7u);
    for (int p = 0; p < 3; ++p) {
        EXPECT_EQ(b.particles[p].Vu, v.particles[p].Vu);
        for (int d = 0; d < 3; ++d) EXPECT_EQ(b.particles[p].m1[d], v.particles[p].m1[d]);
        for (int k = 0; k < 6; ++k) EXPECT_EQ(b.particles[p].J[k], v.particles[p].J[k]);
        EXPECT_EQ(b.particles[p].isotropicJ(), (v.particles[p].J[0] + v.particles[p].J[3] + v.particles[p].J[5]) / 3);
    }
    expectCouplerError([&] { Volumes::fromMessage(m, 4); }, {"Volumes (step 7)", "3 records of 10 values", "4 records of 10"});
}

TEST(TypedMessages, IntegralsRoundTrip)
{
    Integrals in;
    in.step = 7;
    in.iteration = 3;
    for (int p = 0; p < 2; ++p) {
        ForceTorque q;
        for (int d = 0; d < 3; ++d) {
            q.F[d] = value(10 * p + d);
            q.T[d] = value(10 * p + 3 + d);
        }
        in.particles.push_back(q);
    }
    const Message m = overTheWire(in);
    EXPECT_EQ(m.type, MessageType::Integrals);
    EXPECT_EQ(m.width, uint32_t(layout::integralsWidth));
    const Integrals b = Integrals::fromMessage(m, 2);
    EXPECT_EQ(b.step, 7u);
    EXPECT_EQ(b.iteration, 3u);
    for (int p = 0; p < 2; ++p)
        for (int d = 0; d < 3; ++d) {
            EXPECT_EQ(b.particles[p].F[d], in.particles[p].F[d]);
            EXPECT_EQ(b.particles[p].T[d], in.particles[p].T[d]);
        }
}

TEST(TypedMessages, VelocitiesRoundTrip)
{
    Velocities v;
    v.step = 9;
    v.iteration = 12;
    for (int p = 0; p < 4; ++p) {
        RigidVelocity u;
        for (int d = 0; d < 3; ++d) {
            u.U[d] = value(6 * p + d);
            u.omega[d] = value(6 * p + 3 + d);
        }
        v.particles.push_back(u);
    }
    const Message m = overTheWire(v);
    EXPECT_EQ(m.width, uint32_t(layout::velocitiesWidth));
    EXPECT_EQ(m.at(3, layout::vWz), value(23));
    const Velocities b = Velocities::fromMessage(m, 4);
    EXPECT_EQ(b.step, 9u);
    EXPECT_EQ(b.iteration, 12u);
    for (int p = 0; p < 4; ++p)
        for (int d = 0; d < 3; ++d) {
            EXPECT_EQ(b.particles[p].U[d], v.particles[p].U[d]);
            EXPECT_EQ(b.particles[p].omega[d], v.particles[p].omega[d]);
        }
}

TEST(TypedMessages, StepDoneRoundTripsWithAndWithoutStresslets)
{
    StepDone s;
    s.step = 5;
    s.iterations = 17;
    s.residual = 1.0 / 3.0 * 1e-7;
    s.converged = false;
    for (int p = 0; p < 3; ++p) {
        ForceTorque f;
        Stresslet S;
        for (int d = 0; d < 3; ++d) {
            f.F[d] = value(13 * p + d);
            f.T[d] = value(13 * p + 3 + d);
        }
        for (int c = 0; c < 6; ++c) S.S[c] = value(13 * p + 6 + c);
        S.trace = value(13 * p + 12);
        s.forces.push_back(f);
        s.stresslets.push_back(S);
    }
    for (bool withStresslets : {true, false}) {
        if (!withStresslets) s.stresslets.clear();
        const Message m = overTheWire(s);
        EXPECT_EQ(m.width, withStresslets ? 13u : 6u);
        EXPECT_EQ(m.iteration, 17u);
        const StepDone b = StepDone::fromMessage(m, withStresslets, 3);
        EXPECT_EQ(b.step, 5u);
        EXPECT_EQ(b.iterations, 17u);
        EXPECT_EQ(b.residual, s.residual);  // all 17 digits
        EXPECT_FALSE(b.converged);
        ASSERT_EQ(b.forces.size(), 3u);
        ASSERT_EQ(b.stresslets.size(), withStresslets ? 3u : 0u);
        for (int p = 0; p < 3; ++p) {
            for (int d = 0; d < 3; ++d) {
                EXPECT_EQ(b.forces[p].F[d], s.forces[p].F[d]);
                EXPECT_EQ(b.forces[p].T[d], s.forces[p].T[d]);
            }
            if (!withStresslets) continue;
            for (int c = 0; c < 6; ++c) EXPECT_EQ(b.stresslets[p].S[c], s.stresslets[p].S[c]);
            EXPECT_EQ(b.stresslets[p].trace, s.stresslets[p].trace);
        }
        // the other width is refused, naming both
        expectCouplerError([&] { StepDone::fromMessage(m, !withStresslets, 3); },
                           {"StepDone", withStresslets ? "of 13 values" : "of 6 values",
                            withStresslets ? "of 6 were expected" : "of 13 were expected"});
    }
    s.stresslets.resize(1);  // stresslets for one particle of three
    expectCouplerError([&] { s.toMessage(); }, {"1 stresslets for 3 particles"});
}

TEST(TypedMessages, FinishAndErrorRoundTrip)
{
    Finish f;
    f.step = 77;
    const Message fm = overTheWire(f);
    EXPECT_EQ(fm.type, MessageType::Finish);
    EXPECT_EQ(Finish::fromMessage(fm).step, 77u);
    Error e;
    e.text = "fdmFoam: the pressure solver diverged";
    const Message em = overTheWire(e);
    EXPECT_EQ(em.type, MessageType::Error);
    EXPECT_EQ(Error::fromMessage(em).text, e.text);
}

TEST(TypedMessages, MalformedSizesAreRefusedNamingTheMessageAndTheSizes)
{
    // width: an Integrals record of 8 values (protocol 2's)
    Message m = makeMessage(MessageType::Integrals, 4, 2, 3, 8);
    expectCouplerError([&] { Integrals::fromMessage(m); },
                       {"Integrals (step 4, iteration 2)", "3 records of 8 values",
                        "of " + std::to_string(layout::integralsWidth) + " were expected"});
    // count: 2 particles where 3 were announced
    m = makeMessage(MessageType::Velocities, 4, 2, 2, layout::velocitiesWidth);
    expectCouplerError([&] { Velocities::fromMessage(m, 3); }, {"Velocities", "2 records of 6 values", "3 records of 6"});
    m = makeMessage(MessageType::Step, 1, 0, 2, layout::stepWidth, "dt=1 lastStep=2");
    expectCouplerError([&] { Step::fromMessage(m, 1); }, {"Step", "2 records", "1 records of 11"});
    // a Hello of another width, or of two records
    m = makeMessage(MessageType::Hello, 0, 0, 1, 14, "role=fluid version=" + std::to_string(protocolVersion));
    expectCouplerError([&] { FluidHello::fromMessage(m); }, {"Hello of the fluid solver", "1 records of 14 values", "38"});
    m = makeMessage(MessageType::Hello, 0, 0, 2, layout::helloDemWidth, "role=dem");
    expectCouplerError([&] { DemHello::fromMessage(m); }, {"Hello of fdmDEM", "2 records of 10 values"});
    // data that does not hold count x width values (a message built by hand)
    m = makeMessage(MessageType::Velocities, 1, 1, 2, layout::velocitiesWidth);
    m.data.pop_back();
    expectCouplerError([&] { Velocities::fromMessage(m); }, {"11 in all"});
    // a Finish with records, an Error with records
    expectCouplerError([&] { Finish::fromMessage(makeMessage(MessageType::Finish, 1, 0, 1, 1)); }, {"Finish"});
    expectCouplerError([&] { Error::fromMessage(makeMessage(MessageType::Error, 0, 0, 1, 2)); }, {"Error"});
    // another type altogether
    expectCouplerError([&] { Integrals::fromMessage(makeMessage(MessageType::StepDone, 3, 1, 0, 0)); },
                       {"expected Integrals, got StepDone"});
    // StepDone text
    m = makeMessage(MessageType::StepDone, 3, 1, 0, layout::stepDoneWidth, "iterations=1 residual=0 converged=maybe");
    expectCouplerError([&] { StepDone::fromMessage(m, false); }, {"converged=maybe"});
}

// ---- socket -----------------------------------------------------------------------------------------

TEST(Socket, PingPongOfAWholeTimeStep)
{
    SocketPair pair;
    EXPECT_NE(pair.dem->describe().find("socket 127.0.0.1:"), std::string::npos);
    pair.dem->send(makeMessage(MessageType::Hello, 0, 0, 1, layout::helloDemWidth, "role=dem version=3 stresslets=1"));
    EXPECT_EQ(pair.fluid->receive(MessageType::Hello).text, "role=dem version=3 stresslets=1");
    pair.dem->send(makeMessage(MessageType::Step, 1, 0, 2, layout::stepWidth));
    EXPECT_EQ(pair.fluid->receive(MessageType::Step).step, 1u);
    pair.fluid->send(makeMessage(MessageType::Volumes, 1, 0, 2, layout::volumesWidth));
    EXPECT_EQ(pair.dem->receive(MessageType::Volumes).width, uint32_t(layout::volumesWidth));
    for (uint32_t k = 1; k <= 5; ++k) {
        pair.fluid->send(sample(1, k));
        const Message in = pair.dem->receive(MessageType::Integrals);
        EXPECT_EQ(in.iteration, k);
        EXPECT_EQ(in.data, sample().data);
        Message v = makeMessage(MessageType::Velocities, 1, k, 2, layout::velocitiesWidth);
        v.data[0] = k;
        pair.dem->send(v);
        EXPECT_EQ(pair.fluid->receive(MessageType::Velocities).data[0], double(k));
    }
    pair.fluid->send(makeMessage(MessageType::StepDone, 1, 5, 2, layout::stepDoneStressWidth, "iterations=5"));
    const Message done = pair.dem->receive(MessageType::StepDone);
    EXPECT_EQ(done.iteration, 5u);
    EXPECT_EQ(done.width, 13u);
    pair.dem->send(makeMessage(MessageType::Finish, 1, 0, 0, 0));
    EXPECT_EQ(pair.fluid->receive().type, MessageType::Finish);
}

TEST(Socket, LargeMessageArrivesWhole)
{
    SocketPair pair;
    Message m = makeMessage(MessageType::Step, 3, 0, 200000, layout::stepWidth);  // 17.6 MB, > one chunk
    for (size_t i = 0; i < m.data.size(); ++i) m.data[i] = double(i);
    std::thread t([&] { pair.dem->send(m); });
    const Message got = pair.fluid->receive(MessageType::Step);
    t.join();
    EXPECT_EQ(got.data, m.data);
}

TEST(Socket, UnexpectedTypeNamesBothTypesAndThePeer)
{
    SocketPair pair;
    pair.fluid->send(makeMessage(MessageType::StepDone, 4, 2, 0, 0));
    expectCouplerError([&] { pair.dem->receive(MessageType::Integrals); },
                       {"expected Integrals", "fluid solver", "got StepDone", "step 4"});
}

TEST(Socket, ConnectorWaitsForThePortFile)
{
    Options o;
    o.portFile = tempPath("late");
    std::remove(o.portFile.c_str());
    o.connectTimeout = 10;
    std::unique_ptr<Transport> fluid, dem;
    std::thread t([&] { dem = connect(o); });  // starts first, polls for the port file
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    fluid = listen(o);
    t.join();
    dem->send(sample());
    EXPECT_EQ(fluid->receive().data, sample().data);
    struct stat st;
    EXPECT_NE(0, stat(o.portFile.c_str(), &st)) << "the port file outlived the listening socket";
}

TEST(Socket, FixedPortAndReuse)
{
    Options o;
    o.port = 0;
    {
        SocketPair first(o);
        first.dem->send(sample());
        first.fluid->receive();
    }
    // a fixed port can be listened on again at once (SO_REUSEADDR), by port number without a file
    Options fixed;
    fixed.port = 47000 + getpid() % 1000;
    fixed.connectTimeout = 5;
    for (int round = 0; round < 2; ++round) {
        std::unique_ptr<Transport> fluid, dem;
        std::thread t([&] { fluid = listen(fixed); });
        dem = connect(fixed);
        t.join();
        dem->send(sample());
        EXPECT_EQ(fluid->receive().step, 12u);
        fluid->close();  // the listener closes first: the port is left in TIME_WAIT
    }
}

TEST(Socket, PeerThatNeverConnects)
{
    Options o;
    o.portFile = tempPath("never");
    o.connectTimeout = 1;
    o.name = "particle code fdmDEM";
    Clock::time_point t0 = Clock::now();
    expectCouplerError([&] { listen(o); }, {"no peer connected", "within 1 s", "particle code fdmDEM"});
    EXPECT_LT(since(t0), 2.0);
    EXPECT_GT(since(t0), 0.9);
    o.name = "fluid solver";
    t0 = Clock::now();
    expectCouplerError([&] { connect(o); }, {"could not connect to the fluid solver", "within 1 s", "port file"});
    EXPECT_LT(since(t0), 2.0);
    Options byPort;
    byPort.port = 1;  // nobody listens there
    byPort.connectTimeout = 0.5;
    t0 = Clock::now();
    expectCouplerError([&] { connect(byPort); }, {"127.0.0.1:1", "refused"});
    EXPECT_LT(since(t0), 1.5);
}

TEST(Socket, PeerProcessThatDiesIsDetectedAtOnce)
{
    Options o;
    o.portFile = tempPath("dies");
    std::remove(o.portFile.c_str());
    o.receiveTimeout = 60;
    o.name = "particle code";
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {  // the peer: connects, says hello, dies without closing anything
        try {
            std::unique_ptr<Transport> dem = connect(o);
            dem->send(makeMessage(MessageType::Hello, 0, 0, 0, 0, "role=dem"));
            std::this_thread::sleep_for(std::chrono::milliseconds(200));
        } catch (...) {
        }
        ::kill(getpid(), SIGKILL);  // never returns into the test runner
    }
    std::unique_ptr<Transport> fluid = listen(o);
    EXPECT_EQ(fluid->receive().type, MessageType::Hello);
    const Clock::time_point t0 = Clock::now();
    expectCouplerError([&] { fluid->receive(); },
                       {"the particle code closed the connection (did it crash? see its log)"});
    EXPECT_LT(since(t0), 1.0);
    waitpid(child, nullptr, 0);
    // sending to it fails too (EPIPE, not SIGPIPE: we are still alive to check)
    EXPECT_THROW({ for (int i = 0; i < 100; ++i) fluid->send(sample()); }, CouplerError);
}

TEST(Socket, SilentPeerTimesOut)
{
    Options o;
    o.receiveTimeout = 0.5;
    SocketPair pair(o);
    pair.dem->send(sample());
    pair.fluid->receive();  // handshake done: from now on receiveTimeout applies
    const Clock::time_point t0 = Clock::now();
    expectCouplerError([&] { pair.fluid->receive(); }, {"sent nothing for 0.5 s", "hung"});
    EXPECT_LT(since(t0), 1.5);
}

TEST(Socket, HandshakeIsBoundedByTheConnectTimeout)
{
    Options o;
    o.connectTimeout = 0.5;
    o.receiveTimeout = 100;
    SocketPair pair(o);
    const Clock::time_point t0 = Clock::now();
    expectCouplerError([&] { pair.fluid->receive(); }, {"did not complete the handshake", "0.5 s"});
    EXPECT_LT(since(t0), 1.5);
}

TEST(Socket, ErrorMessageCarriesItsText)
{
    SocketPair pair;
    pair.dem->sendError("particle 7 overlaps particle 9");
    expectCouplerError([&] { pair.fluid->receive(MessageType::Step); },
                       {"the particle code stopped: particle 7 overlaps particle 9"});
}

namespace {
// The listening side, and a raw TCP client that is not an fdm coupler: returns its socket.
int listenWithRawClient(const std::string& portFile, std::unique_ptr<Transport>& fluid)
{
    Options o;
    o.portFile = portFile;
    o.name = "particle code";
    std::remove(portFile.c_str());
    std::thread t([&] { fluid = listen(o); });
    int fd = -1;
    for (int attempt = 0; attempt < 200 && fd < 0; ++attempt) {
        std::ifstream in(portFile.c_str());
        int port = 0;
        if (in >> port) {
            fd = socket(AF_INET, SOCK_STREAM, 0);
            sockaddr_in a;
            std::memset(&a, 0, sizeof a);
            a.sin_family = AF_INET;
            a.sin_port = htons(uint16_t(port));
            inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
            if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) { ::close(fd); fd = -1; }
        }
        if (fd < 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    t.join();
    return fd;
}
}  // namespace

TEST(Socket, GarbageFromThePeerIsAnErrorNotACrash)
{
    std::unique_ptr<Transport> fluid;
    const int fd = listenWithRawClient(tempPath("garbage"), fluid);
    ASSERT_GE(fd, 0);
    const char http[] = "GET / HTTP/1.1\r\nHost: localhost\r\n\r\n and some more bytes";
    ASSERT_GT(::send(fd, http, sizeof http, 0), 0);
    expectCouplerError([&] { fluid->receive(); }, {"bad magic"});
    ::close(fd);
}

TEST(Socket, LyingHeaderThenDeathGivesAnErrorAtOnce)
{
    // A valid header announcing 2^24 values (128 MiB) of which only a few come before the peer dies:
    // the reader must report the end of the stream at once (and not wait for, or allocate, the rest).
    std::unique_ptr<Transport> fluid;
    const int fd = listenWithRawClient(tempPath("lying"), fluid);
    ASSERT_GE(fd, 0);
    const std::vector<unsigned char> good = encode(sample());
    std::vector<unsigned char> h(good.begin(), good.begin() + headerSize);
    put32(h, 20, 1u << 21);
    put32(h, 24, 8);
    put32(h, 28, 0);
    put64(h, 32, uint64_t(1) << 24);
    h.resize(headerSize + 800, 0);
    ASSERT_EQ(::send(fd, h.data(), h.size(), 0), ssize_t(h.size()));
    ::close(fd);
    const Clock::time_point t0 = Clock::now();
    expectCouplerError([&] { fluid->receive(); }, {"closed the connection"});
    EXPECT_LT(since(t0), 1.0);
}

TEST(Socket, SendAfterCloseIsAnError)
{
    SocketPair pair;
    pair.dem->close();
    EXPECT_THROW(pair.dem->send(sample()), CouplerError);
    EXPECT_THROW(pair.dem->receive(), CouplerError);
    pair.dem->sendError("never thrown");  // best effort, noexcept
}

// ---- file transport ---------------------------------------------------------------------------------

namespace {
struct FilePair {
    std::unique_ptr<Transport> fluid, dem;
    FilePair(Options o, const std::string& demRecord = "")
    {
        o.transport = "file";
        Options d = o;
        d.recordFile = demRecord;
        std::thread t([&] { fluid = listen(o); });
        dem = connect(d);
        t.join();
    }
};
size_t countMessages(const std::string& record)
{
    std::ifstream in(record.c_str(), std::ios::binary);
    std::vector<unsigned char> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    size_t at = 0, n = 0;
    while (at + headerSize <= b.size()) {
        at += encodedSize(&b[at]);
        ++n;
    }
    EXPECT_EQ(at, b.size());
    return n;
}
}  // namespace

TEST(File, RoundTripAndRecord)
{
    Options o;
    o.directory = tempPath("dir");
    o.connectTimeout = 5;
    o.receiveTimeout = 0.5;
    const std::string record = tempPath("record");
    std::remove(record.c_str());
    FilePair pair(o, record);
    EXPECT_NE(pair.dem->describe().find("file"), std::string::npos);
    pair.dem->send(sample());
    EXPECT_EQ(pair.fluid->receive().data, sample().data);
    for (uint32_t k = 1; k <= 3; ++k) {
        pair.fluid->send(sample(12, k));
        EXPECT_EQ(pair.dem->receive(MessageType::Integrals).iteration, k);
        pair.dem->send(makeMessage(MessageType::Velocities, 12, k, 2, layout::velocitiesWidth));
        EXPECT_EQ(pair.fluid->receive(MessageType::Velocities).iteration, k);
    }
    pair.fluid->send(makeMessage(MessageType::StepDone, 12, 3, 0, 0, "iterations=3"));
    EXPECT_EQ(pair.dem->receive().text, "iterations=3");
    const Clock::time_point t0 = Clock::now();
    expectCouplerError([&] { pair.dem->receive(); }, {"sent nothing for 0.5 s"});
    EXPECT_LT(since(t0), 1.5);
    EXPECT_EQ(countMessages(record), 1u + 3 * 2 + 1);  // every message sent and received, in order
    struct stat st;
    EXPECT_EQ(0, stat((o.directory + "/00000004.dem.msg").c_str(), &st));  // kept on disk for replay
}

TEST(File, StaleMessagesOfAnEarlierRunAreIgnored)
{
    Options o;
    o.directory = tempPath("stale");
    o.connectTimeout = 5;
    {
        FilePair old(o);
        old.dem->send(makeMessage(MessageType::Hello, 0, 0, 0, 0, "role=dem old"));
        old.fluid->send(makeMessage(MessageType::Hello, 0, 0, 0, 0, "role=fluid old"));
    }
    // the processes of the earlier run are gone: their session files name a pid that has exited
    const pid_t gone = fork();
    if (gone == 0) _exit(0);
    waitpid(gone, nullptr, 0);
    for (const char* side : {"fluid", "dem"}) {
        const std::string path = o.directory + "/" + side + ".session";
        std::ifstream in(path.c_str());
        std::string id;
        in >> id;
        std::ofstream(path.c_str()) << id << " pid=" << gone << " host=" << hostName() << "\n";
    }
    FilePair fresh(o);
    fresh.dem->send(makeMessage(MessageType::Hello, 0, 0, 0, 0, "role=dem new"));
    EXPECT_EQ(fresh.fluid->receive().text, "role=dem new");
    fresh.fluid->send(makeMessage(MessageType::Hello, 0, 0, 0, 0, "role=fluid new"));
    EXPECT_EQ(fresh.dem->receive().text, "role=fluid new");
}

TEST(File, ConnectorThatJoinedAStaleSessionFollowsTheNewListener)
{
    Options o;
    o.directory = tempPath("late");
    o.connectTimeout = 5;
    o.transport = "file";
    // a stale session file whose writer looks alive (our own pid): the connector joins it
    ::mkdir(o.directory.c_str(), 0755);
    std::ofstream((o.directory + "/fluid.session").c_str())
        << "session=stale pid=" << getpid() << " host=" << hostName() << "\n";
    std::unique_ptr<Transport> dem = connect(o), fluid;
    dem->send(makeMessage(MessageType::Hello, 0, 0, 0, 0, "role=dem"));
    std::thread t([&] {
        fluid = listen(o);  // cleans the directory, the Hello with it
        fluid->send(makeMessage(MessageType::Hello, 0, 0, 0, 0, "role=fluid"));
    });
    EXPECT_EQ(dem->receive(MessageType::Hello).text, "role=fluid");
    t.join();
    EXPECT_EQ(fluid->receive(MessageType::Hello).text, "role=dem");  // sent again in the new session
}

TEST(File, PeerProcessThatDiesIsDetected)
{
    Options o;
    o.transport = "file";
    o.directory = tempPath("dies");
    o.connectTimeout = 5;
    o.receiveTimeout = 60;
    o.name = "particle code";
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        try {
            std::unique_ptr<Transport> dem = connect(o);
            dem->send(makeMessage(MessageType::Hello, 0, 0, 0, 0, "role=dem"));
        } catch (...) {
        }
        ::kill(getpid(), SIGKILL);  // never returns into the test runner
    }
    std::unique_ptr<Transport> fluid = listen(o);
    EXPECT_EQ(fluid->receive().type, MessageType::Hello);
    waitpid(child, nullptr, 0);
    const Clock::time_point t0 = Clock::now();
    expectCouplerError([&] { fluid->receive(); }, {"particle code closed the connection"});
    EXPECT_LT(since(t0), 1.0);
}

TEST(File, PeerThatNeverJoins)
{
    Options o;
    o.transport = "file";
    o.directory = tempPath("never");
    o.connectTimeout = 0.5;
    Clock::time_point t0 = Clock::now();
    expectCouplerError([&] { listen(o); }, {"no peer joined", o.directory, "0.5 s"});
    EXPECT_LT(since(t0), 1.5);
    std::remove((o.directory + "/fluid.session").c_str());
    t0 = Clock::now();
    expectCouplerError([&] { connect(o); }, {"did not open the coupling directory"});
    EXPECT_LT(since(t0), 1.5);
}

TEST(Transport, UnknownTransportIsNamed)
{
    Options o;
    o.transport = "pigeon";
    expectCouplerError([&] { listen(o); }, {"pigeon"});
}

// ---- replay tool ------------------------------------------------------------------------------------

TEST(Dump, PrintsARecordAndRejectsACorruptOne)
{
    const std::string record = tempPath("dump.record");
    std::remove(record.c_str());
    {
        SocketPair pair(Options(), record);
        pair.dem->send(makeMessage(MessageType::Hello, 0, 0, 1, layout::helloDemWidth, "role=dem version=3 stresslets=1"));
        pair.fluid->receive();
        pair.fluid->send(makeMessage(MessageType::Volumes, 12, 0, 2, layout::volumesWidth));
        pair.dem->receive();
        pair.fluid->send(sample(12, 3));
        pair.dem->receive();
    }
    const std::string command = std::string(FDM_COUPLER_DUMP) + " " + record + " 2>&1";
    FILE* p = popen(command.c_str(), "r");
    ASSERT_TRUE(p != nullptr);
    std::string out;
    char buf[512];
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    EXPECT_EQ(0, WEXITSTATUS(pclose(p))) << out;
    EXPECT_NE(out.find("dem -> fluid Hello"), std::string::npos) << out;
    EXPECT_NE(out.find("fluid -> dem   Integrals  step 12 iteration 3"), std::string::npos) << out;
    EXPECT_NE(out.find("0.75"), std::string::npos) << out;  // 1/1 - 0.25, first value
    EXPECT_NE(out.find("fluid -> dem   Volumes    step 12 iteration 0  2 x 10"), std::string::npos) << out;
    EXPECT_NE(out.find("3 messages"), std::string::npos) << out;

    {
        std::ofstream f(record.c_str(), std::ios::app | std::ios::binary);
        f << "FDMC garbage";
    }
    p = popen(command.c_str(), "r");
    out.clear();
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    EXPECT_NE(0, WEXITSTATUS(pclose(p)));
    EXPECT_NE(out.find("(message 4): truncated"), std::string::npos) << out;
}
