"""The Python call's overhead on `estimate` of the paper's 4 x 8 press (budget: 10 %).

Times pliant.estimate(recording) on examples/foam_press_medium (32 particles, 136 frames, the
recording read once and passed in memory) against the same job called from C++
(estimate_call_bench), in alternating rounds so that both see the same machine load, and prints
the fastest call of each and the overhead. Exit status 1 when the overhead is above the budget
and --enforce is given.

Usage: PYTHONPATH=build/python /usr/bin/python3 bench/python_estimate_overhead.py \
           build/bin/estimate_call_bench [--calls N] [--rounds R] [--enforce]
"""

import argparse
import json
import subprocess
import time
from pathlib import Path

import pliant

BUDGET = 0.10
RECORDING = Path(__file__).resolve().parents[1] / "examples" / "foam_press_medium"


def cpp_calls(bench, calls):
    out = subprocess.run([bench, str(RECORDING), "--calls", str(calls)], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def python_calls(recording, calls):
    seconds, beta = [], None
    for _ in range(calls):
        start = time.perf_counter()
        document = pliant.estimate(recording, quiet=True)
        seconds.append(time.perf_counter() - start)
        beta = document["parameters"]["msm_beta"]
    seconds.sort()
    return {"min_s": seconds[0], "median_s": seconds[len(seconds) // 2], "msm_beta": beta}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("bench", help="the estimate_call_bench program")
    parser.add_argument("--calls", type=int, default=20, help="calls per round and side")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--enforce", action="store_true", help="exit 1 over the budget")
    args = parser.parse_args()

    recording = pliant.read_recording(RECORDING)
    pliant.estimate(recording, quiet=True)  # warm-up: page in the module and the recording
    cpp, python = [], []
    for _ in range(args.rounds):
        cpp.append(cpp_calls(args.bench, args.calls))
        python.append(python_calls(recording, args.calls))
    cpp_min = min(r["min_s"] for r in cpp)
    python_min = min(r["min_s"] for r in python)
    cpp_median = sorted(r["median_s"] for r in cpp)[len(cpp) // 2]
    python_median = sorted(r["median_s"] for r in python)[len(python) // 2]
    overhead = python_min / cpp_min - 1.0
    print(f"estimate of {RECORDING.name} (4 x 8 particles, {recording.frame_count} frames), "
          f"{args.rounds} rounds x {args.calls} calls per side")
    print(f"  C++ call     fastest {cpp_min * 1e3:9.2f} ms   median {cpp_median * 1e3:9.2f} ms   "
          f"msm_beta {cpp[-1]['msm_beta']:.4f}")
    print(f"  Python call  fastest {python_min * 1e3:9.2f} ms   median {python_median * 1e3:9.2f} ms   "
          f"msm_beta {python[-1]['msm_beta']:.4f}")
    print(f"  overhead of the Python call: {overhead * 100:+.2f} % of the fastest C++ call "
          f"(medians: {(python_median / cpp_median - 1.0) * 100:+.2f} %); budget {BUDGET * 100:.0f} %: "
          f"{'within' if overhead <= BUDGET else 'OVER'}")
    return 1 if args.enforce and overhead > BUDGET else 0


if __name__ == "__main__":
    raise SystemExit(main())
