"""fdmFoam's side of the coupling protocol (version 4: Volumes once per step with the rigid-body block; version 2's viscosity,
box faces, stresslets of Eq. 12), checked by fluid/fdmFoam/tests/checkProtocol2.py: it plays the
particle code over the socket against the real fdmFoam, serial and on 2 ranks (see its docstring
for every check)."""
import os
import subprocess
import sys

from conftest import PROJECT


def test_fluid_side_of_protocol_2(env, tmp_path):
    script = os.path.join(PROJECT, "fluid", "fdmFoam", "tests", "checkProtocol2.py")
    proc = subprocess.run([sys.executable, script, "--keep", str(tmp_path)], env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-5000:]
