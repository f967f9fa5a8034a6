"""Scenes of the depth world and their CalculiX runs.

Two kinds of scene, both solved by CalculiX (ccx) with 10-node quadratic tetrahedra (C3D10) and
NLGEOM on a fine gmsh mesh, with the object standing on a table at z = 0 (world frame, metres):

- indentation: a block or cylinder glued to the table, pressed by a rigid flat probe (round or
  square) bonded to part of its top face, moving along an axis that may be tilted from the
  vertical, then released; quasi-static (*STATIC), one increment per camera frame;
- free motion: an upright bar or plate clamped to the table at its base, bent by a lateral load
  on its top face (*STATIC, gravity on), released at t = 0 and vibrating with Rayleigh damping
  (*DYNAMIC with *DAMPING ALPHA, BETA), one increment per camera frame.

The deck writers are this scene's own; meshing helpers, material cards, the ccx runner and the
result readers are those of the CalculiX concealed family (tools/concealed/calculix/).
"""
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "concealed"))
from calculix import ccx, interp, mesh  # noqa: E402

TOL = 1e-7  # geometric tolerance (m) for "on a face"


# ---------------------------------------------------------------------------------------------
# Geometry

def object_height(shape):
    return shape["size"][2] if shape["kind"] == "box" else shape["height"]


def geo_text(shape, footprint, lc):
    """gmsh .geo (OpenCASCADE) of the object centred on the z axis on z = 0; the probe's
    footprint (a disk or a square on the top face) is embedded so both meshes have nodes on its rim."""
    lines = ['SetFactory("OpenCASCADE");']
    if shape["kind"] == "box":
        w, d, h = shape["size"]
        lines.append(f"Box(1) = {{{-w / 2}, {-d / 2}, 0, {w}, {d}, {h}}};")
    else:
        r, h = shape["radius"], shape["height"]
        lines.append(f"Cylinder(1) = {{0, 0, 0, 0, 0, {h}, {r}}};")
    if footprint is not None:
        cx, cy = footprint["center"]
        if footprint["kind"] == "round":
            a = footprint["radius"]
            lines.append(f"Disk(100) = {{{cx}, {cy}, {h}, {a}, {a}}};")
        else:
            s = footprint["side"]
            lines.append(f"Rectangle(100) = {{{cx - s / 2}, {cy - s / 2}, {h}, {s}, {s}}};")
        lines.append("BooleanFragments{ Volume{1}; Delete; }{ Surface{100}; Delete; }")
    lines += mesh.mesh_options(lc)
    return "\n".join(lines) + "\n"


def gmsh_tets(shape, footprint, lc):
    """Linear tetrahedra (points (n,3), tets (m,4), positively oriented) of the object from gmsh."""
    with tempfile.TemporaryDirectory() as tmp:
        geo, msh = os.path.join(tmp, "o.geo"), os.path.join(tmp, "o.msh")
        with open(geo, "w") as f:
            f.write(geo_text(shape, footprint, lc))
        subprocess.run(["gmsh", "-3", "-nt", "1", geo, "-o", msh], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        points, tets = mesh._read_msh2(msh)
    return points, mesh._orient(points, tets)


def in_footprint(points, shape, footprint):
    """Nodes on the top face inside the probe's footprint."""
    h = object_height(shape)
    top = np.abs(points[:, 2] - h) < TOL
    cx, cy = footprint["center"]
    if footprint["kind"] == "round":
        inside = np.hypot(points[:, 0] - cx, points[:, 1] - cy) <= footprint["radius"] + TOL
    else:
        s = footprint["side"] / 2 + TOL
        inside = (np.abs(points[:, 0] - cx) <= s) & (np.abs(points[:, 1] - cy) <= s)
    return np.nonzero(top & inside)[0]


def footprint_outline(footprint, z, segments=32):
    """Corner points (k, 3) of the footprint's outline at height z, counter-clockwise from above."""
    cx, cy = footprint["center"]
    if footprint["kind"] == "round":
        a = np.linspace(0, 2 * np.pi, segments, endpoint=False)
        r = footprint["radius"]
        return np.stack([cx + r * np.cos(a), cy + r * np.sin(a), np.full(segments, z)], axis=1)
    s = footprint["side"] / 2
    return np.array([[cx - s, cy - s, z], [cx + s, cy - s, z], [cx + s, cy + s, z], [cx - s, cy + s, z]])


def tool_axis(tool):
    """Unit vector along which the probe moves into the object: down, tilted by `tilt_deg` toward
    the azimuth `tilt_azimuth_deg` (from +x, counter-clockwise)."""
    t, a = np.radians(tool.get("tilt_deg", 0.0)), np.radians(tool.get("tilt_azimuth_deg", 0.0))
    return np.array([np.sin(t) * np.cos(a), np.sin(t) * np.sin(a), -np.cos(t)])


def quadratic_surface(points10, tets4, tets10):
    """The fine mesh's boundary as linear triangles: each 6-node boundary face split into four."""
    mid = {}
    for k, (a, b) in enumerate(mesh.TET10_EDGES):
        key = np.sort(tets10[:, [a, b]], axis=1)
        for (i, j), m in zip(key, tets10[:, 4 + k]):
            mid[(int(i), int(j))] = int(m)
    faces = mesh.boundary_faces(tets4)
    tris = []
    for a, b, c in faces:
        ab, bc, ca = (mid[tuple(sorted((int(x), int(y))))] for x, y in ((a, b), (b, c), (c, a)))
        tris += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    return np.array(tris, dtype=np.int64)


# ---------------------------------------------------------------------------------------------
# Decks

def _elements(tets10):
    out = ["*ELEMENT, TYPE=C3D10, ELSET=EALL"]
    out += [f"{e + 1}, " + ", ".join(str(int(v) + 1) for v in t) for e, t in enumerate(tets10)]
    return "\n".join(out) + "\n"


def _nodes(points):
    out = ["*NODE, NSET=NALL"] + [f"{i + 1}, {p[0]:.12g}, {p[1]:.12g}, {p[2]:.12g}" for i, p in enumerate(points)]
    return "\n".join(out) + "\n"


def _table(name, pairs, total_time=False):
    flat = [v for p in pairs for v in p]
    head = f"*AMPLITUDE, NAME={name}" + (", TIME=TOTAL TIME" if total_time else "")
    return head + "\n" + ccx._fmt_rows(flat, 8) + "\n"


def indentation_deck(run, automatic):
    """*STATIC, NLGEOM, one increment per frame: bottom fixed, the footprint nodes moved along
    the tool's axis by the amplitude DRIVE (metres); reactions of the footprint printed."""
    pts, t10 = run["points"], run["tets10"]
    text = "*HEADING\npliant depth world: indentation\n" + _nodes(pts) + _elements(t10)
    text += ccx._nset("FIXED", run["fixed"]) + ccx._nset("DRIVEN", run["driven"])
    text += ccx.material_cards("M", run["material"]) + "*SOLID SECTION, ELSET=EALL, MATERIAL=M\n"
    text += _table("DRIVE", list(zip(*run["drive"])))
    dt, t_end = run["dt"], run["t_end"]
    n = int(round(t_end / dt))
    if automatic:
        text += "*TIME POINTS, NAME=FRAMES\n" + ccx._fmt_rows([dt * (k + 1) for k in range(n)], 8) + "\n"
        text += f"*STEP, NLGEOM, INC={20 * n + 100}\n*STATIC\n{dt:.10g}, {t_end:.10g}, {dt * 1e-4:.10g}, {dt:.10g}\n"
    else:
        text += f"*STEP, NLGEOM, INC={n + 10}\n*STATIC, DIRECT\n{dt:.10g}, {t_end:.10g}\n"
    text += "*BOUNDARY\nFIXED, 1, 3\n*BOUNDARY, AMPLITUDE=DRIVE\n"
    ax = run["axis"]
    text += "".join(f"DRIVEN, {d + 1}, {d + 1}, {ax[d]:.12g}\n" for d in range(3))
    when = "TIME POINTS=FRAMES" if automatic else "FREQUENCY=1"
    text += f"*NODE FILE, {when}\nU\n"
    when = "TIME POINTS=FRAMES" if automatic else "FREQUENCYF=1"
    text += f"*NODE PRINT, NSET=DRIVEN, TOTALS=YES, {when}\nRF\n*END STEP\n"
    return text


def free_motion_deck(run, automatic):
    """Step 1 (*STATIC, NLGEOM): gravity and a lateral load on the top face, both ramped in;
    step 2 (*DYNAMIC, NLGEOM, Rayleigh damping): the load is gone (its amplitude drops to zero
    at the step's start, on the total-time clock), gravity stays."""
    pts, t10 = run["points"], run["tets10"]
    text = "*HEADING\npliant depth world: free motion\n" + _nodes(pts) + _elements(t10)
    text += ccx._nset("FIXED", run["fixed"]) + ccx._nset("TIP", run["tip"])
    text += ccx.material_cards("M", run["material"]) + "*SOLID SECTION, ELSET=EALL, MATERIAL=M\n"
    text += _table("LOAD", [(0, 0), (1, 1), (1 + 1e-9, 0), (1e4, 0)], total_time=True)
    text += _table("GRAV", [(0, 0), (1, 1), (1e4, 1)], total_time=True)
    per_node = np.asarray(run["tip_load"]) / len(run["tip"])
    text += "*STEP, NLGEOM, INC=200\n*STATIC\n0.25, 1., 1e-4, 0.25\n*BOUNDARY\nFIXED, 1, 3\n"
    g = np.asarray(run["gravity"], dtype=float)
    gm = float(np.linalg.norm(g))
    text += f"*DLOAD, AMPLITUDE=GRAV\nEALL, GRAV, {gm:.10g}, {g[0] / gm:.10g}, {g[1] / gm:.10g}, {g[2] / gm:.10g}\n"
    text += "*CLOAD, AMPLITUDE=LOAD\n"
    text += "".join(f"{int(i) + 1}, {d + 1}, {per_node[d]:.12g}\n" for i in run["tip"] for d in range(3) if per_node[d] != 0)
    # (ccx asks for energy output in the first step of a nonlinear run that has a damped dynamic step)
    text += "*NODE FILE\nU\n*EL FILE\nENER\n*END STEP\n"
    dt, t_end = run["dt"], run["t_end"]
    n = int(round(t_end / dt))
    if automatic:
        text += "*TIME POINTS, NAME=FRAMES\n" + ccx._fmt_rows([dt * (k + 1) for k in range(n)], 8) + "\n"
        text += f"*STEP, NLGEOM, INC={20 * n + 100}\n*DYNAMIC\n{dt:.10g}, {t_end:.10g}, {dt * 1e-4:.10g}, {dt:.10g}\n"
    else:
        text += f"*STEP, NLGEOM, INC={n + 10}\n*DYNAMIC, DIRECT\n{dt:.10g}, {t_end:.10g}\n"
    a, b = run["damping"]
    text += f"*DAMPING, ALPHA={a:.10g}, BETA={b:.10g}\n"
    when = "TIME POINTS=FRAMES" if automatic else "FREQUENCY=1"
    text += f"*NODE FILE, {when}\nU\n*END STEP\n"
    return text


def run_deck(workdir, writer, run):
    """Fixed increments of one frame; if ccx diverges, automatic incrementation with output at
    the frames. Returns which ran."""
    os.makedirs(workdir, exist_ok=True)
    for automatic in (False, True):
        with open(os.path.join(workdir, "job.inp"), "w") as f:
            f.write(writer(run, automatic))
        try:
            ccx.run_ccx(workdir, "job")
            return "automatic" if automatic else "direct"
        except RuntimeError as err:
            if automatic or "diverge" not in str(err):
                raise
    raise AssertionError("unreachable")
