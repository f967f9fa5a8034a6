#!/usr/bin/python3
"""Converged CalculiX reference forces for two linear-elastic problems near incompressibility.

Our own FEM uses linear tetrahedra, which lock volumetrically as the Poisson ratio approaches
0.5. This script computes reference numbers with an independent solver (CalculiX ccx, quadratic
10-node tetrahedra C3D10, linear static, small strain, no NLGEOM) so that the locking of our
elements can be measured against them. Two problems, E = 100 kPa and
nu in {0.0, 0.3, 0.45, 0.48, 0.49, 0.495}:

  bonded_cylinder  diameter 50 mm, height 30 mm, axis z. Bottom face (z = 0) fully fixed; top face
                   (z = 30 mm) ux = uy = 0, uz = -0.3 mm (1 % nominal strain). Output: total z
                   reaction on the top face and the apparent modulus factor F*H/(E*A*delta) with
                   A = pi*r^2 of the exact circle (exactly 1 for nu = 0).
  indented_block   x, y in [-20, 20] mm, z in [0, 20] mm. Bottom face fully fixed; every top-face
                   node with |x| <= 5 mm and |y| <= 5 mm (a bonded rigid square punch) gets
                   ux = uy = 0, uz = -0.2 mm; the rest of the top face and the sides are free.
                   Output: total z reaction on the punch nodes.

Both problems are symmetric about the planes x = 0 and y = 0 (geometry, loading and an isotropic
material), so ccx solves one quarter (x >= 0, y >= 0) with ux = 0 on x = 0 and uy = 0 on y = 0;
every force reported is the whole-body force (4 times the quarter's). The cylinder is in addition
symmetric about its mid-height plane (reflect z -> H - z and add the rigid shift -delta): there
uz = -delta/2 and the shear tractions vanish, so only its lower half is meshed (z in [0, H/2],
bottom fixed, mid-height nodes uz = -delta/2 with ux, uy free) and F is the z reaction on the
mid-height nodes (the force carried through every horizontal section). These reductions are exact
for linear elasticity and let the finest meshes be finer than a whole model of the same cost.

Meshes come from the gmsh command line (OpenCASCADE geometry, second-order meshes, so the midside
nodes of the curved cylinder surface lie on the circle). The block's top face is split along the
punch edges (the 10 x 10 mm square is a separate surface fragment), so the punch footprint is
exact; its mesh is additionally graded towards the punch edges (a size field that is the nominal
size times a fixed function of position, so halving the nominal size halves every local size).
For every Poisson ratio the force is computed on each mesh level (nominal sizes halving) and
extrapolated (Richardson) from the three finest with the observed order; if the three finest are
not monotone (or do not contract) the finest value is reported instead and the case says so.

Reused from tools/concealed/calculix: ccx.run_ccx (runs ccx single-threaded), ccx.material_cards,
ccx._nset, ccx.read_dat_forces, mesh.TET10_EDGES (the C3D10 midside-node order).

Run (one ccx at a time, single-threaded; about fifteen minutes on one core):

    tools/reference/calculix_locking_references.py
    tools/reference/calculix_locking_references.py --workdir /tmp/ccx_locking --problems bonded_cylinder
    tools/reference/calculix_locking_references.py --markdown-table   # print the table of the JSON

Options: --workdir (ccx and gmsh work files, default /tmp/ccx_locking_references; finished runs
found there are reused unless --fresh), --output (default
tests/host/data/calculix_locking_references.json), --problems, --poisson, --cylinder-sizes-mm,
--block-sizes-mm. Needs /usr/bin/ccx (2.20 was used), the gmsh CLI (4.8.4 was used) and numpy.
"""
import argparse
import datetime
import json
import math
import os
import shutil
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools", "concealed"))
from calculix import ccx, mesh  # noqa: E402

YOUNGS_MODULUS_PA = 100e3
POISSON_RATIOS = [0.0, 0.3, 0.45, 0.48, 0.49, 0.495]

# Geometry in millimetres (the decks are in mm, N, MPa; the JSON is converted to SI).
CYL_RADIUS_MM, CYL_HEIGHT_MM, CYL_DELTA_MM = 25.0, 30.0, 0.3
BLOCK_HALF_MM, BLOCK_HEIGHT_MM, PUNCH_HALF_MM, PUNCH_DELTA_MM = 20.0, 20.0, 5.0, 0.2
# Grading of the block mesh towards the punch edges: size = SIZE_MIN_FACTOR * h within
# GRADE_DIST_MIN_MM of an edge, rising linearly to h at GRADE_DIST_MAX_MM.
SIZE_MIN_FACTOR, GRADE_DIST_MIN_MM, GRADE_DIST_MAX_MM = 0.25, 0.5, 5.0

DEFAULT_CYLINDER_SIZES_MM = [8.0, 4.0, 2.0, 1.0]
DEFAULT_BLOCK_SIZES_MM = [10.0, 5.0, 2.5, 1.25]

GEO_OPTIONS = """Mesh.CharacteristicLengthFromCurvature = 0;
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.ElementOrder = 2;
Mesh.SecondOrderLinear = 0;
Mesh.Optimize = 1;
Mesh.RandomSeed = 1;
General.NumThreads = 1;
Mesh.MshFileVersion = 2.2;
"""


def geo_cylinder(h):
    """Lower half of the quarter cylinder x, y >= 0, z in [0, H/2] (OpenCASCADE: the angle runs
    from the x axis towards y)."""
    return (f'SetFactory("OpenCASCADE");\n'
            f"Cylinder(1) = {{0, 0, 0, 0, 0, {CYL_HEIGHT_MM / 2}, {CYL_RADIUS_MM}, Pi/2}};\n"
            f"Mesh.CharacteristicLengthMax = {h};\n"
            f"Mesh.CharacteristicLengthMin = {h};\n" + GEO_OPTIONS)


def geo_block(h):
    """Quarter block [0,20]^2 x [0,20] with the quarter punch square [0,5]^2 on its top face as a
    separate surface, and a size field graded towards the two punch edges x = 5 and y = 5."""
    a, b, p, eps = BLOCK_HALF_MM, BLOCK_HEIGHT_MM, PUNCH_HALF_MM, 1e-3
    return (f'SetFactory("OpenCASCADE");\n'
            f"Box(1) = {{0, 0, 0, {a}, {a}, {b}}};\n"
            f"Rectangle(100) = {{0, 0, {b}, {p}, {p}}};\n"
            "BooleanFragments{ Volume{1}; Delete; }{ Surface{100}; Delete; }\n"
            f"e1() = Curve In BoundingBox{{{p - eps}, {-eps}, {b - eps}, {p + eps}, {p + eps}, {b + eps}}};\n"
            f"e2() = Curve In BoundingBox{{{-eps}, {p - eps}, {b - eps}, {p + eps}, {p + eps}, {b + eps}}};\n"
            "If (#e1() != 1 || #e2() != 1)\n  Error(\"punch edges not found\");\nEndIf\n"
            "Field[1] = Distance;\n"
            "Field[1].CurvesList = {e1(), e2()};\n"
            "Field[1].NumPointsPerCurve = 400;\n"
            "Field[2] = Threshold;\n"
            "Field[2].InField = 1;\n"
            f"Field[2].SizeMin = {SIZE_MIN_FACTOR * h};\n"
            f"Field[2].SizeMax = {h};\n"
            f"Field[2].DistMin = {GRADE_DIST_MIN_MM};\n"
            f"Field[2].DistMax = {GRADE_DIST_MAX_MM};\n"
            "Background Field = 2;\n"
            f"Mesh.CharacteristicLengthMax = {h};\n" + GEO_OPTIONS)


def read_msh2_tet10(path):
    """Nodes and 10-node tetrahedra (gmsh type 11) of an ASCII .msh 2.2 file, tetrahedra in the
    CalculiX C3D10 node order, renumbered 0..n-1 over the nodes they use."""
    with open(path) as f:
        text = f.read().split("\n")
    i = text.index("$Nodes")
    n = int(text[i + 1])
    rows = np.array([text[i + 2 + k].split() for k in range(n)], dtype=float)
    ids = rows[:, 0].astype(np.int64)
    xyz = rows[:, 1:4]
    j = text.index("$Elements")
    m = int(text[j + 1])
    tets = []
    for k in range(m):
        parts = text[j + 2 + k].split()
        if parts[1] == "11":
            ntags = int(parts[2])
            tets.append([int(v) for v in parts[3 + ntags:3 + ntags + 10]])
    lookup = np.full(ids.max() + 1, -1, dtype=np.int64)
    lookup[ids] = np.arange(n)
    tets = lookup[np.array(tets, dtype=np.int64)]
    used = np.unique(tets)
    remap = -np.ones(n, dtype=np.int64)
    remap[used] = np.arange(len(used))
    points, tets = xyz[used], remap[tets]
    return points, to_ccx_order(points, tets)


def to_ccx_order(points, tets):
    """gmsh writes the midside nodes of a 10-node tetrahedron for the edges (0,1), (1,2), (2,0),
    (0,3), (2,3), (1,3); C3D10 wants ..., (1,3), (2,3) (mesh.TET10_EDGES): swap the last two.
    Checked here node by node (each midside node must be the one nearest the middle of its edge),
    and negatively oriented elements, if any, are turned over with their midside nodes."""
    tets = tets[:, [0, 1, 2, 3, 4, 5, 6, 7, 9, 8]].copy()
    a, b, c, d = (points[tets[:, k]] for k in range(4))
    vol = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a)
    flip = vol < 0
    if np.any(flip):
        # swapping corners 1 and 2 swaps the midside nodes of (0,1)<->(2,0) and (1,3)<->(2,3)
        tets[flip] = tets[flip][:, [0, 2, 1, 3, 6, 5, 4, 7, 9, 8]]
    for k, (p, q) in enumerate(mesh.TET10_EDGES):
        mid = 0.5 * (points[tets[:, p]] + points[tets[:, q]])
        length = np.linalg.norm(points[tets[:, p]] - points[tets[:, q]], axis=1)
        off = np.linalg.norm(points[tets[:, 4 + k]] - mid, axis=1)
        if np.any(off > 0.25 * length):
            raise RuntimeError("unexpected gmsh midside-node order")
    return tets


def gmsh_version():
    proc = subprocess.run(["gmsh", "--version"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True)
    return proc.stdout.strip()


def ccx_version():
    proc = subprocess.run(["ccx", "-v"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return " ".join(proc.stdout.split())


def make_mesh(workdir, geo_text):
    """Run gmsh on the .geo text in workdir (once; reused when the .msh is already there)."""
    os.makedirs(workdir, exist_ok=True)
    geo = os.path.join(workdir, "model.geo")
    msh = os.path.join(workdir, "model.msh")
    old = open(geo).read() if os.path.exists(geo) else None
    if old != geo_text or not os.path.exists(msh):
        with open(geo, "w") as f:
            f.write(geo_text)
        with open(os.path.join(workdir, "gmsh.log"), "w") as log:
            subprocess.run(["gmsh", "-3", "-nt", "1", geo, "-o", msh], check=True, stdout=log,
                           stderr=subprocess.STDOUT)
    return read_msh2_tet10(msh)


def node_sets(problem, points):
    """Boundary node sets (0-based ids) of the solved part, picked by coordinates (mm)."""
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    tol = 1e-6
    sets = {"SYMX": np.nonzero(np.abs(x) < tol)[0], "SYMY": np.nonzero(np.abs(y) < tol)[0],
            "BOTTOM": np.nonzero(np.abs(z) < tol)[0]}
    if problem == "bonded_cylinder":
        # mid-height plane of the whole cylinder: uz = -delta/2, ux and uy free (see the docstring)
        sets["DRIVEN"] = np.nonzero(np.abs(z - CYL_HEIGHT_MM / 2) < tol)[0]
        delta = CYL_DELTA_MM / 2
    else:
        top = np.abs(z - BLOCK_HEIGHT_MM) < tol
        p = PUNCH_HALF_MM + tol
        sets["DRIVEN"] = np.nonzero(top & (x <= p) & (y <= p))[0]
        # the punch edges must be mesh lines: corner and midside nodes on x = 5 and on y = 5
        on_edge = top & (((np.abs(x - PUNCH_HALF_MM) < tol) & (y <= p))
                         | ((np.abs(y - PUNCH_HALF_MM) < tol) & (x <= p)))
        if np.count_nonzero(on_edge) < 5:
            raise RuntimeError("the punch edges are not mesh lines")
        delta = PUNCH_DELTA_MM
    return sets, delta


def write_deck(path, points, tets, sets, delta, nu, element_type, driven_xy_fixed):
    out = ["*HEADING", "pliant locking reference (symmetry-reduced model, mm N MPa)", "*NODE, NSET=NALL"]
    out += [f"{i + 1}, {p[0]:.15g}, {p[1]:.15g}, {p[2]:.15g}" for i, p in enumerate(points)]
    out.append(f"*ELEMENT, TYPE={element_type}, ELSET=EALL")
    out += [f"{k + 1}, " + ", ".join(str(int(v) + 1) for v in t) for k, t in enumerate(tets)]
    text = "\n".join(out) + "\n"
    for name in ("BOTTOM", "SYMX", "SYMY", "DRIVEN"):
        text += ccx._nset(name, sets[name])
    # E in MPa (N/mm^2); the density is unused by a static step
    text += ccx.material_cards("M", {"youngs_modulus": YOUNGS_MODULUS_PA * 1e-6,
                                     "poisson_ratio": nu, "density": 1e-9})
    text += "*SOLID SECTION, ELSET=EALL, MATERIAL=M\n"
    text += ("*STEP\n*STATIC\n*BOUNDARY\nBOTTOM, 1, 3, 0.\nSYMX, 1, 1, 0.\nSYMY, 2, 2, 0.\n"
             + ("DRIVEN, 1, 2, 0.\n" if driven_xy_fixed else "")
             + f"DRIVEN, 3, 3, {-delta:.10g}\n"
             "*NODE PRINT, NSET=DRIVEN, TOTALS=ONLY\nRF\n*END STEP\n")
    with open(path, "w") as f:
        f.write(text)


def solve(workdir, problem, h, nu, element_type, fresh):
    """Force (N, whole body, magnitude) of one mesh level and Poisson ratio; cached in workdir."""
    mesh_dir = os.path.join(workdir, f"{problem}_h{h:g}")
    job = f"nu{nu:g}".replace(".", "p") + ("" if element_type == "C3D10" else "_" + element_type)
    result_path = os.path.join(mesh_dir, job + ".json")
    geo = geo_cylinder(h) if problem == "bonded_cylinder" else geo_block(h)
    geo_path = os.path.join(mesh_dir, "model.geo")
    same_geo = os.path.exists(geo_path) and open(geo_path).read() == geo
    if not same_geo and os.path.isdir(mesh_dir):  # results of another geometry: drop them
        for name in os.listdir(mesh_dir):
            if name.endswith(".json"):
                os.remove(os.path.join(mesh_dir, name))
    if not fresh and same_geo and os.path.exists(result_path):
        with open(result_path) as f:
            return json.load(f)
    points, tets = make_mesh(mesh_dir, geo)
    sets, delta = node_sets(problem, points)
    write_deck(os.path.join(mesh_dir, job + ".inp"), points, tets, sets, delta, nu, element_type,
               driven_xy_fixed=(problem == "indented_block"))
    t0 = time.time()
    ccx.run_ccx(mesh_dir, job, timeout=3600)
    seconds = time.time() - t0
    _, _, _, totals = ccx.read_dat_forces(os.path.join(mesh_dir, job + ".dat"), len(sets["DRIVEN"]))
    with open(os.path.join(mesh_dir, job + ".log")) as f:
        warnings = sorted({" ".join(line.split()) for line in f if "WARNING" in line})
    for ext in (".frd", ".inp", ".cvg", ".sta"):  # keep the .dat and the log only
        if os.path.exists(os.path.join(mesh_dir, job + ext)):
            os.remove(os.path.join(mesh_dir, job + ext))
    result = {"element_size_mm": h, "nodes": int(len(points)), "elements": int(len(tets)),
              "quarter_force_z_n": float(totals[-1][2]), "force_n": float(4 * abs(totals[-1][2])),
              "ccx_seconds": round(seconds, 1), "ccx_warnings": warnings,
              "element_type": element_type}
    with open(result_path, "w") as f:
        json.dump(result, f, indent=1)
    return result


def richardson(sizes, forces):
    """Extrapolate from the three finest levels: (value, observed order, note)."""
    (h1, h2, h3), (f1, f2, f3) = sizes[-3:], forces[-3:]
    r12, r23 = h1 / h2, h2 / h3
    d12, d23 = f1 - f2, f2 - f3
    if d12 * d23 <= 0 or abs(d23) >= abs(d12):
        return f3, None, ("three finest not monotone and contracting: the finest value is "
                          "reported, not an extrapolation")
    if abs(r12 - r23) > 1e-9:
        raise ValueError("the three finest sizes must shrink by one ratio")
    p = math.log(d12 / d23) / math.log(r23)
    return f3 - d23 / (r23 ** p - 1.0), p, "Richardson extrapolation from the three finest meshes"


def describe(problem):
    if problem == "bonded_cylinder":
        r, hgt, d = CYL_RADIUS_MM * 1e-3, CYL_HEIGHT_MM * 1e-3, CYL_DELTA_MM * 1e-3
        return {
            "geometry": {"description": "solid circular cylinder, axis z, bottom face z = 0, top face z = height",
                         "diameter_m": 2 * r, "height_m": hgt},
            "boundary_conditions": {
                "description": ("bottom face nodes: ux = uy = uz = 0; top face nodes: ux = uy = 0, "
                                "uz = -displacement (bonded on both faces); curved side free"),
                "top_displacement_m": d, "nominal_strain": d / hgt},
            "output": ("force_n: magnitude of the total z reaction on the top face; "
                       "apparent_modulus_factor = F*H/(E*A*delta), A = pi*r^2 (exact circle), "
                       "from force_extrapolated_n"),
        }
    a, hgt, p, d = BLOCK_HALF_MM * 1e-3, BLOCK_HEIGHT_MM * 1e-3, PUNCH_HALF_MM * 1e-3, PUNCH_DELTA_MM * 1e-3
    return {
        "geometry": {"description": "block x, y in [-half_width, half_width], z in [0, height]",
                     "half_width_m": a, "height_m": hgt},
        "boundary_conditions": {
            "description": ("bottom face nodes (z = 0): ux = uy = uz = 0; bonded rigid square punch: "
                            "every top-face node with |x| <= punch_half_width and |y| <= "
                            "punch_half_width gets ux = uy = 0, uz = -displacement; the rest of "
                            "the top face and the four sides are free. The punch edges are mesh "
                            "lines (exact footprint)."),
            "punch_half_width_m": p, "punch_displacement_m": d},
        "output": "force_n: magnitude of the total z reaction on the punch nodes",
    }


MODEL = {
    "bonded_cylinder": (
        "one eighth solved: quarter x >= 0, y >= 0 (ux = 0 on x = 0, uy = 0 on y = 0), lower half "
        "z in [0, H/2] (exact mid-height symmetry: nodes on z = H/2 get uz = -delta/2, ux and uy "
        "free); force_n is the whole-body force (4 x the z reaction on the mid-height nodes); "
        "nodes and elements count the eighth"),
    "indented_block": (
        "quarter x >= 0, y >= 0 solved (ux = 0 on x = 0, uy = 0 on y = 0); force_n is the "
        "whole-body force (4 x the quarter's); nodes and elements count the quarter"),
}


def build_case(problem, nu, levels):
    sizes = [lv["element_size_mm"] for lv in levels]
    forces = [lv["force_n"] for lv in levels]
    f_ext, order, note = richardson(sizes, forces)
    case = {"problem": problem, **describe(problem), "poisson_ratio": nu,
            "model": MODEL[problem],
            "element": "C3D10 (second-order gmsh mesh), linear static, small strain",
            "meshes": [{"element_size_m": lv["element_size_mm"] * 1e-3, "nodes": lv["nodes"],
                        "elements": lv["elements"], "force_n": round(lv["force_n"], 9),
                        "ccx_seconds": lv["ccx_seconds"]} for lv in levels],
            "force_extrapolated_n": round(f_ext, 9),
            "observed_order": None if order is None else round(order, 4),
            "extrapolation_note": note,
            "finest_two_relative_difference": round((forces[-2] - forces[-1]) / forces[-1], 7)}
    if problem == "bonded_cylinder":
        area = math.pi * (CYL_RADIUS_MM * 1e-3) ** 2
        k = YOUNGS_MODULUS_PA * area * CYL_DELTA_MM * 1e-3 / (CYL_HEIGHT_MM * 1e-3)
        case["apparent_modulus_factor"] = round(f_ext / k, 7)
        case["apparent_modulus_factor_per_mesh"] = [round(f / k, 7) for f in forces]
    if problem == "indented_block":
        case["mesh_grading"] = (f"size field: nominal size h away from the punch edges, "
                                f"{SIZE_MIN_FACTOR:g} h within {GRADE_DIST_MIN_MM:g} mm of them, "
                                f"linear in between up to {GRADE_DIST_MAX_MM:g} mm")
    warnings = sorted({w for lv in levels for w in lv["ccx_warnings"]})
    if warnings:
        case["ccx_warnings"] = warnings
    return case


def markdown_table(data):
    lines = []
    for problem in ("bonded_cylinder", "indented_block"):
        cases = [c for c in data["cases"] if c["problem"] == problem]
        if not cases:
            continue
        sizes = [m["element_size_m"] * 1e3 for m in cases[0]["meshes"]]
        head = ["nu"] + [f"h = {s:g} mm" for s in sizes] + ["extrapolated", "order", "finest two"]
        if problem == "bonded_cylinder":
            head.append("factor")
        lines += [f"{problem} (force in N)", "", "| " + " | ".join(head) + " |",
                  "|" + "---|" * len(head)]
        for c in cases:
            row = [f"{c['poisson_ratio']:g}"] + [f"{m['force_n']:.6f}" for m in c["meshes"]]
            row += [f"{c['force_extrapolated_n']:.6f}",
                    "-" if c["observed_order"] is None else f"{c['observed_order']:.2f}",
                    f"{100 * c['finest_two_relative_difference']:.3f} %"]
            if problem == "bonded_cylinder":
                row.append(f"{c['apparent_modulus_factor']:.5f}")
            lines.append("| " + " | ".join(row) + " |")
        nodes = ", ".join(f"{m['nodes']}/{m['elements']}" for m in cases[0]["meshes"])
        lines += ["", f"solved-model nodes/elements per level: {nodes}", ""]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--workdir", default="/tmp/ccx_locking_references")
    ap.add_argument("--output", default=os.path.join(ROOT, "tests", "host", "data",
                                                     "calculix_locking_references.json"))
    ap.add_argument("--problems", nargs="+", default=["bonded_cylinder", "indented_block"],
                    choices=["bonded_cylinder", "indented_block"])
    ap.add_argument("--poisson", nargs="+", type=float, default=POISSON_RATIOS)
    ap.add_argument("--cylinder-sizes-mm", nargs="+", type=float, default=DEFAULT_CYLINDER_SIZES_MM)
    ap.add_argument("--block-sizes-mm", nargs="+", type=float, default=DEFAULT_BLOCK_SIZES_MM)
    ap.add_argument("--fresh", action="store_true", help="ignore finished runs in the workdir")
    ap.add_argument("--markdown-table", action="store_true",
                    help="only print the convergence table of the existing output JSON")
    args = ap.parse_args()
    if args.markdown_table:
        with open(args.output) as f:
            print(markdown_table(json.load(f)))
        return
    if shutil.which("ccx") is None or shutil.which("gmsh") is None:
        sys.exit("needs ccx and gmsh on PATH")
    t_start = time.time()
    cases = []
    for problem in args.problems:
        sizes = args.cylinder_sizes_mm if problem == "bonded_cylinder" else args.block_sizes_mm
        for nu in args.poisson:
            levels = []
            for h in sizes:
                lv = solve(args.workdir, problem, h, nu, "C3D10", args.fresh)
                print(f"{problem} nu={nu:g} h={h:g} mm: {lv['nodes']} nodes, "
                      f"F = {lv['force_n']:.6f} N ({lv['ccx_seconds']} s)"
                      + (f" WARNINGS {lv['ccx_warnings']}" if lv["ccx_warnings"] else ""), flush=True)
                levels.append(lv)
            cases.append(build_case(problem, nu, levels))
    data = {
        "generator": {"script": "tools/reference/calculix_locking_references.py",
                      "command": "tools/reference/calculix_locking_references.py " + " ".join(sys.argv[1:]),
                      "ccx_version": ccx_version(), "gmsh_version": gmsh_version(),
                      "date": datetime.date.today().isoformat(),
                      "wall_seconds_this_invocation": round(time.time() - t_start, 1),
                      "note": ("wall_seconds_this_invocation covers only runs not reused from the "
                               "workdir; ccx_seconds per mesh is the solve time of that run")},
        "units": "SI: m, N, Pa",
        "youngs_modulus_pa": YOUNGS_MODULUS_PA,
        "cases": cases,
    }
    os.makedirs(os.path.dirname(args.output), exist_ok=True)
    with open(args.output, "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")
    print(markdown_table(data))
    print(f"wrote {args.output} in {time.time() - t_start:.0f} s")


if __name__ == "__main__":
    main()
