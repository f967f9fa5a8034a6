"""Geometry of the depth-world samples, computed here independently of the generator's renderer:
rays through pixel centres cast against the user's mesh (moved by the truth's displacements),
the probe's prism and the table (Moeller-Trumbore intersections)."""
import csv
import json
import os

import numpy as np


def read_frames(case):
    with open(os.path.join(case, "depth_frames.csv")) as f:
        return list(csv.DictReader(f))


def read_vtk(path):
    with open(path) as f:
        tok = f.read().split()
    i = tok.index("POINTS")
    n = int(tok[i + 1])
    pts = np.array(tok[i + 3:i + 3 + 3 * n], dtype=float).reshape(n, 3)
    j = tok.index("CELLS")
    m = int(tok[j + 1])
    cells = np.array(tok[j + 3:j + 3 + 5 * m], dtype=np.int64).reshape(m, 5)
    assert np.all(cells[:, 0] == 4)
    return pts, cells[:, 1:]


def boundary(tets):
    faces = np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 3, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 1]]])
    _, first, counts = np.unique(np.sort(faces, axis=1), axis=0, return_index=True, return_counts=True)
    return faces[first[counts == 1]]


def rotation(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def camera_pose(case):
    with open(os.path.join(case, "camera_pose.txt")) as f:
        v = [float(s) for s in f.read().strip().split(",")]
    return rotation(v[3:]), np.array(v[:3])


def cast(dirs, tris):
    """Depth z along each ray from the origin (dirs (n, 3) with unit z component) to the nearest
    of the triangles (k, 3, 3), inf when none is hit, and the cosine between the ray and that
    triangle's normal."""
    d = dirs
    best = np.full(len(d), np.inf)
    which = np.full(len(d), -1)
    v0, e1, e2 = tris[:, 0], tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    for s in range(0, len(d), 2000):
        r = d[s:s + 2000]
        p = np.cross(r[:, None, :], e2[None])
        det = np.einsum("rkc,kc->rk", p, e1)
        ok = np.abs(det) > 1e-15
        inv = np.where(ok, 1.0 / np.where(ok, det, 1), 0)
        tvec = -v0[None]  # the rays start at the camera centre (origin)
        u = np.einsum("rkc,rkc->rk", np.broadcast_to(tvec, p.shape), p) * inv
        q = np.cross(np.broadcast_to(tvec, p.shape), e1[None])
        v = np.einsum("rc,rkc->rk", r, q) * inv
        t = np.einsum("kc,rkc->rk", e2, q) * inv
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
        tt = np.where(hit, t, np.inf)
        best[s:s + 2000] = np.min(tt, axis=1)
        which[s:s + 2000] = np.where(np.isfinite(best[s:s + 2000]), np.argmin(tt, axis=1), -1)
    n = np.cross(e1, e2)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    cosang = np.ones(len(d))
    hit = which >= 0
    cosang[hit] = np.abs(np.einsum("rc,rc->r", d[hit], n[which[hit]])) / np.linalg.norm(d[hit], axis=1)
    return best, cosang


def _prism(low, high):
    n, tris = len(low), []
    for i in range(n):
        j = (i + 1) % n
        tris += [(low[i], low[j], high[j]), (low[i], high[j], high[i])]
    for i in range(1, n - 1):
        tris += [(low[0], low[i], low[i + 1]), (high[0], high[i], high[i + 1])]
    return tris


def probe(truth, frame):
    """The probe as truth.json describes it: a head on the footprint and a narrower shaft."""
    tool = truth["tool"]
    fp, axis = tool["footprint"], np.array(tool["axis"])
    shape = truth["spec"]["shape"]
    top = shape["size"][2] if shape["kind"] == "box" else shape["height"]
    cx, cy = fp["center"]
    if fp["kind"] == "round":
        a = np.linspace(0, 2 * np.pi, 32, endpoint=False)
        rim = np.stack([fp["radius"] * np.cos(a), fp["radius"] * np.sin(a), np.zeros(32)], 1)
    else:
        s = fp["side"] / 2
        rim = np.array([[-s, -s, 0], [s, -s, 0], [s, s, 0], [-s, s, 0]])
    centre = np.array([cx, cy, top]) + tool["travel_m"][frame] * axis
    low = centre + rim
    head = low - tool["head_height_m"] * axis
    shaft = centre + tool["shaft_fraction"] * rim - tool["head_height_m"] * axis
    top_end = shaft - (tool["length_m"] - tool["head_height_m"]) * axis
    return np.array(_prism(low, head) + _prism(shaft, top_end))


def scene_depth(case, truth, frame, rows, cols, fx, fy, cx, cy):
    """Depth and incidence cosine of the object (the user's mesh moved by the truth's
    displacements), the probe and the table along the rays of pixels (rows, cols)."""
    R, t = camera_pose(case)
    pts, tets = read_vtk(os.path.join(case, "mesh.vtk"))
    pts = pts + np.array(truth["displacement_m"][frame])
    faces = boundary(tets)
    to_cam = lambda x: (x - t) @ R  # noqa: E731
    dirs = np.stack([(cols - cx) / fx, (rows - cy) / fy, np.ones(len(rows))], 1)
    obj = cast(dirs, to_cam(pts[faces].reshape(-1, 3)).reshape(-1, 3, 3))
    tool = (np.full(len(rows), np.inf), np.ones(len(rows)))
    if "tool" in truth:
        tool = cast(dirs, to_cam(probe(truth, frame).reshape(-1, 3)).reshape(-1, 3, 3))
    n = R.T @ np.array([0, 0, 1.0])
    p0 = to_cam(np.zeros(3))
    den = dirs @ n
    table = (p0 @ n) / den
    table[table <= 0] = np.inf
    table_cos = np.abs(den) / np.linalg.norm(dirs, axis=1)
    return obj, tool, (table, table_cos)


def expected_sigma(z, cosang, sensor, fx):
    """The stated noise of a pixel at depth z on a surface at angle acos(cosang) to the ray:
    Nguyen et al.'s axial term, the lateral one turned into depth on the slanted surface (the
    offset is rounded to whole pixels: its variance gains 1/12 px^2), the disparity step and the
    millimetre rounding (uniform: step / sqrt(12))."""
    theta = np.arccos(np.clip(cosang, 0, 1))
    th = np.minimum(theta, np.radians(89))
    axial = sensor["axial_a_m"] + sensor["axial_b_m_per_m2"] * (z - sensor["axial_z0_m"]) ** 2
    axial = axial + np.where(th > np.radians(sensor["axial_angle_from_deg"]),
                             sensor["axial_angle_coeff_m"] / np.sqrt(z) * th ** 2 / (np.pi / 2 - th) ** 2, 0)
    lat_px = np.sqrt((sensor["lateral_px"] + sensor["lateral_angle_coeff_px"] * th / (np.pi / 2 - th)) ** 2 + 1 / 12)
    lateral = lat_px * z / fx * np.tan(th)
    step = z ** 2 * sensor["disparity_step_px"] / (fx * sensor["baseline_m"])
    return np.sqrt(axial ** 2 + lateral ** 2 + step ** 2 / 12 + (1 / sensor["units_per_metre"]) ** 2 / 12)
