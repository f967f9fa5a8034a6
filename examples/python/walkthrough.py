"""A walk through pliant from Python, in cells (`# %%`) that an editor runs one by one.

Run it whole with the build tree's package on the path:
    PYTHONPATH=build/python /usr/bin/python3 examples/python/walkthrough.py
It reads the bundled foam press (examples/foam_press_medium: the optical-flow MSM paper's 4 x 8
particle grid in the image plane, pressed by a tool, true msm_beta 0.5), estimates how soft it
is, diagnoses what the elastic model misses, and replays it through the online estimator a
controller runs during a grasp. Nothing is plotted: every cell prints.
"""

# %% Read a recording: its arrays are NumPy views of the recording in memory.
import tempfile
import warnings
from pathlib import Path

import numpy as np

import pliant

EXAMPLES = Path(__file__).resolve().parents[1]
rec = pliant.read_recording(EXAMPLES / "foam_press_medium")
print(rec)
print("positions", rec.positions.shape, rec.length_unit, "| times", rec.times[0], "to", rec.times[-1], "s")
print("fixed", list(rec.fixed), "| driven", rec.driven)
tool = rec.driven[0]["id"]
print(f"the tool moves particle {tool} by {rec.positions[-1, tool] - rec.positions[0, tool]} {rec.length_unit}")

# %% Estimate msm_beta: the same dict as `pliant estimate REC --json -`.
result = pliant.estimate(rec, quiet=True)
beta, sd = result["parameters"]["msm_beta"], result["uncertainty"]["msm_beta"]
print(f"msm_beta {beta:.3f} +- {sd:.3f} (truth 0.5), msm_alpha {result['parameters']['msm_alpha']:.3f}")
print("model form:", result["model_options"]["baseline_reason"])
curve = np.array(result["curve"]["error"])
print("error curve minimum at msm_beta", result["curve"]["msm_beta"][int(np.argmin(curve))])

# %% The paper's single fit: msm_alpha held at 1, one step per frame, the final state only.
final = pliant.estimate(rec, mode="final", alpha="fixed=1", steps_per_frame=1, cluster_radius=1.5, quiet=True)
print(f"final-state fit: msm_beta {final['parameters']['msm_beta']:.3f}")

# %% Make a recording from arrays: occlude the tool's neighbour for a second, then estimate again.
observed = rec.observed.copy()
observed[30:60, tool - 1] = False
occluded = pliant.make_recording(rec.times, rec.positions, observed=observed, fixed=rec.fixed,
                                 driven=[(d["id"], d["from"], d["to"]) for d in rec.driven],
                                 length_unit=rec.length_unit, name="occluded")
print(f"{(~occluded.observed).sum()} observations removed;",
      f"msm_beta {pliant.estimate(occluded, quiet=True)['parameters']['msm_beta']:.3f}")

# %% Diagnose: does the elastic model explain the recording, or is physics missing?
with tempfile.TemporaryDirectory() as scratch:
    diagnosis = pliant.diagnose(rec, report=Path(scratch) / "report", quiet=True)
    print(diagnosis["verdict"], "|", diagnosis["explanation"])
    print("report written:", (Path(scratch) / "report" / "index.html").is_file())

# %% Simulate a press with a hidden effect and let the diagnosis find it.
press, truth = pliant.simulate("foam_press", beta=0.3, noise=0.005, seed=11, effect="plasticity")
found = pliant.diagnose(press, quiet=True)
print(f"simulated with {truth['effect']} (msm_beta {truth['parameters']['msm_beta']});",
      f"diagnosis: {found['verdict']} ({found['effect']})")

# %% The online estimator, frame by frame, as a controller runs it during the grasp.
online = pliant.OnlineEstimator(rec)
for k in range(1, rec.frame_count):  # frame 0 is the rest shape
    state = online.update(rec.times[k], rec.times[k] - rec.times[k - 1], rec.positions[k])
    if k % 30 == 0 or k == rec.frame_count - 1:
        print(f"t = {rec.times[k]:.2f} s: msm_beta {state['msm_beta']:.3f} +- {state['msm_beta_std']:.3f}",
              f"({state['steps_per_frame']} steps per frame, msm_alpha {state['msm_alpha']:.2f})")

# %% Errors are exceptions with the command line's messages.
try:
    pliant.estimate(rec, grid=2)
except pliant.UsageError as error:
    print("UsageError:", error)
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    pliant.refine(EXAMPLES / "phantom_compression" / "EF30_0T_A5", substeps=8, quiet=True)
print("warnings:", [str(w.message) for w in caught])
