#!/usr/bin/python3
"""One concealed diagnosis case from CalculiX, an FEM independent of pliant's.

A soft block or cylinder stands on a support (glued, or on a table with Coulomb friction) and
is pressed from above by a platen (the whole top face) or a round indenter (a disk of the top
face), which then holds and lets the object come partly or fully back. CalculiX solves it on a
fine mesh of quadratic tetrahedra (C3D10), with NLGEOM, quasi-statically (*STATIC) or with
inertia (*DYNAMIC, implicit). The recording gets what a user would have:

- mesh.vtk: a separate, coarse linear tetrahedral mesh of the object (the nodes are the
  particles), made by gmsh with a larger element size;
- particles.csv: the positions of the coarse nodes a camera in front of the object sees
  (boundary nodes whose outward normal faces it), interpolated from the CalculiX field with
  the C3D10 shape functions, plus Gaussian noise; the driven nodes (the tool's footprint)
  follow the programmed tool path exactly, as a robot's kinematics would give it; every other
  node is absent from the file (unobserved);
- wrench.csv: the force the tool applies (the sum of CalculiX reaction forces over the driven
  nodes) and its torque about the footprint's centroid, on the sensor's own clock (its rate
  and phase; cubic Hermite interpolation between the solved frames, one ccx increment each),
  delayed when the effect is latency, plus noise;
- recording.json: bottom nodes `fixed`, tool nodes `driven` and `wrench.applied_to`, the
  Poisson ratio and density the user would know; no gravity declared.

truth.json holds the answer (format "pliant-truth"). The effect size is measured by solving the
same scene without the effect (the reference) and comparing noise-free observations.

Usage: /usr/bin/python3 calculix_world.py SPEC.json OUTDIR [--cache DIR] [--keep-work]
(SPEC.json: the fields make_calculix_family.case_specs() builds.)
"""
import argparse
import json
import math
import os
import shutil
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from calculix import ccx, interp, mesh  # noqa: E402

TOL = 1e-7  # geometric tolerance (m) for "on a face"


# ---------------------------------------------------------------------------------------------
# The tool path

def drive_table(protocol):
    """Breakpoints (t, depth) of the tool path: still, press, hold, partial/full release, hold.
    Each ramp is a smoothstep (zero speed at both ends, as a robot moves) sampled at 12 points
    for the *AMPLITUDE table, which ccx interpolates linearly."""
    p = protocol
    t0 = p["still"]
    t1 = t0 + p["press"]
    t2 = t1 + p["hold"]
    t3 = t2 + p["release"]
    t_end = t3 + p["end_hold"]
    d, d_back = p["depth"], p["depth"] * (1 - p["release_fraction"])
    times, values = [0.0, t0], [0.0, 0.0]

    def ramp(ta, tb, va, vb):
        for s in np.linspace(0, 1, 13)[1:]:
            times.append(ta + s * (tb - ta))
            values.append(va + (vb - va) * (3 * s * s - 2 * s * s * s))

    ramp(t0, t1, 0.0, d)
    times.append(t2)
    values.append(d)
    if p["release"] > 0:
        ramp(t2, t3, d, d_back)
    times.append(t_end)
    values.append(values[-1])
    return np.array(times), np.array(values), t_end


def drive_at(table, t):
    times, values, _ = table
    return np.interp(t, times, values)


# ---------------------------------------------------------------------------------------------
# Geometry: meshes and the node sets of both

def object_height(shape):
    return shape["size"][2] if shape["kind"] == "box" else shape["height"]


def on_tool(points, shape, tool):
    """Nodes in the tool's footprint: the whole top face (platen) or the indenter disk."""
    h = object_height(shape)
    top = np.abs(points[:, 2] - h) < TOL
    if tool["kind"] == "platen":
        return np.nonzero(top)[0]
    r = np.hypot(points[:, 0] - tool["center"][0], points[:, 1] - tool["center"][1])
    return np.nonzero(top & (r <= tool["radius"] + TOL))[0]


def in_region(points, region):
    if region["kind"] == "sphere":
        return np.linalg.norm(points - np.asarray(region["center"]), axis=1) <= region["radius"] + TOL
    return points[:, 0] >= region["x0"] - TOL


def camera_nodes(points, tets, camera_dir):
    """Coarse boundary nodes a camera looking along -camera_dir sees on a convex object: the
    outward normal has a clear component toward the camera."""
    faces = mesh.boundary_faces(tets)
    normals = mesh.node_normals(points, faces)
    c = np.asarray(camera_dir, dtype=float)
    c /= np.linalg.norm(c)
    return np.nonzero(normals @ c > 0.35)[0]


def lumped_masses(points, tets, density):
    a, b, c, d = (points[tets[:, k]] for k in range(4))
    vol = np.abs(np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a)) / 6
    m = np.zeros(len(points))
    for k in range(4):
        np.add.at(m, tets[:, k], density * vol / 4)
    return m


# Corner triples of the C3D10 faces S1..S4 (ccx numbering).
TET_FACES = {1: (0, 1, 2), 2: (0, 3, 1), 3: (1, 3, 2), 4: (2, 3, 0)}


def bottom_faces(points, tets10):
    on = np.abs(points[:, 2]) < TOL
    out = []
    for e, t in enumerate(tets10):
        for f, corners in TET_FACES.items():
            if all(on[t[list(corners)]]):
                out.append((e, f))
    return out


# ---------------------------------------------------------------------------------------------
# One CalculiX run

LAW_KEYS = ("locking_stretch", "c20_over_c10", "c30_over_c10", "alpha1", "alpha2", "share2")


def run_spec(spec, variant):
    """What defines one CalculiX run of the case: the scene, the meshes and, for the 'effect'
    variant, the effect's physics; the 'reference' variant is the same scene without the effect
    (homogeneous, glued, no gravity, quasi-static, spec['reference_law']). Noise, seeds and the
    wrench latency are not in it (they are applied afterwards), so cases that share a scene share
    the runs."""
    eff = spec["effect"] if variant == "effect" else "none"
    mat = dict(spec["material"])
    if variant == "reference":
        mat["law"] = spec.get("reference_law", "elastic")
        mat.pop("plastic", None)
        for k in LAW_KEYS:
            mat.pop(k, None)
    r = {
        "shape": spec["shape"], "tool": spec["tool"], "fine_lc": spec["fine_lc"],
        "coarse_lc": spec["coarse_lc"], "protocol": spec["protocol"], "frame_rate_hz": spec["frame_rate_hz"],
        "material": mat, "physics": eff,
        "integrator": spec["integrator"] if variant == "effect" and eff in ("none", "latency", "viscosity") else "static",
    }
    if eff == "viscosity":
        r["integrator"] = "dynamic"
        r["damping"] = [spec["effect_parameters"]["rayleigh_alpha"], spec["effect_parameters"]["rayleigh_beta"]]
    if eff == "gravity":
        r["gravity"] = spec["effect_parameters"]["gravity_m_s2"]
    if eff == "heterogeneity":
        r["region"] = spec["region"]
        r["modulus_factor"] = spec["effect_parameters"]["modulus_factor"]
    if eff == "friction":
        r["friction_coefficient"] = spec["effect_parameters"]["friction_coefficient"]
        r["contact_penalty"] = spec["contact_penalty"]
        r["stick_slope"] = spec["stick_slope"]
    if eff == "latency":
        r["physics"] = "none"
    return r


def run_key(r):
    import hashlib
    return hashlib.sha1(json.dumps(r, sort_keys=True).encode()).hexdigest()[:16]


def solve(r, workdir):
    """Run CalculiX for run spec r. Returns per camera frame (index 0 is t = 0) the displacement
    of every coarse node and the tool's force and torque."""
    shape, tool = r["shape"], r["tool"]
    p4, t4 = mesh.gmsh_tets(shape, tool, r["fine_lc"], r.get("region"))
    fine_pts, fine_t10 = mesh.quadratic(p4, t4)
    coarse_pts, coarse_t4 = mesh.gmsh_tets(shape, tool, r["coarse_lc"])
    elems, weights = interp.locate(fine_pts, fine_t10, coarse_pts)
    mat = r["material"]
    materials = {"BULK": mat}
    element_material = np.array(["BULK"] * len(fine_t10), dtype=object)
    if "region" in r:
        centroid = fine_pts[fine_t10[:, :4]].mean(axis=1)
        incl = dict(mat)
        incl["youngs_modulus"] = mat["youngs_modulus"] * r["modulus_factor"]
        if "plastic" in incl:
            incl["plastic"] = [[s * r["modulus_factor"], e] for s, e in incl["plastic"]]
        materials["REGION"] = incl
        element_material[in_region(centroid, r["region"])] = "REGION"
    driven = on_tool(fine_pts, shape, tool)
    table = drive_table(r["protocol"])
    dt = 1.0 / r["frame_rate_hz"]
    run = {
        "points": fine_pts, "tets10": fine_t10, "materials": materials,
        "element_material": element_material, "driven": driven,
        "drive": (table[0], table[1]), "dt": dt, "t_end": table[2], "integrator": r["integrator"],
        "output_nodes": np.unique(fine_t10[elems]), "damping": r.get("damping"), "gravity": r.get("gravity"),
    }
    bottom = np.nonzero(np.abs(fine_pts[:, 2]) < TOL)[0]
    if "friction_coefficient" in r:
        lo, hi = fine_pts.min(axis=0), fine_pts.max(axis=0)
        pad = 0.5 * (hi[0] - lo[0])
        run["fixed"] = np.array([], dtype=np.int64)
        run["contact"] = {
            "extent": (lo[0] - pad, hi[0] + pad, lo[1] - pad, hi[1] + pad), "thickness": 0.005,
            "bottom_faces": bottom_faces(fine_pts, fine_t10), "mu": r["friction_coefficient"],
            "normal_penalty": r["contact_penalty"], "stick_slope": r["stick_slope"], "anchors": [],
        }
    else:
        run["fixed"] = bottom
    os.makedirs(workdir, exist_ok=True)
    # Fixed increments of one frame first; if ccx diverges with them (nearly incompressible or
    # steeply stiffening material), the same deck with automatic incrementation, output at the
    # frames. Either way the outcome is a function of the run spec alone.
    run["incrementation"] = "direct"
    ccx.write_deck(os.path.join(workdir, "job.inp"), run)
    try:
        ccx.run_ccx(workdir, "job")
    except RuntimeError as err:
        if "diverge" not in str(err):
            raise
        run["incrementation"] = "automatic"
        ccx.write_deck(os.path.join(workdir, "job.inp"), run)
        ccx.run_ccx(workdir, "job")
    t_f, node_ids, per_node, totals = ccx.read_dat_forces(os.path.join(workdir, "job.dat"), len(driven))
    t_u, u_ids, u = ccx.read_frd_displacements(os.path.join(workdir, "job.frd"))
    n_inc = int(round(table[2] / dt))
    if len(t_f) != n_inc or len(t_u) != n_inc:
        raise RuntimeError(f"{workdir}: {len(t_f)} force samples / {len(t_u)} frames, expected {n_inc}")
    full_u = np.zeros((len(t_u), len(fine_pts), 3))
    full_u[:, u_ids, :] = u
    coarse_u = interp.transfer(full_u, fine_t10, elems, weights)
    # torque about the centroid of the coarse footprint's rest positions
    centre = coarse_pts[on_tool(coarse_pts, shape, tool)].mean(axis=0)
    depth = drive_at(table, t_f)
    pos = fine_pts[node_ids][None, :, :] + np.stack(
        [np.zeros_like(depth), np.zeros_like(depth), -depth], axis=1)[:, None, :]
    torque = np.cross(pos - centre, per_node).sum(axis=1)
    # t = 0: static runs take the first increment (the tool has not moved yet: the same
    # state, including a sag under gravity); dynamic runs start at rest.
    if r["integrator"] == "static":
        u0, f0, m0 = coarse_u[:1], totals[:1], torque[:1]
    else:
        u0, f0, m0 = np.zeros_like(coarse_u[:1]), np.zeros((1, 3)), np.zeros((1, 3))
    return {
        "frame_t": np.concatenate([[0.0], t_u]), "u": np.concatenate([u0, coarse_u]),
        "force": np.concatenate([f0, totals]), "torque": np.concatenate([m0, torque]),
        "fine_nodes": len(fine_pts), "fine_elements": len(fine_t10),
        "incrementation": run["incrementation"],
    }


def solve_cached(r, cache_dir, keep_work=False):
    """solve() once per distinct run spec; results kept as .npz in cache_dir."""
    key = run_key(r)
    path = os.path.join(cache_dir, key + ".npz")
    failed = os.path.join(cache_dir, key + ".failed")
    if os.path.exists(failed):  # a failure is as deterministic as a result: don't redo it
        with open(failed) as f:
            raise RuntimeError(f.read())
    if not os.path.exists(path):
        work = os.path.join(cache_dir, key + ".work")
        try:
            res = solve(r, work)
        except RuntimeError as err:
            with open(failed, "w") as f:
                f.write(str(err))
            raise
        np.savez(path + ".tmp.npz", **res)
        os.replace(path + ".tmp.npz", path)
        if not keep_work:
            shutil.rmtree(work, ignore_errors=True)
    with np.load(path) as z:
        return {k: z[k] for k in z.files}


# ---------------------------------------------------------------------------------------------
# Writing the recording

def hermite(t_knots, values, t):
    """Cubic Hermite interpolation with central-difference slopes (values (k, c)) at times t;
    before the first knot the first value (the tool has not moved), after the last the last.
    The force sensor samples the force at its own clock; between two solved camera frames the
    force is a smooth function of time, which this reproduces far below the sensor noise."""
    tk = np.asarray(t_knots)
    v = np.asarray(values)
    slope = np.gradient(v, tk, axis=0)
    t = np.clip(t, tk[0], tk[-1])
    i = np.clip(np.searchsorted(tk, t, side="right") - 1, 0, len(tk) - 2)
    h = tk[i + 1] - tk[i]
    s = ((t - tk[i]) / h)[:, None]
    h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
    return h00 * v[i] + h10 * h[:, None] * slope[i] + h01 * v[i + 1] + h11 * h[:, None] * slope[i + 1]


def write_recording(outdir, spec, coarse_pts, coarse_t4, fixed, driven, observed, frame_t,
                    positions, wrench_t, force, torque):
    os.makedirs(outdir, exist_ok=True)
    mesh.write_vtk(os.path.join(outdir, "mesh.vtk"), coarse_pts, coarse_t4)
    masses = lumped_masses(coarse_pts, coarse_t4, spec["material"]["density"])
    shape = spec["shape"]
    if shape["kind"] == "box":
        what = "soft block %.0f x %.0f x %.0f mm" % tuple(1000 * v for v in shape["size"])
    else:
        what = "soft cylinder %.0f mm diameter, %.0f mm high" % (2000 * shape["radius"], 1000 * shape["height"])
    tool = spec["tool"]
    tool_text = ("flat platen over the whole top face" if tool["kind"] == "platen"
                 else "flat round indenter, %.0f mm diameter" % (2000 * tool["radius"]))
    rec = {
        "format": "pliant-recording",
        "version": 1,
        "dimension": 3,
        "length_unit": "m",
        "particles": {
            "count": int(len(coarse_pts)),
            "mass": [float("%.6g" % m) for m in masses],
            "fixed": [int(i) for i in fixed],
            "driven": [int(i) for i in driven],
        },
        "files": {"particles": "particles.csv", "wrench": "wrench.csv", "mesh": "mesh.vtk"},
        "wrench": {"applied_to": [int(i) for i in driven]},
        "material": {"poisson_ratio": spec["material"]["poisson_ratio"], "density": spec["material"]["density"]},
        "meta": {
            "object": what,
            "tool": tool_text + "; its footprint nodes are driven along the programmed path",
            "camera": "front view, %.0f frames/s; only the surface it sees is tracked" % spec["frame_rate_hz"],
            "wrench_sensor": "%.0f samples/s on its own clock; the force the tool applies to the object" % spec["wrench_rate_hz"],
            "source": "simulated (tools/concealed/calculix_world.py)",
        },
    }
    with open(os.path.join(outdir, "recording.json"), "w") as f:
        json.dump(rec, f, indent=1)
        f.write("\n")
    ids = sorted(set(int(i) for i in observed) | set(int(i) for i in driven))
    with open(os.path.join(outdir, "particles.csv"), "w") as f:
        f.write("t,id,x,y,z\n")
        for k, t in enumerate(frame_t):
            for i in ids:
                x, y, z = positions[k, i]
                f.write(f"{t:.6f},{i},{x:.8g},{y:.8g},{z:.8g}\n")
    with open(os.path.join(outdir, "wrench.csv"), "w") as f:
        f.write("t,fx,fy,fz,tx,ty,tz\n")
        for k, t in enumerate(wrench_t):
            fx, fy, fz = force[k]
            tx, ty, tz = torque[k]
            f.write(f"{t:.6f},{fx:.6g},{fy:.6g},{fz:.6g},{tx:.6g},{ty:.6g},{tz:.6g}\n")


# ---------------------------------------------------------------------------------------------
# One case

def make_case(spec, outdir, cache_dir, keep_work=False):
    """Solve (or reuse) the case's runs and write its recording and truth.json into outdir."""
    rng = np.random.default_rng(spec["seed"])
    shape, tool = spec["shape"], spec["tool"]
    coarse_pts, coarse_t4 = mesh.gmsh_tets(shape, tool, spec["coarse_lc"])
    fixed = np.nonzero(np.abs(coarse_pts[:, 2]) < TOL)[0]
    driven = on_tool(coarse_pts, shape, tool)
    observed = np.setdiff1d(camera_nodes(coarse_pts, coarse_t4, spec["camera"]), driven)

    res = solve_cached(run_spec(spec, "effect"), cache_dir, keep_work)
    ref = None
    if spec["effect"] not in ("none", "latency"):
        ref = solve_cached(run_spec(spec, "reference"), cache_dir, keep_work)

    frame_t = res["frame_t"]
    table = drive_table(spec["protocol"])
    pos = coarse_pts[None] + res["u"]
    # the tool's footprint follows the programmed path exactly (robot kinematics)
    pos[:, driven, :] = coarse_pts[driven][None]
    pos[:, driven, 2] -= drive_at(table, frame_t)[:, None]

    # the force sensor's clock: its own rate and phase; a latency delays what it reports
    period = 1.0 / spec["wrench_rate_hz"]
    wrench_t = np.arange(spec["wrench_phase"] * period, frame_t[-1] + 1e-9, period)
    latency = spec["effect_parameters"].get("wrench_latency_s", 0.0) if spec["effect"] == "latency" else 0.0
    force = hermite(frame_t, res["force"], wrench_t - latency)
    torque = hermite(frame_t, res["torque"], wrench_t - latency)

    edge = mesh.mean_edge_length(coarse_pts, coarse_t4)
    noise_std = spec["noise_fraction"] * edge
    peak_force = float(np.max(np.linalg.norm(res["force"], axis=1)))
    force_noise_std = spec["force_noise_fraction"] * peak_force

    effect_size = None
    if spec["effect"] != "none":
        base = ref if ref is not None else res
        dpos = res["u"][:, observed, :] - base["u"][:, observed, :]
        dforce = force - hermite(frame_t, base["force"], wrench_t)
        effect_size = {
            "rms_over_noise": round(float(np.sqrt(np.mean(dpos ** 2)) / noise_std), 3),
            "force_rms_over_noise": round(float(np.sqrt(np.mean(dforce ** 2)) / force_noise_std), 3),
        }

    noisy = pos.copy()
    noisy[:, observed, :] += rng.normal(0.0, noise_std, size=(len(frame_t), len(observed), 3))
    force_noisy = force + rng.normal(0.0, force_noise_std, size=force.shape)
    torque_noisy = torque + rng.normal(0.0, force_noise_std * 0.005, size=torque.shape)
    write_recording(outdir, spec, coarse_pts, coarse_t4, fixed, driven, observed, frame_t,
                    noisy, wrench_t, force_noisy, torque_noisy)

    integrator = run_spec(spec, "effect")["integrator"]
    truth = {
        "format": "pliant-truth",
        "version": 1,
        "model": "calculix",
        "effect": spec["effect"],
        "effect_parameters": spec["effect_parameters"],
        "effect_size": effect_size,
        "parameters": {
            "youngs_modulus": spec["material"]["youngs_modulus"],
            "poisson_ratio": spec["material"]["poisson_ratio"],
            "density": spec["material"]["density"],
        },
        "material": spec["material"],
        "integrator": ("ccx *DYNAMIC (implicit Hilber-Hughes-Taylor), NLGEOM" if integrator == "dynamic"
                       else "ccx *STATIC, NLGEOM"),
        "incrementation": str(res["incrementation"]) if "incrementation" in res else "direct",
        "rate_hz": spec["frame_rate_hz"],
        "wrench_rate_hz": spec["wrench_rate_hz"],
        "noise_std": noise_std,
        "noise_fraction_of_edge": spec["noise_fraction"],
        "force_noise_std": force_noise_std,
        "peak_force_n": peak_force,
        "mesh": {
            "fine_nodes": int(res["fine_nodes"]), "fine_elements": int(res["fine_elements"]),
            "fine_element_type": "C3D10 (10-node quadratic tetrahedron)",
            "coarse_nodes": int(len(coarse_pts)), "coarse_elements": int(len(coarse_t4)),
            "coarse_element_type": "linear tetrahedron (VTK 10)", "coarse_mean_edge_m": edge,
        },
        "scene": {"shape": shape, "tool": tool, "protocol": spec["protocol"], "camera": spec["camera"],
                  "scene_id": spec.get("scene_id")},
        "observed_particles": int(len(observed)),
        "seed": spec["seed"],
    }
    if spec["effect"] == "friction":
        truth["support_particles"] = [int(i) for i in fixed]
    if spec["effect"] == "heterogeneity":
        truth["region"] = spec["region"]
        truth["region_particles"] = [int(i) for i in np.nonzero(in_region(coarse_pts, spec["region"]))[0]]
    with open(os.path.join(outdir, "truth.json"), "w") as f:
        json.dump(truth, f, indent=1, sort_keys=True)
        f.write("\n")
    return truth


def main():
    ap = argparse.ArgumentParser(description="Write one CalculiX concealed case from a JSON spec.")
    ap.add_argument("spec")
    ap.add_argument("outdir")
    ap.add_argument("--cache", help="directory for CalculiX results shared between cases (default: temporary)")
    ap.add_argument("--keep-work", action="store_true", help="keep the CalculiX decks and result files")
    args = ap.parse_args()
    with open(args.spec) as f:
        spec = json.load(f)
    if args.cache:
        os.makedirs(args.cache, exist_ok=True)
        truth = make_case(spec, args.outdir, args.cache, args.keep_work)
    else:
        with tempfile.TemporaryDirectory() as cache:
            truth = make_case(spec, args.outdir, cache)
    print(json.dumps({"effect": truth["effect"], "effect_size": truth["effect_size"]}))


if __name__ == "__main__":
    main()
