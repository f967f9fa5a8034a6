#!/usr/bin/python3
"""Makes the "msm-world" concealed family: recordings from tools/concealed/msm_world.py, an MSM
simulator that is not the one `pliant diagnose` fits, varied the way the world varies.

Usage: /usr/bin/python3 tools/concealed/make_msm_world_family.py OUTDIR [--count 36] [--seed 15]
       [--only 3,7,...]   (write only these case numbers, e.g. for a committed sample)
       [--twins DIR]      (also write every effect case's effect-free twin into DIR/case_NN:
                           same scene, same noise draw; it separates what the world's
                           difference from the fitted model costs from what the effect costs)

Every effect case is checked against the same scene without the effect: the change of the
particles' displacements must be at least MIN_SIZE noise standard deviations rms per coordinate
(truth.json effect_size.rms_over_noise). A weaker effect is strengthened, and a scene where even
the strongest setting stays below the floor is thrown away and drawn again.

Deterministic: everything comes from numpy Generators seeded by (--seed, case, attempt).
"""

import argparse
import math
import os
import shutil
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import msm_world as mw  # noqa: E402

MIN_SIZE = 4.0      # floor on effect_size.rms_over_noise
ACCEPT_SIZE = 4.5   # aim a little above it

# Which objects each effect is shown on (every list mixes 2D and 3D).
EFFECT_SHAPES = {
    "plasticity": ["block_2d", "block_3d", "ring_2d", "dome_3d", "strip_2d", "cylinder_3d"],
    "viscosity": ["strip_2d", "dome_3d", "block_2d", "cylinder_3d", "ring_2d", "block_3d"],
    "friction": ["block_2d", "block_3d", "ring_2d", "cylinder_3d", "strip_2d", "dome_3d"],
    "gravity": ["strip_2d", "cylinder_3d", "ring_2d", "dome_3d", "block_2d", "block_3d"],
    "heterogeneity": ["block_2d", "block_3d", "strip_2d", "dome_3d", "ring_2d", "cylinder_3d"],
    "stiffening": ["ring_2d", "block_3d", "block_2d", "cylinder_3d", "strip_2d", "dome_3d"],
    "none": ["block_2d", "block_3d", "strip_2d", "ring_2d", "dome_3d", "cylinder_3d"],
}
RATES_2D = [15, 20, 25, 30, 50, 60, 90, 120]
RATES_3D = [15, 20, 25, 30]
MAX_WORLD_RATE = 240.0  # the world steps at most this often (rate x substeps)


def plan(count, seed):
    """Effect of every case, in shuffled order: about a third with no effect, the rest spread
    evenly over the six effects; each effect cycles through its objects."""
    n_none = max(int(math.ceil(count / 4)), int(round(count / 3)))
    effects = [mw.EFFECTS[i % len(mw.EFFECTS)] for i in range(count - n_none)] + ["none"] * n_none
    used = {e: 0 for e in EFFECT_SHAPES}
    cases = []
    for e in effects:
        shape = EFFECT_SHAPES[e][used[e] % len(EFFECT_SHAPES[e])]
        used[e] += 1
        cases.append((e, shape))
    order = np.random.default_rng(seed).permutation(len(cases))
    return [cases[i] for i in order]


def draw_scene(rng, shape, effect):
    """Everything about a case except the effect's strength."""
    dim = 3 if shape.endswith("3d") else 2
    unit = "px" if shape == "block_2d" and rng.random() < 0.5 else "m"
    if unit == "px":
        spacing = rng.uniform(10, 24)
    else:
        spacing = rng.uniform(0.008, 0.02) if dim == 2 else rng.uniform(0.006, 0.015)
    body = mw.SHAPES[shape](rng, spacing, unit)
    if shape in ("block_2d", "block_3d", "strip_2d", "cylinder_3d") and rng.random() < 0.5:
        rest_jitter = rng.uniform(0.02, 0.06)
    else:
        rest_jitter = 0.0
    body = mw.jitter_rest(body, rng, rest_jitter, spacing)
    spacing = mw.median_neighbour_distance(body["rest"])
    rate = float(rng.choice(RATES_2D if dim == 2 else RATES_3D))
    substeps = int(rng.choice([s for s in (1, 2, 3, 4) if rate * s <= MAX_WORLD_RATE]))
    beta = rng.uniform(0.4, 0.9) if effect == "stiffening" else rng.uniform(0.1, 0.9)
    scene = {
        "shape": shape, "dim": dim, "unit": unit, "spacing": spacing, "body": body,
        "rest_jitter": rest_jitter, "rate": rate, "substeps": substeps,
        "alpha": rng.uniform(0.3, 1.0), "beta": beta,
        "radius_factor": rng.uniform(1.3, 2.2),
        "mass_kind": str(rng.choice(["uniform", "random", "gradient"])),
        "kernel": bool(rng.random() < 0.6),
        "noise_fraction": math.exp(rng.uniform(math.log(0.001), math.log(0.01))),
        "occlusion": rng.uniform(0.03, 0.15) if rng.random() < 0.4 else 0.0,
        "frame_jitter": rng.uniform(0.05, 0.2) if rng.random() < 0.25 else 0.0,
    }
    scene["masses"] = mw.particle_masses(body["rest"], rng, scene["mass_kind"])
    scene["clusters"] = mw.build_clusters(body["rest"], scene["radius_factor"], scene["kernel"])
    scene["protocol"] = mw.make_protocol(rng, body, spacing, 6.0 if dim == 2 else 5.0)
    scene["times"] = mw.frame_times(rng, rate, mw.protocol_duration(scene["protocol"]),
                                    scene["frame_jitter"])
    scene["t_release"] = mw.release_time(scene["protocol"])
    scene["seen"] = mw.occlusion_mask(rng, scene["times"], len(body["rest"]), body["driven"],
                                      scene["t_release"], scene["occlusion"])
    scene["noise_std"] = scene["noise_fraction"] * spacing
    return scene


def lerp(a, b, s):
    return a + (b - a) * s


def draw_effect(rng, scene, effect):
    """The effect's fixed choices (kind, region, direction) and a map intensity s in (0, 1] ->
    parameters, larger s a plainer effect."""
    body, dim = scene["body"], scene["dim"]
    rest = body["rest"]
    if effect == "plasticity":
        max_set = rng.uniform(0.2, 0.5)
        return {}, lambda s: {"yield": lerp(0.08, 0.004, s), "creep": lerp(0.5, 10.0, s), "max": max_set}
    if effect == "viscosity":
        if rng.random() < 0.5:
            return {}, lambda s: {"kind": "strain_rate", "damping": 10 ** lerp(0.3, 2.3, s)}
        tau = rng.uniform(0.3, 1.5)
        return {}, lambda s: {"kind": "relaxation", "fraction": lerp(0.1, 0.8, s), "tau": tau}
    if effect == "friction":
        details = {"support_normal": list(body["support_normal"] / np.linalg.norm(body["support_normal"])),
                   "support_particles": list(body["fixed"])}
        return details, lambda s: {"mu": 10 ** lerp(1.3, -1.5, s)}
    if effect == "gravity":
        tilt = math.radians(rng.uniform(0, 30)) if rng.random() < 0.6 else 0.0
        down = -body["up"] / np.linalg.norm(body["up"])
        side = rng.normal(size=dim)
        side -= (side @ down) * down
        direction = math.cos(tilt) * down + math.sin(tilt) * side / np.linalg.norm(side)
        details = {"direction": list(direction), "tilt_deg": math.degrees(tilt)}
        spacing = scene["spacing"]
        return details, lambda s: {"g": spacing * 10 ** lerp(-1.0, 4.0, s)}
    if effect == "heterogeneity":
        region, particles = draw_region(rng, rest, scene["spacing"], body)
        beta = scene["beta"]
        target = 0.0 if (beta > 0.5 if rng.random() < 0.8 else beta <= 0.5) else 1.0
        details = {"region": region, "region_particles": particles, "region_clusters": particles}
        return details, lambda s: {"region_msm_beta": lerp(beta, target, lerp(0.4, 1.0, s))}
    if effect == "stiffening":
        return {}, lambda s: {"k": 10 ** lerp(0.5, 2.0, s)}
    raise ValueError(effect)


def draw_region(rng, rest, spacing, body):
    """A region of the object: an inclusion (ball), one half, or the top layer(s)."""
    kind = str(rng.choice(["inclusion", "half", "layer"]))
    centre = rest.mean(axis=0)
    if kind == "inclusion":
        candidates = np.where(np.linalg.norm(rest - centre, axis=1) < 0.6 * np.ptp(rest, axis=0).max())[0]
        c = rest[int(rng.choice(candidates))]
        radius = rng.uniform(1.2, 2.2) * spacing
        inside = np.where(np.linalg.norm(rest - c, axis=1) <= radius)[0]
        desc = {"kind": kind, "centre": list(c), "radius": radius}
    elif kind == "half":
        axis = int(rng.integers(0, rest.shape[1]))
        side = 1 if rng.random() < 0.5 else -1
        inside = np.where(side * (rest[:, axis] - centre[axis]) > 0)[0]
        desc = {"kind": kind, "axis": axis, "side": side, "split": float(centre[axis])}
    else:
        up = body["up"] / np.linalg.norm(body["up"])
        height = rest @ up
        cut = np.quantile(height, 0.65)
        inside = np.where(height >= cut)[0]
        desc = {"kind": kind, "above": float(cut)}
    return desc, [int(i) for i in inside]


def make_world(scene, effect=None, params=None, details=None):
    return mw.World(scene["body"], scene["masses"], scene["clusters"], scene["alpha"],
                    scene["beta"], effect, params, details)


def run(scene, effect=None, params=None, details=None):
    world = make_world(scene, effect, params, details)
    settle = 1e-3 * scene["noise_std"] if effect == "gravity" else None
    return mw.simulate(world, scene["protocol"], scene["times"], scene["substeps"], settle)


def effect_details(effect, details, params, scene):
    d = dict(details)
    if effect == "gravity":
        d["gravity_vector"] = list(params["g"] * np.asarray(d["direction"]))
    return d


def strengthen(scene, effect, rng, reference):
    """Find an intensity whose effect clears the floor, aiming at a drawn size (6-60 noise std,
    log-uniform) by bisection on the intensity. Returns (params, details, traj, size) or None."""
    fixed, to_params = draw_effect(rng, scene, effect)
    aim = math.exp(rng.uniform(math.log(6.0), math.log(60.0)))
    lo, hi, s = 0.0, 1.0, 0.5
    best = None
    for _ in range(7):
        params = to_params(s)
        details = effect_details(effect, fixed, params, scene)
        traj = run(scene, effect, params, details)
        if not np.all(np.isfinite(traj)):
            hi = s
            s = 0.5 * (lo + hi)
            continue
        size = mw.effect_size(traj, reference, scene["seen"], scene["body"]["driven"], scene["times"],
                              scene["t_release"], scene["noise_std"])
        ratio = size["rms_over_noise"]
        if ratio >= ACCEPT_SIZE and (best is None or abs(math.log(ratio / aim)) < abs(math.log(best[3]["rms_over_noise"] / aim))):
            best = (params, details, traj, size)
        if ratio >= ACCEPT_SIZE and aim / 2.0 <= ratio <= aim * 2.0:
            break
        if ratio < aim:
            lo = s
        else:
            hi = s
        s = 0.5 * (lo + hi)
    return best


def jsonable(x):
    if isinstance(x, dict):
        return {k: jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, (np.floating, float)):
        return float(x)
    if isinstance(x, (np.integer, int)) and not isinstance(x, bool):
        return int(x)
    return x


def make_case(number, effect, shape, seed):
    for attempt in range(8):
        case_seed = seed * 100003 + number * 101 + attempt
        rng = np.random.default_rng(case_seed)
        scene = draw_scene(rng, shape, effect)
        reference = run(scene)
        if not np.all(np.isfinite(reference)):
            continue
        params, details, traj, size = {}, {}, reference, None
        if effect != "none":
            found = strengthen(scene, effect, rng, reference)
            if found is None:
                continue
            params, details, traj, size = found
        noise = rng.normal(0.0, scene["noise_std"], traj.shape)
        scene["twin"] = reference + noise  # the same scene and noise without the effect
        return scene, params, details, traj, traj + noise, size, case_seed, attempt
    raise RuntimeError(f"case {number}: no {effect} scene on {shape} cleared the floor")


def truth_of(scene, effect, params, details, size, case_seed, attempt):
    body, pr = scene["body"], scene["protocol"]
    missing = int((~scene["seen"]).sum())
    truth = {
        "format": "pliant-truth",
        "version": 1,
        "model": "msm-world",
        "effect": effect,
        "effect_parameters": params,
        "effect_details": details,
        "effect_size": size,
        "parameters": {"msm_alpha": scene["alpha"], "msm_beta": scene["beta"]},
        "steps_per_frame": scene["substeps"],
        "cluster_radius_factor": scene["radius_factor"],
        "rate_hz": scene["rate"],
        "frame_jitter": scene["frame_jitter"],
        "noise_std": scene["noise_std"],
        "noise_fraction_of_spacing": scene["noise_fraction"],
        "occlusion": scene["occlusion"],
        "occluded_observations": missing,
        "spacing": scene["spacing"],
        "rest_jitter": scene["rest_jitter"],
        "masses": scene["mass_kind"],
        "goal_blending": "kernel" if scene["kernel"] else "uniform",
        "scenario": body["name"],
        "length_unit": body["unit"],
        "tool_travel": pr["travel"],
        "tool_direction": list(pr["direction"]),
        "tool_ramp": pr["ramp"],
        "release_s": scene["t_release"],
        "duration_s": float(scene["times"][-1]),
        "seed": case_seed,
        "attempt": attempt,
    }
    if effect == "friction":
        truth["support_particles"] = details["support_particles"]
    if effect == "heterogeneity":
        truth["region_particles"] = details["region_particles"]
    return jsonable(truth)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("outdir")
    ap.add_argument("--count", type=int, default=36)
    ap.add_argument("--seed", type=int, default=15)
    ap.add_argument("--only", default="", help="comma-separated case numbers to write (default all)")
    ap.add_argument("--twins", default="", help="directory for the effect cases' effect-free twins")
    args = ap.parse_args()
    if args.count < 8:
        ap.error("--count must be at least 8")
    only = {int(x) for x in args.only.split(",") if x}
    os.makedirs(args.outdir, exist_ok=True)
    start = time.time()
    cases = plan(args.count, args.seed)
    for number, (effect, shape) in enumerate(cases, start=1):
        if only and number not in only:
            continue
        t0 = time.time()
        scene, params, details, traj, observed, size, case_seed, attempt = make_case(number, effect, shape, args.seed)
        path = os.path.join(args.outdir, f"case_{number:02d}")
        if os.path.isdir(path):
            shutil.rmtree(path)
        mw.write_recording(path, scene["body"], scene["times"], observed, scene["seen"], scene["t_release"])
        mw.write_truth(path, truth_of(scene, effect, params, details, size, case_seed, attempt))
        if args.twins and effect != "none":
            twin = os.path.join(args.twins, f"case_{number:02d}")
            if os.path.isdir(twin):
                shutil.rmtree(twin)
            mw.write_recording(twin, scene["body"], scene["times"], scene["twin"], scene["seen"], scene["t_release"])
            mw.write_truth(twin, truth_of(scene, "none", {}, {}, None, case_seed, attempt))
        # Nothing about the content is printed: the log must not reveal the answers.
        print(f"case_{number:02d} done in {time.time() - t0:5.1f} s", flush=True)
    print(f"wrote {len(only) or len(cases)} cases to {args.outdir} in {time.time() - start:.0f} s")


if __name__ == "__main__":
    main()
