#include "boxOperator.H"
#include "boxLattice.H"
#include "OStringStream.H"
#include <algorithm>
#include <array>
#include <complex>
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


//- The statistics of every processor's part of a decomposed box combined
void combine(List<planeStatistics>& planes)
{
    scalarList sum(planes.size()), lowest(planes.size()), highest(planes.size()), count(planes.size());
    forAll(planes, i)
    {
        sum[i] = planes[i].sum;
        lowest[i] = planes[i].min;
        highest[i] = planes[i].max;
        count[i] = planes[i].count;
    }
    Pstream::listCombineGather(sum, plusEqOp<scalar>());
    Pstream::listCombineScatter(sum);
    Pstream::listCombineGather(lowest, minEqOp<scalar>());
    Pstream::listCombineScatter(lowest);
    Pstream::listCombineGather(highest, maxEqOp<scalar>());
    Pstream::listCombineScatter(highest);
    Pstream::listCombineGather(count, plusEqOp<scalar>());
    Pstream::listCombineScatter(count);
    forAll(planes, i)
    {
        planes[i].sum = sum[i];
        planes[i].min = lowest[i];
        planes[i].max = highest[i];
        planes[i].count = label(count[i] + 0.5);
    }
}


//- The processor holding plane p (planeStart: the first plane of each, and
//  the number of planes last)
label planeOwner(const labelList& planeStart, const label p)
{
    return label(std::upper_bound(planeStart.begin(), planeStart.end(), p) - planeStart.begin()) - 1;
}

//- Exchange of contiguous values between every pair of processors; what a
//  processor sends itself is copied
template<class T>
void exchange
(
    const List<List<T>>& send,
    const labelList& recvSizes,
    List<List<T>>& recv
)
{
    Pstream::exchange<List<T>, T>(send, recvSizes, recv);
    recv[Pstream::myProcNo()] = send[Pstream::myProcNo()];
}

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
        const labelList& axes = lattice.patchFaceAxis()[patchi];
        // a processor face across the walls lies above or below its cell
        const labelList& offsets = lattice.patchFaceOffset()[patchi];
        const labelUList& cells = interfaces[patchi].interface().faceCells();
        const scalarField& coeffs = bouCoeffs[patchi];
        forAll(cells, facei)
        {
            const int a = axes[facei];
            const label key = lattice.plane(cells[facei]) + (a == w ? offsets[facei] : 0);
            faces[a][key].add(-coeffs[facei]);
            rowSum[cells[facei]] -= coeffs[facei];
        }
    }
    if (lattice.decomposed())
    {
        for (int a = 0; a < 3; ++a)
        {
            combine(faces[a]);
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
    const label nonZeroAll = lattice.decomposed() ? returnReduce(nonZero, sumOp<label>()) : nonZero;
    if (nonZeroAll == 1)
    {
        reading.reference = true;
        if (nonZero == 1)
        {
            reading.referenceCell = last;
            reading.referenceDelta = rowSum[last];
        }
    }
    else
    {
        forAll(rowSum, celli)
        {
            sums[lattice.plane(celli)].add(rowSum[celli]);
        }
        if (lattice.decomposed())
        {
            combine(sums);
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
    if (lattice.decomposed())
    {
        reduce(reading.departure, maxOp<scalar>());
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
    decomposed(lattice.decomposed())
{
    const List<std::array<long, 3>>& ijk = lattice.ijk();
    if (!decomposed)
    {
        solver.reset(new fdm::separableBoxSolver(lattice.n(), lattice.wallAxis(), measurePlans));
        index.resize(ijk.size());
        forAll(ijk, celli)
        {
            index[celli] = solver->index(ijk[celli][0], ijk[celli][1], ijk[celli][2]);
        }
        work.resize(ijk.size());
        return;
    }

    // slabs of planes across the walls, ranges of in-plane modes: as even
    // as the numbers allow
    const label nProcs = Pstream::nProcs(), me = Pstream::myProcNo();
    const int w = lattice.wallAxis();
    const long planes = lattice.n()[w];
    planeStart.setSize(nProcs + 1);
    forAll(planeStart, proci)
    {
        planeStart[proci] = label(long(proci)*planes/nProcs);
    }
    solver.reset
    (
        new fdm::separableBoxSolver
        (
            lattice.n(), w, measurePlans, planeStart[me], planeStart[me + 1]
        )
    );
    modeStart.setSize(nProcs + 1);
    forAll(modeStart, proci)
    {
        modeStart[proci] = std::size_t(proci)*solver->modesPerPlane()/nProcs;
    }

    // where each cell's value goes, and where what arrives goes
    List<DynamicList<label>> cells(nProcs), positions(nProcs);
    forAll(ijk, celli)
    {
        const label p = label(ijk[celli][w]);
        const label owner = planeOwner(planeStart, p);
        cells[owner].append(celli);
        positions[owner].append
        (
            label
            (
                std::size_t(p - planeStart[owner])*solver->cellsPerPlane()
              + solver->inPlaneIndex(ijk[celli][0], ijk[celli][1], ijk[celli][2])
            )
        );
    }
    sendCells.setSize(nProcs);
    labelListList sendPositions(nProcs);
    forAll(cells, proci)
    {
        sendCells[proci].transfer(cells[proci]);
        sendPositions[proci].transfer(positions[proci]);
    }
    labelList recvSizes;
    Pstream::exchangeSizes(sendPositions, recvSizes);
    exchange(sendPositions, recvSizes, slabPositions);
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


void Foam::boxSolve::boxOperator::solveDecomposed
(
    solveScalarField& z,
    const scalarField& b
)
{
    typedef std::complex<double> complex;
    const label nProcs = Pstream::nProcs(), me = Pstream::myProcNo();
    const std::size_t modes = solver->modesPerPlane();
    const label planes = planeStart[nProcs];
    const label myPlanes = planeStart[me + 1] - planeStart[me];
    const std::size_t myModes = modeStart[me + 1] - modeStart[me];
    auto width = [this](const label proci) { return modeStart[proci + 1] - modeStart[proci]; };
    List<scalarList> send(nProcs), recv(nProcs);
    labelList recvSizes(nProcs);

    // 1. the cells' values to the slabs
    forAll(send, proci)
    {
        const labelList& cells = sendCells[proci];
        send[proci].setSize(cells.size());
        forAll(cells, i)
        {
            send[proci][i] = b[cells[i]];
        }
        recvSizes[proci] = slabPositions[proci].size();
    }
    exchange(send, recvSizes, recv);
    double* slab = solver->planeValues();
    forAll(recv, proci)
    {
        const labelList& at = slabPositions[proci];
        forAll(at, i)
        {
            slab[at[i]] = recv[proci][i];
        }
    }
    solver->forwardPlanes();

    // 2. the slabs' spectra to ranges of modes (each processor all the
    //    planes of its modes), solved
    const complex* spectra = solver->planeSpectra();
    forAll(send, proci)
    {
        const std::size_t m0 = modeStart[proci], n = width(proci);
        send[proci].setSize(label(2*n*myPlanes));
        for (label p = 0; p < myPlanes; ++p)
        {
            const double* from = reinterpret_cast<const double*>(spectra + modes*p + m0);
            std::copy(from, from + 2*n, send[proci].begin() + 2*n*p);
        }
        recvSizes[proci] = label(2*myModes*(planeStart[proci + 1] - planeStart[proci]));
    }
    exchange(send, recvSizes, recv);
    std::vector<complex> y(myModes*planes);
    double* yValues = reinterpret_cast<double*>(y.data());
    forAll(recv, proci)
    {
        std::copy(recv[proci].begin(), recv[proci].end(), yValues + 2*myModes*planeStart[proci]);
    }
    solver->solveModes(y.data(), modeStart[me], modeStart[me + 1]);

    // 3. back to the slabs
    forAll(send, proci)
    {
        const label first = planeStart[proci], count = planeStart[proci + 1] - first;
        send[proci].setSize(label(2*myModes*count));
        std::copy(yValues + 2*myModes*first, yValues + 2*myModes*(first + count), send[proci].begin());
        recvSizes[proci] = label(2*width(proci)*myPlanes);
    }
    exchange(send, recvSizes, recv);
    complex* spectraBack = solver->planeSpectra();
    forAll(recv, proci)
    {
        const std::size_t m0 = modeStart[proci], n = width(proci);
        for (label p = 0; p < myPlanes; ++p)
        {
            double* to = reinterpret_cast<double*>(spectraBack + modes*p + m0);
            std::copy(recv[proci].begin() + 2*n*p, recv[proci].begin() + 2*n*(p + 1), to);
        }
    }
    solver->backwardPlanes();

    // 4. the slabs' values back to the cells
    forAll(send, proci)
    {
        const labelList& at = slabPositions[proci];
        send[proci].setSize(at.size());
        forAll(at, i)
        {
            send[proci][i] = slab[at[i]];
        }
        recvSizes[proci] = sendCells[proci].size();
    }
    exchange(send, recvSizes, recv);
    forAll(recv, proci)
    {
        const labelList& cells = sendCells[proci];
        forAll(cells, i)
        {
            z[cells[i]] = recv[proci][i];
        }
    }
}


void Foam::boxSolve::boxOperator::precondition
(
    solveScalarField& z,
    const solveScalarField& r
)
{
    if (decomposed)
    {
        // as separableBoxSolver::solveWithReference, over the processors
        scalarField b(r);
        scalar sum = 0;
        if (reading.reference)
        {
            sum = gSum(r);
            if (reading.referenceCell >= 0)
            {
                b[reading.referenceCell] -= sum;
            }
        }
        solveDecomposed(z, b);
        if (reading.reference)
        {
            scalar shift = 0;
            if (reading.referenceCell >= 0)
            {
                shift = sum/reading.referenceDelta - z[reading.referenceCell];
            }
            reduce(shift, sumOp<scalar>());
            z += shift;
        }
        return;
    }

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

    bool same = op.sameMatrix(matrix, bouCoeffs, interfaces);
    if (lattice->decomposed())
    {
        // read (collectively) where any processor's part changed
        reduce(same, andOp<bool>());
    }
    if (!same)
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
    if (reading.reference && !op.solver->singular())
    {
        reason = "one row alone does not sum to zero but the rest is not a Laplacian";
        return nullptr;
    }
    if (firstTime(fieldName, "direct"))
    {
        Info<< "FFTBox: " << fieldName << " " << how << " on "
            << lattice->description().c_str() << " (departure from the box "
            << reading.departure
            << (reading.reference ? ", pressure reference solved exactly" : "")
            << ")" << endl;
    }
    return &op;
}


// ************************************************************************* //
