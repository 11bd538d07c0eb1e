#include "FFTBox.H"
#include "FFTBoxPreconditioner.H"
#include "boxOperator.H"
#include "addToRunTimeSelectionTable.H"

// * * * * * * * * * * * * * * Static Data Members * * * * * * * * * * * * * //

namespace Foam
{
    defineTypeNameAndDebug(FFTBox, 0);

    lduMatrix::solver::addsymMatrixConstructorToTable<FFTBox>
        addFFTBoxSymMatrixConstructorToTable_;
}


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
    PCG
    (
        fieldName,
        matrix,
        interfaceBouCoeffs,
        interfaceIntCoeffs,
        interfaces,
        solverControls
    ),
    maxDeparture_(controlDict_.lookupOrDefault<scalar>("maxDeparture", 0.5)),
    measurePlans_(boxSolve::measurePlans(controlDict_, fieldName)),
    operator_(nullptr)
{
    // PCG makes its preconditioner from this entry: the box solve, which
    // takes the operator this solver prepared (FFTBoxPreconditioner)
    controlDict_.set("preconditioner", FFTBoxPreconditioner::typeName);
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
    if (boxSolve::firstTime(fieldName_, "fallback " + reason))
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
    string reason;
    operator_ = boxSolve::prepare
    (
        *this, maxDeparture_, measurePlans_, "solved directly", reason
    );
    if (!operator_)
    {
        return fallback(psi, source, cmpt, reason);
    }

    // OpenFOAM's PCG, preconditioned by the exact box solve: one iteration
    // where the matrix is the box's
    solverPerformance solverPerf = PCG::solve(psi, source, cmpt);
    operator_ = nullptr;
    solverPerf.solverName() = typeName;
    return solverPerf;
}


// ************************************************************************* //
