"""Solve one depth-world scene with CalculiX and carry the solution to the user's coarse mesh.

solve(spec, workdir) returns, per camera frame (frame 0 at t = 0): the fine C3D10 mesh's
displacements (for the renderer), its boundary as linear triangles, the coarse linear mesh (what
the user gets) with its nodes' displacements interpolated by the C3D10 shape functions, and for
an indentation the force the probe applies to the object (sum of ccx's reactions over the
footprint nodes) and the probe's displacement along its axis.
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "concealed"))
from calculix import ccx, interp, mesh  # noqa: E402
from calculix_world import drive_at, drive_table  # noqa: E402

import scene  # noqa: E402


def _meshes(spec, footprint):
    p4, t4 = scene.gmsh_tets(spec["shape"], footprint, spec["fine_lc"])
    fine, t10 = mesh.quadratic(p4, t4)
    coarse, ct4 = scene.gmsh_tets(spec["shape"], footprint, spec["coarse_lc"])
    return p4, t4, fine, t10, coarse, ct4


def at_frames(times, n, dt, what):
    """Indices of the blocks solved at the frames dt, 2 dt, ..., n dt (ccx may add a sliver of an
    increment when the end time is not a whole number of increments in floating point)."""
    times = np.asarray(times)
    idx = np.array([int(np.argmin(np.abs(times - k * dt))) for k in range(1, n + 1)], dtype=np.int64)
    if len(times) == 0 or np.max(np.abs(times[idx] - dt * np.arange(1, n + 1))) > 0.01 * dt:
        raise RuntimeError(f"{what}: no solution at every frame ({len(times)} blocks for {n} frames)")
    return idx


def solve(spec, workdir):
    kind = spec["kind"]
    footprint = spec["tool"]["footprint"] if kind == "indentation" else None
    p4, t4, fine, t10, coarse, ct4 = _meshes(spec, footprint)
    fixed = np.nonzero(np.abs(fine[:, 2]) < scene.TOL)[0]
    dt = 1.0 / spec["frame_rate_hz"]
    mat = spec["material"]
    run = {"points": fine, "tets10": t10, "material": mat, "fixed": fixed, "dt": dt}
    out = {}
    if kind == "indentation":
        table = drive_table(spec["protocol"])
        driven = scene.in_footprint(fine, spec["shape"], footprint)
        run.update(driven=driven, drive=(table[0], table[1]), t_end=table[2], axis=scene.tool_axis(spec["tool"]))
        inc = scene.run_deck(workdir, scene.indentation_deck, run)
        t_f, node_ids, per_node, totals = ccx.read_dat_forces(os.path.join(workdir, "job.dat"), len(driven))
        t_u, ids, u = ccx.read_frd_displacements(os.path.join(workdir, "job.frd"))
        n = int(round(table[2] / dt))
        iu, i_f = at_frames(t_u, n, dt, workdir), at_frames(t_f, n, dt, workdir)
        t_u, u, t_f, per_node, totals = t_u[iu], u[iu], t_f[i_f], per_node[i_f], totals[i_f]
        frame_t = np.concatenate([[0.0], t_u])
        full = np.zeros((n + 1, len(fine), 3))
        full[1:, ids, :] = u  # frame 0: the tool has not moved, nothing is loaded
        out["force"] = np.concatenate([np.zeros((1, 3)), totals])
        # torque about the centroid of the coarse mesh's footprint nodes at rest (recording-v1's
        # reference point: the applied_to particles' rest centroid)
        centre = coarse[scene.in_footprint(coarse, spec["shape"], footprint)].mean(axis=0)
        pos = fine[node_ids][None] + drive_at(table, t_f)[:, None, None] * run["axis"][None, None, :]
        out["torque"] = np.concatenate([np.zeros((1, 3)), np.cross(pos - centre, per_node).sum(axis=1)])
        out["tool_travel"] = drive_at(table, frame_t)
        out["fine_driven"] = driven
    else:
        h = scene.object_height(spec["shape"])
        tip = np.nonzero(np.abs(fine[:, 2] - h) < scene.TOL)[0]
        run.update(tip=tip, tip_load=spec["tip_load_n"], gravity=spec["gravity_m_s2"],
                   damping=(spec["rayleigh_alpha"], spec["rayleigh_beta"]), t_end=spec["duration_s"])
        inc = scene.run_deck(workdir, scene.free_motion_deck, run)
        t_u, ids, u = ccx.read_frd_displacements(os.path.join(workdir, "job.frd"))
        n = int(round(spec["duration_s"] / dt))
        # the static step's blocks come first and end at time 1; the dynamic step's follow (ccx
        # writes the total time: 1 + t)
        last_static = int(np.nonzero(np.abs(t_u - 1.0) < 1e-9)[0][0])
        dyn = last_static + 1 + at_frames(t_u[last_static + 1:] - 1.0, n, dt, workdir)
        full = np.zeros((n + 1, len(fine), 3))
        full[:, ids, :] = u[np.concatenate([[last_static], dyn])]  # the bent state, then the frames
        frame_t = np.arange(n + 1) * dt
    elems, weights = interp.locate(fine, t10, coarse)
    out.update({
        "frame_t": frame_t, "fine_points": fine, "fine_tets10": t10,
        "fine_surface": scene.quadratic_surface(fine, t4, t10), "fine_u": full,
        "coarse_points": coarse, "coarse_tets": ct4, "coarse_u": interp.transfer(full, t10, elems, weights),
        "incrementation": inc,
    })
    return out
