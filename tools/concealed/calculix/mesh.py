"""Meshes for the CalculiX concealed family.

Two meshes of one object are made with gmsh: a fine one that CalculiX solves on (its linear
tetrahedra are upgraded here to 10-node quadratic tetrahedra, C3D10) and a coarse linear one
that goes into the recording as mesh.vtk, the mesh a user would hand to `pliant diagnose`.
They share the geometry (including the circle of the indenter on the top face, so both have
nodes on the tool's rim) but nothing else: different node sets, element order and size.
The fine mesh may also be cut along the boundary of a stiffer or softer region (heterogeneity);
the coarse one never is, since the user does not know about the region.
"""
import os
import subprocess
import tempfile

import numpy as np


def _geo_text(shape, tool, lc, region=None):
    """gmsh .geo (OpenCASCADE kernel) for a box [0,W]x[0,D]x[0,H] or a cylinder of radius R
    and height H standing on z = 0 with its axis through (0, 0)."""
    lines = ['SetFactory("OpenCASCADE");']
    if shape["kind"] == "box":
        w, d, h = shape["size"]
        lines.append(f"Box(1) = {{0, 0, 0, {w}, {d}, {h}}};")
    else:
        r, h = shape["radius"], shape["height"]
        lines.append(f"Cylinder(1) = {{0, 0, 0, 0, 0, {h}, {r}}};")
    tools = []
    if tool["kind"] == "indenter":
        cx, cy = tool["center"]
        lines.append(f"Disk(100) = {{{cx}, {cy}, {h}, {tool['radius']}, {tool['radius']}}};")
        tools.append("Surface{100};")
    if region is not None:
        if region["kind"] == "sphere":
            cx, cy, cz = region["center"]
            lines.append(f"Sphere(200) = {{{cx}, {cy}, {cz}, {region['radius']}}};")
        else:  # half space x > x0, intersected with the object by the fragment below
            x0 = region["x0"]
            big = 1.0
            lines.append(f"Box(200) = {{{x0}, -{big / 2}, -{big / 2}, {big}, {big}, {big}}};")
            lines.append("BooleanIntersection(201) = { Volume{200}; Delete; }{ Volume{1}; };")
        tools.append("Volume{%d};" % (200 if region["kind"] == "sphere" else 201))
    if tools:
        lines.append("BooleanFragments{ Volume{1}; Delete; }{ " + " ".join(tools) + " Delete; }")
    lines += mesh_options(lc)
    return "\n".join(lines) + "\n"


def mesh_options(lc):
    """The gmsh settings of every mesh of these scenes: element sizes from lc (m), optimised,
    deterministic (one thread, a fixed seed), written as ASCII .msh version 2.2."""
    return [
        f"Mesh.CharacteristicLengthMax = {lc};",
        f"Mesh.CharacteristicLengthMin = {0.4 * lc};",
        "Mesh.CharacteristicLengthFromCurvature = 0;",
        "Mesh.CharacteristicLengthFromPoints = 0;",
        "Mesh.Optimize = 1;",
        "Mesh.RandomSeed = 1;",
        "General.NumThreads = 1;",
        "Mesh.MshFileVersion = 2.2;",
    ]


def _read_msh2(path):
    """Nodes and 4-node tetrahedra of a gmsh ASCII .msh version 2 file (other elements skipped)."""
    with open(path) as f:
        text = f.read().split("\n")
    i = text.index("$Nodes")
    n = int(text[i + 1])
    ids = np.empty(n, dtype=np.int64)
    xyz = np.empty((n, 3))
    for k in range(n):
        parts = text[i + 2 + k].split()
        ids[k] = int(parts[0])
        xyz[k] = [float(v) for v in parts[1:4]]
    j = text.index("$Elements")
    m = int(text[j + 1])
    tets = []
    for k in range(m):
        parts = text[j + 2 + k].split()
        if parts[1] == "4":
            ntags = int(parts[2])
            tets.append([int(v) for v in parts[3 + ntags:3 + ntags + 4]])
    index = {v: k for k, v in enumerate(ids)}
    tets = np.array([[index[v] for v in t] for t in tets], dtype=np.int64)
    # Keep only nodes that tetrahedra use (gmsh also writes geometry points), renumbered 0..n-1.
    used = np.unique(tets)
    remap = -np.ones(n, dtype=np.int64)
    remap[used] = np.arange(len(used))
    return xyz[used], remap[tets]


def _orient(points, tets):
    """Make every tetrahedron positively oriented (CalculiX and VTK want a right-handed corner order)."""
    a, b, c, d = (points[tets[:, k]] for k in range(4))
    vol = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a)
    flip = vol < 0
    tets = tets.copy()
    tets[flip, 1], tets[flip, 2] = tets[flip, 2], tets[flip, 1].copy()
    return tets


def gmsh_tets(shape, tool, lc, region=None):
    """Linear tetrahedral mesh (points (n,3), tets (m,4)) of the object from gmsh."""
    with tempfile.TemporaryDirectory() as tmp:
        geo = os.path.join(tmp, "object.geo")
        msh = os.path.join(tmp, "object.msh")
        with open(geo, "w") as f:
            f.write(_geo_text(shape, tool, lc, region))
        subprocess.run(["gmsh", "-3", "-nt", "1", geo, "-o", msh], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        points, tets = _read_msh2(msh)
    return points, _orient(points, tets)


# Edges of a tetrahedron in the CalculiX C3D10 order of its midside nodes 5..10:
# (1-2), (2-3), (3-1), (1-4), (2-4), (3-4).
TET10_EDGES = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]


def quadratic(points, tets):
    """10-node tetrahedra with straight edges: one midside node per unique edge."""
    edges = np.sort(np.concatenate([tets[:, [a, b]] for a, b in TET10_EDGES]), axis=1)
    unique, inverse = np.unique(edges, axis=0, return_inverse=True)
    mid = 0.5 * (points[unique[:, 0]] + points[unique[:, 1]])
    all_points = np.vstack([points, mid])
    m = len(tets)
    mid_ids = len(points) + inverse.reshape(6, m).T
    return all_points, np.hstack([tets, mid_ids])


def boundary_faces(tets):
    """Triangles on the boundary (faces used by exactly one tetrahedron), outward-ordered."""
    faces = np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 3, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 1]]])
    key = np.sort(faces, axis=1)
    _, first, counts = np.unique(key, axis=0, return_index=True, return_counts=True)
    return faces[first[counts == 1]]


def node_normals(points, faces):
    """Area-weighted outward normals of boundary nodes (zero for interior nodes)."""
    n = np.zeros_like(points)
    a, b, c = (points[faces[:, k]] for k in range(3))
    fn = np.cross(b - a, c - a)  # twice the area times the unit normal
    for k in range(3):
        np.add.at(n, faces[:, k], fn)
    norm = np.linalg.norm(n, axis=1)
    out = np.zeros_like(n)
    on = norm > 0
    out[on] = n[on] / norm[on, None]
    return out


def write_vtk(path, points, tets):
    """Legacy VTK ASCII unstructured grid of linear tetrahedra (cell type 10), as recording-v1 asks."""
    with open(path, "w") as f:
        f.write("# vtk DataFile Version 3.0\npliant rest mesh (coarse, for the user)\nASCII\n")
        f.write("DATASET UNSTRUCTURED_GRID\n")
        f.write(f"POINTS {len(points)} double\n")
        for p in points:
            f.write(f"{p[0]:.9g} {p[1]:.9g} {p[2]:.9g}\n")
        f.write(f"CELLS {len(tets)} {5 * len(tets)}\n")
        for t in tets:
            f.write(f"4 {t[0]} {t[1]} {t[2]} {t[3]}\n")
        f.write(f"CELL_TYPES {len(tets)}\n")
        f.write("10\n" * len(tets))


def mean_edge_length(points, tets):
    edges = np.sort(np.concatenate([tets[:, [a, b]] for a, b in TET10_EDGES]), axis=1)
    edges = np.unique(edges, axis=0)
    return float(np.mean(np.linalg.norm(points[edges[:, 0]] - points[edges[:, 1]], axis=1)))
