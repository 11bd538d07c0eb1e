"""Reading fdmFoam's per-step and per-particle records (postProcessing/fdm/*.dat)."""
import io
import os
import warnings

import numpy as np

STEP_COLUMNS = ("step time innerIterations residualLambda converged meanUx meanUy meanUz "
                "lambdaForceX lambdaForceY lambdaForceZ fluidSeconds particleSeconds exchangeSeconds maxCoreSlip "
                "velocityError").split()
PARTICLE_COLUMNS = "step tag x y z radius Ux Uy Uz Wx Wy Wz Fx Fy Fz Tx Ty Tz Vu".split()


def _read(path, columns):
    if not os.path.isfile(path):
        raise FileNotFoundError("%s not found: did fdmFoam run?" % path)
    with open(path) as f:
        text = f.read()
    if text and not text.endswith("\n"):
        # a record cut by a full disk or a killed run: fdmFoam ends every step's records with a
        # new line, so only the last, unfinished line is dropped
        warnings.warn("%s: the last line is incomplete (the run stopped while writing it): ignored" % path)
        text = text[:text.rfind("\n") + 1]
    data = np.loadtxt(io.StringIO(text), comments="#", ndmin=2)
    if data.size == 0:
        raise ValueError("%s has no records" % path)
    if columns is STEP_COLUMNS and data.shape[1] == len(columns) - 1:
        # records of fdmFoam before the velocity error was written
        data = np.hstack([data, np.full((data.shape[0], 1), np.nan)])
    if data.shape[1] != len(columns):
        raise ValueError("%s has %d columns, expected %d (%s)" % (path, data.shape[1], len(columns),
                                                                  " ".join(columns)))
    return {name: data[:, i] for i, name in enumerate(columns)}


def steps(fluid_case):
    return _read(os.path.join(fluid_case, "postProcessing", "fdm", "steps.dat"), STEP_COLUMNS)


def particles(fluid_case):
    return _read(os.path.join(fluid_case, "postProcessing", "fdm", "particles.dat"), PARTICLE_COLUMNS)
