#include "andersonAcceleration.H"

// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::andersonAcceleration::andersonAcceleration
(
    label depth,
    scalar lambdaScale,
    scalar pressureScale
)
:
    depth_(depth),
    lambdaScale_(lambdaScale),
    pressureScale_(pressureScale),
    havePrevious_(false),
    dropped_(0)
{}


// * * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

Foam::List<Foam::scalar> Foam::andersonAcceleration::coefficients
(
    const scalarField& f
)
{
    while (!dF_.empty())
    {
        const label m = dF_.size();

        // Gram matrix and right-hand side in one reduction
        List<scalar> sums(m*m + m, 0.0);
        for (label i = 0; i < m; ++i)
        {
            for (label j = i; j < m; ++j)
            {
                sums[i*m + j] = sum(dF_[i]*dF_[j]);
            }
            sums[m*m + i] = sum(dF_[i]*f);
        }
        Pstream::listCombineGather(sums, plusEqOp<scalar>());
        Pstream::listCombineScatter(sums);

        // Scale the columns to unit norm, then Cholesky A = L L^T
        List<scalar> scale(m), L(m*m, 0.0);
        bool usable = true;
        for (label i = 0; i < m; ++i)
        {
            scale[i] = Foam::sqrt(max(sums[i*m + i], VSMALL));
        }
        for (label i = 0; i < m && usable; ++i)
        {
            for (label j = 0; j <= i; ++j)
            {
                scalar a = sums[min(i, j)*m + max(i, j)]/(scale[i]*scale[j]);
                for (label k = 0; k < j; ++k)
                {
                    a -= L[i*m + k]*L[j*m + k];
                }
                if (i == j)
                {
                    // A pivot this small: the new column is (nearly) a
                    // combination of the others
                    if (a < 1e-10)
                    {
                        usable = false;
                        break;
                    }
                    L[i*m + i] = Foam::sqrt(a);
                }
                else
                {
                    L[i*m + j] = a/L[j*m + j];
                }
            }
        }

        if (!usable)
        {
            dF_.pop_front();
            dG_.pop_front();
            ++dropped_;
            continue;
        }

        // Forward and back substitution
        List<scalar> y(m), gamma(m);
        for (label i = 0; i < m; ++i)
        {
            scalar s = sums[m*m + i]/scale[i];
            for (label k = 0; k < i; ++k)
            {
                s -= L[i*m + k]*y[k];
            }
            y[i] = s/L[i*m + i];
        }
        for (label i = m - 1; i >= 0; --i)
        {
            scalar s = y[i];
            for (label k = i + 1; k < m; ++k)
            {
                s -= L[k*m + i]*gamma[k];
            }
            gamma[i] = s/L[i*m + i];
        }
        forAll(gamma, i)
        {
            gamma[i] /= scale[i];
        }
        return gamma;
    }
    return List<scalar>();
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

void Foam::andersonAcceleration::reset()
{
    dG_.clear();
    dF_.clear();
    previousG_.clear();
    previousF_.clear();
    havePrevious_ = false;
    dropped_ = 0;
}


Foam::tmp<Foam::scalarField> Foam::andersonAcceleration::pack
(
    const volVectorField& U,
    const volVectorField& lambda,
    const volScalarField& p
) const
{
    const vectorField& u = U.primitiveField();
    const vectorField& l = lambda.primitiveField();
    const scalarField& pk = p.primitiveField();
    const label n = u.size();

    tmp<scalarField> tx(new scalarField(7*n));
    scalarField& x = tx.ref();
    for (label i = 0; i < n; ++i)
    {
        for (direction d = 0; d < 3; ++d)
        {
            x[3*i + d] = u[i][d];
            x[3*n + 3*i + d] = lambdaScale_*l[i][d];
        }
        x[6*n + i] = pressureScale_*pk[i];
    }
    return tx;
}


void Foam::andersonAcceleration::accelerate
(
    const scalarField& x,
    volVectorField& U,
    volVectorField& lambda,
    volScalarField& p
)
{
    const scalarField G(pack(U, lambda, p));
    const scalarField f(G - x);

    if (havePrevious_)
    {
        dG_.push_back(scalarField(G - previousG_));
        dF_.push_back(scalarField(f - previousF_));
        if (label(dF_.size()) > depth_)
        {
            dG_.pop_front();
            dF_.pop_front();
        }
    }
    previousG_ = G;
    previousF_ = f;
    havePrevious_ = true;

    const List<scalar> gamma = coefficients(f);
    if (gamma.empty())
    {
        return;     // the plain step: the fields already hold G(x_k)
    }

    scalarField next(G);
    forAll(gamma, j)
    {
        next -= gamma[j]*dG_[j];
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
