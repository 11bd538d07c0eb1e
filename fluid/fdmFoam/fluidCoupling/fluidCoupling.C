#include "fluidCoupling.H"
#include "Pstream.H"
#include "OSspecific.H"
#include "UIPstream.H"
#include "UOPstream.H"
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

namespace cpl = fdm::coupler;

namespace
{
    double wallClock()
    {
        using namespace std::chrono;
        return duration<double>(steady_clock::now().time_since_epoch()).count();
    }

    // The master's wake-up call to the other ranks (waitAsleepForMaster),
    // on a tag of its own: OpenFOAM's messages use msgType() and nearby
    const int wakeUpTag = 32123;

    // The longest nap between two tests of the wake-up call: the latency it
    // adds to an exchange, against the 0.1-10 s a dense scene's particle
    // code takes between two
    const std::chrono::microseconds longestNap(1000);

    // Every rank but the master waits for the master's word asleep, not in
    // MPI's busy poll. While the particle code works (the Eq. 31 solves:
    // most of a dense scene's step) the master waits on the coupler's socket
    // without using its core, but a rank waiting in Pstream::scatter polls
    // (Open MPI, even when yielding): on the paper channel's 2 cores, it held
    // the core the particle code leaves free, a third of the run's CPU
    // (docs/benchmarks.md, "Parallel runs": the fluid ranks' wait).
    void waitAsleepForMaster()
    {
        using namespace Foam;
        char token = 1;
        if (Pstream::master())
        {
            for (int proc = Pstream::firstSlave(); proc <= Pstream::lastSlave(); ++proc)
            {
                UOPstream::write
                (
                    UPstream::commsTypes::scheduled, proc, &token, 1,
                    wakeUpTag, UPstream::worldComm
                );
            }
            return;
        }
        const label request = UPstream::nRequests();
        UIPstream::read
        (
            UPstream::commsTypes::nonBlocking, UPstream::masterNo(), &token, 1,
            wakeUpTag, UPstream::worldComm
        );
        std::chrono::microseconds nap(10);
        while (!UPstream::finishedRequest(request))
        {
            std::this_thread::sleep_for(nap);
            nap = std::min(2*nap, longestNap);
        }
        UPstream::waitRequests(request);
    }

    const char* boxFaceName[6] = {"xlo", "xhi", "ylo", "yhi", "zlo", "zhi"};
    const char* boundaryKindName[4] = {"cyclic", "wall", "slip", "other"};
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::fluidCoupling::fluidCoupling(const Time& runTime, const dictionary& dict)
:
    transport_(),
    exchangeTime_(0),
    step_(-1),
    lastStep_(-1),
    dt_(0),
    nParticles_(0),
    stresslets_(false),
    volumesSent_(false),
    checkpoint_(false),
    checkpointEvery_(0)
{
    if (!Pstream::master())
    {
        return;
    }

    cpl::Options opt;
    opt.name = "fdmDEM (particle code)";
    opt.transport = dict.lookupOrDefault<word>("transport", "socket");
    opt.host = dict.lookupOrDefault<string>("host", "127.0.0.1");
    opt.port = dict.lookupOrDefault<label>("port", 0);
    fileName portFile = dict.lookupOrDefault<fileName>("portFile", "coupling.port");
    fileName directory = dict.lookupOrDefault<fileName>("directory", "coupling");
    fileName record = dict.lookupOrDefault<fileName>("record", "");
    // Relative paths are relative to the case directory
    if (!portFile.empty() && !portFile.isAbsolute()) portFile = runTime.globalPath()/portFile;
    if (!directory.isAbsolute()) directory = runTime.globalPath()/directory;
    if (!record.empty() && !record.isAbsolute()) record = runTime.globalPath()/record;
    opt.portFile = portFile;
    opt.directory = directory;
    opt.recordFile = record;
    opt.connectTimeout = dict.lookupOrDefault<scalar>("connectTimeout", 60);
    opt.receiveTimeout = dict.lookupOrDefault<scalar>("receiveTimeout", 600);

    if (opt.transport != "socket" && opt.transport != "file")
    {
        FatalIOErrorInFunction(dict)
            << "coupling transport " << opt.transport
            << " is not one of: socket file" << exit(FatalIOError);
    }

    Info<< "Waiting for the particle code (" << opt.transport
        << (opt.transport == "socket"
            ? " on " + opt.host + ", port file " + opt.portFile
            : " in " + opt.directory)
        << ", timeout " << opt.connectTimeout << " s)" << endl;

    const double t0 = wallClock();
    try
    {
        transport_ = cpl::listen(opt);
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction
            << "coupling: " << e.what() << exit(FatalError);
    }
    exchangeTime_ += wallClock() - t0;
    Info<< "Particle code connected: " << transport_->describe().c_str()
        << endl;
}


Foam::fluidCoupling::~fluidCoupling()
{
    if (transport_)
    {
        transport_->close();
    }
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

void Foam::fluidCoupling::fatal(const string& message)
{
    if (transport_)
    {
        transport_->sendError("fdmFoam: " + message);
    }
    FatalErrorInFunction << message.c_str() << exit(FatalError);
}


std::vector<fdm::coupler::BoxFace> Foam::fluidCoupling::boxFaces
(
    const uniformCartesianMesh& grid,
    const volVectorField& U,
    string& problem
)
{
    namespace layout = cpl::layout;
    const polyBoundaryMesh& patches = grid.mesh().boundaryMesh();
    const label nGlobal = patches.nNonProcessor();

    // Per patch: kind from U's condition and, for walls, the velocity. A
    // patch may have no face on this processor: the range of its values is
    // reduced over processors (every processor has every non-processor patch,
    // with the same condition type).
    labelList kind(nGlobal, layout::bOther);
    List<vector> wallU(nGlobal, Zero);
    for (label patchi = 0; patchi < nGlobal; ++patchi)
    {
        const fvPatchVectorField& Up = U.boundaryField()[patchi];
        const word& type = Up.type();
        if (type == "cyclic")
        {
            kind[patchi] = layout::bPeriodic;
        }
        else if
        (
            type == "fixedValue" || type == "noSlip"
         || type == "movingWallVelocity"
        )
        {
            kind[patchi] = layout::bWall;
        }
        else if (type == "slip")
        {
            kind[patchi] = layout::bSlip;
        }
        if (kind[patchi] != layout::bWall)
        {
            continue;
        }

        vector lo(GREAT, GREAT, GREAT), hi(-GREAT, -GREAT, -GREAT);
        forAll(Up, facei)
        {
            lo = min(lo, Up[facei]);
            hi = max(hi, Up[facei]);
        }
        reduce(lo, minOp<vector>());
        reduce(hi, maxOp<vector>());
        if (lo.x() > hi.x())
        {
            continue;   // no face anywhere
        }
        // One velocity per wall: the sub-grid wall corrections (Appendix D)
        // see a plane moving rigidly
        const scalar scale = max(cmptMax(cmptMag(lo)), cmptMax(cmptMag(hi)));
        if (cmptMax(hi - lo) > 1e-9*scale && problem.empty())
        {
            OStringStream os;
            os  << "the velocity U on patch " << patches[patchi].name()
                << " (" << type << ") is not uniform: it ranges from " << lo
                << " to " << hi << " (" << U.time().timeName()
                << "/U). fdmFoam tells the particle code "
                << "one velocity per wall (coupling protocol "
                << label(cpl::protocolVersion) << ")";
            problem = os.str();
        }
        wallU[patchi] = 0.5*(lo + hi);
    }

    // Per box face: the kind its patches share (other if they differ), and
    // the wall velocity
    const List<labelList> facePatches = grid.boxFacePatches();
    std::vector<cpl::BoxFace> result(layout::nFaces);
    forAll(facePatches, f)
    {
        const labelList& onFace = facePatches[f];
        label k = onFace.empty() ? label(layout::bOther) : kind[onFace[0]];
        for (const label patchi : onFace)
        {
            if (kind[patchi] != k)
            {
                k = layout::bOther;
            }
        }
        vector Uw(Zero);
        if (k == layout::bWall)
        {
            Uw = wallU[onFace[0]];
            for (const label patchi : onFace)
            {
                const vector& Ui = wallU[patchi];
                if
                (
                    mag(Ui - Uw) > 1e-9*max(mag(Ui), mag(Uw))
                 && problem.empty()
                )
                {
                    OStringStream os;
                    os  << "the walls on the " << boxFaceName[f]
                        << " face of the box move with different velocities: "
                        << "patch " << patches[onFace[0]].name() << " U = "
                        << Uw << ", patch " << patches[patchi].name()
                        << " U = " << Ui << " (" << U.time().timeName()
                        << "/U). fdmFoam tells the "
                        << "particle code one velocity per face of the box";
                    problem = os.str();
                }
            }
        }
        result[f].kind = k;
        for (direction d = 0; d < 3; ++d)
        {
            result[f].velocity[d] = Uw[d];
        }
    }
    return result;
}


void Foam::fluidCoupling::handshake
(
    const uniformCartesianMesh& grid,
    const volVectorField& U,
    label nParticlesExpected,
    scalar alphaLambda,
    scalar rhoFluid,
    scalar eta,
    label resumeStep,
    const vector& gradP0
)
{
    namespace layout = cpl::layout;

    // Collective: every processor, before the master talks
    string boundaryProblem;
    const std::vector<cpl::BoxFace> faces = boxFaces(grid, U, boundaryProblem);

    string problem;
    label stresslets = 0;
    if (Pstream::master())
    {
        const double t0 = wallClock();
        try
        {
            const cpl::Message m = transport_->receive(cpl::MessageType::Hello);
            cpl::DemHello hello;
            try
            {
                hello = cpl::DemHello::fromMessage(m);
            }
            catch (const cpl::CouplerError& e)
            {
                problem = e.what();
            }
            if (problem.empty())
            {
                nParticles_ = label(hello.nParticles);
                const boundBox& bb = grid.bounds();
                const char* axis = "xyz";
                for (direction d = 0; d < 3 && problem.empty(); ++d)
                {
                    const scalar lo = hello.lo[d];
                    const scalar hi = hello.hi[d];
                    const scalar tol = 1e-9*max(mag(bb.span()[d]), 1.0);
                    const bool periodic = hello.periodic[d];
                    OStringStream os;
                    if (mag(lo - bb.min()[d]) > tol || mag(hi - bb.max()[d]) > tol)
                    {
                        os  << axis[d] << " extent: the LIGGGHTS box spans "
                            << lo << " .. " << hi << " but the OpenFOAM mesh "
                            << "(constant/polyMesh) spans " << bb.min()[d]
                            << " .. " << bb.max()[d];
                        problem = os.str();
                    }
                    else if (periodic != grid.periodic()[d])
                    {
                        os  << axis[d] << " boundary: LIGGGHTS says "
                            << (periodic ? "periodic" : "not periodic")
                            << " but the OpenFOAM mesh has "
                            << (grid.periodic()[d] ? "a cyclic patch pair"
                                                   : "no cyclic patch")
                            << " in " << axis[d];
                        problem = os.str();
                    }
                }
                if
                (
                    problem.empty()
                 && nParticlesExpected >= 0
                 && nParticlesExpected != nParticles_
                )
                {
                    problem = "the fluid case expects "
                        + Foam::name(nParticlesExpected)
                        + " particles (constant/fdmProperties nParticles) "
                        "but the LIGGGHTS input has "
                        + Foam::name(nParticles_);
                }
                stresslets = hello.stresslets ? 1 : 0;
                checkpointEvery_ = label(hello.checkpointEvery);
                if (problem.empty() && label(hello.resumeStep) != resumeStep)
                {
                    problem = resumeStep > 0
                      ? "fdmFoam resumes from its checkpoint of step "
                        + Foam::name(resumeStep) + " (checkpoint/fluid."
                        + Foam::name(resumeStep) + ") but fdmDEM "
                        + (hello.resumeStep > 0
                           ? "from step " + Foam::name(label(hello.resumeStep))
                           : string("starts afresh"))
                      : "fdmDEM resumes from its checkpoint of step "
                        + Foam::name(label(hello.resumeStep))
                        + " but fdmFoam starts afresh";
                    problem += ": both codes must resume the same step"
                        " (fdmRun --resume picks the newest both have)";
                }
            }
            if (problem.empty())
            {
                problem = boundaryProblem;
            }

            if (problem.empty())
            {
                cpl::FluidHello reply;
                reply.nParticlesExpected = nParticlesExpected;
                reply.alphaLambda = alphaLambda;
                reply.rhoFluid = rhoFluid;
                reply.delta = grid.delta();
                const boundBox& bb = grid.bounds();
                for (direction d = 0; d < 3; ++d)
                {
                    reply.lo[d] = bb.min()[d];
                    reply.hi[d] = bb.max()[d];
                    reply.periodic[d] = grid.periodic()[d];
                }
                reply.viscosity = eta;
                reply.resumeStep = resumeStep;
                for (direction d = 0; d < 3; ++d)
                {
                    reply.gradP0[d] = gradP0[d];
                }
                for (label f = 0; f < label(layout::nFaces); ++f)
                {
                    reply.faces[f] = faces[f];
                }
                transport_->send(reply.toMessage());
            }
        }
        catch (const std::exception& e)
        {
            FatalErrorInFunction
                << "coupling: " << e.what() << exit(FatalError);
        }
        exchangeTime_ += wallClock() - t0;
    }

    if (Pstream::master() && !problem.empty())
    {
        fatal(problem);
    }
    Pstream::scatter(nParticles_);
    Pstream::scatter(stresslets);
    Pstream::scatter(checkpointEvery_);
    stresslets_ = stresslets != 0;

    Info<< "Coupled with fdmDEM: " << nParticles_ << " particles, "
        << (stresslets_ ? "with" : "without") << " stresslets" << nl
        << "    box faces (for the particle code):";
    for (label f = 0; f < label(layout::nFaces); ++f)
    {
        const cpl::BoxFace& face = faces[f];
        Info<< ' ' << boxFaceName[f] << ' ' << boundaryKindName[face.kind];
        if (face.kind == layout::bWall)
        {
            Info<< ' '
                << vector(face.velocity[0], face.velocity[1], face.velocity[2]);
        }
    }
    Info<< endl;
}


fdm::coupler::Message Foam::fluidCoupling::receive()
{
    const double t0 = wallClock();
    cpl::Message m;
    try
    {
        m = transport_->receive();
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction << "coupling: " << e.what() << exit(FatalError);
    }
    exchangeTime_ += wallClock() - t0;
    return m;
}


void Foam::fluidCoupling::broadcast(cpl::Message& m)
{
    if (!Pstream::parRun())
    {
        return;
    }
    List<char> bytes;
    if (Pstream::master())
    {
        const std::vector<unsigned char> wire = cpl::encode(m);
        bytes.setSize(label(wire.size()));
        forAll(bytes, i) { bytes[i] = char(wire[i]); }
    }
    waitAsleepForMaster();
    Pstream::scatter(bytes);
    if (!Pstream::master())
    {
        m = cpl::decode
        (
            reinterpret_cast<const unsigned char*>(bytes.cdata()),
            size_t(bytes.size())
        );
    }
}


bool Foam::fluidCoupling::receiveStep(List<fdmParticle>& particles)
{
    cpl::Message m;
    if (Pstream::master())
    {
        m = receive();
        if
        (
            m.type != cpl::MessageType::Finish
         && m.type != cpl::MessageType::Step
        )
        {
            fatal
            (
                string("coupling: expected Step or Finish from fdmDEM, got ")
              + cpl::messageTypeName(m.type)
            );
        }
        if (m.type == cpl::MessageType::Step)
        {
            try
            {
                cpl::Step::fromMessage(m, nParticles_);
            }
            catch (const cpl::CouplerError& e)
            {
                fatal
                (
                    string(e.what()) + " (fdmDEM announced "
                  + Foam::name(nParticles_) + " particles at the handshake)"
                );
            }
        }
    }
    broadcast(m);
    if (m.type == cpl::MessageType::Finish)
    {
        return false;
    }

    const cpl::Step step = cpl::Step::fromMessage(m, nParticles_);
    volumesSent_ = false;
    step_ = label(step.step);
    dt_ = step.dt;
    lastStep_ = label(step.lastStep);
    checkpoint_ = step.checkpoint;
    particles.setSize(step.particles.size());
    forAll(particles, p)
    {
        const cpl::StepParticle& q = step.particles[p];
        fdmParticle& part = particles[p];
        part.tag = label(q.tag);
        part.x = point(q.x[0], q.x[1], q.x[2]);
        part.radius = q.radius;
        part.U = vector(q.velocity.U[0], q.velocity.U[1], q.velocity.U[2]);
        part.omega =
            vector(q.velocity.omega[0], q.velocity.omega[1], q.velocity.omega[2]);
    }
    return true;
}


void Foam::fluidCoupling::send(const fdm::coupler::Message& m)
{
    if (!Pstream::master())
    {
        return;
    }
    const double t0 = wallClock();
    try
    {
        transport_->send(m);
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction << "coupling: " << e.what() << exit(FatalError);
    }
    exchangeTime_ += wallClock() - t0;
}


void Foam::fluidCoupling::sendIntegrals
(
    label iteration,
    const List<scalar>& integrals
)
{
    if (!Pstream::master())
    {
        return;
    }
    // particleForcing::integrals: per particle the Volumes record, then the
    // Integrals record
    namespace layout = cpl::layout;
    const label nv = layout::volumesWidth;
    const label width = nv + layout::integralsWidth;
    const label n = integrals.size()/width;
    if (!volumesSent_)
    {
        cpl::Volumes volumes;
        volumes.step = step_;
        volumes.particles.resize(n);
        for (label p = 0; p < n; ++p)
        {
            const scalar* rec = &integrals[width*p];
            volumes.particles[p].Vu = rec[layout::volVu];
            for (label d = 0; d < 3; ++d)
            {
                volumes.particles[p].m1[d] = rec[layout::volM1x + d];
            }
            for (label k = 0; k < 6; ++k)
            {
                volumes.particles[p].J[k] = rec[layout::volJxx + k];
            }
        }
        send(volumes.toMessage());
        volumesSent_ = true;
    }
    cpl::Integrals m;
    m.step = step_;
    m.iteration = iteration;
    m.particles.resize(n);
    for (label p = 0; p < n; ++p)
    {
        const scalar* rec = &integrals[width*p + nv];
        for (direction d = 0; d < 3; ++d)
        {
            m.particles[p].F[d] = rec[layout::iFx + d];
            m.particles[p].T[d] = rec[layout::iTx + d];
        }
    }
    send(m.toMessage());
}


Foam::List<Foam::scalar> Foam::fluidCoupling::receiveVelocities(label iteration)
{
    cpl::Message m;
    if (Pstream::master())
    {
        m = receive();
        if (m.type != cpl::MessageType::Velocities)
        {
            fatal
            (
                string("coupling: expected Velocities from fdmDEM, got ")
              + cpl::messageTypeName(m.type)
            );
        }
        try
        {
            const cpl::Velocities v = cpl::Velocities::fromMessage(m, nParticles_);
            if (label(v.step) != step_ || label(v.iteration) != iteration)
            {
                fatal
                (
                    "coupling: fdmDEM sent the velocities of step "
                  + Foam::name(label(v.step)) + ", iteration "
                  + Foam::name(label(v.iteration)) + " where step "
                  + Foam::name(step_) + ", iteration " + Foam::name(iteration)
                  + " was expected"
                );
            }
        }
        catch (const cpl::CouplerError& e)
        {
            fatal(e.what());
        }
        forAll(m.data, i)
        {
            if (!std::isfinite(m.data[i]))
            {
                fatal
                (
                    "fdmDEM returned a non-finite velocity for particle "
                  + Foam::name(label(i/m.width) + 1)
                  + " at step " + Foam::name(step_) + ", inner iteration "
                  + Foam::name(iteration)
                );
            }
        }
    }
    broadcast(m);

    // per particle [U(3), Omega(3)] (particleForcing::correct)
    const cpl::Velocities v = cpl::Velocities::fromMessage(m, nParticles_);
    List<scalar> velocities(6*v.particles.size());
    forAll(v.particles, p)
    {
        for (direction d = 0; d < 3; ++d)
        {
            velocities[6*p + d] = v.particles[p].U[d];
            velocities[6*p + 3 + d] = v.particles[p].omega[d];
        }
    }
    return velocities;
}


void Foam::fluidCoupling::sendStepDone
(
    label iterations,
    scalar residual,
    bool converged,
    const List<scalar>& forces,
    const List<scalar>& stresslets
)
{
    if (!Pstream::master())
    {
        return;
    }
    const label nf = 6;     // F, T (particleForcing::hydrodynamicForces)
    const label ns = 7;     // S, s (particleForcing::stresslets)
    const label n = forces.size()/nf;
    if (stresslets_ && stresslets.size() != ns*n)
    {
        FatalErrorInFunction
            << "stresslets of " << stresslets.size()/ns << " particles for "
            << n << " forces" << abort(FatalError);
    }

    cpl::StepDone m;
    m.step = step_;
    m.iterations = iterations;
    m.residual = residual;
    m.converged = converged;
    m.forces.resize(n);
    if (stresslets_)
    {
        m.stresslets.resize(n);
    }
    for (label p = 0; p < n; ++p)
    {
        for (direction d = 0; d < 3; ++d)
        {
            m.forces[p].F[d] = forces[nf*p + d];
            m.forces[p].T[d] = forces[nf*p + 3 + d];
        }
        if (!stresslets_)
        {
            continue;
        }
        for (label c = 0; c < 6; ++c)
        {
            m.stresslets[p].S[c] = stresslets[ns*p + c];
        }
        m.stresslets[p].trace = stresslets[ns*p + 6];
    }
    send(m.toMessage());
}
