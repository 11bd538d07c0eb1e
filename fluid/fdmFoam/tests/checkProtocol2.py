#!/usr/bin/env python3
"""Standalone check of fdmFoam's side of the coupling protocol (docs/coupling.md): written for the
additions of version 2 (viscosity, box faces, stresslets), it speaks version 4 (Volumes once per
step, with the rigid-body block: Vu, m1, J). It plays the particle code over the socket (wire format of coupler/include/fdm/coupler.h,
re-implemented here in a few lines) and runs the real fdmFoam.

    . etc/bashrc && python3 fluid/fdmFoam/tests/checkProtocol2.py [--keep DIR]

A free sphere (radius a, a/Delta = 4) at the centre of a wall-driven shear cell (walls at ylo and
yhi moving along -x and +x, cyclic in x and z), the set-up of tests/test_walls.py and paper 5.2.2.
The emulated particle code solves Eq. (31) for one free particle without sub-grid terms:
(rho_f/alpha) [[Vu 1, -[m1]x], [[m1]x, J]] (U, Omega) = (F, T). Checked:

* protocol 4: after each Step one Volumes [Vu, m1 (3), J (6)] (Vu within 10 % of the sphere's volume,
  J of (2/5) a^2 Vu on the diagonal, m1 = 0 and J isotropic for this sphere on a symmetry point of
  the mesh), then Integrals of 6 values [F, T], one per inner iteration, and no other Volumes;

* the fluid Hello: 38 values, the first 13 as in protocol 1, eta = rho_f nu, the six box faces
  (kind, wall velocity), identical in serial and on 2 ranks split across the cyclic direction
  (processorCyclic patches, empty cyclic patches) and across the walls (each wall patch has no
  face on one rank); slip walls give kind 2;
* StepDone: 13 wide with stresslets=1 (also "yes"), 6 wide with stresslets=0 and then bit-equal
  forces; the stresslet of the sphere: S_xy > 0 of the size of (10/3) pi eta a^3 gamma_dot, the
  other components and the trace small; the same on 2 ranks (both decompositions); raising the
  pressure level (PISO pRefValue) by p0 shifts the trace by -3 rho_f p0 int I_lambda dV and
  changes nothing else (the pressure term of Eq. 12 and the caveat of docs/fluid.md);
* refused with an Error naming the cause: no stresslets= entry, stresslets=2, a fixedValue
  velocity that is not uniform over its patch.

Exit status 0 if every check passed. Takes about a minute on 2 cores.
"""
import argparse
import math
import os
import shutil
import socket
import struct
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
PROJECT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
sys.path.insert(0, os.path.join(PROJECT, "scripts"))
from fdmsubgrid import case  # noqa: E402

VERSION = 4
HELLO, STEP, INTEGRALS, VELOCITIES, STEPDONE, FINISH, ERROR, VOLUMES = range(1, 9)
TYPE_NAMES = {1: "Hello", 2: "Step", 3: "Integrals", 4: "Velocities", 5: "StepDone", 6: "Finish", 7: "Error",
              8: "Volumes"}
HEADER = struct.Struct("<4sHHQIIIIQ")  # 40 bytes: magic version type step iteration count width text payload

# Fluid Hello layout (fdm::coupler::layout)
HF_VISCOSITY, HF_FACE_BASE, FACE_WIDTH = 13, 14, 4
FACES = ("xlo", "xhi", "ylo", "yhi", "zlo", "zhi")

failures = []


def check(condition, what):
    print("  %s %s" % ("ok  " if condition else "FAIL", what))
    if not condition:
        failures.append(what)


class Message:
    def __init__(self, type_, step=0, iteration=0, width=0, text="", records=()):
        self.type, self.step, self.iteration, self.width = type_, step, iteration, width
        self.text, self.records = text, [list(r) for r in records]

    def value(self, key):
        for token in self.text.split():
            k, _, v = token.partition("=")
            if k == key:
                return v
        raise KeyError("%s message has no %s= (text %r)" % (TYPE_NAMES[self.type], key, self.text))


class Peer:
    """The particle code's end of a socket connection to fdmFoam."""

    def __init__(self, port_file, fluid_process, timeout=60):
        t0 = time.time()
        while not os.path.isfile(port_file):
            if fluid_process.poll() is not None:
                raise RuntimeError("fdmFoam exited (%d) before listening" % fluid_process.returncode)
            if time.time() - t0 > timeout:
                raise RuntimeError("no port file %s within %d s" % (port_file, timeout))
            time.sleep(0.05)
        time.sleep(0.05)
        port = int(open(port_file).read().split()[0])
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=timeout)
        self.sock.settimeout(600)

    def send(self, m):
        text = m.text.encode()
        payload = b"".join(struct.pack("<%dd" % m.width, *r) for r in m.records)
        self.sock.sendall(HEADER.pack(b"FDMC", VERSION, m.type, m.step, m.iteration, len(m.records), m.width,
                                      len(text), len(m.records) * m.width) + text + payload)

    def _read(self, n):
        b = b""
        while len(b) < n:
            chunk = self.sock.recv(n - len(b))
            if not chunk:
                raise EOFError("fdmFoam closed the connection")
            b += chunk
        return b

    def receive(self):
        magic, version, type_, step, iteration, count, width, ntext, npayload = HEADER.unpack(self._read(40))
        if magic != b"FDMC" or version != VERSION or npayload != count * width:
            raise RuntimeError("bad header from fdmFoam: %r version %d" % (magic, version))
        text = self._read(ntext).decode()
        values = struct.unpack("<%dd" % npayload, self._read(8 * npayload))
        records = [values[i * width:(i + 1) * width] for i in range(count)]
        return Message(type_, step, iteration, width, text, records)

    def close(self):
        self.sock.close()


H, U_WALL, A, DELTA, NU, RHO = 4.0, 1.0, 1.0, 0.25, 0.5, 2.0
BOX_SIZE = (6.0, H, 4.0)
SPHERE = (3.0, H / 2, 2.0, A)
P_SHIFT = 0.1   # kinematic pressure level [m2/s2] for the trace check


def write_case(root, faces_y, u_nonuniform=False):
    box = case.Box((0, 0, 0), BOX_SIZE, DELTA, faces=("cyclic", faces_y, "cyclic"))
    fluid = os.path.join(root, "fluid")
    # The plain iteration (acceleration none): the pressure-level check compares two runs whose
    # pressure solves differ at the linear solvers' tolerance; the accelerated iteration carries that
    # difference into F, T and S at ~1e-6 of the scale, which is the iteration, not the definitions
    # checked here.
    case.write_fluid_case(fluid, box, nu=NU, rho=RHO, tol_lambda=1e-6, n_max=3000, n_particles=1,
                          acceleration="none")
    if u_nonuniform:
        # yHigh: fixedValue with a velocity that varies from face to face
        n = box.n[0] * box.n[2]
        values = " ".join("(%g 0 0)" % (1 + 0.01 * i) for i in range(n))
        path = os.path.join(fluid, "0/U")
        text = open(path).read().replace(
            "yHigh { type fixedValue; value uniform (1 0 0); }",
            "yHigh { type fixedValue; value nonuniform List<vector> %d (%s); }" % (n, values))
        open(path, "w").write(text)
    log = open(os.path.join(root, "log.blockMesh"), "w")
    subprocess.run(["blockMesh", "-case", fluid], stdout=log, stderr=subprocess.STDOUT, check=True)
    return fluid, box


def clean(fluid, processors=False):
    """A fresh start: no time but 0 (fdmFoam restarts from the latest), no postProcessing."""
    for d in os.listdir(fluid):
        path = os.path.join(fluid, d)
        if not os.path.isdir(path) or d in ("0", "constant", "system"):
            continue
        if d.startswith("processor"):
            if processors:
                shutil.rmtree(path)
            else:
                clean(path)
        else:
            shutil.rmtree(path)


def decompose(root, fluid, n):
    clean(fluid, processors=True)
    case.foam_file(os.path.join(fluid, "system/decomposeParDict"), "dictionary", """
numberOfSubdomains 2;
method          hierarchical;
coeffs { n (%d %d %d); order xyz; }
hierarchicalCoeffs { n (%d %d %d); order xyz; }
""" % (n + n))
    log = open(os.path.join(root, "log.decomposePar"), "w")
    subprocess.run(["decomposePar", "-force", "-case", fluid], stdout=log, stderr=subprocess.STDOUT, check=True)


def start_fluid(root, fluid, np_fluid):
    port_file = os.path.join(fluid, "coupling.port")
    if os.path.exists(port_file):
        os.remove(port_file)
    clean(fluid)
    log = open(os.path.join(root, "log.fluid.np%d" % np_fluid), "w")
    if np_fluid > 1:
        cmd = ["mpirun", "-np", str(np_fluid), "--bind-to", "none", "--oversubscribe",
               "fdmFoam", "-parallel", "-case", fluid]
    else:
        cmd = ["fdmFoam", "-case", fluid]
    proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)
    return proc, Peer(port_file, proc), log.name


def dem_hello(box, stresslets_text):
    rec = [1]
    for d in range(3):
        rec += [box.lo[d], box.hi[d]]
    rec += [1.0 if p else 0.0 for p in box.periodic()]
    text = "role=dem version=%d dt=1 lastStep=1" % VERSION + (" " + stresslets_text if stresslets_text else "")
    return Message(HELLO, width=10, text=text, records=[rec])


def run_coupled(root, fluid, box, np_fluid, stresslets_text, n_steps=1):
    """One coupled run of a free sphere; returns (fluid Hello, last StepDone). Checks the order of
    protocol 4: Volumes once per step, before the first Integrals."""
    proc, peer, log = start_fluid(root, fluid, np_fluid)
    try:
        peer.send(dem_hello(box, stresslets_text))
        hello = peer.receive()
        assert hello.type == HELLO, "expected Hello, got %s: %s" % (TYPE_NAMES[hello.type], hello.text)
        alpha, rho = hello.records[0][1], hello.records[0][2]
        x, y, z, a = SPHERE
        v = [0.0] * 6
        done = None
        for step in range(1, n_steps + 1):
            peer.send(Message(STEP, step, 0, 11, "dt=1 lastStep=%d" % n_steps, [[1, x, y, z, a] + v]))
            m = peer.receive()
            assert m.type == VOLUMES, "expected Volumes, got %s: %s" % (TYPE_NAMES[m.type], m.text)
            check(m.step == step and m.width == 10 and len(m.records) == 1,
                  "np %d step %d: Volumes [Vu, m1, J] of the step first" % (np_fluid, step))
            vu, m1x, m1y, m1z, jxx, jxy, jxz, jyy, jyz, jzz = m.records[0]
            ju = (jxx + jyy + jzz) / 3
            sphere = 4.0 / 3.0 * math.pi * a ** 3
            check(abs(vu / sphere - 1) < 0.1 and abs(ju / (0.4 * a * a * vu) - 1) < 0.15,
                  "np %d: Vu %.6g ~ the sphere's volume %.6g, J %.6g ~ (2/5) a^2 Vu" % (np_fluid, vu, sphere, ju))
            # the sphere sits on a mesh vertex: the discrete sphere has the mesh's symmetries
            check(max(abs(m1x), abs(m1y), abs(m1z)) < 1e-12 * vu * a and
                  max(abs(jxy), abs(jxz), abs(jyz), abs(jxx - ju), abs(jyy - ju), abs(jzz - ju)) < 1e-12 * ju,
                  "np %d: m1 = 0 and J isotropic on a symmetry point of the mesh" % np_fluid)
            iterations = 0
            while True:
                m = peer.receive()
                if m.type == STEPDONE:
                    done = m
                    break
                assert m.type == INTEGRALS, "expected Integrals, got %s: %s" % (TYPE_NAMES[m.type], m.text)
                assert m.width == 6, "Integrals of %d values (protocol 4: 6)" % m.width
                iterations += 1
                fx, fy, fz, tx, ty, tz = m.records[0]
                # Eq. (31) for one free particle, no sub-grid terms
                v = [alpha * f / (rho * vu) for f in (fx, fy, fz)] + [alpha * t / (rho * ju) for t in (tx, ty, tz)]
                peer.send(Message(VELOCITIES, step, m.iteration, 6, "", [v]))
            check(iterations == done.iteration, "np %d: %d Integrals, one per inner iteration (StepDone says %d)"
                  % (np_fluid, iterations, done.iteration))
        peer.send(Message(FINISH, n_steps))
        rc = proc.wait(timeout=120)
        check(rc == 0, "fdmFoam (np %d) ends normally after Finish (log %s)" % (np_fluid, log))
        return hello, done
    finally:
        peer.close()
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def run_refused(root, fluid, box, stresslets_text, needle, what):
    proc, peer, log = start_fluid(root, fluid, 1)
    try:
        peer.send(dem_hello(box, stresslets_text))
        m = peer.receive()
        check(m.type == ERROR and needle in m.text, "%s: Error naming %r (got %s: %s)"
              % (what, needle, TYPE_NAMES[m.type], m.text))
        rc = proc.wait(timeout=60)
        check(rc != 0, "%s: fdmFoam stops with an error" % what)
    finally:
        peer.close()
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def check_hello(hello, box, faces, label):
    r = list(hello.records[0])
    check(hello.width == 38 and len(hello.records) == 1, "%s: fluid Hello is one record of 38" % label)
    def close(x, y):
        return abs(x - y) <= 1e-12 * max(abs(x), abs(y), 1.0)

    check(r[0] == 1 and r[2] == RHO and close(r[3], DELTA) and close(r[1], DELTA ** 2 / NU),
          "%s: N, alpha_lambda, rho_f, Delta as in protocol 1 (got %s)" % (label, r[0:4]))
    box_expected = [0, BOX_SIZE[0], 0, BOX_SIZE[1], 0, BOX_SIZE[2]]
    check(all(close(x, y) for x, y in zip(r[4:10], box_expected)), "%s: box %s" % (label, r[4:10]))
    check(list(r[10:13]) == [1, 0, 1], "%s: periodic x z" % label)
    check(abs(r[HF_VISCOSITY] - RHO * NU) < 1e-15, "%s: eta = rho_f nu = %g (got %g)"
          % (label, RHO * NU, r[HF_VISCOSITY]))
    got = [list(r[HF_FACE_BASE + FACE_WIDTH * f:HF_FACE_BASE + FACE_WIDTH * (f + 1)]) for f in range(6)]
    for f in range(6):
        check(got[f] == list(faces[f]), "%s: face %s = %s (expected %s)" % (label, FACES[f], got[f], faces[f]))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--keep", help="work in this directory and keep it")
    args = parser.parse_args()
    for exe in ("fdmFoam", "blockMesh", "decomposePar"):
        if shutil.which(exe) is None:
            sys.exit("%s not found: . etc/bashrc (after ./Allwmake)" % exe)
    work = args.keep or tempfile.mkdtemp(prefix="fdmProtocol2.")
    os.makedirs(work, exist_ok=True)
    shear_faces = [(0, 0, 0, 0), (0, 0, 0, 0), (1, -U_WALL, 0, 0), (1, U_WALL, 0, 0), (0, 0, 0, 0), (0, 0, 0, 0)]

    print("shear cell, serial, stresslets=1")
    root = os.path.join(work, "shear")
    fluid, box = write_case(root, ((-U_WALL, 0, 0), (U_WALL, 0, 0)))
    hello, done = run_coupled(root, fluid, box, 1, "stresslets=1")
    check_hello(hello, box, shear_faces, "serial")
    check(done.width == 13, "StepDone is 13 wide with stresslets=1")
    rec = done.records[0]
    F, T = rec[0:3], rec[3:6]
    S = dict(zip(("xx", "xy", "xz", "yy", "yz", "zz"), rec[6:12]))
    s = rec[12]
    gamma = 2 * U_WALL / H
    scale = 10.0 / 3.0 * math.pi * RHO * NU * A ** 3 * gamma
    print("    S* = S_xy/((10/3) pi eta a^3 gamma_dot) = %.4f; S = %s; s = %.3g; F = %s; T = %s"
          % (S["xy"] / scale, {k: round(v / scale, 5) for k, v in S.items()}, s / scale, F, T))
    check(abs(S["xx"] + S["yy"] + S["zz"]) < 1e-10 * scale, "S is traceless")
    check(1.0 < S["xy"] / scale < 1.6, "S_xy/((10/3) pi eta a^3 gamma_dot) in (1, 1.6): walls at H = 4a raise it")
    check(max(abs(S[k]) for k in ("xx", "yy", "zz", "xz", "yz")) < 0.02 * scale, "other components of S small")
    check(abs(s) < 0.05 * scale, "trace s small (symmetric set-up)")

    print("shear cell, serial, pressure level raised by pRefValue = %g" % P_SHIFT)
    fv = os.path.join(fluid, "system/fvSolution")
    text = open(fv).read()
    open(fv, "w").write(text.replace("pRefValue       0;", "pRefValue       %r;" % P_SHIFT))
    _, done_shift = run_coupled(root, fluid, box, 1, "stresslets=1")
    open(fv, "w").write(text)
    rec_shift = done_shift.records[0]
    # Eq. (12): s gains -3 rho_f p0 int I_lambda dV; I_lambda = 1 on the cells whose centre lies
    # within a + c Delta of the centre (c = 0.3), S and the forces do not change
    x, y, z, a = SPHERE
    reach, n = a + 0.3 * DELTA, [int(round(L / DELTA)) for L in BOX_SIZE]
    n_cells = sum(1 for i in range(n[0]) for j in range(n[1]) for k in range(n[2])
                  if ((i + 0.5) * DELTA - x) ** 2 + ((j + 0.5) * DELTA - y) ** 2 + ((k + 0.5) * DELTA - z) ** 2
                  <= reach ** 2)
    expected = -3 * RHO * P_SHIFT * n_cells * DELTA ** 3
    got = rec_shift[12] - rec[12]
    print("    s shift %.6g, expected -3 rho_f p0 V_lambda = %.6g (%d cells)" % (got, expected, n_cells))
    check(abs(got - expected) < 1e-3 * abs(expected), "trace shifts by -3 rho_f p0 int I_lambda dV")
    check(max(abs(u - v) for u, v in zip(rec_shift[0:12], rec[0:12])) < 1e-6 * scale,
          "S, F, T do not depend on the pressure level")

    print("shear cell, serial, stresslets=0: 6 wide, same forces")
    hello0, done0 = run_coupled(root, fluid, box, 1, "stresslets=0")
    check(done0.width == 6, "StepDone is 6 wide with stresslets=0")
    check(list(done0.records[0]) == list(rec[0:6]), "forces bit-equal to the run with stresslets")
    check(hello0.records == hello.records, "same fluid Hello")

    for n, what in (((2, 1, 1), "split across the cyclic x"), ((1, 2, 1), "split across the walls")):
        print("shear cell, 2 ranks, %s" % what)
        decompose(root, fluid, n)
        hello_p, done_p = run_coupled(root, fluid, box, 2, "stresslets=yes")
        check(hello_p.records == hello.records, "fluid Hello identical to serial")
        rec_p = done_p.records[0]
        diff = max(abs(a - b) for a, b in zip(rec_p[6:13], rec[6:13]))
        print("    largest stresslet difference to serial: %.3g (S*: %.6f)" % (diff / scale, rec_p[7] / scale))
        check(done_p.width == 13 and diff < 2e-3 * scale, "stresslets as in serial (2e-3 of the scale)")

    print("handshake refusals")
    run_refused(root, fluid, box, "", "stresslets=", "DEM Hello without stresslets=")
    run_refused(root, fluid, box, "stresslets=2", "stresslets=2", "DEM Hello with stresslets=2")
    root_nu = os.path.join(work, "nonuniform")
    fluid_nu, box_nu = write_case(root_nu, ((-U_WALL, 0, 0), (U_WALL, 0, 0)), u_nonuniform=True)
    run_refused(root_nu, fluid_nu, box_nu, "stresslets=1", "yHigh", "non-uniform fixedValue wall")

    print("slip walls")
    root_slip = os.path.join(work, "slip")
    fluid_slip, box_slip = write_case(root_slip, "slip")
    hello_s, done_s = run_coupled(root_slip, fluid_slip, box_slip, 1, "stresslets=1")
    slip_faces = [(0, 0, 0, 0), (0, 0, 0, 0), (2, 0, 0, 0), (2, 0, 0, 0), (0, 0, 0, 0), (0, 0, 0, 0)]
    check_hello(hello_s, box_slip, slip_faces, "slip")
    check(max(abs(x) for x in done_s.records[0]) < 1e-10, "at rest: no force, no stresslet")

    if not args.keep:
        shutil.rmtree(work, ignore_errors=True)
    print("%d check(s) failed" % len(failures) if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
