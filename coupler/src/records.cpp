// The typed messages of the fdm coupler (coupler.h): the one place where records are packed and
// unpacked with the layouts of fdm::coupler::layout.
#include "fdm/coupler.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace fdm {
namespace coupler {

namespace {

// dt goes with 10 significant digits, as protocols 1 and 2 always sent it (the fluid's time step
// is the rounded value; more digits would change every result in its last digits).
std::string tenDigits(double x)
{
    std::ostringstream os;
    os.precision(10);
    os << x;
    return os.str();
}

std::string allDigits(double x)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", x);
    return buf;
}

std::string where(const Message& m)
{
    return " (step " + std::to_string(m.step) + ", iteration " + std::to_string(m.iteration) + ")";
}

// Type, record width and count (and that the data holds count*width values, for messages built by
// hand rather than decoded): the contract of every typed message.
void expectShape(const Message& m, MessageType type, const std::string& name, uint32_t width, long expectedCount,
                 const std::string& context)
{
    if (m.type != type)
        throw CouplerError("coupling: expected " + name + ", got " + messageTypeName(m.type) + where(m));
    const bool countOk = expectedCount < 0 || uint64_t(m.count) == uint64_t(expectedCount);
    if (m.width != width || !countOk || m.data.size() != size_t(m.count) * m.width)
        throw CouplerError("coupling: " + name + context + " has " + std::to_string(m.count) + " records of " +
                           std::to_string(m.width) + " values (" + std::to_string(m.data.size()) +
                           " in all) where " +
                           (expectedCount < 0 ? std::string("records") : std::to_string(expectedCount) + " records") +
                           " of " + std::to_string(width) + " were expected");
}

void expectVersion(const Message& m, const std::string& name)
{
    const double version = m.textNumber("version");
    if (version != protocolVersion)
        throw CouplerError("coupling: protocol version mismatch: the " + name + " says version " +
                           tenDigits(version) + ", this side speaks version " + std::to_string(protocolVersion));
}

// A 0|1 flag read tolerantly: any number equal to 0 or 1, or true/false, yes/no, on/off in any case.
bool readFlag(std::string v, bool& flag)
{
    for (char& c : v) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (v == "true" || v == "yes" || v == "on") { flag = true; return true; }
    if (v == "false" || v == "no" || v == "off") { flag = false; return true; }
    char* end = nullptr;
    const double x = std::strtod(v.c_str(), &end);
    if (v.empty() || *end != '\0' || (x != 0 && x != 1)) return false;
    flag = (x == 1);
    return true;
}

void putMotion(double* r, const RigidVelocity& v, int u, int w)
{
    for (int d = 0; d < 3; ++d) {
        r[u + d] = v.U[d];
        r[w + d] = v.omega[d];
    }
}
RigidVelocity getMotion(const double* r, int u, int w)
{
    RigidVelocity v;
    for (int d = 0; d < 3; ++d) {
        v.U[d] = r[u + d];
        v.omega[d] = r[w + d];
    }
    return v;
}
void putForce(double* r, const ForceTorque& f, int F, int T)
{
    for (int d = 0; d < 3; ++d) {
        r[F + d] = f.F[d];
        r[T + d] = f.T[d];
    }
}
ForceTorque getForce(const double* r, int F, int T)
{
    ForceTorque f;
    for (int d = 0; d < 3; ++d) {
        f.F[d] = r[F + d];
        f.T[d] = r[T + d];
    }
    return f;
}

// An optional whole-number text entry (checkpoint and resume keys, which older peers of protocol 3
// do not send): its value, or `absent`.
long long optionalCount(const Message& m, const std::string& key, long long absent)
{
    if (m.text.find(key + "=") == std::string::npos) return absent;
    return std::llround(m.textNumber(key));
}

const char* faceName(int f)
{
    static const char* names[layout::nFaces] = {"xlo", "xhi", "ylo", "yhi", "zlo", "zhi"};
    return names[f];
}

}  // namespace

// ---- Hello ------------------------------------------------------------------------------------------

Message DemHello::toMessage() const
{
    using namespace layout;
    Message m = makeMessage(MessageType::Hello, 0, 0, 1, helloDemWidth,
                            "role=dem version=" + std::to_string(version) + " dt=" + tenDigits(dt) +
                            " lastStep=" + std::to_string(lastStep) + " stresslets=" + (stresslets ? "1" : "0") +
                            " resume=" + std::to_string(resumeStep) + " checkpoint=" + std::to_string(checkpointEvery));
    double* r = &m.data[0];
    r[hdNParticles] = double(nParticles);
    for (int d = 0; d < 3; ++d) {
        r[hdXlo + 2 * d] = lo[d];
        r[hdXlo + 2 * d + 1] = hi[d];
        r[hdPeriodic + d] = periodic[d] ? 1 : 0;
    }
    return m;
}

DemHello DemHello::fromMessage(const Message& m)
{
    using namespace layout;
    expectShape(m, MessageType::Hello, "Hello of fdmDEM", helloDemWidth, 1, "");
    expectVersion(m, "Hello of fdmDEM");
    DemHello h;
    h.dt = m.textNumber("dt");
    h.lastStep = std::llround(m.textNumber("lastStep"));
    h.resumeStep = optionalCount(m, "resume", 0);
    h.checkpointEvery = optionalCount(m, "checkpoint", 0);
    // protocol 2 on: the DEM side always says whether StepDone carries stresslets
    std::string value;
    try {
        value = m.textValue("stresslets");
    } catch (const CouplerError&) {
        throw CouplerError("coupling: the Hello of fdmDEM has no stresslets= entry (text: \"" + m.text +
                           "\"), which coupling protocol " + std::to_string(protocolVersion) + " requires");
    }
    if (!readFlag(value, h.stresslets))
        throw CouplerError("coupling: the Hello of fdmDEM says stresslets=" + value + ", which is not 0 or 1");
    const double* r = &m.data[0];
    h.nParticles = std::llround(r[hdNParticles]);
    for (int d = 0; d < 3; ++d) {
        h.lo[d] = r[hdXlo + 2 * d];
        h.hi[d] = r[hdXlo + 2 * d + 1];
        h.periodic[d] = r[hdPeriodic + d] != 0;
    }
    return h;
}

Message FluidHello::toMessage() const
{
    using namespace layout;
    Message m = makeMessage(MessageType::Hello, 0, 0, 1, helloFluidWidth,
                            "role=fluid version=" + std::to_string(version) + " resume=" + std::to_string(resumeStep) +
                                " gradP0x=" + allDigits(gradP0[0]) + " gradP0y=" + allDigits(gradP0[1]) +
                                " gradP0z=" + allDigits(gradP0[2]));
    double* r = &m.data[0];
    r[hfNParticles] = double(nParticlesExpected);
    r[hfAlphaLambda] = alphaLambda;
    r[hfRhoFluid] = rhoFluid;
    r[hfDelta] = delta;
    for (int d = 0; d < 3; ++d) {
        r[hfXlo + 2 * d] = lo[d];
        r[hfXlo + 2 * d + 1] = hi[d];
        r[hfPeriodic + d] = periodic[d] ? 1 : 0;
    }
    r[hfViscosity] = viscosity;
    for (uint32_t f = 0; f < nFaces; ++f) {
        double* face = r + hfFaceBase + faceWidth * f;
        face[fKind] = faces[f].kind;
        face[fUx] = faces[f].velocity[0];
        face[fUy] = faces[f].velocity[1];
        face[fUz] = faces[f].velocity[2];
    }
    return m;
}

FluidHello FluidHello::fromMessage(const Message& m)
{
    using namespace layout;
    expectShape(m, MessageType::Hello, "Hello of the fluid solver", helloFluidWidth, 1, "");
    expectVersion(m, "Hello of the fluid solver");
    FluidHello h;
    h.resumeStep = optionalCount(m, "resume", 0);
    for (int d = 0; d < 3; ++d) {
        const std::string key = std::string("gradP0") + "xyz"[d];
        if (m.text.find(key + "=") != std::string::npos) h.gradP0[d] = m.textNumber(key);
    }
    const double* r = &m.data[0];
    h.nParticlesExpected = std::llround(r[hfNParticles]);
    h.alphaLambda = r[hfAlphaLambda];
    h.rhoFluid = r[hfRhoFluid];
    h.delta = r[hfDelta];
    for (int d = 0; d < 3; ++d) {
        h.lo[d] = r[hfXlo + 2 * d];
        h.hi[d] = r[hfXlo + 2 * d + 1];
        h.periodic[d] = r[hfPeriodic + d] != 0;
    }
    h.viscosity = r[hfViscosity];
    for (uint32_t f = 0; f < nFaces; ++f) {
        const double* face = r + hfFaceBase + faceWidth * f;
        const double kind = face[fKind];
        if (!(kind == bPeriodic || kind == bWall || kind == bSlip || kind == bOther))
            throw CouplerError(std::string("coupling: the Hello of the fluid solver gives face ") + faceName(int(f)) +
                               " the boundary kind " + allDigits(kind) + " (0 periodic, 1 wall, 2 slip, 3 other)");
        h.faces[f].kind = int(kind);
        for (int d = 0; d < 3; ++d) h.faces[f].velocity[d] = face[fUx + d];
    }
    return h;
}

// ---- one time step ----------------------------------------------------------------------------------

Message Step::toMessage() const
{
    using namespace layout;
    Message m = makeMessage(MessageType::Step, step, 0, uint32_t(particles.size()), stepWidth,
                            "dt=" + tenDigits(dt) + " lastStep=" + std::to_string(lastStep) +
                            (checkpoint ? " checkpoint=1" : ""));
    for (size_t p = 0; p < particles.size(); ++p) {
        const StepParticle& q = particles[p];
        double* r = &m.data[p * stepWidth];
        r[sTag] = double(q.tag);
        for (int d = 0; d < 3; ++d) r[sX + d] = q.x[d];
        r[sRadius] = q.radius;
        putMotion(r, q.velocity, sUx, sWx);
    }
    return m;
}

Step Step::fromMessage(const Message& m, long expectedCount)
{
    using namespace layout;
    expectShape(m, MessageType::Step, "Step", stepWidth, expectedCount, where(m));
    Step s;
    s.step = m.step;
    s.dt = m.textNumber("dt");
    s.lastStep = std::llround(m.textNumber("lastStep"));
    s.checkpoint = optionalCount(m, "checkpoint", 0) != 0;
    s.particles.resize(m.count);
    for (size_t p = 0; p < s.particles.size(); ++p) {
        const double* r = &m.data[p * stepWidth];
        StepParticle& q = s.particles[p];
        q.tag = std::llround(r[sTag]);
        for (int d = 0; d < 3; ++d) q.x[d] = r[sX + d];
        q.radius = r[sRadius];
        q.velocity = getMotion(r, sUx, sWx);
    }
    return s;
}

Message Volumes::toMessage() const
{
    using namespace layout;
    Message m = makeMessage(MessageType::Volumes, step, 0, uint32_t(particles.size()), volumesWidth);
    for (size_t p = 0; p < particles.size(); ++p) {
        double* rec = &m.data[p * volumesWidth];
        rec[volVu] = particles[p].Vu;
        for (int d = 0; d < 3; ++d) rec[volM1x + d] = particles[p].m1[d];
        for (int k = 0; k < 6; ++k) rec[volJxx + k] = particles[p].J[k];
    }
    return m;
}

Volumes Volumes::fromMessage(const Message& m, long expectedCount)
{
    using namespace layout;
    expectShape(m, MessageType::Volumes, "Volumes", volumesWidth, expectedCount, " (step " + std::to_string(m.step) + ")");
    Volumes v;
    v.step = m.step;
    v.particles.resize(m.count);
    for (size_t p = 0; p < v.particles.size(); ++p) {
        const double* rec = &m.data[p * volumesWidth];
        v.particles[p].Vu = rec[volVu];
        for (int d = 0; d < 3; ++d) v.particles[p].m1[d] = rec[volM1x + d];
        for (int k = 0; k < 6; ++k) v.particles[p].J[k] = rec[volJxx + k];
    }
    return v;
}

Message Integrals::toMessage() const
{
    using namespace layout;
    Message m = makeMessage(MessageType::Integrals, step, iteration, uint32_t(particles.size()), integralsWidth);
    for (size_t p = 0; p < particles.size(); ++p) putForce(&m.data[p * integralsWidth], particles[p], iFx, iTx);
    return m;
}

Integrals Integrals::fromMessage(const Message& m, long expectedCount)
{
    using namespace layout;
    expectShape(m, MessageType::Integrals, "Integrals", integralsWidth, expectedCount, where(m));
    Integrals in;
    in.step = m.step;
    in.iteration = m.iteration;
    in.particles.resize(m.count);
    for (size_t p = 0; p < in.particles.size(); ++p) in.particles[p] = getForce(&m.data[p * integralsWidth], iFx, iTx);
    return in;
}

Message Velocities::toMessage() const
{
    using namespace layout;
    Message m = makeMessage(MessageType::Velocities, step, iteration, uint32_t(particles.size()), velocitiesWidth);
    for (size_t p = 0; p < particles.size(); ++p) putMotion(&m.data[p * velocitiesWidth], particles[p], vUx, vWx);
    return m;
}

Velocities Velocities::fromMessage(const Message& m, long expectedCount)
{
    using namespace layout;
    expectShape(m, MessageType::Velocities, "Velocities", velocitiesWidth, expectedCount, where(m));
    Velocities v;
    v.step = m.step;
    v.iteration = m.iteration;
    v.particles.resize(m.count);
    for (size_t p = 0; p < v.particles.size(); ++p) v.particles[p] = getMotion(&m.data[p * velocitiesWidth], vUx, vWx);
    return v;
}

Message StepDone::toMessage() const
{
    using namespace layout;
    const bool withStresslets = !stresslets.empty();
    if (withStresslets && stresslets.size() != forces.size())
        throw CouplerError("coupling: StepDone of step " + std::to_string(step) + " with " +
                           std::to_string(stresslets.size()) + " stresslets for " + std::to_string(forces.size()) +
                           " particles");
    const uint32_t width = withStresslets ? uint32_t(stepDoneStressWidth) : uint32_t(stepDoneWidth);
    Message m = makeMessage(MessageType::StepDone, step, iterations, uint32_t(forces.size()), width,
                            "iterations=" + std::to_string(iterations) + " residual=" + allDigits(residual) +
                            " converged=" + (converged ? "1" : "0"));
    for (size_t p = 0; p < forces.size(); ++p) {
        double* r = &m.data[p * width];
        putForce(r, forces[p], dFx, dTx);
        if (!withStresslets) continue;
        for (int c = 0; c < 6; ++c) r[dSxx + c] = stresslets[p].S[c];
        r[dTrace] = stresslets[p].trace;
    }
    return m;
}

StepDone StepDone::fromMessage(const Message& m, bool withStresslets, long expectedCount)
{
    using namespace layout;
    const uint32_t width = withStresslets ? uint32_t(stepDoneStressWidth) : uint32_t(stepDoneWidth);
    expectShape(m, MessageType::StepDone, withStresslets ? "StepDone with stresslets" : "StepDone", width,
                expectedCount, " (step " + std::to_string(m.step) + ")");
    StepDone s;
    s.step = m.step;
    s.iterations = uint32_t(std::lround(m.textNumber("iterations")));
    s.residual = m.textNumber("residual");
    const std::string converged = m.textValue("converged");
    if (converged != "0" && converged != "1")
        throw CouplerError("coupling: StepDone of step " + std::to_string(m.step) + " says converged=" + converged +
                           ", which is not 0 or 1");
    s.converged = converged == "1";
    s.forces.resize(m.count);
    if (withStresslets) s.stresslets.resize(m.count);
    for (size_t p = 0; p < s.forces.size(); ++p) {
        const double* r = &m.data[p * width];
        s.forces[p] = getForce(r, dFx, dTx);
        if (!withStresslets) continue;
        for (int c = 0; c < 6; ++c) s.stresslets[p].S[c] = r[dSxx + c];
        s.stresslets[p].trace = r[dTrace];
    }
    return s;
}

// ---- the end ----------------------------------------------------------------------------------------

Message Finish::toMessage() const { return makeMessage(MessageType::Finish, step, 0, 0, 0); }

Finish Finish::fromMessage(const Message& m)
{
    expectShape(m, MessageType::Finish, "Finish", 0, 0, " (step " + std::to_string(m.step) + ")");
    Finish f;
    f.step = m.step;
    return f;
}

Message Error::toMessage() const { return makeMessage(MessageType::Error, 0, 0, 0, 0, text); }

Error Error::fromMessage(const Message& m)
{
    expectShape(m, MessageType::Error, "Error", 0, 0, "");
    Error e;
    e.text = m.text;
    return e;
}

}  // namespace coupler
}  // namespace fdm
