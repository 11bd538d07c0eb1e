"""Shared fixtures of the coupled tests: they run the real fdmFoam (OpenFOAM) against the real
fdmDEM (LIGGGHTS) through fdmRun, on small meshes. ./Alltest builds both first."""
import importlib.util
import os
import shutil
import subprocess
import sys

import pytest

TESTS = os.path.dirname(os.path.abspath(__file__))
PROJECT = os.path.dirname(TESTS)
# the package of this checkout, whichever one is installed
sys.path.insert(0, os.path.join(PROJECT, "scripts"))

FULL = os.environ.get("FDM_FULL") == "1"


def load_case_module(name, script=None):
    """cases/<name>/<script>.py (default <name>.py) as a module. Its folder goes on the import path, as
    when the script runs (Python puts a script's folder first): the scripts of one case import each other."""
    script = script or name
    folder = os.path.join(PROJECT, "cases", name)
    if folder not in sys.path:
        sys.path.insert(0, folder)
    path = os.path.join(folder, script + ".py")
    spec = importlib.util.spec_from_file_location(script, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def assert_refused(main, options, messages, tmp_path, capsys, extra=()):
    """A case script's main(options) stops as argparse does (exit code 2) before running anything,
    its error names every one of `messages` (a string or a list), and no results file is written."""
    out = tmp_path / "r.json"
    with pytest.raises(SystemExit) as exit_info:
        main(list(options) + ["--workdir", str(tmp_path), "--out", str(out)] + list(extra))
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    for message in [messages] if isinstance(messages, str) else messages:
        assert message in err, (message, err)
    assert not out.exists()


@pytest.fixture(scope="session")
def env():
    """The project's environment (etc/bashrc) as a dict, for subprocesses."""
    out = subprocess.run(["bash", "-c", ". '%s/etc/bashrc' && env -0" % PROJECT], check=True,
                         stdout=subprocess.PIPE).stdout
    environment = dict(item.split("=", 1) for item in out.decode().split("\0") if "=" in item)
    for exe in ("fdmFoam", "fdmDEM"):
        if shutil.which(exe, path=environment["PATH"]) is None:
            pytest.fail("%s not built: run ./Allwmake" % exe)
    return environment


@pytest.fixture(scope="session")
def periodic_array():
    return load_case_module("periodicArray")


@pytest.fixture(scope="module")
def ct():
    """cases/contactTuning/contactTuning.py: the DEM-only contact scenes."""
    return load_case_module("contactTuning")


@pytest.fixture(scope="module")
def res(ct, tmp_path_factory):
    """The contact modes' resistances (Stokes drag + sub-grid lubrication, fdmsubgrid.contactstability) at the
    cut-offs fdmDEM uses."""
    from fdmsubgrid import contactstability
    cutoff, wall_cutoff = ct.probe_cutoffs(str(tmp_path_factory.mktemp("probe")))
    p = ct.BASE
    return contactstability.ContactResistances(p["a"], p["eta"], p["delta"], cutoff, wall_cutoff)


def pytest_configure(config):
    config.addinivalue_line("markers", "full: full-size validation, run by ./Alltest --full only")


def pytest_collection_modifyitems(config, items):
    if FULL:
        return
    skip = pytest.mark.skip(reason="full-size validation: ./Alltest --full")
    for item in items:
        if "full" in item.keywords:
            item.add_marker(skip)
