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


void Foam::fieldKernels::boundaryDiag
(
    const fvVectorMatrix& UEqn,
    vectorField& bd
) const
{
    // fvMatrix::H: addBoundaryDiag, negate, addCmptAvBoundaryDiag, per
    // component
    bd.setSize(mesh_.nCells());
    bd = Zero;
    forAll(UEqn.internalCoeffs(), patchi)
    {
        const labelUList& faceCells = mesh_.boundary()[patchi].faceCells();
        const vectorField& ic = UEqn.internalCoeffs()[patchi];
        forAll(faceCells, facei)
        {
            bd[faceCells[facei]] += ic[facei];
        }
    }
    bd = -bd;
    forAll(UEqn.internalCoeffs(), patchi)
    {
        const labelUList& faceCells = mesh_.boundary()[patchi].faceCells();
        const vectorField& ic = UEqn.internalCoeffs()[patchi];
        forAll(faceCells, facei)
        {
            const scalar av = cmptAv(ic[facei]);
            vector& b = bd[faceCells[facei]];
            for (direction d = 0; d < 3; ++d)
            {
                b[d] += av;
            }
        }
    }
}


void Foam::fieldKernels::HbyA
(
    const fvVectorMatrix& UEqn,
    const vectorField& bd,
    const volScalarField& rAU,
    vectorField& H,
    volVectorField& HbyA
) const
{
    const volVectorField& U = UEqn.psi();
    const vectorField& u = U.primitiveField();
    const label n = u.size();

    // lduMatrix::H: -sum of the neighbours' coefficients times their u
    H.setSize(n);
    H = Zero;
    {
        const labelUList& l = UEqn.lduAddr().lowerAddr();
        const labelUList& up = UEqn.lduAddr().upperAddr();
        const scalarField& lower = UEqn.lower();
        const scalarField& upper = UEqn.upper();
        forAll(l, facei)
        {
            H[up[facei]] -= lower[facei]*u[l[facei]];
            H[l[facei]] -= upper[facei]*u[up[facei]];
        }
    }
    // + the boundary diagonal times u, + the source
    const vectorField& b = UEqn.source();
    for (label i = 0; i < n; ++i)
    {
        H[i] = cmptMultiply(bd[i], u[i]) + (H[i] + b[i]);
    }
    // fvMatrix::addBoundarySource
    forAll(U.boundaryField(), patchi)
    {
        const fvPatchVectorField& Up = U.boundaryField()[patchi];
        const labelUList& faceCells = mesh_.boundary()[patchi].faceCells();
        const vectorField& bc = UEqn.boundaryCoeffs()[patchi];
        if (!Up.coupled())
        {
            forAll(faceCells, facei)
            {
                H[faceCells[facei]] += bc[facei];
            }
        }
        else
        {
            const tmp<vectorField> tpnf = Up.patchNeighbourField();
            const vectorField& pnf = tpnf();
            forAll(faceCells, facei)
            {
                H[faceCells[facei]] += cmptMultiply(bc[facei], pnf[facei]);
            }
        }
    }

    // H /= V, HbyA = rAU H
    const scalarField& V = mesh_.V();
    const scalarField& r = rAU.primitiveField();
    vectorField& h = HbyA.primitiveFieldRef();
    for (label i = 0; i < n; ++i)
    {
        H[i] /= V[i];
        h[i] = r[i]*H[i];
    }

    // Coupled patches: the neighbours' HbyA (a processor patch holds the
    // other rank's cell values, which the flux reads; there rAU_b H_b is
    // that rank's own product, the same bits). Walls: U's value where it
    // cannot be assigned (constrainHbyA), else rAU times H extrapolated
    // (H's extrapolatedCalculated patches).
    HbyA.correctBoundaryConditions();
    volVectorField::Boundary& hbf = HbyA.boundaryFieldRef();
    forAll(hbf, patchi)
    {
        const fvPatchVectorField& Up = U.boundaryField()[patchi];
        if (Up.coupled())
        {
            continue;
        }
        if (!Up.assignable())
        {
            hbf[patchi] = Up;
        }
        else
        {
            hbf[patchi] =
                rAU.boundaryField()[patchi]
               *vectorField(H, mesh_.boundary()[patchi].faceCells());
        }
    }
}


void Foam::fieldKernels::flux
(
    const volVectorField& HbyA,
    surfaceScalarField& phi
) const
{
    const labelUList& P = mesh_.owner();
    const labelUList& N = mesh_.neighbour();
    const vectorField& Sf = mesh_.Sf();
    const scalarField& w = mesh_.weights();
    const vectorField& h = HbyA.primitiveField();
    scalarField& phiI = phi.primitiveFieldRef();

    forAll(P, facei)
    {
        phiI[facei] =
            Sf[facei] & (w[facei]*(h[P[facei]] - h[N[facei]]) + h[N[facei]]);
    }

    surfaceScalarField::Boundary& phibf = phi.boundaryFieldRef();
    forAll(phibf, patchi)
    {
        const vectorField& pSf = mesh_.Sf().boundaryField()[patchi];
        const fvPatchVectorField& hp = HbyA.boundaryField()[patchi];
        if (hp.coupled())
        {
            const scalarField& pLambda = mesh_.weights().boundaryField()[patchi];
            phibf[patchi] =
                pSf
              & (
                    pLambda*hp.patchInternalField()
                  + (1.0 - pLambda)*hp.patchNeighbourField()
                );
        }
        else
        {
            phibf[patchi] = pSf & hp;
        }
    }
}
