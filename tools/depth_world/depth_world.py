#!/usr/bin/python3
"""One depth-world case: a CalculiX scene seen by a simulated Kinect-class depth camera.

Writes into OUTDIR what a user of `pliant track-depth` would have, as one directory that is
both the plan recording (recording-v1) and the depth input:

- depth/NNNNNN.png, depth_frames.csv: 16-bit depth in millimetres and the camera's intrinsics
  (the format of `pliant record`, docs/record.md); full 640 x 480 frames, or a stated crop of
  them (cx, cy shifted by the crop's corner);
- mesh.vtk: the user's coarse linear tetrahedral mesh (gmsh), at rest, in the world frame
  (table z = 0); camera_pose.txt: the camera's pose in that frame as `--camera-pose` takes it;
- recording.json, particles.csv: the plan: the rest shape (frame 0), the fixed base and, for an
  indentation, the probe's footprint nodes driven along the probe's programmed path on the
  depth frames' clock; masses, Poisson ratio and density (what a user knows);
- wrench.csv (indentation): the probe's force and torque on the object from a force/torque
  sensor on its own clock, with noise;
- truth.json: everything else (no pliant command reads it).

Usage: /usr/bin/python3 depth_world.py SPEC.json OUTDIR [--cache DIR]
"""
import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "concealed"))
import png16  # noqa: E402
import render  # noqa: E402
import scene  # noqa: E402
import sensor  # noqa: E402
from calculix import mesh  # noqa: E402
from calculix_world import hermite, lumped_masses  # noqa: E402

SOLVE_KEYS = ("kind", "shape", "tool", "fine_lc", "coarse_lc", "frame_rate_hz", "material", "protocol",
              "tip_load_n", "gravity_m_s2", "rayleigh_alpha", "rayleigh_beta", "duration_s")


def solve_cached(spec, cache_dir):
    import simulate
    what = {k: spec.get(k) for k in SOLVE_KEYS}
    if what["tool"] is not None:  # the probe's shape above its footprint does not touch the solve
        what["tool"] = {k: spec["tool"][k] for k in ("footprint", "tilt_deg", "tilt_azimuth_deg")}
    key = hashlib.sha1(json.dumps(what, sort_keys=True).encode()).hexdigest()[:16]
    path = os.path.join(cache_dir, key + ".npz")
    if not os.path.exists(path):
        work = os.path.join(cache_dir, key + ".work")
        res = simulate.solve(spec, work)
        np.savez(path + ".tmp.npz", **res)
        os.replace(path + ".tmp.npz", path)
        shutil.rmtree(work, ignore_errors=True)
    with np.load(path) as z:
        return {k: z[k] for k in z.files}


def prism_triangles(low, high):
    """Sides and caps of a prism between two outlines (k, 3) of the same shape."""
    n = len(low)
    tris = []
    for i in range(n):
        j = (i + 1) % n
        tris += [(low[i], low[j], high[j]), (low[i], high[j], high[i])]
    for i in range(1, n - 1):
        tris += [(low[0], low[i + 1], low[i]), (high[0], high[i], high[i + 1])]
    return tris


def tool_triangles(spec, travel):
    """The probe: a head over its footprint (`head_height` thick along the axis) and a shaft of
    `shaft_fraction` of its size up to `length`, moved `travel` along its axis; triangles (k, 3, 3)
    in the world frame."""
    tool = spec["tool"]
    axis = scene.tool_axis(tool)
    fp = tool["footprint"]
    top = scene.object_height(spec["shape"])
    low = scene.footprint_outline(fp, top) + travel * axis
    head = low - tool["head_height"] * axis
    centre = np.array(list(fp["center"]) + [top])
    shaft = centre + tool["shaft_fraction"] * (low - (centre + travel * axis)) + travel * axis - tool["head_height"] * axis
    return np.array(prism_triangles(low, head) + prism_triangles(shaft, shaft - (tool["length"] - tool["head_height"]) * axis))


def camera_of(spec):
    c = spec["camera"]
    h = scene.object_height(spec["shape"])
    R, pos = render.look_at([0.0, 0.0, c.get("target_height_fraction", 0.5) * h], c["distance"],
                            c["elevation_deg"], c["azimuth_deg"])
    return render.Camera(c["fx"], c["fy"], c["cx"], c["cy"], 640, 480, R, pos)


def render_frames(spec, res, cam):
    """Clean depth, triangle ids and incidence cosines of camera and projector per frame."""
    p = dict(sensor.DEFAULTS, **spec.get("sensor", {}))
    proj = cam.shifted([p["baseline_m"], 0.0, 0.0], pad=120)
    surf = res["fine_surface"]
    n_obj = len(surf)
    table = (np.zeros(3), np.array([0.0, 0.0, 1.0]))
    frames = []
    for k in range(len(res["frame_t"])):
        pts = res["fine_points"] + res["fine_u"][k]
        tris = pts[surf]
        if spec["kind"] == "indentation":
            tris = np.concatenate([tris, tool_triangles(spec, res["tool_travel"][k])])
        z, ident, cosang = render.render(cam, tris, table)
        zp, _, _ = render.render(proj, tris, table)
        label = np.where(ident >= n_obj, 2, np.where(ident >= 0, 1, np.where(ident == -1, 0, -1)))
        frames.append((z, cosang, ident, zp, label))
    return frames, proj, p


def crop_box(frames, margin=24):
    """A fixed window holding the object and the tool in every frame, with `margin` pixels of table."""
    any_obj = np.any([f[4] >= 1 for f in frames], axis=0)
    vs, us = np.nonzero(any_obj)
    u0, u1 = max(0, us.min() - margin), min(640, us.max() + 1 + margin)
    v0, v1 = max(0, vs.min() - margin), min(480, vs.max() + 1 + margin)
    return int(u0), int(v0), int(u1 - u0), int(v1 - v0)


def write_plan(outdir, spec, res, fixed, driven, travel_axis, camera_text):
    pts, tets = res["coarse_points"], res["coarse_tets"]
    mesh.write_vtk(os.path.join(outdir, "mesh.vtk"), pts, tets)
    mat = spec["material"]
    shape = spec["shape"]
    if shape["kind"] == "box":
        what = "soft %s %.0f x %.0f x %.0f mm" % (("bar" if spec["kind"] == "free_motion" else "block"),
                                                 *(1000 * v for v in shape["size"]))
    else:
        what = "soft cylinder %.0f mm diameter, %.0f mm high" % (2000 * shape["radius"], 1000 * shape["height"])
    files = {"particles": "particles.csv", "mesh": "mesh.vtk", "depth_frames": "depth_frames.csv"}
    rec = {
        "format": "pliant-recording", "version": 1, "dimension": 3, "length_unit": "m",
        "particles": {"count": int(len(pts)),
                      "mass": [float("%.6g" % m) for m in lumped_masses(pts, tets, mat["density"])],
                      "fixed": [int(i) for i in fixed], "driven": [int(i) for i in driven]},
        "files": files,
        "material": {"poisson_ratio": mat["poisson_ratio"], "density": mat["density"]},
        "meta": {"object": what, "source": "simulated (tools/depth_world/depth_world.py, CalculiX)",
                 "camera": camera_text},
    }
    if spec["kind"] == "indentation":
        files["wrench"] = "wrench.csv"
        rec["wrench"] = {"applied_to": [int(i) for i in driven]}
        fp = spec["tool"]["footprint"]
        rec["meta"]["tool"] = ("flat %s probe (%s), bonded to the top face, moving along (%.4f, %.4f, %.4f); "
                               "its footprint nodes are driven along the programmed path" % (
                                   fp["kind"], ("%.0f mm diameter" % (2000 * fp["radius"]) if fp["kind"] == "round"
                                                else "%.0f mm square" % (1000 * fp["side"])), *travel_axis))
        rec["meta"]["wrench_sensor"] = "%.0f samples/s on its own clock; the force the probe applies" % spec["wrench"]["rate_hz"]
    else:
        rec["gravity"] = list(spec["gravity_m_s2"])
        rec["meta"]["motion"] = "clamped at its base; released at t = 0 from a bent shape (a lateral load removed)"
    with open(os.path.join(outdir, "recording.json"), "w") as f:
        json.dump(rec, f, indent=1)
        f.write("\n")
    known = sorted(set(int(i) for i in fixed) | set(int(i) for i in driven))
    with open(os.path.join(outdir, "particles.csv"), "w") as f:
        f.write("t,id,x,y,z\n")
        for k, t in enumerate(res["frame_t"]):
            for i in (range(len(pts)) if k == 0 else known):
                x = pts[i] + (res["tool_travel"][k] * travel_axis if i in driven else 0.0)
                f.write(f"{t:.6f},{i},{x[0]:.9g},{x[1]:.9g},{x[2]:.9g}\n")


def ccx_version():
    out = subprocess.run(["ccx", "-v"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True).stdout
    return " ".join(line.strip() for line in out.split("\n") if "Version" in line)


def make_case(spec, outdir, cache_dir):
    rng = np.random.default_rng(spec["seed"])
    res = solve_cached(spec, cache_dir)
    cam = camera_of(spec)
    frames, proj, p = render_frames(spec, res, cam)
    u0, v0, w, h = crop_box(frames) if spec["camera"].get("crop") else (0, 0, 640, 480)
    shutil.rmtree(os.path.join(outdir, "depth"), ignore_errors=True)  # no frames left from an earlier run
    os.makedirs(os.path.join(outdir, "depth"))
    rows, counts = [], []
    for k, (z, cosang, ident, zp, label) in enumerate(frames):
        raw, masks = sensor.apply(cam, z, cosang, ident, proj, zp, rng, p)
        raw = raw[v0:v0 + h, u0:u0 + w]
        name = "depth/%06d.png" % k
        png16.write(os.path.join(outdir, name), raw)
        rows.append(f"{k},{res['frame_t'][k]:.6f},{name},{1.0 / p['units_per_metre']:.6g},"
                    f"{cam.fx:.6g},{cam.fy:.6g},{cam.cx - u0:.6g},{cam.cy - v0:.6g}")
        win = (slice(v0, v0 + h), slice(u0, u0 + w))
        counts.append({m: int(masks[m][win].sum()) for m in masks} | {"valid": int((raw > 0).sum())})
    with open(os.path.join(outdir, "depth_frames.csv"), "w") as f:
        f.write("index,t,file,depth_scale_m,fx,fy,cx,cy\n" + "\n".join(rows) + "\n")

    pts = res["coarse_points"]
    fixed = np.nonzero(np.abs(pts[:, 2]) < scene.TOL)[0]
    axis = scene.tool_axis(spec["tool"]) if spec["kind"] == "indentation" else np.zeros(3)
    driven = (scene.in_footprint(pts, spec["shape"], spec["tool"]["footprint"]) if spec["kind"] == "indentation"
              else np.array([], dtype=np.int64))
    pose = list(cam.t) + list(render.quaternion(cam.R))
    text = ("Kinect-class depth camera, 640 x 480%s, %.0f frames/s; its pose in this recording's frame "
            "(x = R(q) x_camera + t) is camera_pose.txt: --camera-pose %s" % (
                "" if (w, h) == (640, 480) else " cropped to %d x %d at (%d, %d)" % (w, h, u0, v0),
                spec["frame_rate_hz"], ",".join("%.9g" % v for v in pose)))
    write_plan(outdir, spec, res, fixed, driven, axis, text)
    with open(os.path.join(outdir, "camera_pose.txt"), "w") as f:
        f.write(",".join("%.9g" % v for v in pose) + "\n")

    truth = {
        "format": "pliant-truth", "version": 1, "model": "calculix depth world", "kind": spec["kind"],
        "parameters": {"youngs_modulus": spec["material"]["youngs_modulus"],
                       "poisson_ratio": spec["material"]["poisson_ratio"], "density": spec["material"]["density"]},
        "material": spec["material"],
        "solver": {"program": ccx_version(), "element": "C3D10 (10-node quadratic tetrahedron), NLGEOM",
                   "procedure": ("*STATIC, one increment per frame" if spec["kind"] == "indentation"
                                 else "*STATIC (bent by the load, gravity on), then *DYNAMIC with *DAMPING"),
                   "incrementation": str(res["incrementation"]),
                   "fine_nodes": int(len(res["fine_points"])), "fine_elements": int(len(res["fine_tets10"])),
                   "coarse_nodes": int(len(pts)), "coarse_elements": int(len(res["coarse_tets"])),
                   "fine_lc_m": spec["fine_lc"], "coarse_lc_m": spec["coarse_lc"],
                   "coarse_mean_edge_m": mesh.mean_edge_length(pts, res["coarse_tets"])},
        "frame_t": [round(float(t), 6) for t in res["frame_t"]],
        "displacement_m": np.round(res["coarse_u"], 8).tolist(),
        "camera": {"fx": cam.fx, "fy": cam.fy, "cx": cam.cx, "cy": cam.cy, "width": 640, "height": 480,
                   "crop": {"u0": u0, "v0": v0, "width": w, "height": h},
                   "rotation_world_from_camera": cam.R.tolist(), "position_m": cam.t.tolist(),
                   "camera_pose_option": ",".join("%.9g" % v for v in pose)},
        "sensor": p, "mask_counts_per_frame": counts,
        "seed": spec["seed"], "spec": spec,
    }
    if spec["kind"] == "indentation":
        wr = spec["wrench"]
        period = 1.0 / wr["rate_hz"]
        wt = np.arange(wr["phase"] * period, res["frame_t"][-1] + 1e-9, period)
        force, torque = hermite(res["frame_t"], res["force"], wt), hermite(res["frame_t"], res["torque"], wt)
        peak = float(np.max(np.linalg.norm(res["force"], axis=1)))
        fs = wr["noise_fraction"] * peak
        fn = force + rng.normal(0.0, fs, force.shape)
        tn = torque + rng.normal(0.0, fs * wr["torque_noise_m"], torque.shape)
        with open(os.path.join(outdir, "wrench.csv"), "w") as f:
            f.write("t,fx,fy,fz,tx,ty,tz\n")
            for k, t in enumerate(wt):
                f.write(f"{t:.6f}," + ",".join("%.6g" % v for v in (*fn[k], *tn[k])) + "\n")
        truth["contact_force_n"] = np.round(res["force"], 6).tolist()
        truth["contact_torque_nm"] = np.round(res["torque"], 8).tolist()
        truth["wrench"] = {"rate_hz": wr["rate_hz"], "phase": wr["phase"], "force_noise_std_n": fs,
                           "torque_noise_std_nm": fs * wr["torque_noise_m"], "peak_force_n": peak,
                           "interpolation": "cubic Hermite between the solved frames"}
        truth["tool"] = {"footprint": spec["tool"]["footprint"], "axis": axis.tolist(),
                         "length_m": spec["tool"]["length"], "head_height_m": spec["tool"]["head_height"],
                         "shaft_fraction": spec["tool"]["shaft_fraction"], "travel_m": np.round(res["tool_travel"], 9).tolist(),
                         "driven_particles": [int(i) for i in driven]}
    else:
        truth["parameters"].update(rayleigh_alpha=spec["rayleigh_alpha"], rayleigh_beta=spec["rayleigh_beta"])
    write_truth(os.path.join(outdir, "truth.json"), truth)
    return truth


def write_truth(path, truth):
    """JSON with the per-frame arrays one frame to a line (the file stays readable and small)."""
    per_frame = ("displacement_m", "contact_force_n", "contact_torque_nm", "mask_counts_per_frame")
    text = json.dumps({k: ("@" + k if k in per_frame else v) for k, v in truth.items()}, indent=1, sort_keys=True)
    for k in per_frame:
        if k in truth:
            rows = ",\n  ".join(json.dumps(row, separators=(",", ":"), sort_keys=True) for row in truth[k])
            text = text.replace(json.dumps("@" + k), "[\n  " + rows + "\n ]")
    with open(path, "w") as f:
        f.write(text + "\n")


def main():
    ap = argparse.ArgumentParser(description="Write one depth-world case from a JSON spec.")
    ap.add_argument("spec")
    ap.add_argument("outdir")
    ap.add_argument("--cache", help="directory for CalculiX results (default: temporary)")
    args = ap.parse_args()
    with open(args.spec) as f:
        spec = json.load(f)
    if args.cache:
        os.makedirs(args.cache, exist_ok=True)
        make_case(spec, args.outdir, args.cache)
    else:
        with tempfile.TemporaryDirectory() as cache:
            make_case(spec, args.outdir, cache)


if __name__ == "__main__":
    main()
