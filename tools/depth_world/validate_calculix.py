#!/usr/bin/python3
"""CalculiX as the depth world drives it, against a closed-form answer.

A cube (C3D10 from the same gmsh and quadratic-element helpers, *ELASTIC, NLGEOM, the same
*STATIC one-increment-per-step procedure) compressed between frictionless platens: the bottom
face held in z, the faces x = 0 and y = 0 held in x and y (symmetry), the top face moved down by
delta. The stress is uniform, so the platen force is F = E A delta / H (uniaxial compression); at
0.2 % strain the geometric nonlinearity changes it by about 0.2 %. Writes the measured and the
reference force to a JSON file, which tests/depth_world checks.

Usage: /usr/bin/python3 validate_calculix.py OUT.json [--workdir DIR]
"""
import argparse
import json
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scene  # noqa: E402
from scene import ccx, mesh  # noqa: E402


def run(workdir, e=120e3, nu=0.45, side=0.02, strain=0.002):
    shape = {"kind": "box", "size": [side, side, side]}
    p4, t4 = scene.gmsh_tets(shape, None, side / 5)
    pts, t10 = mesh.quadratic(p4, t4)
    pts = pts + np.array([side / 2, side / 2, 0.0])  # corner at the origin
    on = lambda d, v: np.nonzero(np.abs(pts[:, d] - v) < scene.TOL)[0]  # noqa: E731
    delta = strain * side
    text = "*HEADING\npliant depth world: uniaxial check\n" + scene._nodes(pts) + scene._elements(t10)
    text += ccx._nset("BOT", on(2, 0)) + ccx._nset("X0", on(0, 0)) + ccx._nset("Y0", on(1, 0)) + ccx._nset("TOP", on(2, side))
    text += ccx.material_cards("M", {"law": "elastic", "youngs_modulus": e, "poisson_ratio": nu, "density": 1000})
    text += "*SOLID SECTION, ELSET=EALL, MATERIAL=M\n"
    text += "*STEP, NLGEOM\n*STATIC, DIRECT\n0.25, 1.\n*BOUNDARY\nBOT, 3, 3, 0.\nX0, 1, 1, 0.\nY0, 2, 2, 0.\n"
    text += f"TOP, 3, 3, {-delta:.12g}\n*NODE PRINT, NSET=TOP, TOTALS=ONLY\nRF\n*END STEP\n"
    os.makedirs(workdir, exist_ok=True)
    with open(os.path.join(workdir, "job.inp"), "w") as f:
        f.write(text)
    ccx.run_ccx(workdir, "job")
    force = None
    lines = open(os.path.join(workdir, "job.dat")).read().split("\n")
    for i, line in enumerate(lines):
        if line.strip().startswith("total force (fx,fy,fz) for set TOP"):
            force = [ccx.ffloat(v) for v in lines[i + 2].split()[:3]]
    reference = e * side * side * strain
    return {
        "check": "uniaxial compression of a cube between frictionless platens, F = E A delta / H",
        "program": " ".join(l.strip() for l in os.popen("ccx -v 2>&1").read().split("\n") if "Version" in l),
        "element": "C3D10, NLGEOM, *ELASTIC, *STATIC DIRECT (4 increments)",
        "youngs_modulus": e, "poisson_ratio": nu, "side_m": side, "strain": strain,
        "fine_nodes": int(len(pts)), "fine_elements": int(len(t10)),
        "force_z_n": force[2], "reference_n": -reference, "relative_error": abs(-force[2] - reference) / reference,
    }


def main():
    ap = argparse.ArgumentParser(description="Check CalculiX against uniaxial compression.")
    ap.add_argument("out")
    ap.add_argument("--workdir")
    args = ap.parse_args()
    if args.workdir:
        res = run(args.workdir)
    else:
        with tempfile.TemporaryDirectory() as tmp:
            res = run(tmp)
    with open(args.out, "w") as f:
        json.dump(res, f, indent=1, sort_keys=True)
        f.write("\n")
    print(json.dumps(res))


if __name__ == "__main__":
    main()
