"""The DEM-only contact scenes of docs/contact.md (sections 3 and 4) and their runners: fdmDEM with fix
fdm/couple transport none on one of three LIGGGHTS inputs (in.normal: two spheres pressed together, in.wall:
a sphere pressed on a wall, in.sliding: a sphere between two walls; the folder given to use_inputs, the
case cases/contactTuning), each run measured against the theory of fdmsubgrid.contactstability:

  (a) normal     a loaded contact from a gap to its steady state (normal_run, normal_sweep)
  (b) sliding    a sphere between two walls pulled along them: stuck or sliding, the threshold by
                 bisection (sliding_run, sliding_sweep); a sphere pulled on one wall rolls (rolling_runs)
  (c) stability  explicit springs: the time-step limit by bisection against dt k/zeta (StabilityConfig,
                 stability_study)
  (d) implicit   implicit springs beyond the explicit limits: stability, steady gaps, convergence in dt
                 (implicit_stability, implicit_equilibrium, implicit_convergence, implicit_study)

Units SI at the 1 m scale (BASE): a = 1 m, eta = 1 Pa s, Delta = 0.2 m, h_r = 0.01 m, k_n = k_t = 2000 N/m,
loads LOAD = 10 N. Every runner takes the resistances of the contact modes (contactstability.ContactResistances
at the pair style's cut-offs, probe_cutoffs) and a folder for the runs, and returns plain dicts (JSON)."""
import concurrent.futures
import math
import os
import re
import shutil
import threading
import time

import numpy as np

from . import contactstability as cs, theory
from .demonly import fdmdem, run_in

# the scene: every length in units of a = 1 m, eta = 1 Pa s (the velocity scale F/(6 pi eta a))
BASE = dict(a=1.0, eta=1.0, delta=0.2, hr=0.01, kn=2000.0, kt=2000.0, mu=0.5)
LOAD = 10.0                      # N: F/k_n = h_r/2 at the base k_n


# ---------------------------------------------------------------------------------------------
# running fdmDEM
# ---------------------------------------------------------------------------------------------

def _value(v):
    return "%.17g" % v if isinstance(v, float) else str(v)


_counter = [0]
_counter_lock = threading.Lock()
_inputs = [None]     # the folder of in.normal, in.wall, in.sliding (use_inputs)


def use_inputs(folder: str) -> None:
    """The folder of the scenes' LIGGGHTS inputs (in.normal, in.wall, in.sliding: cases/contactTuning, where
    they also run by hand), which run_scene runs."""
    _inputs[0] = os.path.abspath(folder)


def run_scene(scene, variables, workdir, name=None, timeout=900):
    """Runs `fdmDEM -in in.<scene> -var ...` in a folder of workdir; returns a dict with the output
    table (`data`, numpy, one row per printed step), `ok`, `log` (the end of the screen output),
    `seconds` and the sub-grid cut-offs the pair style reported."""
    with _counter_lock:
        _counter[0] += 1
        index = _counter[0]
    run_dir = os.path.join(workdir, name or "%s_%04d" % (scene, index))
    if os.path.isdir(run_dir):
        shutil.rmtree(run_dir)
    os.makedirs(run_dir)
    out = scene + ".dat"
    if _inputs[0] is None:
        raise RuntimeError("fdmsubgrid.contactscenes: the folder of the scenes' inputs (in.normal, in.wall, "
                           "in.sliding) is not set: call use_inputs(folder) first (cases/contactTuning does)")
    cmd = [fdmdem(), "-in", os.path.join(_inputs[0], "in." + scene)]
    # the sections of docs/contact.md 3a-3c measure the explicit springs unless asked otherwise
    variables = dict(dict(cint="explicit"), **variables)
    for key, v in dict(variables, out=out).items():
        cmd += ["-var", key, _value(v)]
    proc, seconds = run_in(cmd, run_dir, "log", timeout)
    data = None
    path = os.path.join(run_dir, out)
    if os.path.isfile(path):
        try:
            data = np.loadtxt(path, comments="#", ndmin=2)
        except ValueError:
            data = None
    pair = re.search(r"pairs within a surface gap of ([0-9.eE+-]+) mesh cells", proc.stdout)
    wall = re.search(r"walls within ([0-9.eE+-]+) mesh cells", proc.stdout)
    ok = proc.returncode == 0 and data is not None and data.shape[0] > 0 and np.isfinite(data).all()
    return dict(ok=ok, returncode=proc.returncode, data=data, log=proc.stdout[-3000:], seconds=seconds,
                run_dir=run_dir, cutoff=float(pair.group(1)) if pair else None,
                wall_cutoff=float(wall.group(1)) if wall else None)


def probe_cutoffs(workdir):
    """The cut-offs (mesh cells) pair_style fdm/subgrid uses by default, from its start-up line."""
    r = run_scene("wall", dict(steps=1), workdir, name="probe")
    if not r["ok"]:
        raise RuntimeError("fdmDEM -in in.wall failed:\n" + r["log"])
    pair_default, wall_default = theory.pair_style_cutoffs()   # if the log does not say
    return (r["cutoff"] or pair_default, r["wall_cutoff"] or wall_default)


def parallel(jobs, function, items):
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        return list(pool.map(function, items))


# ---------------------------------------------------------------------------------------------
# (a) normal contact: pair and wall under a load
# ---------------------------------------------------------------------------------------------

def normal_run(res, workdir, geometry, kn, load, hr, lubrication=True, integrator="ab2", gap0=0.05, r_target=0.25,
               max_steps=200000, steps=None, p=BASE):
    """One loaded contact from gap0 to its steady state; dt = r_target zeta(h_r)/kn (the smallest
    resistance met in contact; the estimate of the limit is zeta/kn for ab2). The number of steps
    comes from the predicted gap history (until settled to 1e-9 F/kn), unless `steps` is given
    (then no prediction)."""
    a, eta = p["a"], p["eta"]
    zeta_of = res.pair_normal if geometry == "pair" else res.wall_normal
    g_ss = cs.steady_gap(hr, load, kn)
    compression = load / kn
    zeta_entry = zeta_of(hr, lubrication)
    zeta_ss = zeta_of(g_ss, lubrication)
    dt = r_target * min(zeta_entry, zeta_ss) / kn
    if steps is None:
        table = res.gap_table(geometry, lubrication)
        predicted = cs.step_gap_history(gap0, load, kn, hr, dt, max_steps, table, integrator,
                                settle=(g_ss, 1e-9 * compression))
        steps = min(max_steps, int(1.15 * len(predicted)) + 40)
    else:
        predicted = None
    variables = dict(kn=kn, kt=p["kt"], mu=p["mu"], hr=hr, F=load, dt=dt, steps=steps, gap0=gap0, a=a, eta=eta,
                     delta=p["delta"], lub="yes" if lubrication else "no", integ=integrator)
    r = run_scene("normal" if geometry == "pair" else "wall", variables, workdir)
    out = dict(geometry=geometry, kn=kn, load=load, hr=hr, lubrication=lubrication, integrator=integrator, dt=dt,
               steps=steps, gap0=gap0, gap_theory=g_ss, compression_theory=compression, zeta_at_hr=zeta_entry,
               zeta_steady=zeta_ss, tau_steady=zeta_ss / kn, ok=r["ok"], seconds=r["seconds"])
    if not r["ok"]:
        out["log"] = r["log"]
        return out
    d = r["data"]
    gap = d[:, 1]
    t = d[:, 0] * dt
    if geometry == "pair":
        contact = d[:, 4]                       # contact force on sphere 1 (along x: -F_n)
        out["force_balance"] = float(np.max(np.abs(d[:, 4] + d[:, 5])) / load)   # |F1 + F2| / F
        normal_force_end = -contact[-1]
    else:
        normal_force_end = d[-1, 3]
        out["force_balance"] = None
    out.update(
        gap_end=float(gap[-1]),
        gap_error=float((gap[-1] - g_ss) / compression),     # relative to the spring compression F/kn
        normal_force_end=float(normal_force_end),
        normal_force_error=float((normal_force_end - load) / load),
        t_contact=float(t[np.argmax(gap < hr)]) if (gap < hr).any() else None,
        min_gap=float(gap.min()),
    )
    i = cs.settle_index(gap, g_ss, 0.01 * compression)
    out["t_settle"] = float(t[i]) if i is not None else None
    if predicted is not None:
        n_pred = min(len(predicted), len(gap))
        out["history_vs_prediction"] = float(np.max(np.abs(gap[:n_pred] - predicted[:n_pred])) / compression)
        j = cs.settle_index(predicted, g_ss, 0.01 * compression)
        out["t_settle_predicted"] = float((j + 1) * dt) if j is not None else None
    if out["t_settle"] is not None and out["t_contact"] is not None:
        out["relaxation_over_tau"] = (out["t_settle"] - out["t_contact"]) / out["tau_steady"]
    # every 10th point of the history for the figure
    out["history"] = dict(t=t[::max(1, len(t) // 400)].tolist(), gap=gap[::max(1, len(t) // 400)].tolist())
    return out


def normal_sweep(res, workdir, full, jobs, integrator):
    cases = []
    kns = [10000, 4000, 2000, 1333.3333333333333, 1111.1111111111111] if full else [4000, 2000, 1111.1111111111111]
    for geometry in ("pair", "wall"):
        for kn in kns:
            cases.append(dict(geometry=geometry, kn=kn, load=LOAD, hr=BASE["hr"], lubrication=True))
    if full:
        for geometry in ("pair", "wall"):
            for hr in (0.0075, 0.02):
                cases.append(dict(geometry=geometry, kn=BASE["kn"], load=LOAD, hr=hr, lubrication=True))
            for kn in (4000, 2000, 1000, 666.6666666666666):   # F/kn = h_r/4 ... 1.5 h_r: overlap without lubrication
                cases.append(dict(geometry=geometry, kn=kn, load=LOAD, hr=BASE["hr"], lubrication=False))
            # an overlap with lubrication: the sub-grid functions are frozen at a gap of 1e-5 a
            cases.append(dict(geometry=geometry, kn=666.6666666666666, load=LOAD, hr=BASE["hr"], lubrication=True))
    else:
        cases.append(dict(geometry="pair", kn=666.6666666666666, load=LOAD, hr=BASE["hr"], lubrication=False))
    return parallel(jobs, lambda c: normal_run(res, workdir, integrator=integrator, **c), cases)


# ---------------------------------------------------------------------------------------------
# (b) sliding threshold: a sphere between two walls
# ---------------------------------------------------------------------------------------------

def sliding_run(res, workdir, ratio, integrator="ab2", lubrication=True, Fn=LOAD, kt=None, r_target=0.25, steps=400,
                p=BASE, cint="explicit"):
    """Ft = ratio mu_s Fn per contact."""
    kn, kt, mu, hr = p["kn"], kt or p["kt"], p["mu"], p["hr"]
    Ft = ratio * mu * Fn
    g_w = cs.steady_gap(hr, Fn, kn)
    zeta_t = res.between_walls_tangential(g_w, lubrication)
    dt = r_target * zeta_t / (2 * kt)
    variables = dict(kn=kn, kt=kt, mu=mu, hr=hr, Fn=Fn, Ft=Ft, dt=dt, steps=steps, a=p["a"], eta=p["eta"],
                     delta=p["delta"], lub="yes" if lubrication else "no", integ=integrator, cint=cint)
    r = run_scene("sliding", variables, workdir)
    out = dict(ratio=ratio, Ft=Ft, Fn=Fn, mu=mu, kt=kt, dt=dt, integrator=integrator, lubrication=lubrication,
               zeta_t=zeta_t, ok=r["ok"])
    if not r["ok"]:
        out["log"] = r["log"]
        return out
    d = r["data"]
    u, ft, dx = d[:, 2], d[:, 4], d[:, 1]
    scale = 2 * Ft / zeta_t                               # the initial speed
    stuck = bool(abs(u[-1]) < 1e-8 * scale)
    sliding_speed = cs.sliding_speed_between_walls(Ft, Fn, mu, zeta_t)
    out.update(stuck=stuck, U_end=float(u[-1]), ft_end=float(ft[-1]), ft_over_Ft=float(ft[-1] / Ft),
               ft_over_muFn=float(ft[-1] / (mu * Fn)), displacement=float(dx[-1]),
               spring_theory=Ft / kt, omega_max=float(np.max(np.abs(d[:, 3]))),
               normal_force_sum_max=float(np.max(np.abs(d[:, 5]))), gap_wall=float(d[-1, 6]),
               gap_wall_theory=g_w)
    if stuck:
        # the spring history adds the displacement of each step (either integrator): the sphere's
        # displacement is the spring's elongation Ft/kt
        out["displacement_over_spring"] = float(dx[-1] / (Ft / kt))
    else:
        out["sliding_speed_theory"] = sliding_speed
        out["sliding_speed_error"] = float((u[-1] - sliding_speed) / sliding_speed)
        out["steady"] = bool(abs(u[-1] - u[-11]) < 1e-6 * abs(u[-1]))
    return out


def sliding_sweep(res, workdir, full, jobs, integrator):
    ratios = [0.25, 0.5, 0.75, 0.9, 0.95, 0.98, 1.02, 1.05, 1.1, 1.5, 2.0, 3.0] if full else [0.5, 0.9, 0.98, 1.02,
                                                                                                1.1, 1.5]
    runs = parallel(jobs, lambda q: sliding_run(res, workdir, q, integrator), ratios)
    extra = [dict(ratio=0.5, integrator="euler" if integrator == "ab2" else "ab2")]
    if full:
        extra += [dict(ratio=0.5, lubrication=False), dict(ratio=1.5, lubrication=False)]
    runs_extra = parallel(jobs, lambda c: sliding_run(res, workdir, integrator=c.get("integrator", integrator),
                                                      ratio=c["ratio"], lubrication=c.get("lubrication", True)), extra)
    # the threshold by bisection between the largest stuck and the smallest sliding load
    stuck = [r["ratio"] for r in runs if r["ok"] and r["stuck"]]
    slid = [r["ratio"] for r in runs if r["ok"] and not r["stuck"]]
    threshold = None
    if stuck and slid and max(stuck) < min(slid):
        lo, hi = max(stuck), min(slid)
        for _ in range(8 if full else 5):
            mid = 0.5 * (lo + hi)
            r = sliding_run(res, workdir, mid, integrator, steps=800)
            if not r["ok"]:
                break
            if r["stuck"]:
                lo = mid
            else:
                hi = mid
        threshold = dict(ratio=0.5 * (lo + hi), bracket=[lo, hi])
    return dict(runs=runs, extra=runs_extra, threshold=threshold)


def rolling_runs(res, workdir, jobs, integrator):
    """A sphere pressed on one wall (F) and pulled at its centre along it (Ft): it rolls, the contact
    point sticks and carries the fraction c of Ft, c = 4/7 without lubrication."""
    def one(lubrication):
        kn, F, Ft = BASE["kn"], LOAD, 1.0
        # the slip of the contact point of a free sphere: translation and rotation, Stokes drag only
        # (a lower bound of the resistance), 1/zeta = 1/(6 pi eta a) + a^2/(8 pi eta a^3)
        zeta_slip = cs.wall_slip_resistance_stokes(BASE["a"], BASE["eta"])
        dt = 0.25 * min(res.wall_normal(BASE["hr"], lubrication), zeta_slip) / max(kn, BASE["kt"])
        # settle the normal gap, then the rolling: several normal and tangential time scales
        steps = 3000 if not lubrication else 1500
        r = run_scene("wall", dict(kn=kn, kt=BASE["kt"], mu=BASE["mu"], hr=BASE["hr"], F=F, Ft=Ft, dt=dt, steps=steps,
                                   gap0=BASE["hr"] - F / kn, lub="yes" if lubrication else "no", integ=integrator),
                      workdir)
        out = dict(lubrication=lubrication, Ft=Ft, F=F, dt=dt, ok=r["ok"])
        if r["ok"]:
            d = r["data"]
            ux, w, ft = d[-1, 8], d[-1, 9], d[-1, 10]
            out.update(ft_over_Ft=float(-ft / Ft), U=float(ux), a_omega=float(-BASE["a"] * w),
                       slip_over_U=float((ux + BASE["a"] * w) / ux), theory_no_lubrication=cs.ROLLING_CONTACT_FRACTION)
        else:
            out["log"] = r["log"]
        return out
    return parallel(jobs, one, [False, True])


# ---------------------------------------------------------------------------------------------
# (c) stability of the explicit contact
# ---------------------------------------------------------------------------------------------

class StabilityConfig:
    """A steady contact perturbed a little, run at a given dt; `mode` is 'normal' (gap) or
    'tangential' (stuck spring between two walls)."""

    def __init__(self, res, name, geometry, lubrication, integrator, p=BASE, cint="explicit"):
        self.res, self.name, self.geometry, self.lubrication, self.integrator, self.p = (
            res, name, geometry, lubrication, integrator, p)
        self.cint = cint
        self.kn, self.kt, self.hr = p["kn"], p["kt"], p["hr"]
        if geometry == "tangential":
            self.Fn = LOAD
            self.Ft = 0.1 * p["mu"] * LOAD          # far below the cap: the growth is seen before sliding
            self.g_w = cs.steady_gap(self.hr, self.Fn, self.kn)
            self.zeta = res.between_walls_tangential(self.g_w, lubrication)
            self.stiffness = 2 * self.kt            # two springs on one sphere
        elif geometry == "pair_tangential":
            # two free spheres at their steady gap; a tangential kick of one step loads the spring,
            # which then relaxes (or not) with the spheres translating and rotating
            self.load = LOAD
            self.g_ss = cs.steady_gap(self.hr, self.load, self.kn)
            self.kick = 0.01 * p["mu"] * LOAD
            self.zeta = res.pair_slip(self.g_ss, lubrication)
            self.stiffness = self.kt
        else:
            self.load = LOAD
            self.g_ss = cs.steady_gap(self.hr, self.load, self.kn)
            self.compression = self.load / self.kn
            self.perturbation = 0.01 * self.compression
            zeta = res.pair_normal if geometry == "pair" else res.wall_normal
            self.zeta = zeta(self.g_ss, lubrication)
            self.zeta_at_start = zeta(self.g_ss + self.perturbation, lubrication)
            self.stiffness = self.kn
        # the tangential spring is integrated with the displacement of the step, so by the fix's integrator
        self.limit_r = cs.limit_ratio(integrator)
        self.dt_estimate = cs.explicit_time_step_limit(self.zeta, self.stiffness, integrator)

    def run(self, workdir, dt, steps=400):
        p = self.p
        common = dict(kn=self.kn, kt=self.kt, mu=p["mu"], hr=self.hr, dt=dt, steps=steps, a=p["a"], eta=p["eta"],
                      delta=p["delta"], lub="yes" if self.lubrication else "no", integ=self.integrator,
                      cint=self.cint)
        if self.geometry == "tangential":
            r = run_scene("sliding", dict(common, Fn=self.Fn, Ft=self.Ft), workdir)
        elif self.geometry == "pair_tangential":
            r = run_scene("normal", dict(common, F=self.load, gap0=self.g_ss, kick=self.kick, kicksteps=1), workdir)
        else:
            r = run_scene("normal" if self.geometry == "pair" else "wall",
                          dict(common, F=self.load, gap0=self.g_ss + self.perturbation), workdir)
        out = dict(dt=dt, r=dt * self.stiffness / self.zeta, ok=r["ok"])
        if not r["ok"]:
            out.update(stable=False, label="run failed", log=r["log"][-600:])
            return out
        d = r["data"]
        if self.geometry == "tangential":
            c = cs.classify_perturbation(d[:, 4] - self.Ft, self.Ft)
            out["ft_max"] = float(np.abs(d[:, 4]).max())
            out["sliding_seen"] = bool(np.abs(d[:, 4]).max() >= 0.999 * p["mu"] * self.Fn)
            if c["label"] == "growing":
                c["label"] = "chatter at the Coulomb cap" if out["sliding_seen"] else "growing"
        elif self.geometry == "pair_tangential":
            ft = d[1:, 10]                          # tangential contact force on sphere 1, after the kick
            c = cs.classify_perturbation(ft, self.kick)
            out["ft_max"] = float(np.abs(ft).max())
            out["sliding_seen"] = bool(out["ft_max"] >= 0.999 * p["mu"] * self.load)
            if c["label"] == "growing":
                c["label"] = "chatter at the Coulomb cap" if out["sliding_seen"] else "growing"
        else:
            gap = d[:, 1]
            c = cs.classify_perturbation(gap - self.g_ss, self.compression, self.hr, gap, self.g_ss)
            out["min_gap"] = float(gap.min())
            out["max_gap"] = float(gap.max())
            # zeta from the fix's own outputs at the first step: -(F^SG + F^FDM)/closing speed
            if self.geometry == "pair":
                out["zeta_from_outputs"] = float(-(d[0, 8] + d[0, 9]) / (d[0, 2] - d[0, 3]))
            else:
                out["zeta_from_outputs"] = float(-(d[0, 4] + d[0, 5]) / d[0, 2])
        out.update(c)
        out["factor_theory"] = (cs.implicit_growth_factor(out["r"], self.integrator) if self.cint == "implicit"
                                else cs.explicit_growth_factor(out["r"], self.integrator))
        return out

    def find_limit(self, workdir, rel_tol=0.01, steps=400):
        """Bisection in dt between a stable and an unstable run, starting from the estimate."""
        lo, hi, runs = cs.bisect_stability_limit(lambda dt: self.run(workdir, dt, steps), self.dt_estimate, rel_tol)
        measured = math.sqrt(lo * hi)
        summary = dict(name=self.name, geometry=self.geometry, lubrication=self.lubrication,
                       integrator=self.integrator, stiffness=self.stiffness, zeta=self.zeta,
                       limit_r_theory=self.limit_r, dt_estimate=self.dt_estimate, dt_measured=measured,
                       dt_bracket=[lo, hi], measured_over_estimate=measured / self.dt_estimate,
                       r_measured=measured * self.stiffness / self.zeta, runs=len(runs))
        if self.geometry in ("pair", "wall"):
            summary.update(gap_steady=self.g_ss, zeta_at_start=self.zeta_at_start,
                           zeta_from_outputs=runs[0].get("zeta_from_outputs"))
        elif self.geometry == "pair_tangential":
            summary.update(gap_steady=self.g_ss)
        else:
            summary.update(gap_wall=self.g_w)
        return summary


def stability_study(res, workdir, full, jobs):
    configs = []
    for integrator in ("ab2", "euler"):
        configs += [StabilityConfig(res, "pair, lubrication", "pair", True, integrator),
                    StabilityConfig(res, "pair, no lubrication", "pair", False, integrator)]
    configs += [StabilityConfig(res, "wall, lubrication", "wall", True, "ab2"),
                StabilityConfig(res, "tangential (two walls), lubrication", "tangential", True, "ab2"),
                StabilityConfig(res, "pair tangential, lubrication", "pair_tangential", True, "ab2")]
    if full:
        configs += [StabilityConfig(res, "wall, lubrication", "wall", True, "euler"),
                    StabilityConfig(res, "tangential (two walls), lubrication", "tangential", True, "euler"),
                    StabilityConfig(res, "pair tangential, lubrication", "pair_tangential", True, "euler"),
                    StabilityConfig(res, "pair tangential, no lubrication", "pair_tangential", False, "ab2")]
        for integrator in ("ab2", "euler"):
            configs += [StabilityConfig(res, "wall, no lubrication", "wall", False, integrator),
                        StabilityConfig(res, "tangential (two walls), no lubrication", "tangential", False,
                                        integrator)]
    tolerance = 0.001 if full else 0.01
    limits = parallel(jobs, lambda c: c.find_limit(workdir, rel_tol=tolerance), configs)
    # dt grid of the figure: the pair with lubrication, both integrators, r = dt kn / zeta
    grid_r = ([0.1, 0.25, 0.5, 0.75, 0.9, 1.1, 1.25, 1.5, 1.75, 1.9, 2.1, 2.5, 3, 4, 6] if full
              else [0.25, 0.5, 0.75, 0.9, 1.1, 1.5, 1.9, 2.1, 3.0])
    grid = []
    for integrator in ("ab2", "euler"):
        c = StabilityConfig(res, "pair, lubrication", "pair", True, integrator)
        runs = parallel(jobs, lambda rr: c.run(workdir, rr * c.zeta / c.stiffness, 400), grid_r)
        for r in runs:
            r["integrator"] = integrator
        grid += runs
    if full:
        c = StabilityConfig(res, "pair, no lubrication", "pair", False, "euler")
        runs = parallel(jobs, lambda rr: c.run(workdir, rr * c.zeta / c.stiffness, 400), grid_r)
        for r in runs:
            r["integrator"] = "euler"
            r["config"] = "pair, no lubrication"
        grid += runs
    return dict(limits=limits, grid=grid, bisection_tolerance=tolerance)


# ---------------------------------------------------------------------------------------------
# (d) implicit springs (contact_integration implicit, docs/contact.md 2b and 3c)
# ---------------------------------------------------------------------------------------------

def implicit_stability(res, workdir, jobs, multiples=(10, 100, 1000)):
    """The scenes of the stability study (ab2; the pair also euler) run with implicit springs at
    `multiples` times their explicit limit, and with explicit springs at 10 times it."""
    configs = []
    for cint in ("implicit", "explicit"):
        configs += [StabilityConfig(res, "pair, lubrication", "pair", True, "ab2", cint=cint),
                    StabilityConfig(res, "pair, lubrication", "pair", True, "euler", cint=cint),
                    StabilityConfig(res, "pair, no lubrication", "pair", False, "ab2", cint=cint),
                    StabilityConfig(res, "wall, lubrication", "wall", True, "ab2", cint=cint),
                    StabilityConfig(res, "tangential (two walls), lubrication", "tangential", True, "ab2", cint=cint),
                    StabilityConfig(res, "pair tangential, lubrication", "pair_tangential", True, "ab2", cint=cint)]
    # the free pair, loaded along a fixed direction, buckles: once the kick has tilted the line of
    # centres the spheres roll on each other (growth ~0.22/s here, the same with explicit springs at
    # a small dt): its tangential spring is judged over the physical time of the explicit runs only
    jobs_list = [(c, m) for c in configs
                 for m in (multiples if c.cint == "implicit" and c.geometry != "pair_tangential" else (10,))]

    def one(item):
        c, m = item
        steps = 40 if c.geometry == "pair_tangential" else 400
        out = c.run(workdir, m * c.dt_estimate, steps)
        out.update(name=c.name, geometry=c.geometry, integrator=c.integrator, cint=c.cint, multiple=m,
                   dt_explicit_limit=c.dt_estimate)
        return out
    return parallel(jobs, one, jobs_list)


def implicit_equilibrium(res, workdir, jobs, multiple=10):
    """Loaded contacts run to their steady state at `multiple` times the explicit limit of the
    normal spring at the steady gap (zeta(h_ss)/kn, ab2): the steady gap h_r - F/kn, the contact
    force, F1 + F2 = 0 at every step."""
    p = BASE
    cases = [dict(geometry="pair", kn=2000.0, lubrication=True),
             dict(geometry="wall", kn=2000.0, lubrication=True),
             dict(geometry="pair", kn=2000.0 / 3.0, lubrication=False),    # overlap of h_r/2
             # overlap with the frozen lubrication (tau = 707 s): from inside the roughness layer (an
             # approach from 0.05 a at this dt would move the spheres by ~1000 m in the first step)
             dict(geometry="pair", kn=2000.0 / 3.0, lubrication=True, gap0=0.005),
             # 100 times stiffer (F/kn = h_r/200) at the explicit limit of kn = 2000 N/m: 200 times its own
             dict(geometry="pair", kn=2e5, lubrication=True, dt=0.4646754831724052)]

    def one(c):
        zeta_of = res.pair_normal if c["geometry"] == "pair" else res.wall_normal
        g_ss = cs.steady_gap(p["hr"], LOAD, c["kn"])
        zeta_ss = zeta_of(g_ss, c["lubrication"])
        dt = c.get("dt", multiple * zeta_ss / c["kn"])
        steps = 300
        r = run_scene("normal" if c["geometry"] == "pair" else "wall",
                      dict(kn=c["kn"], kt=p["kt"], mu=p["mu"], hr=p["hr"], F=LOAD, dt=dt, steps=steps,
                           gap0=c.get("gap0", 0.05),
                           a=p["a"], eta=p["eta"], delta=p["delta"], lub="yes" if c["lubrication"] else "no",
                           integ="ab2", cint="implicit"), workdir)
        out = dict(c, dt=dt, dt_explicit_limit=zeta_ss / c["kn"], gap_theory=g_ss, ok=r["ok"], steps=steps)
        if not r["ok"]:
            out["log"] = r["log"]
            return out
        d = r["data"]
        gap = d[:, 1]
        force = -d[-1, 4] if c["geometry"] == "pair" else d[-1, 3]
        compression = LOAD / c["kn"]
        out.update(gap_end=float(gap[-1]), gap_error=float((gap[-1] - g_ss) / compression),
                   normal_force_error=float((force - LOAD) / LOAD), min_gap=float(gap.min()),
                   force_balance=float(np.max(np.abs(d[:, 4] + d[:, 5])) / LOAD) if c["geometry"] == "pair" else None,
                   settled_step=cs.settle_index(gap, g_ss, 1e-6 * compression))
        return out
    return parallel(jobs, one, cases)


def implicit_convergence(res, workdir, jobs, T=3.0, dts=(0.2, 0.1, 0.05, 0.025, 0.0125), dt_ref=0.0005, gap0=0.0099):
    """Two spheres pressed together from the gap gap0 (inside the roughness layer: the spring acts
    from the start; k_n = 2000 N/m, lubrication, ab2) over the time T (6 tau): the gap history with
    explicit and implicit springs at several dt (all below the explicit limit 0.46 s) against an
    explicit run at dt_ref: max |gap - gap_ref| over the common times, in F/k_n, and the order of
    convergence from the two smallest dt."""
    p = BASE
    kn = p["kn"]

    def run(item):
        cint, dt = item
        steps = int(round(T / dt))
        r = run_scene("normal", dict(kn=kn, kt=p["kt"], mu=p["mu"], hr=p["hr"], F=LOAD, dt=dt, steps=steps, gap0=gap0,
                                     a=p["a"], eta=p["eta"], delta=p["delta"], lub="yes", integ="ab2", cint=cint),
                      workdir)
        return cint, dt, r
    runs = parallel(jobs, run, [("explicit", dt_ref)] + [(c, dt) for c in ("explicit", "implicit") for dt in dts])
    ref = runs[0][2]["data"]
    # the positions printed at step n are those moved in step n, with the velocities of step n - 1:
    # step 1 still holds gap0 (the input's velocities are 0), so the time of step n is (n - 1) dt
    t_ref, g_ref = (ref[:, 0] - 1) * dt_ref, ref[:, 1]
    out = dict(T=T, dt_ref=dt_ref, kn=kn, gap0=gap0, runs=[])
    for cint, dt, r in runs[1:]:
        d = r["data"]
        t, g = (d[:, 0] - 1) * dt, d[:, 1]
        g_at = np.interp(t, t_ref, g_ref)
        out["runs"].append(dict(cint=cint, dt=dt, error=float(np.max(np.abs(g - g_at)) / (LOAD / kn)),
                                gap_end=float(g[-1])))
    for cint in ("explicit", "implicit"):
        e = [(x["dt"], x["error"]) for x in out["runs"] if x["cint"] == cint]
        (d1, e1), (d2, e2) = e[-2], e[-1]
        out["order_" + cint] = float(np.log(e1 / e2) / np.log(d1 / d2))
    return out


def implicit_study(res, workdir, jobs):
    t = time.time()
    out = dict(stability=implicit_stability(res, workdir, jobs), equilibrium=implicit_equilibrium(res, workdir, jobs),
               convergence=implicit_convergence(res, workdir, jobs),
               sliding=[sliding_run(res, workdir, q, cint="implicit", r_target=10.0) for q in (0.5, 1.5)])
    out["seconds"] = time.time() - t
    return out
