#!/usr/bin/env python3
"""FDM overhead (issue 13): one fdmFoam inner iteration against one icoFoam PISO step on the same
mesh, fvSolution and fvSchemes, and the cost of a whole fdmFoam time step in icoFoam steps.

The scene: a cubic box of --cells^3 cells (a1/Delta = --a-over-delta, a1 = 1, nu = 1), periodic in
x and z, walls at -U and +U (U = 1) in y, so the shear rate is 2U/L; fdmFoam gets --particles
bidisperse spheres (a2 = 1.4 a1, equal volumes, a random non-overlapping packing from
fdmsubgrid.packing.channel_packing) with `pair_style fdm/subgrid` (lubrication, frictional contact, both
walls) and, for comparison, one sphere a1 at the centre. icoFoam (Debian's /usr/bin/icoFoam,
OpenFOAM v1912) runs on the same polyMesh with fdmFoam's fvSolution and fvSchemes plus only what it
needs (ddt Euler, div(phi,U) Gauss linear) and deltaT = alpha_lambda = Delta^2/nu, the pseudo-time
step of fdmFoam's inner iteration; both start from rest (u = 0, the walls moving).

  iteration  fdmFoam with a fixed number of inner iterations per step (nMin = nMax = --iterations,
             tolLambda 0), --steps time steps of dt = 0.05/gamma_dot, Anderson acceleration and the
             plain iteration (`acceleration none`), --particles spheres and 1 sphere; icoFoam,
             --ico-steps steps. The runs alternate in one batch (icoFoam, N spheres Anderson, N
             plain, icoFoam, 1 sphere Anderson, 1 plain), --repeats times. fdmFoam's seconds per
             inner iteration: steps.dat fluidSeconds / innerIterations (the PISO solve and the
             acceleration), and fluid + particleSeconds (forcing: stencil integrals, lambda
             correction) + exchangeSeconds (messages and the whole particle side while fdmFoam
             waits) per inner iteration, the median over steps 2..; icoFoam's wall seconds per
             step from the time its log prints each step's ExecutionTime line, median over steps
             2..; then the medians over the repeats.
  step       the N-sphere scene with the criterion of the suspension runs (tolLambda --tol-lambda,
             nMax --n-max, the same for the first step), --scene-steps steps of dt = 0.05/gamma_dot,
             the flow starting from the undisturbed linear shear profile; Anderson and plain, once
             each (inner-iteration counts are deterministic): inner iterations per step and the
             cost of a step in icoFoam steps = inner iterations per step x (seconds per inner
             iteration / seconds per icoFoam step) with the medians of `iteration`, and the step's
             own wall seconds over the icoFoam step.

  python3 scripts/benchmarkOverhead.py                       # both parts (about 20 min on 2 cores)
  python3 scripts/benchmarkOverhead.py --only iteration --repeats 3
  python3 scripts/benchmarkOverhead.py --only step --scene-steps 10   # keeps `iteration` from the JSON

Needs the project's environment (. etc/bashrc: fdmFoam, fdmDEM, blockMesh) and /usr/bin/icoFoam.
Writes docs/data/benchmarks_overhead.json; run folders go to --workdir.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

from fdmsubgrid import case, output, packing

HERE = os.path.dirname(os.path.abspath(__file__))
PROJECT = os.path.dirname(HERE)

A1, NU, U_WALL = 1.0, 1.0, 1.0
# frictional contact as in the suspension cases (kn, kt, mu_s, h_r), docs/contact.md
CONTACT = (20000.0, 200.0, 0.5, 0.005)


class Scene:
    """The box, the mesh spacing and the time step of every run."""

    def __init__(self, cells, a_over_delta, tol_u, tol_p):
        self.cells = cells
        self.delta = A1 / a_over_delta
        self.L = cells * self.delta
        self.box = case.Box((0, 0, 0), (self.L,) * 3, self.delta,
                            faces=("cyclic", ((-U_WALL, 0, 0), (U_WALL, 0, 0)), "cyclic"))
        self.shear_rate = 2 * U_WALL / self.L
        self.dt = 0.05 / self.shear_rate
        self.alpha = self.delta ** 2 / NU       # alpha_lambda, fdmFoam's default (Eq. 29)
        self.tol_u, self.tol_p = tol_u, tol_p

    def describe(self):
        return dict(cells=self.cells ** 3, mesh=[self.cells] * 3, delta=self.delta, L=self.L, a_over_delta=A1 / self.delta,
                    nu=NU, wall_velocity=U_WALL, shear_rate=self.shear_rate, dt=self.dt, alpha_lambda=self.alpha,
                    tol_u=self.tol_u, tol_p=self.tol_p, contact=dict(zip(("kn", "kt", "mu_s", "h_r"), CONTACT)))


def spheres_of(scene, n, seed):
    if n == 1:
        c = scene.L / 2
        return [(c + 0.3 * scene.delta, c + 0.1 * scene.delta, c + 0.2 * scene.delta, A1, 1)], None
    p = packing.channel_packing((scene.L,) * 3, n=n, seed=seed, min_gap=0.05, a1=A1)
    return [tuple(x) + (float(a), int(t)) for x, a, t in zip(p.positions, p.radii, p.types)], p.summary()


def write_fdm_run(run_dir, scene, spheres, mesh, steps, acceleration, n_min, n_max, tol_lambda, shear_start):
    shutil.rmtree(run_dir, ignore_errors=True)
    fluid = os.path.join(run_dir, "fluid")
    case.write_fluid_case(fluid, scene.box, nu=NU, rho=1.0, tol_lambda=tol_lambda, n_min=n_min, n_max=n_max,
                          first_step=(tol_lambda, n_max), tol_u=scene.tol_u, tol_p=scene.tol_p,
                          n_particles=len(spheres), acceleration=acceleration)
    if shear_start:
        write_shear_profile(os.path.join(fluid, "0", "U"), scene)
    link_mesh(fluid, mesh)
    pair = ("fdm/subgrid contact %r %r %r %r wall ylo %r 0 0 wall yhi %r 0 0"
            % (CONTACT + (-U_WALL, U_WALL)))
    # move yes (the fix's default): the particles move with the shear, as in a suspension run
    case.write_dem_input(os.path.join(run_dir, "dem"), scene.box, spheres, dt=scene.dt, pair_style=pair,
                         fix_options="move yes", runs=("run %d" % steps,), name="in.overhead")


def write_shear_profile(path, scene):
    """0/U as the undisturbed Couette flow u_x = U (2 y / L - 1) at the cell centres (blockMesh's
    cell order: x fastest, then y, then z)."""
    n = scene.cells
    y = (np.arange(n) + 0.5) * scene.delta
    ux = U_WALL * (2 * y / scene.L - 1)
    with open(path) as f:
        text = f.read()
    rows = "\n".join("(%.12g 0 0)" % ux[j] for k in range(n) for j in range(n) for i in range(n))
    text = text.replace("internalField   uniform (0 0 0);",
                        "internalField   nonuniform List<vector>\n%d\n(\n%s\n);" % (n ** 3, rows))
    with open(path, "w") as f:
        f.write(text)


def link_mesh(fluid, mesh):
    target = os.path.join(fluid, "constant", "polyMesh")
    shutil.rmtree(target, ignore_errors=True)
    os.symlink(mesh, target)


def make_mesh(workdir, scene):
    """One blockMesh for every run: workdir/mesh/constant/polyMesh."""
    mesh_case = os.path.join(workdir, "mesh")
    mesh = os.path.join(mesh_case, "constant", "polyMesh")
    if os.path.isfile(os.path.join(mesh, "points")) and os.path.isfile(os.path.join(mesh_case, "cells.txt")):
        with open(os.path.join(mesh_case, "cells.txt")) as f:
            if f.read().strip() == "%d %r" % (scene.cells, scene.delta):
                return mesh
    shutil.rmtree(mesh_case, ignore_errors=True)
    case.write_fluid_case(mesh_case, scene.box, nu=NU)
    subprocess.run(["blockMesh", "-case", mesh_case], check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(mesh_case, "cells.txt"), "w") as f:
        f.write("%d %r\n" % (scene.cells, scene.delta))
    return mesh


def fdm_per_iteration(run_dir):
    """fdmFoam's seconds per inner iteration over steps 2.. (median over steps)."""
    st = output.steps(os.path.join(run_dir, "fluid"))
    later = slice(1, None) if len(st["step"]) > 1 else slice(None)
    inner = st["innerIterations"][later]
    fluid = st["fluidSeconds"][later] / inner
    whole = (st["fluidSeconds"] + st["particleSeconds"] + st["exchangeSeconds"])[later] / inner
    return dict(fluid=float(np.median(fluid)), whole=float(np.median(whole)),
                forcing=float(np.median(st["particleSeconds"][later] / inner)),
                exchange=float(np.median(st["exchangeSeconds"][later] / inner)),
                fluid_steps=fluid.tolist(), whole_steps=whole.tolist(), inner_iterations=st["innerIterations"].tolist())


def linear_solver_iterations(log_path):
    """Mean linear-solver iterations per PISO step over a whole OpenFOAM log: U (Ux + Uy + Uz) and
    p (all correctors); the count of PISO steps is the count of momentum solves (Ux lines)."""
    u = p = steps = 0
    with open(log_path, errors="replace") as f:
        for line in f:
            if "Solving for U" in line:
                u += int(line.rsplit(None, 1)[-1])
                if "Solving for Ux" in line:
                    steps += 1
            elif "Solving for p" in line:
                p += int(line.rsplit(None, 1)[-1])
    return dict(U=u / max(steps, 1), p=p / max(steps, 1), piso_steps=steps)


# ------------------------------------------------------------------------------------------------
# icoFoam
# ------------------------------------------------------------------------------------------------

ICO = "/usr/bin/icoFoam"


def write_ico_run(run_dir, fdm_fluid, scene, steps):
    """icoFoam on fdmFoam's mesh, fvSolution and fvSchemes (plus ddt Euler, div(phi,U) Gauss linear),
    deltaT = alpha_lambda, from fdmFoam's initial fields."""
    shutil.rmtree(run_dir, ignore_errors=True)
    os.makedirs(os.path.join(run_dir, "system"))
    os.makedirs(os.path.join(run_dir, "constant"))
    shutil.copy(os.path.join(fdm_fluid, "system", "fvSolution"), os.path.join(run_dir, "system"))
    shutil.copytree(os.path.join(fdm_fluid, "0"), os.path.join(run_dir, "0"))
    with open(os.path.join(fdm_fluid, "system", "fvSchemes")) as f:
        schemes = f.read()
    schemes = schemes.replace("ddtSchemes { default none; }", "ddtSchemes { default Euler; }")
    schemes = schemes.replace("divSchemes { default none; }", "divSchemes { default none; div(phi,U) Gauss linear; }")
    if "Euler" not in schemes or "div(phi,U)" not in schemes:
        raise RuntimeError("fdmFoam's fvSchemes changed: cannot add icoFoam's ddt and div schemes")
    with open(os.path.join(run_dir, "system", "fvSchemes"), "w") as f:
        f.write(schemes)
    case.write_control_dict(run_dir, application="icoFoam", write_interval=1000000,
                            end_time=(steps + 0.5) * scene.alpha, delta_t=scene.alpha)
    case.foam_file(os.path.join(run_dir, "constant", "transportProperties"), "dictionary",
                   "\nnu              [0 2 -1 0 0 0 0] %.17g;\n" % NU)
    link_mesh(run_dir, os.path.realpath(os.path.join(fdm_fluid, "constant", "polyMesh")))


def run_ico(run_dir):
    """Runs icoFoam; returns the wall seconds of each time step (the time between the log's
    successive ExecutionTime lines; the first from the first 'Time =' line)."""
    stamps, start = [], None
    with open(os.path.join(run_dir, "log.icoFoam"), "w") as log:
        proc = subprocess.Popen([ICO, "-case", run_dir], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                text=True, bufsize=1)
        for line in proc.stdout:
            now = time.monotonic()
            log.write(line)
            if start is None and line.startswith("Time = "):
                start = now
            elif line.startswith("ExecutionTime"):
                stamps.append(now)
        if proc.wait() != 0:
            raise RuntimeError("icoFoam failed in %s (log.icoFoam)" % run_dir)
    if start is None or not stamps:
        raise RuntimeError("icoFoam printed no time steps in %s" % run_dir)
    return np.diff([start] + stamps).tolist()


# ------------------------------------------------------------------------------------------------
# the two parts
# ------------------------------------------------------------------------------------------------

def iteration_part(args, scene, mesh, spheres):
    runs = {"icoFoam": [], "N anderson": [], "N none": [], "1 anderson": [], "1 none": []}
    order = [("icoFoam", None), ("N anderson", spheres["N"]), ("N none", spheres["N"]),
             ("icoFoam", None), ("1 anderson", spheres["1"]), ("1 none", spheres["1"])]
    root = os.path.join(args.workdir, "iteration")
    # icoFoam's system/ and 0/ come from an fdmFoam case of the same scene (not run)
    write_fdm_run(os.path.join(root, "template"), scene, spheres["1"], mesh, args.steps, "anderson",
                  args.iterations, args.iterations, 0.0, shear_start=False)
    template = os.path.join(root, "template", "fluid")
    for rep in range(args.repeats):
        for k, (name, sph) in enumerate(order):
            run_dir = os.path.join(root, "%s_%d_%d" % (name.replace(" ", "_"), rep, k))
            if name == "icoFoam":
                write_ico_run(run_dir, template, scene, args.ico_steps)
                seconds = run_ico(run_dir)
                later = seconds[1:] if len(seconds) > 1 else seconds
                r = dict(step=float(np.median(later)), steps=seconds,
                         solver_iterations=linear_solver_iterations(os.path.join(run_dir, "log.icoFoam")))
                print("repeat %d %-11s %.3f s per PISO step (steps 2..: %s)"
                      % (rep, name, r["step"], " ".join("%.3f" % s for s in later)), flush=True)
            else:
                write_fdm_run(run_dir, scene, sph, mesh, args.steps, name.split()[1], args.iterations, args.iterations,
                              0.0, shear_start=False)
                wall = case.run(run_dir)
                r = fdm_per_iteration(run_dir)
                r["wall"] = wall
                r["solver_iterations"] = linear_solver_iterations(os.path.join(run_dir, "log.fluid"))
                print("repeat %d %-11s %.3f s per inner iteration fluid, %.3f with forcing and exchange "
                      "(forcing %.4f, exchange %.4f)" % (rep, name, r["fluid"], r["whole"], r["forcing"],
                                                         r["exchange"]), flush=True)
                shutil.rmtree(os.path.join(run_dir, "fluid", "processor0"), ignore_errors=True)
            runs[name].append(r)
    return runs


def summarise_iteration(runs):
    ico = [r["step"] for r in runs["icoFoam"]]
    out = dict(icoFoam_step=dict(median=float(np.median(ico)), runs=ico,
                                 solver_iterations=runs["icoFoam"][0].get("solver_iterations")))
    for name in ("N anderson", "N none", "1 anderson", "1 none"):
        fl = [r["fluid"] for r in runs[name]]
        wh = [r["whole"] for r in runs[name]]
        # the ratio within each repeat (against that repeat's icoFoam runs), then its median
        per_rep = len(ico) // max(len(fl), 1)
        ratios = [fl[i] / float(np.median(ico[i * per_rep:(i + 1) * per_rep])) for i in range(len(fl))]
        out[name] = dict(solver_iterations=runs[name][0].get("solver_iterations"), fluid_per_iteration=float(np.median(fl)), fluid_runs=fl,
                         whole_per_iteration=float(np.median(wh)), whole_runs=wh,
                         forcing_per_iteration=float(np.median([r["forcing"] for r in runs[name]])),
                         exchange_per_iteration=float(np.median([r["exchange"] for r in runs[name]])),
                         ratio_fluid=float(np.median(fl) / np.median(ico)),
                         ratio_whole=float(np.median(wh) / np.median(ico)),
                         ratio_fluid_per_repeat=ratios)
    return out


def relate(r, acc, iteration):
    """The cost of a step in icoFoam steps: with the seconds per inner iteration of `iteration`
    (its N-sphere runs with the same acceleration) and with the step run's own seconds."""
    if not iteration:
        return
    ico = iteration["icoFoam_step"]["median"]
    it = iteration["N %s" % acc]
    r["step_in_ico_steps"] = r["inner_mean"] * it["whole_per_iteration"] / ico
    r["step_in_ico_steps_fluid_only"] = r["inner_mean"] * it["fluid_per_iteration"] / ico
    r["step_in_ico_steps_own_timing"] = r["step_seconds_mean"] / ico


def step_part(args, scene, mesh, spheres, iteration):
    out = {}
    for acc in ("anderson", "none"):
        run_dir = os.path.join(args.workdir, "step", acc)
        write_fdm_run(run_dir, scene, spheres, mesh, args.scene_steps, acc, 1, args.n_max, args.tol_lambda,
                      shear_start=True)
        wall = case.run(run_dir)
        st = output.steps(os.path.join(run_dir, "fluid"))
        inner = st["innerIterations"]
        total = st["fluidSeconds"] + st["particleSeconds"] + st["exchangeSeconds"]
        r = dict(inner_iterations=inner.tolist(), converged=st["converged"].tolist(),
                 step_seconds=total.tolist(), fluid_seconds=st["fluidSeconds"].tolist(), wall=wall,
                 inner_mean=float(np.mean(inner)), inner_mean_after_first=float(np.mean(inner[1:])) if len(inner) > 1
                 else float(inner[0]), step_seconds_median=float(np.median(total)),
                 fluid_per_iteration=float(np.sum(st["fluidSeconds"]) / np.sum(inner)),
                 whole_per_iteration=float(np.sum(total) / np.sum(inner)))
        r["step_seconds_mean"] = float(np.mean(total))
        relate(r, acc, iteration)
        out[acc] = r
        print("step %-8s inner iterations per step %s (mean %.1f, after the first %.1f), %.3f s per inner "
              "iteration%s" % (acc, " ".join("%d" % i for i in inner), r["inner_mean"], r["inner_mean_after_first"],
                               r["whole_per_iteration"], ", %.1f icoFoam steps per step" % r["step_in_ico_steps"]
                               if "step_in_ico_steps" in r else ""), flush=True)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", nargs="+", choices=("iteration", "step"), default=None)
    ap.add_argument("--cells", type=int, default=64, help="cells per side of the cubic box")
    ap.add_argument("--a-over-delta", type=float, default=4.0, help="a1/Delta")
    ap.add_argument("--particles", type=int, default=100, help="spheres of the many-particle scene")
    ap.add_argument("--seed", type=int, default=1, help="seed of the packing")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--iterations", type=int, default=6, help="inner iterations per step in `iteration`")
    ap.add_argument("--steps", type=int, default=3, help="time steps of the `iteration` fdmFoam runs")
    ap.add_argument("--ico-steps", type=int, default=8, help="icoFoam time steps")
    ap.add_argument("--scene-steps", type=int, default=10, help="time steps of the `step` runs")
    ap.add_argument("--tol-lambda", type=float, default=1e-3, help="tolLambda of the `step` runs")
    ap.add_argument("--n-max", type=int, default=100, help="nMax of the `step` runs")
    ap.add_argument("--tol-u", type=float, default=1e-5, help="U solver tolerance (paper section 6)")
    ap.add_argument("--tol-p", type=float, default=1e-3, help="p solver tolerance (paper section 6)")
    ap.add_argument("--workdir", default=os.path.join(tempfile.gettempdir(), "fdmOverhead"))
    ap.add_argument("--out", default=os.path.join(PROJECT, "docs", "data", "benchmarks_overhead.json"))
    args = ap.parse_args(argv)
    parts = args.only or ["iteration", "step"]
    if not os.path.isfile(ICO):
        sys.exit("%s not found (Debian's openfoam package)" % ICO)
    os.makedirs(args.workdir, exist_ok=True)
    scene = Scene(args.cells, args.a_over_delta, args.tol_u, args.tol_p)
    results = dict(date=time.strftime("%Y-%m-%d %H:%M"), cores=os.cpu_count(),
                   load_average_start=list(os.getloadavg()),
                   command=" ".join(["scripts/benchmarkOverhead.py"] + (argv if argv is not None else sys.argv[1:])),
                   scene=scene.describe())
    if os.path.isfile(args.out):  # keep the part not re-run
        with open(args.out) as f:
            old = json.load(f)
        for k in ("iteration", "step"):
            if k not in parts and k in old:
                results[k] = old[k]
    mesh = make_mesh(args.workdir, scene)
    many, summary = spheres_of(scene, args.particles, args.seed)
    results["scene"]["packing"] = summary
    spheres = {"N": many, "1": spheres_of(scene, 1, args.seed)[0]}
    if "iteration" in parts:
        runs = iteration_part(args, scene, mesh, spheres)
        results["iteration"] = dict(settings=dict(repeats=args.repeats, iterations=args.iterations, steps=args.steps,
                                                  ico_steps=args.ico_steps, particles=args.particles),
                                    runs=runs, summary=summarise_iteration(runs))
    if "step" in parts:
        results["step"] = dict(settings=dict(steps=args.scene_steps, tol_lambda=args.tol_lambda, n_max=args.n_max,
                                             particles=args.particles),
                               runs=step_part(args, scene, mesh, many,
                                              results.get("iteration", {}).get("summary")))
    if "iteration" in results and "step" in results:  # either may come from an earlier run
        for acc, r in results["step"]["runs"].items():
            r.setdefault("step_seconds_mean", float(np.mean(r["step_seconds"])))
            relate(r, acc, results["iteration"]["summary"])
    results["load_average_end"] = list(os.getloadavg())
    with open(args.out, "w") as f:
        json.dump(results, f, indent=1)
    if "iteration" in results:
        s = results["iteration"]["summary"]
        print("\nicoFoam PISO step: %.3f s (runs %s)" % (s["icoFoam_step"]["median"],
                                                         " ".join("%.3f" % v for v in s["icoFoam_step"]["runs"])))
        for name in ("N anderson", "N none", "1 anderson", "1 none"):
            r = s[name]
            print("%-11s fluid %.3f s/iteration (ratio %.2f), with forcing and exchange %.3f (ratio %.2f)"
                  % (name.replace("N", str(args.particles)), r["fluid_per_iteration"], r["ratio_fluid"],
                     r["whole_per_iteration"], r["ratio_whole"]))
    if "step" in results:
        for acc, r in results["step"]["runs"].items():
            print("step %-8s inner iterations per step %.1f (after the first %.1f), %.1f icoFoam steps per step "
                  "(with its own seconds: %.1f)" % (acc, r["inner_mean"], r["inner_mean_after_first"],
                                                    r.get("step_in_ico_steps", float("nan")),
                                                    r.get("step_in_ico_steps_own_timing", float("nan"))))
    print("wrote", args.out)


if __name__ == "__main__":
    main()
