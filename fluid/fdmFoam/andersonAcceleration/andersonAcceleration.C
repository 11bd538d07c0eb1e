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
    const labelUList& lambdaCells,
    scalarField& x
) const
{
    const vectorField& u = U.primitiveField();
    const vectorField& l = lambda.primitiveField();
    const scalarField& pk = p.primitiveField();
    const label n = u.size();
    const label m = lambdaCells.size();

    // u, then lambda in the covered cells, then p: the order of the full
    // state with lambda's zeros left out, so every inner product adds the
    // same nonzero terms in the same order
    x.setSize(4*n + 3*m);
    scalar* xu = x.data();
    scalar* xl = xu + 3*n;
    scalar* xp = xl + 3*m;
    for (label i = 0; i < n; ++i)
    {
        for (direction d = 0; d < 3; ++d)
        {
            xu[3*i + d] = u[i][d];
        }
        xp[i] = pressureScale_*pk[i];
    }
    for (label j = 0; j < m; ++j)
    {
        const vector& lj = l[lambdaCells[j]];
        for (direction d = 0; d < 3; ++d)
        {
            xl[3*j + d] = lambdaScale_*lj[d];
        }
    }
}


void Foam::andersonAcceleration::accelerate
(
    const scalarField& x,
    const labelUList& lambdaCells,
    volVectorField& U,
    volVectorField& lambda,
    volScalarField& p
)
{
    scalarField& next = next_;
    pack(U, lambda, p, lambdaCells, next);
    if (!mixing_.mix(x.cdata(), next.data(), next.size()))
    {
        return;     // no history yet: the fields already hold G(x_k)
    }

    vectorField& u = U.primitiveFieldRef();
    vectorField& l = lambda.primitiveFieldRef();
    scalarField& pk = p.primitiveFieldRef();
    const label n = u.size();
    const label m = lambdaCells.size();
    const scalar* xu = next.cdata();
    const scalar* xl = xu + 3*n;
    const scalar* xp = xl + 3*m;
    for (label i = 0; i < n; ++i)
    {
        for (direction d = 0; d < 3; ++d)
        {
            u[i][d] = xu[3*i + d];
        }
        pk[i] = xp[i]/pressureScale_;
    }
    for (label j = 0; j < m; ++j)
    {
        vector& lj = l[lambdaCells[j]];
        for (direction d = 0; d < 3; ++d)
        {
            lj[d] = xl[3*j + d]/lambdaScale_;
        }
    }
    U.correctBoundaryConditions();
    lambda.correctBoundaryConditions();
    p.correctBoundaryConditions();
}
