#!/usr/bin/python3
"""A depth-world case's true trajectories as a recording (recording-v1), for comparison.

  /usr/bin/python3 tools/depth_world/truth_recording.py CASE OUT

Writes OUT with the case's recording.json, mesh.vtk and wrench.csv and a particles.csv holding
every coarse node at its true position (truth.json) in every frame: what a perfect tracker
would give. `pliant refine OUT` then shows how close the FEM gets without tracking error (the
reference the issue's free-motion target is measured against). The output is derived from
truth.json; it is not an input for a method under test.
"""
import json
import os
import shutil
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "depth_world"))
import depth_world_checks as chk  # noqa: E402


def main():
    case, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(case, "truth.json")) as f:
        truth = json.load(f)
    with open(os.path.join(case, "recording.json")) as f:
        rec = json.load(f)
    rec["files"].pop("depth_frames", None)
    rec["meta"]["source"] = "true trajectories of " + os.path.abspath(case) + " (tools/depth_world/truth_recording.py)"
    with open(os.path.join(out, "recording.json"), "w") as f:
        json.dump(rec, f, indent=1)
        f.write("\n")
    for name in ("mesh.vtk", "wrench.csv"):
        if os.path.exists(os.path.join(case, name)):
            shutil.copy(os.path.join(case, name), os.path.join(out, name))
    rest, _ = chk.read_vtk(os.path.join(case, "mesh.vtk"))
    pos = rest[None] + np.array(truth["displacement_m"])
    with open(os.path.join(out, "particles.csv"), "w") as f:
        f.write("t,id,x,y,z\n")
        for k, t in enumerate(truth["frame_t"]):
            for i, x in enumerate(pos[k]):
                f.write(f"{t:.6f},{i},{x[0]:.9g},{x[1]:.9g},{x[2]:.9g}\n")


if __name__ == "__main__":
    main()
