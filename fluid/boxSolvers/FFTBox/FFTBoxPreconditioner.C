#include "FFTBoxPreconditioner.H"
#include "FFTBox.H"
#include "boxOperator.H"
#include "addToRunTimeSelectionTable.H"

// * * * * * * * * * * * * * * Static Data Members * * * * * * * * * * * * * //

namespace Foam
{
    defineTypeNameAndDebug(FFTBoxPreconditioner, 0);

    lduMatrix::preconditioner::addsymMatrixConstructorToTable<FFTBoxPreconditioner>
        addFFTBoxPreconditionerSymMatrixConstructorToTable_;
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::FFTBoxPreconditioner::FFTBoxPreconditioner
(
    const lduMatrix::solver& sol,
    const dictionary& controls
)
:
    lduMatrix::preconditioner(sol),
    operator_(nullptr)
{
    // inside the FFTBox solver: the operator it prepared for this solve
    const FFTBox* box = dynamic_cast<const FFTBox*>(&sol);
    if (box && box->prepared())
    {
        operator_ = box->prepared();
        return;
    }

    const scalar maxDeparture = controls.lookupOrDefault<scalar>("maxDeparture", 0.5);
    const bool measure = boxSolve::measurePlans(controls, sol.fieldName());
    string reason;
    operator_ = boxSolve::prepare
    (
        sol, maxDeparture, measure, "preconditioned by the box solve", reason
    );
    if (operator_)
    {
        return;
    }

    // the fallback preconditioner: DIC, or the `fallback` entry, a word or a
    // preconditioner's dictionary
    dictionary fallbackControls;
    if (controls.found("fallback"))
    {
        const entry& e = controls.lookupEntry("fallback", keyType::LITERAL);
        autoPtr<entry> copy(e.clone(fallbackControls));
        copy->keyword() = "preconditioner";
        fallbackControls.add(copy.ptr());
    }
    else
    {
        fallbackControls.add("preconditioner", "DIC");
    }
    const word name(lduMatrix::preconditioner::getName(fallbackControls));
    if (name == typeName)
    {
        FatalIOErrorInFunction(controls)
            << "FFTBox for " << sol.fieldName() << ": the fallback of the FFTBox"
            << " preconditioner cannot be FFTBox" << exit(FatalIOError);
    }
    if (boxSolve::firstTime(sol.fieldName(), "fallback preconditioner " + reason))
    {
        Info<< "FFTBox: " << sol.fieldName() << " is preconditioned by " << name
            << " (the fallback): " << reason.c_str() << endl;
    }
    fallback_ = lduMatrix::preconditioner::New(sol, fallbackControls);
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

void Foam::FFTBoxPreconditioner::precondition
(
    solveScalarField& wA,
    const solveScalarField& rA,
    const direction cmpt
) const
{
    if (operator_)
    {
        operator_->precondition(wA, rA);
    }
    else
    {
        fallback_->precondition(wA, rA, cmpt);
    }
}


// ************************************************************************* //
