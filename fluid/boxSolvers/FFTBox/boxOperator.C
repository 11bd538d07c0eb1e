#include "boxOperator.H"
#include "boxLattice.H"
#include "OStringStream.H"
#include <array>
#include <map>
#include <set>
#include <stdexcept>

// * * * * * * * * * * * * * * * Local Functions * * * * * * * * * * * * * * //

namespace
{
using namespace Foam;
using Foam::boxSolve::separableReading;

//- Running sum, minimum and maximum of the coefficients of one plane
struct planeStatistics
{
    scalar sum = 0, min = GREAT, max = -GREAT;
    label count = 0;
    void add(const scalar v)
    {
        sum += v;
        min = Foam::min(min, v);
        max = Foam::max(max, v);
        ++count;
    }
    scalar mean() const { return count ? sum/count : 0; }
    scalar spread() const
    {
        return count ? (max - min)/Foam::max(mag(mean()), VSMALL) : 0;
    }
};

separableReading readSeparable
(
    const boxLattice& lattice,
    const lduMatrix& matrix,
    const FieldField<Field, scalar>& bouCoeffs,
    const lduInterfaceFieldPtrsList& interfaces
)
{
    const label nPlanes = lattice.nPlanes();
    const int w = lattice.wallAxis();
    const scalarField& diag = matrix.diag();
    const scalarField& upper = matrix.upper();
    const labelUList& lower = matrix.lduAddr().lowerAddr();
    const labelUList& upperCell = matrix.lduAddr().upperAddr();

    // the off-diagonal coefficients by axis and plane (faces normal to the
    // wall axis by the plane below them), and each row's sum
    std::array<List<planeStatistics>, 3> faces;
    for (int a = 0; a < 3; ++a)
    {
        faces[a].setSize(a == w ? nPlanes - 1 : nPlanes);
    }
    scalarField rowSum(diag);
    const List<unsigned char>& faceAxis = lattice.faceAxis();
    forAll(upper, facei)
    {
        const label l = lower[facei], u = upperCell[facei];
        const int a = faceAxis[facei];
        const label key = (a == w) ? min(lattice.plane(l), lattice.plane(u)) : lattice.plane(l);
        faces[a][key].add(upper[facei]);
        rowSum[l] += upper[facei];
        rowSum[u] += upper[facei];
    }
    // a coupled (cyclic) face enters row c as -bouCoeffs (lduMatrix::Amul)
    forAll(interfaces, patchi)
    {
        if (!interfaces.set(patchi))
        {
            continue;
        }
        const int a = lattice.patchAxis()[patchi];
        const labelUList& cells = interfaces[patchi].interface().faceCells();
        const scalarField& coeffs = bouCoeffs[patchi];
        forAll(cells, facei)
        {
            faces[a][lattice.plane(cells[facei])].add(-coeffs[facei]);
            rowSum[cells[facei]] -= coeffs[facei];
        }
    }

    separableReading reading;
    for (int a = 0; a < 3; ++a)
    {
        for (const planeStatistics& s : faces[a])
        {
            reading.M.offDiag[a].push_back(s.mean());
            reading.departure = max(reading.departure, s.spread());
        }
    }

    // Row sums: zero but at one cell is a Laplacian with its pressure
    // reference; otherwise their plane averages go into M's diagonal
    const scalar scale = gMax(mag(diag)());
    const scalar zero = 1e-10*scale;
    label nonZero = 0, last = -1;
    forAll(rowSum, celli)
    {
        if (mag(rowSum[celli]) > zero)
        {
            ++nonZero;
            last = celli;
        }
    }
    List<planeStatistics> sums(nPlanes);
    if (nonZero == 1)
    {
        reading.referenceCell = last;
        reading.referenceDelta = rowSum[last];
    }
    else
    {
        forAll(rowSum, celli)
        {
            sums[lattice.plane(celli)].add(rowSum[celli]);
        }
        forAll(rowSum, celli)
        {
            reading.departure = max
            (
                reading.departure,
                mag(rowSum[celli] - sums[lattice.plane(celli)].mean())/scale
            );
        }
    }

    // diag of M: its row sum minus its off-diagonals
    reading.M.diag.assign(nPlanes, 0.0);
    for (label p = 0; p < nPlanes; ++p)
    {
        scalar d = sums[p].mean();
        for (int a = 0; a < 3; ++a)
        {
            if (a == w)
            {
                if (p > 0) d -= reading.M.offDiag[a][p-1];
                if (p < nPlanes-1) d -= reading.M.offDiag[a][p];
            }
            else
            {
                d -= 2*reading.M.offDiag[a][p];
            }
        }
        reading.M.diag[p] = d;
    }
    return reading;
}


} // End anonymous namespace


// * * * * * * * * * * * * * * * * boxOperator * * * * * * * * * * * * * * * //

Foam::boxSolve::boxOperator::boxOperator
(
    const boxLattice& lattice,
    const bool measurePlans
)
:
    solver
    (
        new fdm::separableBoxSolver(lattice.n(), lattice.wallAxis(), measurePlans)
    )
{
    const List<std::array<long, 3>>& ijk = lattice.ijk();
    index.resize(ijk.size());
    forAll(ijk, celli)
    {
        index[celli] = solver->index(ijk[celli][0], ijk[celli][1], ijk[celli][2]);
    }
    work.resize(ijk.size());
}


bool Foam::boxSolve::boxOperator::sameMatrix
(
    const lduMatrix& matrix,
    const FieldField<Field, scalar>& bouCoeffs,
    const lduInterfaceFieldPtrsList& interfaces
) const
{
    if (!read || matrix.diag() != diag || matrix.upper() != upper)
    {
        return false;
    }
    forAll(interfaces, patchi)
    {
        if (interfaces.set(patchi) && bouCoeffs[patchi] != interfaceCoeffs[patchi])
        {
            return false;
        }
    }
    return true;
}


void Foam::boxSolve::boxOperator::keep
(
    const lduMatrix& matrix,
    const FieldField<Field, scalar>& bouCoeffs,
    const lduInterfaceFieldPtrsList& interfaces,
    const separableReading& r
)
{
    diag = matrix.diag();
    upper = matrix.upper();
    interfaceCoeffs.setSize(interfaces.size());
    forAll(interfaces, patchi)
    {
        if (interfaces.set(patchi))
        {
            interfaceCoeffs[patchi] = bouCoeffs[patchi];
        }
    }
    reading = r;
    read = true;
}


void Foam::boxSolve::boxOperator::precondition
(
    solveScalarField& z,
    const solveScalarField& r
)
{
    // in the solver's order
    std::vector<double>& w = work;
    forAll(r, celli)
    {
        w[index[celli]] = r[celli];
    }
    if (reading.referenceCell >= 0)
    {
        solver->solveWithReference
        (
            w.data(), w.data(), index[reading.referenceCell],
            reading.referenceDelta
        );
    }
    else
    {
        solver->solve(w.data(), w.data());
    }
    forAll(z, celli)
    {
        z[celli] = w[index[celli]];
    }
}


// * * * * * * * * * * * * * * * * Functions  * * * * * * * * * * * * * * * //

bool Foam::boxSolve::firstTime(const word& fieldName, const string& what)
{
    static std::set<std::string> said;
    return said.insert(fieldName + ":" + what).second;
}


bool Foam::boxSolve::measurePlans
(
    const dictionary& controls,
    const word& fieldName
)
{
    const word planning(controls.lookupOrDefault<word>("fftwPlanning", "estimate"));
    if (planning != "estimate" && planning != "measure")
    {
        FatalIOErrorInFunction(controls)
            << "FFTBox for " << fieldName << ": fftwPlanning " << planning
            << " is not estimate or measure" << exit(FatalIOError);
    }
    return planning == "measure";
}


Foam::boxSolve::boxOperator* Foam::boxSolve::prepare
(
    const lduMatrix::solver& sol,
    const scalar maxDeparture,
    const bool measurePlans,
    const char* how,
    string& reason
)
{
    const lduMatrix& matrix = sol.matrix();
    const word& fieldName = sol.fieldName();
    const FieldField<Field, scalar>& bouCoeffs = sol.interfaceBouCoeffs();
    const lduInterfaceFieldPtrsList& interfaces = sol.interfaces();

    const boxLattice* lattice = boxLattice::find(matrix.mesh());
    if (!lattice)
    {
        reason = "the matrix is not on an fvMesh";
        return nullptr;
    }
    if (!lattice->ok())
    {
        reason = lattice->reason();
        return nullptr;
    }

    // one operator per mesh and field: FFTW's plans and the factors are kept
    // for the run
    static std::map<std::pair<const lduMesh*, std::string>, std::unique_ptr<boxOperator>> operators;
    auto& slot = operators[std::make_pair(&matrix.mesh(), std::string(fieldName))];
    if (!slot)
    {
        slot.reset(new boxOperator(*lattice, measurePlans));
    }
    boxOperator& op = *slot;

    if (!op.sameMatrix(matrix, bouCoeffs, interfaces))
    {
        op.keep
        (
            matrix, bouCoeffs, interfaces,
            readSeparable(*lattice, matrix, bouCoeffs, interfaces)
        );
    }
    const separableReading& reading = op.reading;
    if (reading.departure > maxDeparture)
    {
        OStringStream why;
        why << "its coefficients spread by " << reading.departure
            << " of their plane averages (maxDeparture " << maxDeparture << ")";
        reason = why.str();
        return nullptr;
    }

    try
    {
        op.solver->setCoefficients(reading.M);
    }
    catch (const std::invalid_argument& e)
    {
        reason = e.what();
        return nullptr;
    }
    if (reading.referenceCell >= 0 && !op.solver->singular())
    {
        reason = "one row alone does not sum to zero but the rest is not a Laplacian";
        return nullptr;
    }
    if (firstTime(fieldName, "direct"))
    {
        Info<< "FFTBox: " << fieldName << " " << how << " on "
            << lattice->description().c_str() << " (departure from the box "
            << reading.departure
            << (reading.referenceCell >= 0 ? ", pressure reference solved exactly" : "")
            << ")" << endl;
    }
    return &op;
}


// ************************************************************************* //
