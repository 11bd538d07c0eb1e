#include "separableBoxSolver.H"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace
{
    const double pi = 3.14159265358979323846;

    //- Relative size below which a pivot or a row sum counts as zero
    const double zeroTolerance = 1e-10;

    std::vector<double> cosines(long n)
    {
        // wavenumber m of an axis of n cells: cos(2 pi m/n); the real to
        // complex transform keeps m = 0 .. n/2 on its last axis only, and
        // cos is even, so one table serves both
        std::vector<double> c(n);
        for (long m = 0; m < n; ++m)
        {
            c[m] = std::cos(2*pi*double(m)/double(n));
        }
        return c;
    }
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

fdm::separableBoxSolver::separableBoxSolver
(
    const std::array<long, 3>& n,
    int wallAxis,
    bool measurePlans,
    long planeBegin,
    long planeEnd
)
:
    n_(n),
    wall_(wallAxis),
    slow_(-1),
    fast_(-1),
    nPlanes_(1),
    nSlow_(1),
    nFast_(1),
    planeBegin_(0),
    planeEnd_(0),
    nCells_(0),
    nModes_(0),
    factorised_(false),
    singular_(false),
    forward_(nullptr),
    backward_(nullptr),
    real_(nullptr),
    spectrum_(nullptr)
{
    if (wallAxis < -1 || wallAxis > 2)
    {
        throw std::invalid_argument
        (
            "separableBoxSolver: wall axis " + std::to_string(wallAxis)
          + " is not -1 (fully periodic), 0, 1 or 2"
        );
    }
    for (int a = 0; a < 3; ++a)
    {
        if (n[a] < 1)
        {
            throw std::invalid_argument
            (
                "separableBoxSolver: " + std::to_string(n[a])
              + " cells along axis " + std::to_string(a)
            );
        }
    }
    nCells_ = std::size_t(n[0])*n[1]*n[2];

    if (wall_ >= 0)
    {
        // the periodic axes: the lower one contiguous (x in OpenFOAM's order)
        fast_ = (wall_ == 0) ? 1 : 0;
        slow_ = 3 - wall_ - fast_;
        nPlanes_ = n[wall_];
        nSlow_ = n[slow_];
        nFast_ = n[fast_];
        nModes_ = std::size_t(nSlow_)*(nFast_/2 + 1);
    }
    else
    {
        // [z][y][x]: z and y together are the slow axis of one 3-D transform
        nPlanes_ = 1;
        nSlow_ = n[2]*n[1];
        nFast_ = n[0];
        nModes_ = std::size_t(n[2])*n[1]*(n[0]/2 + 1);
    }

    if (planeEnd < 0)
    {
        planeEnd = nPlanes_;
    }
    if (planeBegin < 0 || planeBegin > planeEnd || planeEnd > nPlanes_)
    {
        throw std::invalid_argument
        (
            "separableBoxSolver: planes [" + std::to_string(planeBegin) + ", "
          + std::to_string(planeEnd) + ") are not within the "
          + std::to_string(nPlanes_) + " planes across the walls"
        );
    }
    if (wall_ < 0 && planeEnd - planeBegin != nPlanes_)
    {
        throw std::invalid_argument
        (
            "separableBoxSolver: a fully periodic box is solved whole"
            " (its parts need a wall axis)"
        );
    }
    planeBegin_ = planeBegin;
    planeEnd_ = planeEnd;
    const long localPlanes = planeEnd_ - planeBegin_;

    // the buffers of the planes transformed here (at least one element:
    // fftw_malloc(0) may return nullptr)
    const std::size_t localCells = std::size_t(nSlow_*nFast_)*localPlanes;
    const std::size_t localModes = nModes_*localPlanes;
    real_ = static_cast<double*>(fftw_malloc(sizeof(double)*std::max<std::size_t>(localCells, 1)));
    spectrum_ = reinterpret_cast<std::complex<double>*>
    (
        fftw_malloc(sizeof(fftw_complex)*std::max<std::size_t>(localModes, 1))
    );
    if (!real_ || !spectrum_)
    {
        throw std::bad_alloc();
    }
    fftw_complex* spec = reinterpret_cast<fftw_complex*>(spectrum_);

    // FFTW_MEASURE times a few algorithms once (it overwrites the buffers,
    // which hold nothing yet); every solve then reuses the plans
    const unsigned flags = measurePlans ? FFTW_MEASURE : FFTW_ESTIMATE;
    if (wall_ >= 0)
    {
        cosSlow_ = cosines(nSlow_);
        cosFast_ = cosines(nFast_);
        if (localPlanes == 0)
        {
            // a processor without planes of its own: nothing to transform
            return;
        }
        // one 2-D transform per plane across the walls
        const int dims[2] = {int(nSlow_), int(nFast_)};
        const int realPerPlane = int(nSlow_*nFast_);
        const int modesPerPlane = int(nModes_);
        forward_ = fftw_plan_many_dft_r2c
        (
            2, dims, int(localPlanes),
            real_, nullptr, 1, realPerPlane,
            spec, nullptr, 1, modesPerPlane,
            flags
        );
        backward_ = fftw_plan_many_dft_c2r
        (
            2, dims, int(localPlanes),
            spec, nullptr, 1, modesPerPlane,
            real_, nullptr, 1, realPerPlane,
            flags
        );
    }
    else
    {
        forward_ = fftw_plan_dft_r2c_3d
        (
            int(n[2]), int(n[1]), int(n[0]), real_, spec, flags
        );
        backward_ = fftw_plan_dft_c2r_3d
        (
            int(n[2]), int(n[1]), int(n[0]), spec, real_, flags
        );
    }
    if (!forward_ || !backward_)
    {
        throw std::runtime_error("separableBoxSolver: FFTW could not plan");
    }
}


fdm::separableBoxSolver::~separableBoxSolver()
{
    if (forward_) fftw_destroy_plan(static_cast<fftw_plan>(forward_));
    if (backward_) fftw_destroy_plan(static_cast<fftw_plan>(backward_));
    fftw_free(real_);
    fftw_free(spectrum_);
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

std::size_t fdm::separableBoxSolver::index(long i, long j, long k) const
{
    const long ijk[3] = {i, j, k};
    if (wall_ >= 0)
    {
        return std::size_t(ijk[fast_])
          + std::size_t(nFast_)*(ijk[slow_] + std::size_t(nSlow_)*ijk[wall_]);
    }
    return std::size_t(i) + std::size_t(n_[0])*(j + std::size_t(n_[1])*k);
}


std::size_t fdm::separableBoxSolver::inPlaneIndex(long i, long j, long k) const
{
    const long ijk[3] = {i, j, k};
    if (wall_ >= 0)
    {
        return std::size_t(ijk[fast_]) + std::size_t(nFast_)*ijk[slow_];
    }
    return index(i, j, k);
}


bool fdm::separableBoxSolver::sameCoefficients(const coefficients& c) const
{
    return factorised_ && c.diag == coeffs_.diag && c.offDiag == coeffs_.offDiag;
}


void fdm::separableBoxSolver::setCoefficients(const coefficients& c)
{
    if (sameCoefficients(c))
    {
        return;
    }
    const std::size_t planes = std::size_t(nPlanes_);
    bool ok = c.diag.size() == planes;
    for (int a = 0; a < 3; ++a)
    {
        const std::size_t expected = (a == wall_) ? planes - 1 : planes;
        ok = ok && c.offDiag[a].size() == expected;
    }
    if (!ok)
    {
        throw std::invalid_argument
        (
            "separableBoxSolver::setCoefficients: expected "
          + std::to_string(planes) + " plane values (and one fewer face "
            "values across the walls)"
        );
    }
    coeffs_ = c;
    factorise();
}


void fdm::separableBoxSolver::factorise()
{
    const auto& d = coeffs_.diag;
    const auto& off = coeffs_.offDiag;

    // singular: every row sums to zero (a Laplacian without a Dirichlet or
    // zero-order part; its null vector is the constant)
    singular_ = true;
    for (long p = 0; p < nPlanes_; ++p)
    {
        double rowSum = d[p], scale = std::abs(d[p]);
        for (int a = 0; a < 3; ++a)
        {
            if (a == wall_)
            {
                if (p > 0) { rowSum += off[a][p-1]; scale += std::abs(off[a][p-1]); }
                if (p < nPlanes_-1) { rowSum += off[a][p]; scale += std::abs(off[a][p]); }
            }
            else
            {
                rowSum += 2*off[a][p];
                scale += 2*std::abs(off[a][p]);
            }
        }
        if (std::abs(rowSum) > zeroTolerance*scale)
        {
            singular_ = false;
        }
    }

    invPivot_.assign(nModes_*nPlanes_, 0.0);
    upper_.assign(nModes_*std::max<long>(nPlanes_ - 1, 0), 0.0);

    if (wall_ < 0)
    {
        // a scalar per mode: the eigenvalue
        const std::vector<double> cx = cosines(n_[0]), cy = cosines(n_[1]),
            cz = cosines(n_[2]);
        const long nxHalf = n_[0]/2 + 1;
        const double scale =
            std::abs(d[0]) + 2*(std::abs(off[0][0]) + std::abs(off[1][0]) + std::abs(off[2][0]));
        for (long k = 0; k < n_[2]; ++k)
        {
            for (long j = 0; j < n_[1]; ++j)
            {
                for (long i = 0; i < nxHalf; ++i)
                {
                    const double lambda = d[0] + 2*off[0][0]*cx[i]
                      + 2*off[1][0]*cy[j] + 2*off[2][0]*cz[k];
                    const std::size_t m = i + nxHalf*(j + std::size_t(n_[1])*k);
                    if (std::abs(lambda) <= zeroTolerance*scale)
                    {
                        if (!(singular_ && m == 0))
                        {
                            throw std::invalid_argument
                            (
                                "separableBoxSolver: the operator is singular"
                                " at a non-constant Fourier mode"
                            );
                        }
                        invPivot_[m] = 0;   // the constant: left at zero
                    }
                    else
                    {
                        invPivot_[m] = 1/lambda;
                    }
                }
            }
        }
        factorised_ = true;
        return;
    }

    // a tridiagonal system across the walls per in-plane mode (Thomas)
    const long nFastHalf = nFast_/2 + 1;
    const auto& cSlow = off[slow_];
    const auto& cFast = off[fast_];
    const auto& cWall = off[wall_];
    for (long s = 0; s < nSlow_; ++s)
    {
        for (long f = 0; f < nFastHalf; ++f)
        {
            const std::size_t m = f + nFastHalf*std::size_t(s);
            double previousUpper = 0;
            for (long p = 0; p < nPlanes_; ++p)
            {
                const double main = d[p] + 2*cSlow[p]*cosSlow_[s] + 2*cFast[p]*cosFast_[f];
                const double below = (p > 0) ? cWall[p-1] : 0.0;
                const double pivot = main - below*previousUpper;
                const double scale = std::abs(d[p]) + 2*(std::abs(cSlow[p]) + std::abs(cFast[p]))
                  + std::abs(below) + ((p < nPlanes_-1) ? std::abs(cWall[p]) : 0.0);
                double inv;
                if (std::abs(pivot) <= zeroTolerance*scale)
                {
                    if (!(singular_ && m == 0 && p == nPlanes_-1))
                    {
                        throw std::invalid_argument
                        (
                            "separableBoxSolver: zero pivot in plane "
                          + std::to_string(p) + " of in-plane mode "
                          + std::to_string(m) + " (the operator is not definite)"
                        );
                    }
                    inv = 0;        // the constant mode: its last value 0
                }
                else
                {
                    inv = 1/pivot;
                }
                invPivot_[m + nModes_*p] = inv;
                if (p < nPlanes_-1)
                {
                    previousUpper = cWall[p]*inv;
                    upper_[m + nModes_*p] = previousUpper;
                }
            }
        }
    }
    factorised_ = true;
}


void fdm::separableBoxSolver::solve(const double* b, double* x)
{
    if (!factorised_)
    {
        throw std::logic_error("separableBoxSolver::solve before setCoefficients");
    }
    if (planeEnd_ - planeBegin_ != nPlanes_)
    {
        throw std::logic_error
        (
            "separableBoxSolver::solve on a part of the box (planes "
          + std::to_string(planeBegin_) + " to " + std::to_string(planeEnd_)
          + "): solve in parts"
        );
    }
    std::copy(b, b + nCells_, real_);
    forwardPlanes();
    if (wall_ < 0)
    {
        for (std::size_t m = 0; m < nModes_; ++m)
        {
            spectrum_[m] *= invPivot_[m];
        }
    }
    else
    {
        solveModes(spectrum_, 0, nModes_);
    }
    backwardPlanes();
    std::copy(real_, real_ + nCells_, x);
}


void fdm::separableBoxSolver::forwardPlanes()
{
    if (forward_)
    {
        fftw_execute(static_cast<fftw_plan>(forward_));
    }
}


void fdm::separableBoxSolver::backwardPlanes()
{
    if (!backward_)
    {
        return;
    }
    fftw_execute(static_cast<fftw_plan>(backward_));
    // FFTW's transforms are unnormalised: forward then backward multiplies
    // by the number of points transformed
    const double norm = 1.0/double(nSlow_*nFast_);
    const std::size_t cells = std::size_t(nSlow_*nFast_)*(planeEnd_ - planeBegin_);
    for (std::size_t c = 0; c < cells; ++c)
    {
        real_[c] *= norm;
    }
}


void fdm::separableBoxSolver::solveModes
(
    std::complex<double>* y,
    const std::size_t modeBegin,
    const std::size_t modeEnd
) const
{
    if (!factorised_ || wall_ < 0 || modeBegin > modeEnd || modeEnd > nModes_)
    {
        throw std::logic_error
        (
            "separableBoxSolver::solveModes needs the coefficients, a wall"
            " axis and modes within the "
          + std::to_string(nModes_) + " in-plane modes"
        );
    }
    // forward elimination, then back substitution, all modes of a plane at
    // once (contiguous)
    const std::size_t width = modeEnd - modeBegin;
    const auto& cWall = coeffs_.offDiag[wall_];
    {
        const double* inv = invPivot_.data() + modeBegin;
        for (std::size_t m = 0; m < width; ++m)
        {
            y[m] *= inv[m];
        }
    }
    for (long p = 1; p < nPlanes_; ++p)
    {
        std::complex<double>* yp = y + width*p;
        const std::complex<double>* yBelow = yp - width;
        const double* inv = invPivot_.data() + nModes_*p + modeBegin;
        const double c = cWall[p-1];
        for (std::size_t m = 0; m < width; ++m)
        {
            yp[m] = (yp[m] - c*yBelow[m])*inv[m];
        }
    }
    for (long p = nPlanes_ - 2; p >= 0; --p)
    {
        std::complex<double>* yp = y + width*p;
        const std::complex<double>* yAbove = yp + width;
        const double* up = upper_.data() + nModes_*p + modeBegin;
        for (std::size_t m = 0; m < width; ++m)
        {
            yp[m] -= up[m]*yAbove[m];
        }
    }
}


void fdm::separableBoxSolver::solveWithReference
(
    const double* b,
    double* x,
    std::size_t r,
    double delta
)
{
    if (!singular_ || delta == 0 || r >= nCells_)
    {
        throw std::invalid_argument
        (
            "separableBoxSolver::solveWithReference needs a singular operator,"
            " a non-zero delta and a cell of the lattice"
        );
    }
    // Summing the rows of (M + delta e_r e_r^T) x = b: delta x_r = sum(b).
    // What is left, M x = b - sum(b) e_r, is compatible.
    double sum = 0;
    for (std::size_t c = 0; c < nCells_; ++c)
    {
        sum += b[c];
    }
    std::copy(b, b + nCells_, x);
    x[r] -= sum;
    solve(x, x);
    const double shift = sum/delta - x[r];
    for (std::size_t c = 0; c < nCells_; ++c)
    {
        x[c] += shift;
    }
}


void fdm::separableBoxSolver::apply(const double* x, double* y) const
{
    const auto& d = coeffs_.diag;
    const auto& off = coeffs_.offDiag;
    for (long k = 0; k < n_[2]; ++k)
    {
        for (long j = 0; j < n_[1]; ++j)
        {
            for (long i = 0; i < n_[0]; ++i)
            {
                const long ijk[3] = {i, j, k};
                const long p = (wall_ >= 0) ? ijk[wall_] : 0;
                const std::size_t c = index(i, j, k);
                double sum = d[p]*x[c];
                for (int a = 0; a < 3; ++a)
                {
                    long lo[3] = {i, j, k}, hi[3] = {i, j, k};
                    if (a == wall_)
                    {
                        if (ijk[a] > 0)
                        {
                            lo[a] -= 1;
                            sum += off[a][ijk[a]-1]*x[index(lo[0], lo[1], lo[2])];
                        }
                        if (ijk[a] < n_[a]-1)
                        {
                            hi[a] += 1;
                            sum += off[a][ijk[a]]*x[index(hi[0], hi[1], hi[2])];
                        }
                    }
                    else
                    {
                        lo[a] = (ijk[a] + n_[a] - 1) % n_[a];
                        hi[a] = (ijk[a] + 1) % n_[a];
                        sum += off[a][p]*
                        (
                            x[index(lo[0], lo[1], lo[2])]
                          + x[index(hi[0], hi[1], hi[2])]
                        );
                    }
                }
                y[c] = sum;
            }
        }
    }
}


// ************************************************************************* //
