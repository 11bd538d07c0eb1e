// fdm/coupler.h -- the thin library that the fluid solver (fdmFoam) and the particle code
// (fdmDEM, LIGGGHTS) both link. A versioned message format, one typed struct per message that
// packs and unpacks its records, and two transports (TCP socket between the two master ranks, or
// a shared directory of message files for debugging and replay). Nothing else: no physics, no
// MPI. See docs/coupling.md for the protocol.
//
// Must stay C++11: OpenFOAM v1912 code includes it.
#ifndef FDM_COUPLER_H
#define FDM_COUPLER_H

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace fdm {
namespace coupler {

// Bump when the wire format or the meaning of a record changes; a peer with another
// version is refused at the handshake with both versions in the message.
// 2: fluid Hello gains the viscosity and the box faces' boundaries; DEM Hello asks for
//    stresslets; StepDone may carry them (for the sub-grid lubrication pair style).
// 3: Vu and Ju (they depend only on the positions) go once per time step in the new Volumes
//    message, before the first Integrals; Integrals keep F and T only (6 values per particle).
// 4: Volumes carry the first moment m1 and the inertia tensor J of the discrete sphere instead
//    of the isotropic Ju (Eq. 31's rigid-body block, Galilean invariant).
const uint16_t protocolVersion = 4;

// How deep (in radii: of the sphere for a wall, of the smaller sphere for a pair) a contact pressed
// in by its load may go and still be accepted by both codes, at any step and when a run resumes
// (fdmFoam warns once of a wall overlap); deeper is an escape through a wall, or springs too soft
// for their loads, and stops the run (docs/contact.md).
constexpr double contactOverlapTolerance = 0.05;

enum class MessageType : uint16_t {
    Hello      = 1,  // handshake, once per connection, each side sends one
    Step       = 2,  // DEM -> fluid: particle positions/radii/velocities, once per time step
    Volumes    = 8,  // fluid -> DEM: Vu, m1, J of every particle, once per time step (protocol 4)
    Integrals  = 3,  // fluid -> DEM: per-particle integrals of Eq. (38), every inner iteration
    Velocities = 4,  // DEM -> fluid: rigid velocities (U_p, Omega_p), every inner iteration
    StepDone   = 5,  // fluid -> DEM: inner iterations converged, hydrodynamic force/torque
    Finish     = 6,  // DEM -> fluid: no more steps, both sides end normally
    Error      = 7   // either way: the sender is stopping; text says why
};

const char* messageTypeName(MessageType t);

// One message: a small fixed header, an optional text (key=value metadata or an error
// message) and `count` records of `width` doubles each (row-major).
struct Message {
    MessageType type = MessageType::Error;
    uint64_t step = 0;        // DEM time step index (LIGGGHTS ntimestep)
    uint32_t iteration = 0;   // inner iteration index within the step, from 1
    uint32_t count = 0;       // number of records (particles)
    uint32_t width = 0;       // doubles per record
    std::string text;
    std::vector<double> data; // count*width values

    double& at(uint32_t record, uint32_t field) { return data[size_t(record)*width + field]; }
    double at(uint32_t record, uint32_t field) const { return data[size_t(record)*width + field]; }

    // Value of `key` in text of the form "key1=value1 key2=value2"; throws CouplerError naming
    // the key and the message type if it is absent.
    std::string textValue(const std::string& key) const;
    double textNumber(const std::string& key) const;
};

Message makeMessage(MessageType type, uint64_t step, uint32_t iteration,
                    uint32_t count, uint32_t width, const std::string& text = "");

// Record layouts (field indices) -- the whole contract between the two codes.
namespace layout {
    // Hello from the DEM side.
    //   text: "role=dem version=<v> dt=<s> lastStep=<n> stresslets=<0|1>"
    //   (stresslets=1: the DEM side wants the FDM stresslets in StepDone)
    //   one record: [nParticles, xlo, xhi, ylo, yhi, zlo, zhi, periodicX, periodicY, periodicZ]
    enum HelloDemField {
        hdNParticles = 0,
        hdXlo = 1,        // xlo, xhi, ylo, yhi, zlo, zhi at hdXlo + 2d, hdXlo + 2d + 1
        hdPeriodic = 7    // periodic in direction d at hdPeriodic + d
    };
    // Hello from the fluid side. text: "role=fluid version=<v>"
    //   one record, 38 values:
    //    0      nParticlesExpected (-1 = any)
    //    1      alphaLambda [s]
    //    2      rhoFluid [kg/m3]
    //    3      delta [m]
    //    4..9   xlo, xhi, ylo, yhi, zlo, zhi [m]
    //    10..12 periodicX, periodicY, periodicZ (0|1)
    //    13     eta: dynamic viscosity rho_f nu [Pa s]                          (hfViscosity)
    //    14..37 per box face f = 0..5 in the order xlo, xhi, ylo, yhi, zlo, zhi, the 4 values
    //           at hfFaceBase + faceWidth*f + [fKind, fUx, fUy, fUz]:
    //           kind (BoundaryKind: 0 periodic, 1 no-slip wall, 2 slip, 3 other) and the
    //           wall velocity [m/s] (the uniform fixedValue of U; 0 unless kind 1)
    enum HelloFluidField {
        hfNParticles = 0, hfAlphaLambda = 1, hfRhoFluid = 2, hfDelta = 3,
        hfXlo = 4,        // xlo, xhi, ylo, yhi, zlo, zhi at hfXlo + 2d, hfXlo + 2d + 1
        hfPeriodic = 10,  // periodic in direction d at hfPeriodic + d
        hfViscosity = 13,
        hfFaceBase = 14
    };
    const uint32_t nFaces = 6;
    const uint32_t faceWidth = 4;
    enum FaceField { fKind, fUx, fUy, fUz };
    enum BoundaryKind {
        bPeriodic = 0,  // cyclic patch pair
        bWall = 1,      // no-slip wall: fixedValue velocity (moving or not)
        bSlip = 2,      // slip
        bOther = 3      // anything else
    };
    const uint32_t helloDemWidth = 10;
    const uint32_t helloFluidWidth = hfFaceBase + nFaces*faceWidth;  // 38

    // Step: one record per particle, ordered by tag (tags 1..N). text: "dt=<s> lastStep=<n>"
    enum StepField { sTag, sX, sY, sZ, sRadius, sUx, sUy, sUz, sWx, sWy, sWz, stepWidth };

    // Volumes: once per time step, after Step and before the first Integrals; one record per
    // particle (same order as Step), from the fluid's indicator function I_u, r = x - x_p:
    //   Vu = int I_u dV                               (rigid translation)
    //   m1 = int I_u r dV                             (first moment: zero only on the mesh's
    //                                                  symmetry points)
    //   J  = int I_u (|r|^2 1 - r r) dV               (inertia tensor: xx xy xz yy yz zz)
    // Eq. (31)'s block of the particle is (rho_f/alpha) [[Vu 1, -[m1]x], [[m1]x, J]].
    enum VolumeField { volVu, volM1x, volM1y, volM1z, volJxx, volJxy, volJxz, volJyy, volJyz, volJzz,
                       volumesWidth };

    // Integrals: every inner iteration, one record per particle, all in SI units:
    //   F  = rho_f int (I_u u*/alpha - I_lambda lambda^n) dV               (Eq. 32)
    //   T  = rho_f int (x-x_p) x (I_u u*/alpha - I_lambda lambda^n) dV     (Eq. 32)
    enum IntegralField { iFx, iFy, iFz, iTx, iTy, iTz, integralsWidth };

    // Velocities: one record per particle: [Ux, Uy, Uz, Wx, Wy, Wz]
    enum VelocityField { vUx, vUy, vUz, vWx, vWy, vWz, velocitiesWidth };

    // StepDone: text "iterations=<n> residual=<lambda residual> converged=<0|1>"
    //   one record per particle: hydrodynamic force and torque of the fluid solve,
    //   -rho_f int I_lambda lambda dV and -rho_f int (x-x_p) x I_lambda lambda dV (Eq. 7);
    //   stepDoneWidth (6) wide, or stepDoneStressWidth (13) if the DEM Hello said
    //   stresslets=1: then also the FDM stresslet of Eq. (12) [N m], with r = x - x_p,
    //   S = -rho_f int I_lambda [sym(lambda r) - (lambda.r/3) delta] dV (traceless,
    //   Sxx Sxy Sxz Syy Syz Szz) and its trace s = -int I_lambda [rho_f lambda.r + 3 p] dV
    //   (p: the solver's pressure, whose reference level s depends on: docs/fluid.md).
    enum StepDoneField {
        dFx, dFy, dFz, dTx, dTy, dTz,
        stepDoneWidth,
        dSxx = stepDoneWidth, dSxy, dSxz, dSyy, dSyz, dSzz, dTrace,
        stepDoneStressWidth
    };
}

// Any coupling failure: peer died, never connected, timed out, malformed or unexpected
// message, or an Error message from the peer. what() is meant for the user.
class CouplerError : public std::runtime_error {
public:
    explicit CouplerError(const std::string& what) : std::runtime_error(what) {}
};

// ---- Typed messages -----------------------------------------------------------------------------
// One struct per message: toMessage() packs it, fromMessage() checks the type, the record count and
// width and unpacks it, throwing a CouplerError that names the message and the sizes. They are the
// only code that indexes records (with the layout above): the two codes use these. A negative
// expectedCount accepts any number of particles.

// Hello from the particle code (fdmDEM).
struct DemHello {
    int version = protocolVersion;
    double dt = 0;             // DEM time step [s] (sent with 10 significant digits)
    long long lastStep = 0;    // last step of the current run
    bool stresslets = false;   // StepDone must carry the FDM stresslets
    // Checkpoint and resume (docs/coupling.md, "Checkpoint and resume"); optional text entries,
    // 0 when absent: the step both codes resume from (0: a fresh start), and the checkpoint
    // interval of fix fdm/couple (0: none; for the fluid's log only, each Step says when)
    long long resumeStep = 0;
    long long checkpointEvery = 0;
    long long nParticles = 0;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};  // the box [m]
    bool periodic[3] = {false, false, false};

    Message toMessage() const;
    // stresslets= is required and read tolerantly: 0|1 as any number, true/false, yes/no, on/off.
    static DemHello fromMessage(const Message& m);
};

// One face of the box as the fluid case bounds it (fluid Hello).
struct BoxFace {
    int kind = layout::bOther;                 // layout::BoundaryKind
    double velocity[3] = {0, 0, 0};            // wall velocity [m/s] (kind bWall), else 0
};

// Hello from the fluid solver (fdmFoam).
struct FluidHello {
    int version = protocolVersion;
    long long nParticlesExpected = -1;         // -1: any
    double alphaLambda = 0;                    // [s]
    double rhoFluid = 0;                       // [kg/m3]
    double delta = 0;                          // mesh size [m]
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    bool periodic[3] = {false, false, false};
    double viscosity = 0;                      // eta = rho_f nu [Pa s]
    BoxFace faces[layout::nFaces];             // xlo, xhi, ylo, yhi, zlo, zhi
    long long resumeStep = 0;                  // the checkpoint step the fluid resumes from (0: fresh)
    double gradP0[3] = {0, 0, 0};              // imposed mean pressure gradient [Pa/m] (Eq. 42;
                                               // optional text entries, 0 when absent)

    Message toMessage() const;
    static FluidHello fromMessage(const Message& m);
};

// Per particle: rigid-body velocity (Step, Velocities).
struct RigidVelocity {
    double U[3];
    double omega[3];
};

// Per particle: force and torque (Integrals, StepDone).
struct ForceTorque {
    double F[3];
    double T[3];
};

// Step: the particles of DEM time step `step`, by tag 1..N.
struct StepParticle {
    long long tag;
    double x[3];
    double radius;
    RigidVelocity velocity;
};
struct Step {
    uint64_t step = 0;
    double dt = 0;                             // [s] (sent with 10 significant digits)
    long long lastStep = 0;
    bool checkpoint = false;                   // both codes write a checkpoint at the end of this step
    std::vector<StepParticle> particles;

    Message toMessage() const;
    static Step fromMessage(const Message& m, long expectedCount = -1);
};

// Volumes of the time step `step` (they depend only on the positions): Eq. (31)'s rigid-body block.
struct ParticleVolume {
    double Vu = 0;
    double m1[3] = {0, 0, 0};
    double J[6] = {0, 0, 0, 0, 0, 0};   // xx xy xz yy yz zz
    // the isotropic part, trace(J)/3 = int I_u (2/3)|r|^2 dV (protocol 3's Ju)
    double isotropicJ() const { return (J[0] + J[3] + J[5]) / 3; }
};
struct Volumes {
    uint64_t step = 0;
    std::vector<ParticleVolume> particles;

    Message toMessage() const;
    static Volumes fromMessage(const Message& m, long expectedCount = -1);
};

// Integrals of inner iteration `iteration`: the fluid part of F^tot (Eqs. 32, 38).
struct Integrals {
    uint64_t step = 0;
    uint32_t iteration = 0;
    std::vector<ForceTorque> particles;

    Message toMessage() const;
    static Integrals fromMessage(const Message& m, long expectedCount = -1);
};

// Velocities: the solution of Eq. (31) for inner iteration `iteration`.
struct Velocities {
    uint64_t step = 0;
    uint32_t iteration = 0;
    std::vector<RigidVelocity> particles;

    Message toMessage() const;
    static Velocities fromMessage(const Message& m, long expectedCount = -1);
};

// The FDM stresslet of Eq. (12) [N m]: traceless S (xx xy xz yy yz zz) and the trace s.
struct Stresslet {
    double S[6];
    double trace;
};

// StepDone: the inner iterations of `step` ended; hydrodynamic force and torque (Eq. 7) and, if the
// DEM Hello asked for them, the stresslets.
struct StepDone {
    uint64_t step = 0;
    uint32_t iterations = 0;
    double residual = 0;                       // lambda residual of the last inner iteration
    bool converged = false;
    std::vector<ForceTorque> forces;
    std::vector<Stresslet> stresslets;         // empty, or one per particle

    Message toMessage() const;                 // stepDoneStressWidth wide if stresslets are given
    static StepDone fromMessage(const Message& m, bool withStresslets, long expectedCount = -1);
};

// Finish: no more steps.
struct Finish {
    uint64_t step = 0;

    Message toMessage() const;
    static Finish fromMessage(const Message& m);
};

// Error: the sender stops; text says why.
struct Error {
    std::string text;

    Message toMessage() const;
    static Error fromMessage(const Message& m);
};

struct Options {
    std::string transport = "socket";  // "socket" or "file"
    // socket: the fluid side listens on host:port (port 0 = any free port); if portFile is
    // set the listening side writes the chosen port there and the connecting side reads it
    // (waiting for the file up to connectTimeout).
    std::string host = "127.0.0.1";
    int port = 0;
    std::string portFile;
    // file: both sides use this directory; each message is one file, written atomically.
    std::string directory;
    double connectTimeout = 60.0;   // s: the peer never showed up
    double receiveTimeout = 600.0;  // s: the peer is alive but silent (hung)
    std::string recordFile;         // if set, every message sent and received is appended here
    std::string name = "peer";      // how this side is named in error messages ("fluid", "dem")
};

// One end of a connection. send() and receive() throw CouplerError; receive() turns an Error
// message from the peer into a CouplerError carrying its text.
class Transport {
public:
    virtual ~Transport() {}
    virtual void send(const Message& m) = 0;
    virtual Message receive() = 0;
    // Receive and check the type; throws CouplerError "expected X from <peer>, got Y".
    Message receive(MessageType expected);
    // Best effort, never throws: tell the peer why we stop.
    void sendError(const std::string& why) noexcept;
    virtual void close() noexcept = 0;
    virtual std::string describe() const = 0;  // e.g. "socket 127.0.0.1:40123"
};

// The fluid side listens, the DEM side connects. Both block until the peer is there or
// connectTimeout expires (CouplerError "no peer connected to ... within N s").
std::unique_ptr<Transport> listen(const Options& options);
std::unique_ptr<Transport> connect(const Options& options);

// Wire format (exposed for tests and the replay tool).
std::vector<unsigned char> encode(const Message& m);
Message decode(const unsigned char* bytes, size_t size);  // throws CouplerError if malformed

// Every message starts with a header of this many bytes.
const size_t headerSize = 40;
// Total encoded size of the message whose header starts at `header` (headerSize bytes); throws
// CouplerError if the header is malformed (bad magic, other version, unknown type, absurd sizes).
// Lets a reader walk a record file or a stream message by message.
size_t encodedSize(const unsigned char* header);

}  // namespace coupler
}  // namespace fdm

#endif
