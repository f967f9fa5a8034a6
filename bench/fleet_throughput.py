#!/usr/bin/python3
"""Fleet throughput: recordings per second of `python3 -m pliant.fleet` with 1 and 2 local workers.

Simulates N small presses (2D foam_press, some with a concealed effect) once, then runs the same
batch into a fresh results directory with 1 worker and with 2, and prints for each the cluster's
start-up, the time from the first job submitted to the last row written, recordings per second
over that time, and the speed-up of 2 workers over 1. Reports, does not judge (exit status 0).

    /usr/bin/python3 bench/fleet_throughput.py [--recordings 24] [--jobs diagnose] [--cli build/bin/pliant]

or `cmake --build build --target fleet_throughput` (bench/CMakeLists.txt).
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EFFECTS = ("plasticity", "viscosity", None, None)


def simulate(cli, directory, index, rate):
    command = [cli, "simulate", "foam_press", "-o", directory, "--beta", f"{0.15 + 0.7 * (index % 8) / 7:.3f}",
               "--seed", str(index + 1), "--noise", "0.004", "--rate", rate]
    if EFFECTS[index % len(EFFECTS)] and index % 3 == 0:
        command += ["--effect", EFFECTS[index % len(EFFECTS)]]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)


def run_batch(recordings, out, workers, jobs, cli, env):
    command = [sys.executable, "-m", "pliant.fleet", recordings, "-o", out, "--workers", str(workers), "--jobs", jobs,
               "--cli", cli, "--quiet"]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, env=env)
    with open(os.path.join(out, "summary.json")) as stream:
        return json.load(stream)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--recordings", type=int, default=24, help="how many presses (default 24)")
    parser.add_argument("--jobs", default="diagnose", help="the fleet's --jobs (default diagnose)")
    parser.add_argument("--rate", default="8", help="frames per second of the presses (default 8: 33 frames)")
    parser.add_argument("--cli", default=os.environ.get("PLIANT_CLI", os.path.join(REPO, "build", "bin", "pliant")),
                        help="the pliant program (default $PLIANT_CLI, else build/bin/pliant)")
    args = parser.parse_args()
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [os.environ.get("PLIANT_PYTHONPATH",
                                                                     os.path.join(REPO, "build", "python")),
                                                      os.environ.get("PYTHONPATH")]))
    with tempfile.TemporaryDirectory(prefix="pliant-fleet-bench-") as scratch:
        recordings = os.path.join(scratch, "recordings")
        for index in range(args.recordings):
            simulate(args.cli, os.path.join(recordings, f"press_{index:03d}"), index, args.rate)
        print(f"fleet throughput: {args.recordings} foam_press recordings at {args.rate} Hz, jobs {args.jobs}, "
              f"{os.cpu_count()} cores, {sys.executable}")
        print(f"{'workers':>7}  {'jobs':>5}  {'start-up s':>10}  {'run s':>8}  {'recordings/s':>12}  {'wall s':>8}  "
              f"{'errors':>6}")
        rates = {}
        for workers in (1, 2):
            summary = run_batch(recordings, os.path.join(scratch, f"out_{workers}"), workers, args.jobs, args.cli, env)
            batch = summary["batch"]
            rates[workers] = args.recordings / batch["run_s"]
            print(f"{workers:>7}  {batch['ran']:>5}  {batch['startup_s']:>10.2f}  {batch['run_s']:>8.2f}  "
                  f"{rates[workers]:>12.3f}  {batch['wall_s']:>8.2f}  {summary['errors']:>6}")
        print(f"speed-up of 2 workers over 1: {rates[2] / rates[1]:.2f}x")


if __name__ == "__main__":
    main()
