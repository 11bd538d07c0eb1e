#include "fluidCoupling.H"
#include "Pstream.H"
#include "OSspecific.H"
#include <chrono>
#include <cstdio>

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
    nParticles_(0)
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


void Foam::fluidCoupling::handshake
(
    const uniformCartesianMesh& grid,
    label nParticlesExpected,
    scalar alphaLambda,
    scalar rhoFluid
)
{
    string problem;
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
            else if (hello.count != 1 || hello.width < cpl::layout::helloDemWidth)
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
            }

            if (problem.empty())
            {
                cpl::Message reply = cpl::makeMessage
                (
                    cpl::MessageType::Hello, 0, 0, 1,
                    cpl::layout::helloFluidWidth,
                    "role=fluid version="
                  + std::to_string(cpl::protocolVersion)
                );
                const boundBox& bb = grid.bounds();
                double* r = &reply.data[0];
                r[0] = nParticlesExpected;
                r[1] = alphaLambda;
                r[2] = rhoFluid;
                r[3] = grid.delta();
                for (direction d = 0; d < 3; ++d)
                {
                    r[4 + 2*d] = bb.min()[d];
                    r[5 + 2*d] = bb.max()[d];
                    r[10 + d] = grid.periodic()[d] ? 1 : 0;
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
    Info<< "Coupled with fdmDEM: " << nParticles_ << " particles" << endl;
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
    const List<scalar>& forces
)
{
    if (!Pstream::master())
    {
        return;
    }
    const double t0 = wallClock();
    cpl::Message m = cpl::makeMessage
    (
        cpl::MessageType::StepDone, step_, iterations,
        forces.size()/cpl::layout::stepDoneWidth,
        cpl::layout::stepDoneWidth,
        "iterations=" + std::to_string(iterations)
      + " residual=" + number(residual)
      + " converged=" + std::string(converged ? "1" : "0")
    );
    forAll(forces, i) { m.data[i] = forces[i]; }
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
