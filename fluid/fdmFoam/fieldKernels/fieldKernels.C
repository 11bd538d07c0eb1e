#include "fieldKernels.H"

// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

void Foam::fieldKernels::grad
(
    const volScalarField& p,
    vectorField& gradp
) const
{
    const labelUList& owner = mesh_.owner();
    const labelUList& neighbour = mesh_.neighbour();
    const vectorField& Sf = mesh_.Sf();
    const scalarField& w = mesh_.weights();
    const scalarField& pi = p.primitiveField();

    gradp.setSize(pi.size());
    gradp = Zero;

    // Internal faces: the linear face value times Sf
    forAll(owner, facei)
    {
        const label P = owner[facei];
        const label N = neighbour[facei];
        const scalar pf = w[facei]*(pi[P] - pi[N]) + pi[N];
        const vector Sfssf = Sf[facei]*pf;
        gradp[P] += Sfssf;
        gradp[N] -= Sfssf;
    }

    // Boundary faces: coupled ones interpolated across (the same field
    // expressions as the interpolation scheme), the others the patch values
    forAll(mesh_.boundary(), patchi)
    {
        const labelUList& faceCells = mesh_.boundary()[patchi].faceCells();
        const vectorField& pSf = mesh_.Sf().boundaryField()[patchi];
        const fvPatchScalarField& pp = p.boundaryField()[patchi];
        if (pp.coupled())
        {
            const scalarField& pLambda = mesh_.weights().boundaryField()[patchi];
            const scalarField pf
            (
                pLambda*pp.patchInternalField()
              + (1.0 - pLambda)*pp.patchNeighbourField()
            );
            forAll(faceCells, facei)
            {
                gradp[faceCells[facei]] += pSf[facei]*pf[facei];
            }
        }
        else
        {
            forAll(faceCells, facei)
            {
                gradp[faceCells[facei]] += pSf[facei]*pp[facei];
            }
        }
    }

    gradp /= mesh_.V();
}


void Foam::fieldKernels::divTimesVolume
(
    const surfaceScalarField& phi,
    scalarField& s
) const
{
    const labelUList& owner = mesh_.owner();
    const labelUList& neighbour = mesh_.neighbour();
    const scalarField& phiI = phi.primitiveField();

    s.setSize(mesh_.nCells());
    s = Zero;
    forAll(owner, facei)
    {
        s[owner[facei]] += phiI[facei];
        s[neighbour[facei]] -= phiI[facei];
    }
    forAll(mesh_.boundary(), patchi)
    {
        const labelUList& faceCells = mesh_.boundary()[patchi].faceCells();
        const fvsPatchScalarField& pphi = phi.boundaryField()[patchi];
        forAll(faceCells, facei)
        {
            s[faceCells[facei]] += pphi[facei];
        }
    }

    // fvc::div divides by V, the matrix source multiplies by it again
    const scalarField& V = mesh_.V();
    forAll(s, celli)
    {
        s[celli] = V[celli]*(s[celli]/V[celli]);
    }
}
