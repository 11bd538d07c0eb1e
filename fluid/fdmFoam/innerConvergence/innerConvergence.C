#include "innerConvergence.H"

const Foam::scalar Foam::innerConvergence::rhoMin_ = 0.5;
const Foam::scalar Foam::innerConvergence::rhoMax_ = 0.98;

// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::innerConvergence::innerConvergence()
:
    tolVelocity_(0),
    tolLambda_(0),
    lambdaResidual_(GREAT),
    bestLambdaResidual_(GREAT),
    flowChange_(GREAT),
    particleChange_(GREAT),
    errorEstimate_(GREAT),
    iterationsAboveOne_(0),
    lambdaNormAboveOne_(0)
{}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

void Foam::innerConvergence::reset(scalar tolVelocity, scalar tolLambda)
{
    tolVelocity_ = tolVelocity;
    tolLambda_ = tolLambda;
    changes_.clear();
    previousVelocities_.clear();
    lambdaResidual_ = flowChange_ = particleChange_ = errorEstimate_ = GREAT;
    bestLambdaResidual_ = GREAT;
    iterationsAboveOne_ = 0;
    lambdaNormAboveOne_ = 0;
}


Foam::string Foam::innerConvergence::diverging
(
    label innerIteration,
    scalar lambdaResidual,
    scalar lambdaNorm
)
{
    if (!std::isfinite(lambdaResidual))
    {
        return
            "produced a non-finite residual (" + name(lambdaResidual)
          + ") at inner iteration " + name(innerIteration)
          + ": check the time step, gradP0 and the particle forces";
    }
    bestLambdaResidual_ = min(bestLambdaResidual_, lambdaResidual);

    // geometric divergence with a bounded relative residual
    if (lambdaResidual < 1)
    {
        iterationsAboveOne_ = 0;
    }
    else if (iterationsAboveOne_++ == 0)
    {
        lambdaNormAboveOne_ = lambdaNorm;
    }
    if (iterationsAboveOne_ >= 20 && lambdaNorm > 1e3*lambdaNormAboveOne_)
    {
        return
            "is diverging: the lambda residual has stayed above 1 for "
          + name(iterationsAboveOne_) + " inner iterations (now "
          + name(lambdaResidual) + " at inner iteration "
          + name(innerIteration) + ") while |lambda| grew by "
          + name(lambdaNorm/max(lambdaNormAboveOne_, VSMALL)) + "."
            " Use the Anderson acceleration (innerIterations {"
            " acceleration anderson; }), keep meanFlowDamping above 0, or"
            " try a smaller pseudoTimeFactor in constant/fdmProperties";
    }

    // a spike
    if (innerIteration > 20 && lambdaResidual > 1e4*bestLambdaResidual_)
    {
        return
            "is diverging: residual " + name(lambdaResidual)
          + " at inner iteration " + name(innerIteration) + " after reaching "
          + name(bestLambdaResidual_)
          + " (try a smaller pseudoTimeFactor in constant/fdmProperties)";
    }
    return string::null;
}


void Foam::innerConvergence::startIteration(const volVectorField& U)
{
    flowBefore_ = U.primitiveField();
}


void Foam::innerConvergence::endIteration
(
    const volVectorField& U,
    const List<scalar>& velocities,
    const scalarList& radii,
    scalar lambdaResidual
)
{
    lambdaResidual_ = lambdaResidual;

    // max |u|, sum |u - u_before|^2 and sum |u|^2 in one loop, each sum in
    // the order gSum adds (max |u| as the root of max |u|^2: the root is
    // monotonic and correctly rounded, so the same number)
    const vectorField& u = U.primitiveField();
    scalar uMax2 = 0, sumChange2 = 0, sumU2 = 0;
    forAll(u, celli)
    {
        const scalar u2 = magSqr(u[celli]);
        uMax2 = max(uMax2, u2);
        sumChange2 += magSqr(u[celli] - flowBefore_[celli]);
        sumU2 += u2;
    }
    reduce(uMax2, maxOp<scalar>());
    reduce(sumChange2, sumOp<scalar>());
    reduce(sumU2, sumOp<scalar>());
    const scalar uMax = max(Foam::sqrt(uMax2), VSMALL);
    flowChange_ =
        Foam::sqrt(sumChange2)/max(Foam::sqrt(sumU2), VSMALL);

    // The first inner iteration of a step has no previous velocities of
    // this step to compare with: its change counts as large.
    particleChange_ = GREAT;
    if (previousVelocities_.size() == velocities.size())
    {
        particleChange_ = 0;
        forAll(radii, p)
        {
            for (direction d = 0; d < 3; ++d)
            {
                particleChange_ = max
                (
                    particleChange_,
                    max
                    (
                        mag(velocities[6*p + d] - previousVelocities_[6*p + d]),
                        radii[p]
                       *mag(velocities[6*p + 3 + d] - previousVelocities_[6*p + 3 + d])
                    )/uMax
                );
            }
        }
    }
    previousVelocities_ = velocities;

    const label k = changes_.size();
    changes_.append(max(flowChange_, particleChange_));

    // Mean contraction over the last four iterations (two early in the
    // step): the accelerated iteration is not monotone from one iteration
    // to the next
    scalar rho = rhoMax_;
    const label span = min(k, label(4));
    if (span >= 2 && changes_[k - span] > 0)
    {
        rho = Foam::pow(changes_[k]/changes_[k - span], 1.0/span);
    }
    rho = min(max(rho, rhoMin_), rhoMax_);
    const scalar last = k >= 1 ? max(changes_[k], changes_[k - 1]) : changes_[k];
    errorEstimate_ = last*rho/(1 - rho);
}


bool Foam::innerConvergence::converged() const
{
    const bool velocityOk = tolVelocity_ <= 0 || errorEstimate_ <= tolVelocity_;
    const bool lambdaOk = tolLambda_ <= 0 || lambdaResidual_ <= tolLambda_;
    return velocityOk && lambdaOk;
}
