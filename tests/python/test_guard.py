"""pliant.GraspGuard against the core grasp guard (guard_reference.cpp) on the same scripted grasp."""

import json
import math
import os
import subprocess

import numpy as np

import pliant


def nan_for_none(sample):
    return {key: (math.nan if value is None else value) for key, value in sample.items()}


def reference():
    out = subprocess.run([os.environ["PLIANT_GUARD_REFERENCE"]], capture_output=True, text=True, check=True).stdout
    return json.loads(out)


def test_every_cycle_matches_the_core_guard():
    script = reference()
    rest = np.array(script["rest"]).reshape(-1, 3)
    guard = pliant.GraspGuard(rest, script["axis"], **script["config"])
    verdicts = set()
    for index, cycle in enumerate(script["cycles"]):
        samples = {source: nan_for_none(cycle[source]) for source in ("gripper", "wrench", "deformation", "estimate")
                   if source in cycle}
        if "deformation" in cycle:
            closure = cycle["closure_for_strain"]
            stretch = 1.0 - closure / 0.064
            bulge = 1.0 / math.sqrt(stretch)
            frame = rest * np.array([stretch, bulge, bulge])
            measured = guard.measure_strain(frame)
            assert math.isclose(measured["strain"], samples["deformation"]["strain"], rel_tol=1e-12), index
        if cycle.get("reset"):
            guard.reset()
        output = guard.update(cycle["now"], **samples)
        expected = cycle["output"]
        for key, value in expected.items():
            got = output[key]
            if value is None:
                assert not math.isfinite(got), (index, key, got)
            elif isinstance(value, float):
                assert math.isclose(got, value, rel_tol=1e-12, abs_tol=1e-15), (index, key, got, value)
            else:
                assert got == value, (index, key, got, value)
        verdicts.add(output["verdict"])
    assert {"ok", "stop"} <= verdicts  # the script reaches both: a NaN force and a bus-off stop
    assert any(c.get("reset") for c in script["cycles"])
