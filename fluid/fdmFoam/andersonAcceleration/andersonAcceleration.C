#include "andersonAcceleration.H"

namespace
{
    // Partial sums of every processor added up, on every processor
    void sumOverProcessors(std::vector<double>& sums)
    {
        Foam::List<Foam::scalar> list(Foam::label(sums.size()));
        forAll(list, i)
        {
            list[i] = sums[i];
        }
        Foam::Pstream::listCombineGather(list, Foam::plusEqOp<Foam::scalar>());
        Foam::Pstream::listCombineScatter(list);
        forAll(list, i)
        {
            sums[i] = list[i];
        }
    }
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::andersonAcceleration::andersonAcceleration
(
    label depth,
    scalar lambdaScale,
    scalar pressureScale
)
:
    lambdaScale_(lambdaScale),
    pressureScale_(pressureScale),
    mixing_(depth, sumOverProcessors)
{}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

void Foam::andersonAcceleration::pack
(
    const volVectorField& U,
    const volVectorField& lambda,
    const volScalarField& p,
    scalarField& x
) const
{
    const vectorField& u = U.primitiveField();
    const vectorField& l = lambda.primitiveField();
    const scalarField& pk = p.primitiveField();
    const label n = u.size();

    x.setSize(7*n);
    for (label i = 0; i < n; ++i)
    {
        for (direction d = 0; d < 3; ++d)
        {
            x[3*i + d] = u[i][d];
            x[3*n + 3*i + d] = lambdaScale_*l[i][d];
        }
        x[6*n + i] = pressureScale_*pk[i];
    }
}


void Foam::andersonAcceleration::accelerate
(
    const scalarField& x,
    volVectorField& U,
    volVectorField& lambda,
    volScalarField& p
)
{
    scalarField& next = next_;
    pack(U, lambda, p, next);
    if (!mixing_.mix(x.cdata(), next.data(), next.size()))
    {
        return;     // no history yet: the fields already hold G(x_k)
    }

    vectorField& u = U.primitiveFieldRef();
    vectorField& l = lambda.primitiveFieldRef();
    scalarField& pk = p.primitiveFieldRef();
    const label n = u.size();
    for (label i = 0; i < n; ++i)
    {
        for (direction d = 0; d < 3; ++d)
        {
            u[i][d] = next[3*i + d];
            l[i][d] = next[3*n + 3*i + d]/lambdaScale_;
        }
        pk[i] = next[6*n + i]/pressureScale_;
    }
    U.correctBoundaryConditions();
    lambda.correctBoundaryConditions();
    p.correctBoundaryConditions();
}
