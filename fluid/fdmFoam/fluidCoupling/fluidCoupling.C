#include "fluidCoupling.H"
#include "Pstream.H"
#include "OSspecific.H"
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>

namespace cpl = fdm::coupler;

namespace
{
    double wallClock()
    {
        using namespace std::chrono;
        return duration<double>(steady_clock::now().time_since_epoch()).count();
    }

    std::string number(double x)
    {
        char buf[32];
        std::snprintf(buf, sizeof(buf), "%.17g", x);
        return buf;
    }

    Foam::List<Foam::scalar> toList(const std::vector<double>& v)
    {
        Foam::List<Foam::scalar> l(v.size());
        forAll(l, i) { l[i] = v[i]; }
        return l;
    }

    // A 0|1 flag of a peer's text, read tolerantly: any number equal to 0 or
    // 1, or true/false, yes/no, on/off in any case. False if it is none.
    bool readFlag(std::string v, bool& flag)
    {
        for (char& c : v)
        {
            c = char(std::tolower(static_cast<unsigned char>(c)));
        }
        if (v == "true" || v == "yes" || v == "on") { flag = true; return true; }
        if (v == "false" || v == "no" || v == "off") { flag = false; return true; }
        char* end = nullptr;
        const double x = std::strtod(v.c_str(), &end);
        if (v.empty() || *end != '\0' || (x != 0 && x != 1))
        {
            return false;
        }
        flag = (x == 1);
        return true;
    }

    const char* boxFaceName[6] = {"xlo", "xhi", "ylo", "yhi", "zlo", "zhi"};
    const char* boundaryKindName[4] = {"cyclic", "wall", "slip", "other"};
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::fluidCoupling::fluidCoupling(const Time& runTime, const dictionary& dict)
:
    runTime_(runTime),
    transport_(),
    exchangeTime_(0),
    step_(-1),
    lastStep_(-1),
    dt_(0),
    nParticles_(0),
    stresslets_(false)
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


Foam::List<Foam::scalar> Foam::fluidCoupling::boxFaces
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
    List<scalar> result(layout::nFaces*layout::faceWidth, 0.0);
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
        scalar* rec = &result[layout::faceWidth*f];
        rec[layout::fKind] = k;
        rec[layout::fUx] = Uw.x();
        rec[layout::fUy] = Uw.y();
        rec[layout::fUz] = Uw.z();
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
    scalar eta
)
{
    namespace layout = cpl::layout;

    // Collective: every processor, before the master talks
    string boundaryProblem;
    const List<scalar> faces = boxFaces(grid, U, boundaryProblem);

    string problem;
    label stresslets = 0;
    if (Pstream::master())
    {
        const double t0 = wallClock();
        try
        {
            cpl::Message hello = transport_->receive(cpl::MessageType::Hello);
            const int version = int(hello.textNumber("version"));
            if (version != cpl::protocolVersion)
            {
                problem = "coupling protocol version mismatch: fdmDEM speaks "
                    + Foam::name(version) + ", fdmFoam speaks "
                    + Foam::name(label(cpl::protocolVersion));
            }
            else if (hello.count != 1 || hello.width < layout::helloDemWidth)
            {
                problem = "malformed Hello from fdmDEM";
            }
            else
            {
                nParticles_ = label(hello.at(0, 0));
                const boundBox& bb = grid.bounds();
                const char* axis = "xyz";
                for (direction d = 0; d < 3 && problem.empty(); ++d)
                {
                    const scalar lo = hello.at(0, 1 + 2*d);
                    const scalar hi = hello.at(0, 2 + 2*d);
                    const scalar tol = 1e-9*max(mag(bb.span()[d]), 1.0);
                    const bool periodic = hello.at(0, 7 + d) != 0;
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

                // Protocol 2 always says whether StepDone carries stresslets
                std::string value;
                bool found = true, flag = false;
                try
                {
                    value = hello.textValue("stresslets");
                }
                catch (const cpl::CouplerError&)
                {
                    found = false;
                }
                if (problem.empty() && !found)
                {
                    problem = "the Hello of fdmDEM has no stresslets= entry"
                        " (text: \"" + hello.text + "\"), which coupling"
                        " protocol " + Foam::name(label(cpl::protocolVersion))
                      + " requires";
                }
                else if (problem.empty() && !readFlag(value, flag))
                {
                    problem = "the Hello of fdmDEM says stresslets=" + value
                      + ", which is not 0 or 1";
                }
                stresslets = flag ? 1 : 0;
            }
            if (problem.empty())
            {
                problem = boundaryProblem;
            }

            if (problem.empty())
            {
                cpl::Message reply = cpl::makeMessage
                (
                    cpl::MessageType::Hello, 0, 0, 1,
                    layout::helloFluidWidth,
                    "role=fluid version="
                  + std::to_string(cpl::protocolVersion)
                );
                const boundBox& bb = grid.bounds();
                double* r = &reply.data[0];
                r[layout::hfNParticles] = nParticlesExpected;
                r[layout::hfAlphaLambda] = alphaLambda;
                r[layout::hfRhoFluid] = rhoFluid;
                r[layout::hfDelta] = grid.delta();
                for (direction d = 0; d < 3; ++d)
                {
                    r[layout::hfXlo + 2*d] = bb.min()[d];
                    r[layout::hfXlo + 2*d + 1] = bb.max()[d];
                    r[layout::hfPeriodic + d] = grid.periodic()[d] ? 1 : 0;
                }
                r[layout::hfViscosity] = eta;
                forAll(faces, i)
                {
                    r[layout::hfFaceBase + i] = faces[i];
                }
                transport_->send(reply);
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
    stresslets_ = stresslets != 0;

    Info<< "Coupled with fdmDEM: " << nParticles_ << " particles, "
        << (stresslets_ ? "with" : "without") << " stresslets" << nl
        << "    box faces (for the particle code):";
    for (label f = 0; f < label(layout::nFaces); ++f)
    {
        const scalar* rec = &faces[layout::faceWidth*f];
        const label k = label(rec[layout::fKind]);
        Info<< ' ' << boxFaceName[f] << ' ' << boundaryKindName[k];
        if (k == layout::bWall)
        {
            Info<< ' '
                << vector(rec[layout::fUx], rec[layout::fUy], rec[layout::fUz]);
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


bool Foam::fluidCoupling::receiveStep(List<fdmParticle>& particles)
{
    List<scalar> data;
    label finished = 0;
    label lastStep = lastStep_;
    label step = step_;
    scalar dt = dt_;

    if (Pstream::master())
    {
        cpl::Message m = receive();
        if (m.type == cpl::MessageType::Finish)
        {
            finished = 1;
        }
        else if (m.type != cpl::MessageType::Step)
        {
            fatal
            (
                string("coupling: expected Step or Finish from fdmDEM, got ")
              + cpl::messageTypeName(m.type)
            );
        }
        else if
        (
            label(m.count) != nParticles_
         || m.width != cpl::layout::stepWidth
        )
        {
            fatal
            (
                "coupling: fdmDEM sent " + Foam::name(label(m.count))
              + " particles in step " + Foam::name(label(m.step))
              + " but announced " + Foam::name(nParticles_)
              + " at the handshake"
            );
        }
        else
        {
            step = label(m.step);
            dt = m.textNumber("dt");
            lastStep = label(m.textNumber("lastStep"));
            data = toList(m.data);
        }
    }

    Pstream::scatter(finished);
    if (finished)
    {
        return false;
    }
    Pstream::scatter(data);
    Pstream::scatter(step);
    Pstream::scatter(dt);
    Pstream::scatter(lastStep);
    step_ = step;
    dt_ = dt;
    lastStep_ = lastStep;

    const label w = cpl::layout::stepWidth;
    particles.setSize(data.size()/w);
    forAll(particles, p)
    {
        const scalar* rec = &data[w*p];
        fdmParticle& part = particles[p];
        part.tag = label(rec[cpl::layout::sTag]);
        part.x = point(rec[cpl::layout::sX], rec[cpl::layout::sY], rec[cpl::layout::sZ]);
        part.radius = rec[cpl::layout::sRadius];
        part.U = vector(rec[cpl::layout::sUx], rec[cpl::layout::sUy], rec[cpl::layout::sUz]);
        part.omega = vector(rec[cpl::layout::sWx], rec[cpl::layout::sWy], rec[cpl::layout::sWz]);
    }
    return true;
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
    const double t0 = wallClock();
    cpl::Message m = cpl::makeMessage
    (
        cpl::MessageType::Integrals, step_, iteration,
        integrals.size()/cpl::layout::integralsWidth,
        cpl::layout::integralsWidth
    );
    forAll(integrals, i) { m.data[i] = integrals[i]; }
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


Foam::List<Foam::scalar> Foam::fluidCoupling::receiveVelocities(label iteration)
{
    List<scalar> data;
    if (Pstream::master())
    {
        cpl::Message m = receive();
        if (m.type != cpl::MessageType::Velocities)
        {
            fatal
            (
                string("coupling: expected Velocities from fdmDEM, got ")
              + cpl::messageTypeName(m.type)
            );
        }
        if
        (
            label(m.count) != nParticles_
         || m.width != cpl::layout::velocitiesWidth
         || label(m.step) != step_
         || label(m.iteration) != iteration
        )
        {
            fatal
            (
                "coupling: fdmDEM sent velocities for " + Foam::name(label(m.count))
              + " particles (step " + Foam::name(label(m.step)) + ", iteration "
              + Foam::name(label(m.iteration)) + ") where "
              + Foam::name(nParticles_) + " particles (step " + Foam::name(step_)
              + ", iteration " + Foam::name(iteration) + ") were expected"
            );
        }
        data = toList(m.data);
        forAll(data, i)
        {
            if (!std::isfinite(data[i]))
            {
                fatal
                (
                    "fdmDEM returned a non-finite velocity for particle "
                  + Foam::name(i/cpl::layout::velocitiesWidth + 1)
                  + " at step " + Foam::name(step_) + ", inner iteration "
                  + Foam::name(iteration)
                );
            }
        }
    }
    Pstream::scatter(data);
    return data;
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
    namespace layout = cpl::layout;
    const label nf = layout::stepDoneWidth;                         // F, T
    const label ns = layout::stepDoneStressWidth - layout::stepDoneWidth; // S, s
    const label n = forces.size()/nf;
    if (stresslets_ && stresslets.size() != ns*n)
    {
        FatalErrorInFunction
            << "stresslets of " << stresslets.size()/ns << " particles for "
            << n << " forces" << abort(FatalError);
    }

    const double t0 = wallClock();
    const label width =
        stresslets_ ? layout::stepDoneStressWidth : layout::stepDoneWidth;
    cpl::Message m = cpl::makeMessage
    (
        cpl::MessageType::StepDone, step_, iterations, n, width,
        "iterations=" + std::to_string(iterations)
      + " residual=" + number(residual)
      + " converged=" + std::string(converged ? "1" : "0")
    );
    for (label p = 0; p < n; ++p)
    {
        for (label k = 0; k < nf; ++k)
        {
            m.at(p, layout::dFx + k) = forces[nf*p + k];
        }
        for (label k = 0; stresslets_ && k < ns; ++k)
        {
            m.at(p, layout::dSxx + k) = stresslets[ns*p + k];
        }
    }
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
