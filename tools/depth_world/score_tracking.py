#!/usr/bin/python3
"""How far a tracked recording of a depth-world case is from the truth.

  /usr/bin/python3 tools/depth_world/score_tracking.py CASE TRACKED

TRACKED is the recording `pliant track-depth CASE CASE/depth_frames.csv -o TRACKED
--camera-pose $(cat CASE/camera_pose.txt)` wrote (particle i is the mesh's node i). Prints, over
the particle-frames the recording holds (fixed and driven ones left out), the rms and the 95th
percentile of the 3D distance to the true position, and the rms of the true motion for scale.
"""
import csv
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "depth_world"))
import depth_world_checks as chk  # noqa: E402


def main():
    case, tracked = sys.argv[1], sys.argv[2]
    with open(os.path.join(case, "truth.json")) as f:
        truth = json.load(f)
    with open(os.path.join(case, "recording.json")) as f:
        plan = json.load(f)
    rest, _ = chk.read_vtk(os.path.join(case, "mesh.vtk"))
    u = np.array(truth["displacement_m"])
    t_index = {round(t, 6): k for k, t in enumerate(truth["frame_t"])}
    held = set(plan["particles"].get("fixed", [])) | set(plan["particles"].get("driven", []))
    err, motion = [], []
    with open(os.path.join(tracked, "particles.csv")) as f:
        for row in csv.DictReader(f):
            i = int(row["id"])
            x = np.array([float(row[c]) for c in "xyz"])
            k = t_index.get(round(float(row["t"]), 6))
            if i in held or k is None or k == 0 or not np.all(np.isfinite(x)):
                continue
            err.append(np.linalg.norm(x - rest[i] - u[k, i]))
            motion.append(np.linalg.norm(u[k, i] - u[0, i]))
    err, motion = np.array(err), np.array(motion)
    print(json.dumps({"particle_frames": int(len(err)), "rms_m": float(np.sqrt(np.mean(err ** 2))),
                      "p95_m": float(np.percentile(err, 95)), "true_motion_rms_m": float(np.sqrt(np.mean(motion ** 2)))}))


if __name__ == "__main__":
    main()
