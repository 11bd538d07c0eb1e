/*---------------------------------------------------------------------------*\
    fdmFoam: fictitious-domain Stokes solver with sub-grid corrections
    (Orsi, Lobry & Peters, J. Comput. Phys. 474, 2023)

Application
    fdmFoam

Description
    Steady Stokes flow (Eqs. 28a-b) on a uniform Cartesian mesh with rigid
    particles enforced by direct forcing (Eqs. 29, 33, 38), coupled every inner
    iteration to the particle code fdmDEM (LIGGGHTS), which solves Eq. (31)
    for the particle velocities and moves the particles.

    Per time step (section 4.3): receive the particle positions (step 1),
    truncate lambda outside the particles (2), then repeat until the lambda
    residual is below tolLambda: PISO solve for u*, p (3); send the particle
    integrals, receive U_p, Omega_p (4); correct lambda (5) and u (6).

    The particle code drives time: fdmFoam runs until it sends Finish.

Usage
    fdmFoam [-parallel] [-case dir]   (start it before fdmDEM; see scripts/fdmRun)
    fdmFoam -postProcess [-func name] [-latestTime]   (function objects on a
        finished case; those of system/controlDict also run during a run)
    fdmFoam -resume STEP   (continue from the checkpoint of DEM step STEP,
        checkpoint/fluid.STEP, with fdmDEM -resume; fdmRun --resume does both)

\*---------------------------------------------------------------------------*/

#include "fvCFD.H"
#include "pisoControl.H"
#include "OFstream.H"
#include "OStringStream.H"
#include "emptyFvPatch.H"
#include "fixedValueFvPatchFields.H"
#include "slipFvPatchFields.H"
#include "uniformCartesianMesh.H"
#include "particleForcing.H"
#include "fluidCoupling.H"
#include "andersonAcceleration.H"
#include "innerConvergence.H"
#include "fluidCheckpoint.H"
#include "meanFlowCorrection.H"
#include "runProfile.H"
#include "fieldKernels.H"
#include <chrono>

namespace
{
    //- What the construction of an fvMatrix does to its field first (the
    //  matrices of UEqn.H and pEqn.H are kept, not constructed again): the
    //  patches' coefficients updated, its event number left as it was
    template<class Type>
    void updatePatchCoeffs(Foam::GeometricField<Type, Foam::fvPatchField, Foam::volMesh>& psi)
    {
        const Foam::label eventNo = psi.eventNo();
        psi.boundaryFieldRef().updateCoeffs();
        psi.eventNo() = eventNo;
    }

    double wallClock()
    {
        using namespace std::chrono;
        return duration<double>(steady_clock::now().time_since_epoch()).count();
    }
}

// * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * //

int main(int argc, char *argv[])
{
    argList::addNote
    (
        "Fictitious-domain Stokes solver for particle suspensions, coupled to"
        " the particle code fdmDEM (LIGGGHTS) through the fdm coupler."
    );

    argList::addOption
    (
        "resume", "step",
        "continue from the checkpoint of this DEM step (checkpoint/fluid.<step>;"
        " fdmRun --resume)"
    );

    // fdmFoam -postProcess -func ...: the function objects on a finished case
    // (createFields.H needs the PISO controls, not fdmProperties)
    #define CREATE_CONTROL createPisoControl.H
    #include "postProcess.H"

    #include "setRootCaseLists.H"
    #include "createTime.H"
    #include "createMesh.H"

    pisoControl piso(mesh);

    // -resume STEP: the time of the checkpoint, before the fields are read
    #include "resumeCheckpoint.H"

    #include "createFields.H"
    #include "readFdmProperties.H"

    particleForcing forcing
    (
        grid, indicatorB, indicatorC, alphaLambda, rho.value()
    );

    fluidCoupling coupling(runTime, fdmProperties.subOrEmptyDict("coupling"));
    coupling.handshake
    (
        grid, U, nParticlesExpected, alphaLambda, rho.value(),
        rho.value()*nu.value(),     // eta
        label(resumed.step),
        gradP0.value()
    );

    meanFlowCorrection meanFlow
    (
        grid, U, nu.value(), correctMeanFlow, meanFlowDamping
    );
    Info<< meanFlow.description().c_str() << endl;

    #include "createOutput.H"

    // The inner iteration's acceleration and its stopping test
    andersonAcceleration anderson
    (
        andersonDepth, alphaLambda, alphaLambda/grid.delta()
    );
    innerConvergence convergence;
    scalarList radii;

    scalar fluidTime = 0, particleTime = 0, outputTime = 0, checkpointTime = 0;
    // the inner iteration's parts, printed at the end of the run
    fdm::runProfile profile;
    label nStepsDone = 0, nInnerTotal = 0;
    // steps of the run before this session (a resumed run continues its count)
    const label stepsBefore = label(resumed.stepsDone);
    label lastCheckpoint = -1;
    label sessionFirstStep = -1;    // the DEM step of this session's first Step
    const double runStart = wallClock();
    // waiting for the particle code to connect is not part of the run
    const scalar exchangeBeforeRun = coupling.exchangeTime();
    // where the last step's exchange ended: a step's exchange (steps.dat)
    // begins there, so that it holds the wait for this step's particles too,
    // i.e. the particle steps between fluid steps (fix fdm/couple fluid_every
    // K) and the particle code's own step, and the records' seconds sum to
    // the run's time
    scalar exchangeMark = exchangeBeforeRun;
    List<fdmParticle> stepParticles;

    // The function objects of system/controlDict. fdmDEM drives time, so
    // instead of runTime.run() the loop calls what it would: start() before
    // the first step, execute() after each step, end() after the last.
    // In a box whose faces are all periodic or slip no wall holds the fluid
    // along the periodic directions (a slip wall takes no tangential force):
    // a steady Stokes flow under gradP0 exists only if the particles carry
    // its force, V0 gradP0 along them (Eq. 43; an external force: move no
    // fixes the places, not the velocities). Checked at converged steps;
    // otherwise the mean flow grows by gradP0 alpha_lambda/rho per inner
    // iteration, which the divergence message then names
    bool noWallHolds = true;
    forAll(mesh.boundary(), patchi)
    {
        const fvPatch& patch = mesh.boundary()[patchi];
        if
        (
            !patch.coupled() && !isA<emptyFvPatch>(patch)
         && !isA<slipFvPatchVectorField>(U.boundaryField()[patchi])
        )
        {
            noWallHolds = false;
        }
    }
    const bool unheldGradient = noWallHolds && mag(gradP0.value()) > 0;
    const scalar boxVolume = gSum(mesh.V());

    runTime.functionObjects().start();

    Info<< nl << "Starting time loop (driven by fdmDEM)" << nl << endl;

    while (coupling.receiveStep(stepParticles))
    {
        const double stepStart = wallClock();
        if (sessionFirstStep < 0)
        {
            sessionFirstStep = coupling.step();
        }
        scalar stepFluidTime = 0, stepParticleTime = 0;

        // Step 1: particles moved by the DEM side
        const string outside = forcing.checkInsideDomain(stepParticles);
        if (!outside.empty())
        {
            coupling.fatal(outside + " at time step " + name(coupling.step()));
        }
        forcing.setParticles(stepParticles);
        runTime.setDeltaT(coupling.dt());
        // The time index is the DEM step, also where the fluid solves only
        // every K-th one (fix fdm/couple ... fluid_every K: the step then
        // spans K of them): writeInterval and the function objects count DEM
        // steps, and a write time is one of the particles' output steps
        runTime.setTime(runTime.value(), label(coupling.step()) - 1);
        ++runTime;

        // Step 2
        forcing.truncateLambda(lambda);
        forcing.pseudoTimeCoefficient(rDTau, rDTauInside, rDTauOutside);
        rAUCurrent = false;     // matrixCache.H: the matrices for this rDTau
        meanFlow.setForcedCells(forcing.covered());
        stepParticleTime += wallClock() - stepStart;

        // the run's first step, or the first after a compact snapshot's
        // restart from rest (fluidCheckpoint::fromRest)
        const bool firstStep = resumed.firstStep(nStepsDone);
        const label nMax = firstStep ? nInnerMaxFirst : nInnerMax;
        convergence.reset
        (
            firstStep ? tolVelocityFirst : tolVelocity,
            firstStep ? tolLambdaFirst : tolLambda
        );
        anderson.reset();       // the map has changed with the positions
        radii.setSize(stepParticles.size());
        forAll(stepParticles, pi)
        {
            radii[pi] = stepParticles[pi].radius;
        }

        label innerIteration = 0;
        scalar residual = GREAT;
        bool converged = false;
        List<scalar> integrals, velocities;
        scalarField state;

        while (true)
        {
            ++innerIteration;
            double t0 = wallClock();
            profile.start();
            if (accelerate)
            {
                anderson.pack(U, lambda, p, forcing.coveredCells(), state);
                profile.lap("Anderson mixing");
            }
            convergence.startIteration(U);
            profile.lap("convergence test");

            // Step 3: fluid sub-problem
            {
                #include "UEqn.H"
                while (piso.correct())
                {
                    #include "pEqn.H"
                }
            }
            // The slowest modes, the plane-averaged channel profile, solved
            // exactly (meanFlowCorrection.H)
            meanFlow.correct(U, lambda, gradP0.value()/rho.value());
            profile.lap("mean-flow correction");
            double t1 = wallClock();
            stepFluidTime += t1 - t0;

            // Step 4: particle velocities from the DEM side (Eq. 31)
            integrals = forcing.integrals(U, lambda);
            profile.lap("particle integrals");
            stepParticleTime += wallClock() - t1;
            coupling.sendIntegrals(innerIteration, integrals);
            velocities = coupling.receiveVelocities(innerIteration);
            profile.lap("exchange + DEM");

            // Steps 5-6: correct lambda and u (Eq. 38)
            t0 = wallClock();
            residual = forcing.correct(U, lambda, velocities);
            profile.lap("lambda and u correction");
            stepParticleTime += wallClock() - t0;

            const string divergence =
                convergence.diverging(innerIteration, residual, forcing.lambdaNorm());
            if (!divergence.empty())
            {
                OStringStream msg;
                msg << "the lambda iteration at time step " << coupling.step()
                    << " " << divergence.c_str();
                if (unheldGradient)
                {
                    msg << ". No wall holds the fluid in this box (its faces"
                        << " are periodic or slip): under gradP0 "
                        << gradP0.value() << " Pa/m a steady flow exists only"
                        << " if the particles carry V0 gradP0 = "
                        << boxVolume*gradP0.value() << " N (Eq. 43; fix"
                        << " addforce)";
                }
                coupling.fatal(msg.str());
            }
            convergence.endIteration(U, velocities, radii, residual);
            profile.lap("convergence test");
            if (reportIterations)
            {
                Info<< "    inner " << innerIteration << " residual lambda "
                    << residual << " |lambda| " << forcing.lambdaNorm()
                    << " flow change "
                    << convergence.flowChange() << " particle change "
                    << convergence.particleChange() << " velocity error "
                    << convergence.errorEstimate() << " mean-flow change "
                    << meanFlow.lastChange() << endl;
            }

            converged = innerIteration >= nInnerMin && convergence.converged();
            if (converged || innerIteration >= nMax)
            {
                break;
            }

            // Step 7 with Anderson acceleration: the next iterate mixes the
            // last ones (andersonAcceleration.H). Every mixed state has
            // lambda = 0 outside the particles, so the mixture has too.
            if (accelerate)
            {
                t0 = wallClock();
                profile.start();
                anderson.accelerate(state, forcing.coveredCells(), U, lambda, p);
                profile.lap("Anderson mixing");
                stepFluidTime += wallClock() - t0;
            }
        }

        if (converged && unheldGradient)
        {
            // Eq. (43) at a converged step, before anything of it is written
            // (fix fdm/couple checks the particles' forces before the step
            // in a periodic box; this also sees slip walls), along the
            // periodic directions (slip walls take the normal force)
            const vector lambdaForce =
                -rho.value()*gSum(lambda.primitiveField()*mesh.V());
            const vector imposed = boxVolume*gradP0.value();
            vector mismatch = lambdaForce + imposed;
            for (direction d = 0; d < vector::nComponents; ++d)
            {
                if (!grid.periodic()[d])
                {
                    mismatch[d] = 0;
                }
            }
            if (mag(mismatch) > 0.1*mag(imposed))
            {
                OStringStream msg;
                msg << "constant/fdmProperties: gradP0 " << gradP0.value()
                    << " Pa/m in a box whose faces are periodic or slip (no"
                    << " wall holds the fluid) has no steady Stokes flow"
                    << " unless the particles carry its force, V0 gradP0 = "
                    << imposed << " N (Eq. 43); at time step "
                    << coupling.step() << " the lambda force on the liquid is "
                    << lambdaForce << " N. Give the particles that external"
                    << " force (fix addforce; move no fixes their places, not"
                    << " their velocities), or bound the flow with walls";
                coupling.fatal(msg.str());
            }
        }

        const double tEnd = wallClock();
        List<scalar> hydroForces = forcing.hydrodynamicForces(lambda);
        List<scalar> stresslets;
        if (coupling.stresslets())
        {
            // Eq. (12) from the last lambda and p, only when fdmDEM asks
            stresslets = forcing.stresslets(lambda, p);
        }
        stepParticleTime += wallClock() - tEnd;
        // (the coupling times the send itself, as exchange)
        coupling.sendStepDone
        (
            innerIteration, residual, converged, hydroForces, stresslets
        );
        const scalar stepExchangeTime = coupling.exchangeTime() - exchangeMark;
        exchangeMark = coupling.exchangeTime();

        const double tOut = wallClock();
        #include "writeStepOutput.H"
        runTime.functionObjects().execute();
        outputTime += wallClock() - tOut;

        if (coupling.checkpoint())
        {
            const double tCheckpoint = wallClock();
            #include "writeCheckpoint.H"
            checkpointTime += wallClock() - tCheckpoint;
            lastCheckpoint = coupling.step();
        }

        ++nStepsDone;
        nInnerTotal += innerIteration;
        fluidTime += stepFluidTime;
        particleTime += stepParticleTime;

        // the ETA per DEM step: with fix fdm/couple ... fluid_every K the
        // fluid solves only every K-th of them
        const scalar elapsed = wallClock() - runStart;
        const label remaining = max(label(0), coupling.lastStep() - coupling.step());
        const label demStepsDone = max(label(1), coupling.step() - sessionFirstStep + 1);
        Info<< "Step " << coupling.step() << " t = " << runTime.timeName()
            << "  inner " << innerIteration << "  residual lambda " << residual
            << "  velocity error " << convergence.errorEstimate()
            << (converged ? "" : " (NOT converged)")
            << "  | fluid " << stepFluidTime << " s, particles "
            << stepParticleTime << " s, exchange " << stepExchangeTime
            << " s | ETA " << remaining*elapsed/demStepsDone << " s" << endl;

        if (!converged)
        {
            WarningInFunction
                << "time step " << coupling.step() << ": not converged after "
                << innerIteration << " inner iterations (nMax): velocity "
                << "error " << convergence.errorEstimate() << " (tolVelocity "
                << convergence.tolVelocity() << "), lambda residual "
                << residual << " (tolLambda " << convergence.tolLambda()
                << ")" << endl;
        }
    }

    // Final state, so that a run can be restarted from it (unless the last
    // step's checkpoint holds it: its binary fields stay as they are)
    forcing.indicator(particleIndicator);
    if (lastCheckpoint >= 0 && lastCheckpoint == coupling.step())
    {
        particleIndicator.write();
    }
    else
    {
        runTime.writeNow();
    }
    runTime.functionObjects().end();

    const scalar total = wallClock() - runStart;
    const scalar exchange = coupling.exchangeTime() - exchangeBeforeRun;
    auto pct = [total](scalar t) { return 100*t/max(total, VSMALL); };
    Info<< nl << "fdmFoam time breakdown (" << nStepsDone << " steps, "
        << nInnerTotal << " inner iterations, " << total << " s wall):" << nl
        << "    fluid solve      " << fluidTime << " s (" << pct(fluidTime) << " %)" << nl
        << "    particle forcing " << particleTime << " s (" << pct(particleTime) << " %)" << nl
        << "    exchange + DEM   " << exchange << " s (" << pct(exchange) << " %)" << nl
        << "    output           " << outputTime << " s (" << pct(outputTime) << " %)" << nl;
    if (coupling.checkpointEvery() > 0)
    {
        Info<< "    checkpoints      " << checkpointTime << " s ("
            << pct(checkpointTime) << " %; every "
            << coupling.checkpointEvery() << " steps and at the end)" << nl;
    }
    Info<< "fdmFoam momentum and pressure matrices assembled at "
        << nMatrixAssemblies << " of " << nStepsDone << " steps (when the"
        << " pseudo-time coefficient or a wall velocity changed)" << nl;
    Info<< "fdmFoam inner iterations by part (" << nInnerTotal << " inner iterations, "
        << profile.total() << " s):" << nl
        << profile.report(profile.total(), nInnerTotal, "iteration").c_str() << endl;

    Info<< "End\n" << endl;
    return 0;
}
