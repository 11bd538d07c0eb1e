#include "FFTBox.H"
#include "boxLattice.H"
#include "separableBoxSolver.H"
#include "addToRunTimeSelectionTable.H"
#include "OStringStream.H"
#include <map>
#include <memory>
#include <set>
#include <stdexcept>

// * * * * * * * * * * * * * * Static Data Members * * * * * * * * * * * * * //

namespace Foam
{
    defineTypeNameAndDebug(FFTBox, 0);

    lduMatrix::solver::addsymMatrixConstructorToTable<FFTBox>
        addFFTBoxSymMatrixConstructorToTable_;
}


// * * * * * * * * * * * * * * * Local Functions * * * * * * * * * * * * * * //

namespace
{
using namespace Foam;

//- A matrix read as the separable operator of its plane averages
struct separableReading
{
    fdm::separableBoxSolver::coefficients M;
    //- The pressure reference (fvMatrix::setReference) of a singular M:
    //  the one cell whose row does not sum to zero, and that sum
    label referenceCell = -1;
    scalar referenceDelta = 0;
    //- Largest relative departure of the matrix from M
    scalar departure = 0;
};

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


//- The separable solver of one field (and component) on one mesh: FFTW's
//  plans and the factors are kept for the run
struct boxOperator
{
    std::unique_ptr<fdm::separableBoxSolver> solver;
    //- Position of each cell in the solver's arrays
    std::vector<std::size_t> index;
    std::vector<double> work;
    //- The matrix last read and its reading: a solver gets a new matrix at
    //  every solve, mostly with the same coefficients (reading them costs
    //  more than the FFTs, comparing them a tenth of that)
    scalarField diag, upper;
    List<scalarField> interfaceCoeffs;
    separableReading reading;
    bool read = false;

    bool sameMatrix
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

    void keep
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
};

boxOperator& operatorFor
(
    const lduMesh& mesh,
    const word& key,
    const boxLattice& lattice,
    const bool measurePlans
)
{
    static std::map<std::pair<const lduMesh*, std::string>, std::unique_ptr<boxOperator>> operators;
    auto& op = operators[std::make_pair(&mesh, std::string(key))];
    if (!op)
    {
        op.reset(new boxOperator);
        op->solver.reset
        (
            new fdm::separableBoxSolver(lattice.n(), lattice.wallAxis(), measurePlans)
        );
        const List<std::array<long, 3>>& ijk = lattice.ijk();
        op->index.resize(ijk.size());
        forAll(ijk, celli)
        {
            op->index[celli] = op->solver->index(ijk[celli][0], ijk[celli][1], ijk[celli][2]);
        }
        op->work.resize(ijk.size());
    }
    return *op;
}

//- Says a thing once per field
bool firstTime(const word& fieldName, const string& what)
{
    static std::set<std::string> said;
    return said.insert(fieldName + ":" + what).second;
}

} // End anonymous namespace


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::FFTBox::FFTBox
(
    const word& fieldName,
    const lduMatrix& matrix,
    const FieldField<Field, scalar>& interfaceBouCoeffs,
    const FieldField<Field, scalar>& interfaceIntCoeffs,
    const lduInterfaceFieldPtrsList& interfaces,
    const dictionary& solverControls
)
:
    lduMatrix::solver
    (
        fieldName,
        matrix,
        interfaceBouCoeffs,
        interfaceIntCoeffs,
        interfaces,
        solverControls
    ),
    maxDeparture_(controlDict_.lookupOrDefault<scalar>("maxDeparture", 0.5)),
    measurePlans_(false)
{
    const word planning(controlDict_.lookupOrDefault<word>("fftwPlanning", "estimate"));
    measurePlans_ = (planning == "measure");
    if (planning != "estimate" && !measurePlans_)
    {
        FatalIOErrorInFunction(controlDict_)
            << "FFTBox for " << fieldName << ": fftwPlanning " << planning
            << " is not estimate or measure" << exit(FatalIOError);
    }
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

Foam::solverPerformance Foam::FFTBox::fallback
(
    scalarField& psi,
    const scalarField& source,
    const direction cmpt,
    const string& reason
) const
{
    dictionary controls(controlDict_.subOrEmptyDict("fallback"));
    if (!controls.found("solver"))
    {
        controls.add("solver", "GAMG");
        controls.add("smoother", "GaussSeidel");
    }
    for (const word key : {"tolerance", "relTol", "maxIter", "minIter"})
    {
        if (!controls.found(key) && controlDict_.found(key))
        {
            controls.add(controlDict_.lookupEntry(key, keyType::LITERAL), false);
        }
    }
    if (firstTime(fieldName_, "fallback " + reason))
    {
        Info<< "FFTBox: " << fieldName_ << " is solved by "
            << controls.get<word>("solver") << " (the fallback): " << reason.c_str()
            << endl;
    }
    return lduMatrix::solver::New
    (
        fieldName_, matrix_, interfaceBouCoeffs_, interfaceIntCoeffs_,
        interfaces_, controls
    )->solve(psi, source, cmpt);
}


Foam::solverPerformance Foam::FFTBox::solve
(
    scalarField& psi,
    const scalarField& source,
    const direction cmpt
) const
{
    const boxLattice* lattice = boxLattice::find(matrix_.mesh());
    if (!lattice)
    {
        return fallback(psi, source, cmpt, "the matrix is not on an fvMesh");
    }
    if (!lattice->ok())
    {
        return fallback(psi, source, cmpt, lattice->reason());
    }

    boxOperator& op = operatorFor(matrix_.mesh(), fieldName_, *lattice, measurePlans_);
    if (!op.sameMatrix(matrix_, interfaceBouCoeffs_, interfaces_))
    {
        op.keep
        (
            matrix_, interfaceBouCoeffs_, interfaces_,
            readSeparable(*lattice, matrix_, interfaceBouCoeffs_, interfaces_)
        );
    }
    const separableReading& reading = op.reading;
    if (reading.departure > maxDeparture_)
    {
        OStringStream why;
        why << "its coefficients spread by " << reading.departure
            << " of their plane averages (maxDeparture " << maxDeparture_ << ")";
        return fallback(psi, source, cmpt, why.str());
    }

    fdm::separableBoxSolver& box = *op.solver;
    try
    {
        box.setCoefficients(reading.M);
    }
    catch (const std::invalid_argument& e)
    {
        return fallback(psi, source, cmpt, e.what());
    }
    if (reading.referenceCell >= 0 && !box.singular())
    {
        return fallback
        (
            psi, source, cmpt,
            "one row alone does not sum to zero but the rest is not a Laplacian"
        );
    }
    if (firstTime(fieldName_, "direct"))
    {
        Info<< "FFTBox: " << fieldName_ << " solved directly on "
            << lattice->description().c_str() << " (departure from the box "
            << reading.departure
            << (reading.referenceCell >= 0 ? ", pressure reference solved exactly" : "")
            << ")" << endl;
    }

    // z = M^-1 r, in the solver's order
    auto precondition = [&](scalarField& z, const scalarField& r)
    {
        std::vector<double>& w = op.work;
        forAll(r, celli)
        {
            w[op.index[celli]] = r[celli];
        }
        if (reading.referenceCell >= 0)
        {
            box.solveWithReference
            (
                w.data(), w.data(), op.index[reading.referenceCell],
                reading.referenceDelta
            );
        }
        else
        {
            box.solve(w.data(), w.data());
        }
        forAll(z, celli)
        {
            z[celli] = w[op.index[celli]];
        }
    };

    // Conjugate gradients preconditioned by the exact box solve (as
    // OpenFOAM's PCG): one iteration where the matrix is the box's
    solverPerformance solverPerf(typeName, fieldName_);
    const label nCells = psi.size();
    scalarField pA(nCells), wA(nCells);

    matrix_.Amul(wA, psi, interfaceBouCoeffs_, interfaces_, cmpt);
    scalarField rA(source - wA);
    const scalar normFactor = this->normFactor(psi, source, wA, pA);
    solverPerf.initialResidual() = gSumMag(rA, matrix().mesh().comm())/normFactor;
    solverPerf.finalResidual() = solverPerf.initialResidual();

    if (minIter_ > 0 || !solverPerf.checkConvergence(tolerance_, relTol_))
    {
        scalar wArA = solverPerf.great_, wArAold = wArA;
        do
        {
            wArAold = wArA;
            precondition(wA, rA);
            wArA = gSumProd(wA, rA, matrix().mesh().comm());
            if (solverPerf.nIterations() == 0)
            {
                pA = wA;
            }
            else
            {
                const scalar beta = wArA/wArAold;
                forAll(pA, celli)
                {
                    pA[celli] = wA[celli] + beta*pA[celli];
                }
            }
            matrix_.Amul(wA, pA, interfaceBouCoeffs_, interfaces_, cmpt);
            const scalar wApA = gSumProd(wA, pA, matrix().mesh().comm());
            if (solverPerf.checkSingularity(mag(wApA)/normFactor))
            {
                break;
            }
            const scalar alpha = wArA/wApA;
            forAll(psi, celli)
            {
                psi[celli] += alpha*pA[celli];
                rA[celli] -= alpha*wA[celli];
            }
            solverPerf.finalResidual() = gSumMag(rA, matrix().mesh().comm())/normFactor;
        } while
        (
            (
                ++solverPerf.nIterations() < maxIter_
             && !solverPerf.checkConvergence(tolerance_, relTol_)
            )
         || solverPerf.nIterations() < minIter_
        );
    }
    return solverPerf;
}


// ************************************************************************* //
