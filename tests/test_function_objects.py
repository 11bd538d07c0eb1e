"""OpenFOAM's function objects run in fdmFoam: those of system/controlDict at every time step of a
coupled run, and on a finished case with fdmFoam -postProcess."""
import os
import subprocess

from fdmsubgrid import case

PROJECT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

FUNCTIONS = """
functions
{
    minMax
    {
        type            fieldMinMax;
        libs            ("libfieldFunctionObjects.so");
        fields          (U p);
        writeControl    timeStep;
        writeInterval   1;
    }
}
"""


def write_case(root, steps):
    box = case.Box((0, 0, 0), (4, 4, 4), 0.5)
    fluid = os.path.join(root, "fluid")
    grad_p0 = (-0.01, 0, 0)
    case.write_fluid_case(fluid, box, grad_p0=grad_p0, tol_lambda=1e-3, n_max=20)
    with open(os.path.join(fluid, "system", "controlDict"), "a") as f:
        f.write(FUNCTIONS)
    # the sphere carries V0 grad P0 (Eq. 43): the fully periodic box has a steady flow
    case.write_dem_input(os.path.join(root, "dem"), box, [(2.0, 2.0, 2.0, 0.5)], fix_options="move no",
                         before_run=case.balancing_force_line(box, grad_p0), runs=("run %d" % steps,))
    return fluid


def min_max_rows(fluid, start="0"):
    # the function object writes under the time it started at
    path = os.path.join(fluid, "postProcessing", "minMax", start, "fieldMinMax.dat")
    with open(path) as f:
        return [line.split() for line in f if not line.startswith("#")]


def test_controlDict_functions_run_every_step(tmp_path, env):
    fluid = write_case(str(tmp_path / "case"), steps=3)
    case.run(str(tmp_path / "case"))
    rows = min_max_rows(fluid)
    # U and p at each of the three steps (times 1, 2, 3: dt = 1)
    assert [(r[0], r[1]) for r in rows] == [(t, f) for t in ("1", "2", "3") for f in ("mag(U)", "p")], rows


def test_postProcess_on_a_finished_case(tmp_path, env):
    root = str(tmp_path / "case")
    fluid = write_case(root, steps=2)
    case.run(root)
    # needs neither fdmProperties nor the particle code: only the fields
    os.remove(os.path.join(fluid, "constant", "fdmProperties"))
    proc = subprocess.run(["fdmFoam", "-postProcess", "-func", "mag(U)", "-case", fluid, "-latestTime"], env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=60)
    assert proc.returncode == 0, proc.stdout[-2000:]
    assert os.path.isfile(os.path.join(fluid, "2", "mag(U)")), proc.stdout[-2000:]
    # and the functions of controlDict, on every written time
    proc = subprocess.run(["fdmFoam", "-postProcess", "-case", fluid, "-time", "2"], env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=60)
    assert proc.returncode == 0, proc.stdout[-2000:]
    assert [(r[0], r[1]) for r in min_max_rows(fluid, start="2")] == [("2", "mag(U)"), ("2", "p")]
