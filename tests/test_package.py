"""The Python package fdmsubgrid (scripts/fdmsubgrid) as a user meets it: importable from any folder
after ./Allwmake (a notebook), declared by scripts/pyproject.toml, finding the project's programs
through the environment rather than through the file's location."""
import importlib.metadata
import os
import shutil
import site
import subprocess
import sys
import sysconfig
import tomllib

import pytest

TESTS = os.path.dirname(os.path.abspath(__file__))
PROJECT = os.path.dirname(TESTS)
MODULES = ("calibration", "case", "cellpositions", "channelscenes", "checkpoint", "cli", "contacts", "contactscenes",
           "contactstability", "convergence", "couettescene", "decomposition", "deminput", "demonly", "environment",
           "files", "foamcase", "output", "packing", "pairshearstresslet", "pairstresslet", "pairtangential",
           "periodicarray", "poiseuille", "profiles", "results", "rheology", "runner", "sbm", "shear", "squeeze",
           "steadystate", "subgridinterp", "suspension", "theory", "timeseries", "validation", "wallcalibration")


def clean_environment() -> dict:
    """The environment of a new shell: no PYTHONPATH, no project variables, no project folders on the PATH."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH" and not k.startswith("FDM_")}
    env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep) if not p.startswith(PROJECT))
    return env


def test_importable_from_any_folder_after_Allwmake():
    # what a notebook does: no sys.path manipulation, started elsewhere
    code = "import fdmsubgrid, %s; print(fdmsubgrid.__version__)" % ", ".join("fdmsubgrid." + m for m in MODULES)
    proc = subprocess.run([sys.executable, "-c", code], cwd="/", env=clean_environment(), text=True,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    assert proc.returncode == 0, "import fdmsubgrid failed (./Allwmake installs it):\n" + proc.stdout


def test_installed_by_pip_with_its_command():
    # etc/install-python-package.sh (./Allwmake): pip knows the package, editable from this checkout, and
    # installed the command of pyproject.toml; its offline fallback (a .pth file) is said in docs/install.md
    show = subprocess.run([sys.executable, "-m", "pip", "show", "fdmsubgrid"], env=clean_environment(), text=True,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    if show.returncode != 0:
        code = "import site, sysconfig, os; print(any(os.path.isfile(os.path.join(d, 'fdmsubgrid.pth')) for d in " \
               "(sysconfig.get_paths()['purelib'], site.getusersitepackages())))"
        fallback = subprocess.run([sys.executable, "-c", code], text=True, stdout=subprocess.PIPE).stdout.strip()
        if fallback == "True":
            pytest.skip("fdmsubgrid made importable by the .pth fallback (no wheel package offline: docs/install.md)")
        pytest.fail("pip does not know fdmsubgrid: run etc/install-python-package.sh (./Allwmake)\n" + show.stdout)
    fields = dict(line.split(": ", 1) for line in show.stdout.splitlines() if ": " in line)
    assert os.path.samefile(fields["Editable project location"], os.path.join(PROJECT, "scripts")), show.stdout
    # the command pip wrote beside the interpreter (or in the user's bin folder for a user install)
    commands = [e for e in importlib.metadata.entry_points(group="console_scripts") if e.name == "fdmProfiles"]
    assert commands and commands[0].value == "fdmsubgrid.shear:command"
    folders = (sysconfig.get_paths()["scripts"], os.path.join(site.getuserbase(), "bin"))
    assert any(os.access(os.path.join(d, "fdmProfiles"), os.X_OK) for d in folders), folders


def test_pyproject_declares_the_package_and_its_command():
    with open(os.path.join(PROJECT, "scripts", "pyproject.toml"), "rb") as f:
        project = tomllib.load(f)
    assert project["project"]["name"] == "fdmsubgrid"
    assert project["tool"]["setuptools"]["packages"] == ["fdmsubgrid"]
    import fdmsubgrid
    assert project["project"]["version"] == fdmsubgrid.__version__
    module, function = project["project"]["scripts"]["fdmProfiles"].split(":")
    assert callable(getattr(__import__(module, fromlist=[function]), function))
    # every module of the package is listed here, so that the import test covers it
    here = sorted(f[:-3] for f in os.listdir(os.path.join(PROJECT, "scripts", "fdmsubgrid"))
                  if f.endswith(".py") and f != "__init__.py")
    assert here == sorted(MODULES)


def test_programs_found_through_the_environment(tmp_path):
    # a copy of the package outside any checkout (a non-editable install): FDM_ROOT (etc/bashrc) is
    # how it finds fdmRun and fdmResistance; without it, an error that says what to source
    shutil.copytree(os.path.join(PROJECT, "scripts", "fdmsubgrid"), tmp_path / "fdmsubgrid")
    code = "from fdmsubgrid.environment import program; print(program('fdmRun')); print(program('fdmResistance'))"
    env = clean_environment()
    env["PYTHONPATH"] = str(tmp_path)
    with_root = subprocess.run([sys.executable, "-S", "-c", code], env=dict(env, FDM_ROOT=PROJECT), text=True,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, cwd=str(tmp_path))
    assert with_root.returncode == 0, with_root.stdout
    fdm_run, resistance = with_root.stdout.split()
    assert os.path.samefile(fdm_run, os.path.join(PROJECT, "scripts", "fdmRun"))
    assert os.path.basename(resistance) == "fdmResistance" and os.access(resistance, os.X_OK)
    without = subprocess.run([sys.executable, "-S", "-c", code], env=env, text=True, stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, cwd=str(tmp_path))
    assert without.returncode != 0
    assert "fdmRun not found" in without.stdout and "etc/bashrc" in without.stdout


@pytest.mark.parametrize("name", ["fdmRun", "fdmProfiles"])
def test_commands_on_the_path_of_etc_bashrc(env, name):
    exe = shutil.which(name, path=env["PATH"])
    assert exe is not None, name
    if name == "fdmProfiles" and not os.path.samefile(exe, os.path.join(PROJECT, "scripts", name)):
        # the command pip installed from pyproject.toml, where the interpreter's folder comes first on the PATH
        with open(exe, errors="replace") as f:
            assert "fdmsubgrid.shear" in f.read(), exe
    else:
        assert os.path.samefile(exe, os.path.join(PROJECT, "scripts", name))
    proc = subprocess.run([exe, "--help"], env=env, text=True, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    assert proc.returncode == 0 and "usage" in proc.stdout.lower(), proc.stdout[-1000:]
