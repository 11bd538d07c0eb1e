"""Theoretical references from the project's resistance library, through its command-line tool
fdmResistance (dem/resistance/, docs/resistance.md): one source of resistance functions for the solver,
the tests and the post-processing."""
import json
import os
import shutil
import subprocess

from . import PROJECT_DIR


def _tool():
    exe = shutil.which("fdmResistance") or os.path.join(PROJECT_DIR, ".cache", "build", "bin", "fdmResistance")
    if not os.path.isfile(exe):
        raise FileNotFoundError("fdmResistance not built: run ./Allwmake")
    return exe


def resistance(*args):
    """JSON output of `fdmResistance args...` as a dict."""
    out = subprocess.run([_tool()] + [str(a) for a in args], check=True, stdout=subprocess.PIPE, text=True).stdout
    return json.loads(out)


def pair_squeeze_velocity(a1, a2, xi):
    """Closing velocity of two spheres pushed together along their line of centres by equal and
    opposite forces F, in units of F/(6 pi eta a1): full-range two-sphere theory (Jeffrey & Onishi)."""
    return resistance("squeeze", "--a1", a1, "--a2", a2, "--xi", xi)["closing_velocity_normalised"]


def wall_squeeze_velocity(a, eps):
    """Velocity of a sphere pushed toward a plane wall by a force F, in units of F/(6 pi eta a):
    1/X^A_wall (Brenner 1961)."""
    return resistance("squeeze", "--a", a, "--eps", eps, "--wall")["closing_velocity_normalised"]


def relative_errors(values, reference):
    """(value - reference) / reference, element by element."""
    return [(v - r) / r for v, r in zip(values, reference)]
