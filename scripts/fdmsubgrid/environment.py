"""Where the project's programs are: the binaries (fdmFoam, fdmDEM, fdmResistance) and the launcher
fdmRun, found through the environment, not through this file's location.

The order: the PATH (etc/bashrc puts the project's bin/ and scripts/ on it); then $FDM_BIN and
$FDM_ROOT/scripts (set by etc/bashrc); then the checkout this package sits in, if it sits in one
(an editable install: `pip install -e scripts`, what ./Allwmake does). A package installed
elsewhere without the environment gets an error that says what to source."""
from __future__ import annotations

import os
import shutil

_HERE = os.path.dirname(os.path.abspath(__file__))


def project_dir() -> str | None:
    """The project's root folder: $FDM_ROOT, else the checkout holding this package, else None."""
    root = os.environ.get("FDM_ROOT")
    if root and os.path.isdir(root):
        return root
    checkout = os.path.dirname(os.path.dirname(_HERE))   # <root>/scripts/fdmsubgrid
    if os.path.isfile(os.path.join(checkout, "etc", "bashrc")):
        return checkout
    return None


def build_dir() -> str | None:
    """The build folder ($FDM_BUILD, else <cache>/build with the cache $FDM_CACHE or <root>/.cache)."""
    if os.environ.get("FDM_BUILD"):
        return os.environ["FDM_BUILD"]
    root = project_dir()
    if root is None:
        return None
    return os.path.join(os.environ.get("FDM_CACHE") or os.path.join(root, ".cache"), "build")


def search_path() -> str:
    """PATH followed by the project's bin/ and scripts/ folders."""
    parts = [os.environ.get("PATH", "")]
    build, root = build_dir(), project_dir()
    if os.environ.get("FDM_BIN"):
        parts.append(os.environ["FDM_BIN"])
    if build:
        parts.append(os.path.join(build, "bin"))
    if root:
        parts.append(os.path.join(root, "scripts"))
    return os.pathsep.join(p for p in parts if p)


def program(name: str) -> str:
    """The full path of one of the project's programs (fdmRun, fdmFoam, fdmDEM, fdmResistance);
    FileNotFoundError saying what to do if it is not there."""
    exe = shutil.which(name, path=search_path())
    if exe is None:
        where = project_dir()
        hint = ("run %s/Allwmake" % where) if where else \
            "source <project>/etc/bashrc (or set FDM_ROOT to the project's folder) after ./Allwmake"
        raise FileNotFoundError("%s not found on the PATH nor in the project's build: %s" % (name, hint))
    return exe


def run_environment() -> dict[str, str]:
    """os.environ plus what the project's programs need to start: the library path of the build
    (etc/bashrc's LD_LIBRARY_PATH), the PATH of search_path(), and Open MPI's run-as-root flags."""
    env = dict(os.environ)
    build = build_dir()
    if build:
        lib = os.path.join(build, "lib")
        if lib not in env.get("LD_LIBRARY_PATH", "").split(":"):
            env["LD_LIBRARY_PATH"] = lib + (":" + env["LD_LIBRARY_PATH"] if env.get("LD_LIBRARY_PATH") else "")
    env["PATH"] = search_path()
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    return env
