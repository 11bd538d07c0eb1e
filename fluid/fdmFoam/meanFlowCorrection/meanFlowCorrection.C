#include "meanFlowCorrection.H"
#include "channelProfile.H"
#include "surfaceFields.H"

// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::meanFlowCorrection::meanFlowCorrection
(
    const uniformCartesianMesh& grid,
    const volVectorField& U,
    scalar nu,
    bool enabled,
    scalar damping
)
:
    grid_(grid),
    nu_(nu),
    axis_(-1),
    uLow_(Zero),
    uHigh_(Zero),
    damping_(damping),
    lastChange_(0)
{
    const Vector<bool>& periodic = grid.periodic();
    label nPeriodic = 0, wallAxis = -1;
    for (direction d = 0; d < 3; ++d)
    {
        if (periodic[d])
        {
            ++nPeriodic;
        }
        else
        {
            wallAxis = d;
        }
    }
    if (!enabled || nPeriodic != 2)
    {
        return;
    }

    // Faces in the order xlo, xhi, ylo, yhi, zlo, zhi
    const List<labelList> facePatches = grid.boxFacePatches();
    const labelList& lowPatches = facePatches[2*wallAxis];
    const labelList& highPatches = facePatches[2*wallAxis + 1];
    for (const labelList* face : {&lowPatches, &highPatches})
    {
        if (face->empty())
        {
            return;
        }
        for (const label patchi : *face)
        {
            if (!U.boundaryField()[patchi].fixesValue())
            {
                return;
            }
        }
    }
    axis_ = wallAxis;
    uLow_ = wallVelocity(U, lowPatches);
    uHigh_ = wallVelocity(U, highPatches);

    const scalar lo = grid.bounds().min()[axis_];
    const label n = grid.nCells()[axis_];
    const vectorField& C = grid.mesh().C().primitiveField();
    plane_.setSize(C.size());
    forAll(C, celli)
    {
        plane_[celli] =
            min(n - 1, max(label(0), label((C[celli][axis_] - lo)/grid.delta())));
    }
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

Foam::vector Foam::meanFlowCorrection::wallVelocity
(
    const volVectorField& U,
    const labelList& patches
) const
{
    vector sum(Zero);
    scalar area = 0;
    for (const label patchi : patches)
    {
        const scalarField& magSf = grid_.mesh().boundary()[patchi].magSf();
        sum += gSum(magSf*U.boundaryField()[patchi]);
        area += gSum(magSf);
    }
    return sum/max(area, VSMALL);
}


Foam::string Foam::meanFlowCorrection::description() const
{
    if (!active())
    {
        return
            "mean-flow correction off (it needs a channel: two periodic "
            "directions and walls with fixed velocities on the other faces)";
    }
    const char* names[] = {"x", "y", "z"};
    return
        string("mean-flow correction on: the profile of the flow averaged over ")
      + "planes normal to " + names[axis_] + " (" + name(grid_.nCells()[axis_])
      + " planes) solved exactly at every inner iteration"
      + (
            damping_ > 0
          ? ", damped where particles force the flow (meanFlowDamping "
          + name(damping_) + ")"
          : string(", undamped (meanFlowDamping 0)")
        );
}


Foam::List<Foam::vector> Foam::meanFlowCorrection::planeAverages
(
    const volVectorField& U
) const
{
    const label n = nPlanes();
    List<vector> averages(n, Zero);
    if (!active())
    {
        return averages;
    }
    forAll(U, celli)
    {
        averages[plane_[celli]] += U[celli];
    }
    Pstream::listCombineGather(averages, plusEqOp<vector>());
    Pstream::listCombineScatter(averages);
    const Vector<label>& nCells = grid_.nCells();
    const scalar cellsPerPlane = scalar(nCells.x())*nCells.y()*nCells.z()/n;
    forAll(averages, j)
    {
        averages[j] /= cellsPerPlane;
    }
    return averages;
}


void Foam::meanFlowCorrection::setForcedCells
(
    const boolList& covered
)
{
    nuP_.clear();
    if (!active() || damping_ <= 0)
    {
        return;
    }
    const label n = nPlanes();
    List<scalar> count(n, 0.0);
    forAll(covered, celli)
    {
        if (covered[celli])
        {
            count[plane_[celli]] += 1;
        }
    }
    Pstream::listCombineGather(count, plusEqOp<scalar>());
    Pstream::listCombineScatter(count);
    const Vector<label>& nCells = grid_.nCells();
    const scalar cellsPerPlane = scalar(nCells.x())*nCells.y()*nCells.z()/n;
    nuP_.resize(n + 1);
    for (label f = 0; f <= n; ++f)
    {
        const scalar below = count[max(f - 1, label(0))];
        const scalar above = count[min(f, n - 1)];
        nuP_[f] = damping_*nu_*0.5*(below + above)/cellsPerPlane;
    }
}


void Foam::meanFlowCorrection::correct
(
    volVectorField& U,
    const volVectorField& lambda,
    const vector& gradP0OverRho
)
{
    if (!active())
    {
        return;
    }
    const label n = grid_.nCells()[axis_];
    vectorField& u = U.primitiveFieldRef();
    const vectorField& l = lambda.primitiveField();

    // Plane sums over all processors (equal cell volumes), in one
    // reduction: u in [0, n), lambda in [n, 2n)
    List<vector> sums(2*n, Zero);
    forAll(u, celli)
    {
        sums[plane_[celli]] += u[celli];
        sums[n + plane_[celli]] += l[celli];
    }
    Pstream::listCombineGather(sums, plusEqOp<vector>());
    Pstream::listCombineScatter(sums);

    const Vector<label>& nCells = grid_.nCells();
    const scalar cellsPerPlane = scalar(nCells.x())*nCells.y()*nCells.z()/n;

    List<vector> shift(n, Zero);
    scalar largest = 0;
    for (direction d = 0; d < 3; ++d)
    {
        if (d == axis_)
        {
            continue;
        }
        // source, and the PISO solution's own plane averages (nu_P holds
        // the new profile close to them)
        std::vector<double> source(n), piso(n);
        for (label j = 0; j < n; ++j)
        {
            source[j] = sums[n + j][d]/cellsPerPlane - gradP0OverRho[d];
            piso[j] = sums[j][d]/cellsPerPlane;
        }
        const std::vector<double> profile = fdm::channel::solveProfile
        (
            source, nu_, grid_.delta(), uLow_[d], uHigh_[d],
            nuP_, piso
        );
        for (label j = 0; j < n; ++j)
        {
            shift[j][d] = profile[j] - piso[j];
            largest = max(largest, mag(shift[j][d]));
        }
    }

    forAll(u, celli)
    {
        u[celli] += shift[plane_[celli]];
    }
    U.correctBoundaryConditions();
    lastChange_ = largest/max(gMax(mag(u)), VSMALL);
}
