"""CalculiX (ccx) input writer, runner and result readers for the concealed family.

The deck is one step. Quasi-static runs use *STATIC, dynamic ones *DYNAMIC (ccx's implicit
alpha method, Hilber-Hughes-Taylor), both with NLGEOM and fixed increments (DIRECT) of one
camera frame, so every increment is one frame (the wrench stream, at its own rate, is
interpolated from these by the caller). The tool is a prescribed displacement (*BOUNDARY with an *AMPLITUDE) of the driven
nodes; the force the tool applies is the reaction RF summed over them (*NODE PRINT, totals),
read from the .dat file; displacements of a chosen node set come from the .frd file.
"""
import os
import re
import subprocess

import numpy as np


def _fmt_rows(values, per_line=8):
    out = []
    for i in range(0, len(values), per_line):
        out.append(", ".join(f"{v:.10g}" if not isinstance(v, (int, np.integer)) else str(v)
                             for v in values[i:i + per_line]))
    return "\n".join(out)


def _nset(name, ids):
    # ccx node numbers start at 1
    return f"*NSET, NSET={name}\n" + _fmt_rows([int(i) + 1 for i in ids], 16) + "\n"


def _elset(name, ids):
    return f"*ELSET, ELSET={name}\n" + _fmt_rows([int(i) + 1 for i in ids], 16) + "\n"


def material_cards(name, mat):
    """*MATERIAL block. mat['law']: 'elastic' (St. Venant-Kirchhoff under NLGEOM), 'neo_hooke',
    'arruda_boyce', 'yeoh', 'ogden2', optionally with 'plastic' (von Mises, isotropic hardening)."""
    e, nu = mat["youngs_modulus"], mat["poisson_ratio"]
    mu = e / (2 * (1 + nu))
    bulk = e / (3 * (1 - 2 * nu))
    d1 = 2.0 / bulk  # ccx/Abaqus compressibility D1 = 2 / K
    lines = [f"*MATERIAL, NAME={name}", "*DENSITY", f"{mat['density']:.10g}"]
    law = mat.get("law", "elastic")
    if law == "elastic":
        lines += ["*ELASTIC", f"{e:.10g}, {nu:.10g}"]
    elif law == "neo_hooke":
        lines += ["*HYPERELASTIC, NEO HOOKE", f"{mu / 2:.10g}, {d1:.10g}"]
    elif law == "arruda_boyce":
        # mu, locking stretch lambda_m, D: stiffens steeply as the chains approach lambda_m
        lines += ["*HYPERELASTIC, ARRUDA-BOYCE", f"{mu:.10g}, {mat['locking_stretch']:.10g}, {d1:.10g}"]
    elif law == "yeoh":
        # C10 = mu/2, C20, C30 > 0: the strain energy grows with (I1-3)^2, ^3
        c10 = mu / 2
        lines += ["*HYPERELASTIC, YEOH",
                  f"{c10:.10g}, {mat['c20_over_c10'] * c10:.10g}, {mat['c30_over_c10'] * c10:.10g}, "
                  f"{d1:.10g}, 0., 0."]
    elif law == "ogden2":
        # two-term Ogden: a large positive exponent stiffens; shear modulus sum(mu_i) = mu
        a1, a2, share = mat["alpha1"], mat["alpha2"], mat["share2"]
        mu1, mu2 = (1 - share) * mu, share * mu
        lines += ["*HYPERELASTIC, OGDEN, N=2",
                  f"{mu1:.10g}, {a1:.10g}, {mu2:.10g}, {a2:.10g}, {d1:.10g}, 0."]
    else:
        raise ValueError(law)
    if "plastic" in mat:
        lines.append("*PLASTIC")
        for stress, strain in mat["plastic"]:
            lines.append(f"{stress:.10g}, {strain:.10g}")
    return "\n".join(lines) + "\n"


def write_deck(path, run):
    """Write the .inp of one run. `run` holds: points (n,3), tets10 (m,10), materials {name: mat},
    element_material (m names), fixed, driven (node ids), drive (times, values in metres along
    -z), dt (one camera frame), t_end, integrator ('static'|'dynamic'), incrementation
    ('direct' or 'automatic'), damping (alpha, beta) or None, gravity vector or None, output
    nodes, contact (dict) or None."""
    pts, tets = run["points"], run["tets10"]
    out = ["*HEADING", "pliant concealed family: CalculiX run", "*NODE, NSET=NALL"]
    out += [f"{i + 1}, {p[0]:.12g}, {p[1]:.12g}, {p[2]:.12g}" for i, p in enumerate(pts)]
    names = sorted(run["materials"])
    elem_mat = np.asarray(run["element_material"])
    eid = 1
    for name in names:
        sel = np.nonzero(elem_mat == name)[0]
        if len(sel) == 0:
            continue
        out.append(f"*ELEMENT, TYPE=C3D10, ELSET=E_{name}")
        for k in sel:
            out.append(f"{eid}, " + ", ".join(str(int(v) + 1) for v in tets[k]))
            eid += 1
    n_solid_elems = eid - 1
    text = "\n".join(out) + "\n"
    text += _nset("FIXED", run["fixed"]) if len(run["fixed"]) else ""
    text += _nset("DRIVEN", run["driven"])
    text += _nset("OUTN", run["output_nodes"])
    contact = run.get("contact")
    if contact:
        text += contact_model_cards(run, n_solid_elems)
    for name in names:
        if np.any(elem_mat == name):
            text += material_cards("M_" + name, run["materials"][name])
            text += f"*SOLID SECTION, ELSET=E_{name}, MATERIAL=M_{name}\n"
    times, values = run["drive"]
    pairs = []
    for t, v in zip(times, values):
        pairs += [t, v]
    text += "*AMPLITUDE, NAME=DRIVE\n" + _fmt_rows(pairs, 8) + "\n"
    if run.get("gravity") is not None:
        text += "*AMPLITUDE, NAME=ALWAYS\n0., 1., 1000., 1.\n"
    dt, t_end = run["dt"], run["t_end"]
    n_inc = int(round(t_end / dt))
    automatic = run.get("incrementation") == "automatic"
    if automatic:
        # ccx may cut increments back; output only at the camera frames
        text += "*TIME POINTS, NAME=FRAMES\n" + _fmt_rows([dt * (k + 1) for k in range(n_inc)], 8) + "\n"
    text += f"*STEP, NLGEOM, INC={20 * n_inc + 100}\n"
    kind = "*DYNAMIC" if run["integrator"] == "dynamic" else "*STATIC"
    if automatic:
        text += f"{kind}\n{dt:.10g}, {t_end:.10g}, {dt * 1e-4:.10g}, {dt:.10g}\n"
    else:
        text += f"{kind}, DIRECT\n{dt:.10g}, {t_end:.10g}\n"
    if run.get("damping"):
        a, b = run["damping"]
        text += f"*DAMPING, ALPHA={a:.10g}, BETA={b:.10g}\n"
    if len(run["fixed"]):
        text += "*BOUNDARY\nFIXED, 1, 3\n"
    if contact:
        text += contact_step_cards(run)
    text += "*BOUNDARY, AMPLITUDE=DRIVE\nDRIVEN, 1, 2, 0.\nDRIVEN, 3, 3, -1.\n"
    if run.get("gravity") is not None:
        g = np.asarray(run["gravity"], dtype=float)
        mag = float(np.linalg.norm(g))
        text += "*DLOAD, AMPLITUDE=ALWAYS\n"
        for name in names:
            if np.any(elem_mat == name):
                text += f"E_{name}, GRAV, {mag:.10g}, {g[0] / mag:.10g}, {g[1] / mag:.10g}, {g[2] / mag:.10g}\n"
    when = "TIME POINTS=FRAMES" if automatic else "FREQUENCY=1"
    text += f"*NODE FILE, NSET=OUTN, {when}\nU\n"
    when = "TIME POINTS=FRAMES" if automatic else "FREQUENCYF=1"
    text += f"*NODE PRINT, NSET=DRIVEN, TOTALS=YES, {when}\nRF\n"
    text += "*END STEP\n"
    with open(path, "w") as f:
        f.write(text)


def contact_model_cards(run, first_free_element):
    """A rigid table under the object: one layer of 8-node bricks, all nodes pinned, whose top
    face is the master surface; the object's bottom faces are the slave surface. Coulomb friction
    with a penalty stick slope, linear penalty in the normal direction."""
    c = run["contact"]
    lines = ["*NODE, NSET=TABLE"]
    base = len(run["points"])
    x0, x1, y0, y1 = c["extent"]
    z_top, z_bot = 0.0, -c["thickness"]
    corners = [(x0, y0, z_bot), (x1, y0, z_bot), (x1, y1, z_bot), (x0, y1, z_bot),
               (x0, y0, z_top), (x1, y0, z_top), (x1, y1, z_top), (x0, y1, z_top)]
    for k, (x, y, z) in enumerate(corners):
        lines.append(f"{base + k + 1}, {x:.10g}, {y:.10g}, {z:.10g}")
    tid = first_free_element + 1
    lines.append("*ELEMENT, TYPE=C3D8, ELSET=E_TABLE")
    lines.append(f"{tid}, " + ", ".join(str(base + k + 1) for k in range(8)))
    # C3D8 face S2 is the one through nodes 5-8 (the top, z = 0).
    lines.append("*SURFACE, NAME=S_TABLE, TYPE=ELEMENT")
    lines.append(f"{tid}, S2")
    # slave: faces of the object's tetrahedra lying on z = 0 (element-face surface)
    lines.append("*SURFACE, NAME=S_BOTTOM, TYPE=ELEMENT")
    lines += [f"{e + 1}, S{f}" for e, f in c["bottom_faces"]]
    lines.append("*MATERIAL, NAME=M_TABLE\n*ELASTIC\n1e9, 0.3\n*DENSITY\n1000.")
    lines.append("*SOLID SECTION, ELSET=E_TABLE, MATERIAL=M_TABLE")
    lines.append("*SURFACE INTERACTION, NAME=SI_TABLE")
    lines.append("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR")
    lines.append(f"{c['normal_penalty']:.10g}")
    lines.append("*FRICTION")
    lines.append(f"{c['mu']:.10g}, {c['stick_slope']:.10g}")
    lines.append("*CONTACT PAIR, INTERACTION=SI_TABLE, TYPE=SURFACE TO SURFACE")
    lines.append("S_BOTTOM, S_TABLE")
    return "\n".join(lines) + "\n"


def contact_step_cards(run):
    c = run["contact"]
    lines = ["*BOUNDARY", "TABLE, 1, 3"]
    # the object's own rigid-body modes in the table plane: pin x and y of one centre node
    # (symmetric loading: it would not slide anyway) and x of one node on the y axis through it
    for node, dofs in c["anchors"]:
        for d in dofs:
            lines.append(f"{int(node) + 1}, {d}, {d}, 0.")
    return "\n".join(lines) + "\n"


def run_ccx(workdir, jobname, timeout=900):
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1",
               CCX_NPROC_RESULTS="1", NUMBER_OF_CPUS="1")
    proc = subprocess.run(["ccx", "-i", jobname], cwd=workdir, env=env, timeout=timeout,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    log = proc.stdout
    with open(os.path.join(workdir, jobname + ".log"), "w") as f:
        f.write(log)
    if proc.returncode != 0 or "*ERROR" in log or "Job finished" not in log:
        tail = "\n".join(log.strip().split("\n")[-15:])
        raise RuntimeError(f"ccx failed in {workdir}/{jobname}:\n{tail}")


def ffloat(text):
    """A number as ccx prints it; Fortran drops the E of three-digit exponents (1.5-114)."""
    text = text.strip()
    try:
        return float(text)
    except ValueError:
        return float(re.sub(r"(\d)([-+]\d+)$", r"\1E\2", text))


def read_dat_forces(path, driven_count):
    """Per-time reaction forces of the DRIVEN set: times (k,), per-node (k, n, 3) with node
    ids (n,), totals (k, 3)."""
    times, totals, per_node = [], [], []
    node_ids = None
    with open(path) as f:
        lines = f.read().split("\n")
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.strip().startswith("forces (fx,fy,fz) for set DRIVEN"):
            t = float(line.split()[-1])
            i += 2
            ids, vals = [], []
            while i < len(lines) and lines[i].strip():
                parts = lines[i].split()
                ids.append(int(parts[0]) - 1)
                vals.append([ffloat(v) for v in parts[1:4]])
                i += 1
            times.append(t)
            per_node.append(vals)
            node_ids = ids
            continue
        if line.strip().startswith("total force (fx,fy,fz) for set DRIVEN"):
            i += 2
            totals.append([ffloat(v) for v in lines[i].split()[:3]])
        i += 1
    return np.array(times), np.array(node_ids), np.array(per_node), np.array(totals)


def read_frd_displacements(path):
    """Displacement blocks of an ASCII .frd: times (k,), node ids (n,) 0-based, U (k, n, 3)."""
    times, blocks = [], []
    ids = None
    with open(path) as f:
        lines = f.read().split("\n")
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("  100C"):
            t = ffloat(line[12:24])
            if lines[i + 1].startswith(" -4  DISP"):
                i += 2
                while lines[i].startswith(" -5"):
                    i += 1
                node, vals = [], []
                while not lines[i].startswith(" -3"):
                    l = lines[i]
                    node.append(int(l[3:13]))
                    vals.append([ffloat(l[13:25]), ffloat(l[25:37]), ffloat(l[37:49])])
                    i += 1
                times.append(t)
                blocks.append(vals)
                ids = np.array(node) - 1
                continue
        i += 1
    return np.array(times), ids, np.array(blocks)
