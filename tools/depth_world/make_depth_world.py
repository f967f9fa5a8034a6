#!/usr/bin/python3
"""The depth world: indentation and free-motion cases of CalculiX seen by a simulated depth camera.

  /usr/bin/python3 tools/depth_world/make_depth_world.py --samples examples/depth_world
  /usr/bin/python3 tools/depth_world/make_depth_world.py --family /tmp/depth_world --cases 12 --seed 2026

--samples writes the three committed cases (short, cropped to a window around the object);
--family writes N cases drawn from the ranges below with the given seed (full 640 x 480
frames, longer protocols). A case's CalculiX run is cached in DIR/.calculix_cache (reused when
the same scene is asked for again). One ccx job at a time, one thread (docs/depth_world.md).
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import depth_world  # noqa: E402


def camera(rng, distance, elevation, azimuth, crop):
    f = float(np.round(rng.uniform(525, 580), 1))
    return {"distance": distance, "elevation_deg": elevation, "azimuth_deg": azimuth, "fx": f, "fy": f,
            "cx": float(np.round(319.5 + rng.uniform(-6, 6), 2)), "cy": float(np.round(239.5 + rng.uniform(-6, 6), 2)),
            "crop": crop}


def sensor(rng):
    return {"grazing_limit_deg": float(np.round(rng.uniform(72, 80), 1)),
            "dropout_fraction": float(np.round(rng.uniform(0.01, 0.03), 3))}


def tip_load_for(shape, e, deflection):
    """Lateral load (N, along x) that bends an upright bar of cross-section a (x) by b (y) and
    height L by `deflection` at its top (Euler-Bernoulli, 3 E I d / L^3)."""
    a, b, length = shape["size"]
    return [3 * e * (b * a ** 3 / 12) * deflection / length ** 3, 0.0, 0.0]


def samples():
    rng = np.random.default_rng(18)
    out = []
    out.append({
        "name": "indent_block_round", "kind": "indentation", "seed": 1801,
        "shape": {"kind": "box", "size": [0.05, 0.04, 0.03]},
        "tool": {"footprint": {"kind": "round", "center": [0.004, 0.0], "radius": 0.009},
                 "tilt_deg": 0.0, "tilt_azimuth_deg": 0.0, "length": 0.045, "head_height": 0.005, "shaft_fraction": 0.4},
        "fine_lc": 0.0055, "coarse_lc": 0.009, "frame_rate_hz": 30,
        "material": {"law": "neo_hooke", "youngs_modulus": 60e3, "poisson_ratio": 0.45, "density": 1050},
        "protocol": {"still": 0.2, "press": 0.3, "hold": 0.1, "release": 0.3, "end_hold": 0.0,
                     "depth": 0.006, "release_fraction": 1.0},
        "camera": camera(rng, 0.55, 50, 12, True), "sensor": sensor(rng),
        "wrench": {"rate_hz": 250, "phase": 0.37, "noise_fraction": 0.005, "torque_noise_m": 0.01},
    })
    out.append({
        "name": "indent_cylinder_square_tilted", "kind": "indentation", "seed": 1802,
        "shape": {"kind": "cylinder", "radius": 0.022, "height": 0.025},
        "tool": {"footprint": {"kind": "square", "center": [-0.003, 0.002], "side": 0.014},
                 "tilt_deg": 20.0, "tilt_azimuth_deg": 60.0, "length": 0.045, "head_height": 0.005, "shaft_fraction": 0.4},
        "fine_lc": 0.005, "coarse_lc": 0.008, "frame_rate_hz": 30,
        "material": {"law": "elastic", "youngs_modulus": 250e3, "poisson_ratio": 0.35, "density": 1100},
        "protocol": {"still": 0.2, "press": 0.3, "hold": 0.1, "release": 0.3, "end_hold": 0.0,
                     "depth": 0.004, "release_fraction": 1.0},
        "camera": camera(rng, 0.6, 40, -15, True), "sensor": sensor(rng),
        "wrench": {"rate_hz": 400, "phase": 0.81, "noise_fraction": 0.004, "torque_noise_m": 0.01},
    })
    shape = {"kind": "box", "size": [0.016, 0.016, 0.06]}
    out.append({
        "name": "free_bar", "kind": "free_motion", "seed": 1803, "shape": shape,
        "fine_lc": 0.0045, "coarse_lc": 0.008, "frame_rate_hz": 60, "duration_s": 0.5,
        "material": {"law": "elastic", "youngs_modulus": 100e3, "poisson_ratio": 0.45, "density": 1000},
        "tip_load_n": tip_load_for(shape, 100e3, 0.006), "gravity_m_s2": [0.0, 0.0, -9.81],
        "rayleigh_alpha": 1.0, "rayleigh_beta": 0.0015,
        "camera": dict(camera(rng, 0.5, 45, 0, True), target_height_fraction=0.6), "sensor": sensor(rng),
    })
    return out


def family(seed, n):
    """n cases: about two thirds indentations, the rest free motion, drawn from the stated ranges."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        case_seed = int(rng.integers(1, 2**31))
        r = np.random.default_rng(case_seed)
        e = float(np.round(np.exp(r.uniform(np.log(20e3), np.log(500e3))), -2))
        nu = float(np.round(r.uniform(0.3, 0.49), 3))
        rho = float(np.round(r.uniform(950, 1150), 0))
        law = str(r.choice(["elastic", "neo_hooke"]))
        cam = camera(r, float(np.round(r.uniform(0.4, 1.0), 3)), float(np.round(r.uniform(35, 60), 1)),
                     float(np.round(r.uniform(-30, 30), 1)), False)
        if k % 3 != 2:
            if r.random() < 0.5:
                shape = {"kind": "box", "size": [float(np.round(r.uniform(0.035, 0.06), 4)),
                                                 float(np.round(r.uniform(0.03, 0.05), 4)),
                                                 float(np.round(r.uniform(0.02, 0.035), 4))]}
                half = min(shape["size"][:2]) / 2
                h = shape["size"][2]
            else:
                shape = {"kind": "cylinder", "radius": float(np.round(r.uniform(0.017, 0.028), 4)),
                         "height": float(np.round(r.uniform(0.02, 0.035), 4))}
                half = shape["radius"] / 1.5
                h = shape["height"]
            size = float(np.round(r.uniform(0.3, 0.45) * half, 4))
            # round and square probes alternate, and every other pair of indentations is tilted
            # by 5-25 deg (the draws are made either way, so the other parameters do not move)
            j = k - k // 3
            r.random()
            fp = {"kind": "round", "radius": size} if j % 2 == 0 else {"kind": "square", "side": 2 * size}
            fp["center"] = [float(np.round(v, 4)) for v in r.uniform(-0.25, 0.25, 2) * half]
            r.random()
            tilt = float(np.round(5 + 20 * r.random(), 1)) if j % 4 in (2, 3) else 0.0
            depth_fraction = r.uniform(0.10, 0.25)
            out.append({
                "name": "case_%02d" % k, "kind": "indentation", "seed": case_seed, "shape": shape,
                "tool": {"footprint": fp, "tilt_deg": tilt, "tilt_azimuth_deg": float(np.round(r.uniform(0, 360), 1)),
                         "length": 0.045, "head_height": 0.005, "shaft_fraction": 0.4},
                "fine_lc": float(np.round(max(0.005, h / 5), 4)), "coarse_lc": float(np.round(max(0.0075, h / 3.2), 4)),
                "frame_rate_hz": 30,
                # St. Venant-Kirchhoff collapses in strong compression: deep presses are neo-Hookean
                "material": {"law": law if depth_fraction < 0.15 else "neo_hooke", "youngs_modulus": e,
                             "poisson_ratio": nu, "density": rho},
                # whole frames (30 Hz) in every phase, so that the solved increments are the frames
                "protocol": {"still": 0.3, "press": int(r.integers(12, 22)) / 30, "hold": 0.2,
                             "release": int(r.integers(12, 22)) / 30, "end_hold": 0.1,
                             "depth": float(np.round(depth_fraction * h, 5)), "release_fraction": 1.0},
                "camera": cam, "sensor": sensor(r),
                "wrench": {"rate_hz": float(r.choice([100, 125, 200, 250, 500])), "phase": float(np.round(r.random(), 3)),
                           "noise_fraction": float(np.round(r.uniform(0.003, 0.01), 4)), "torque_noise_m": 0.01},
            })
        else:
            plate = r.random() < 0.5
            a = float(np.round(r.uniform(0.008, 0.012) if plate else r.uniform(0.012, 0.02), 4))
            b = float(np.round(r.uniform(0.03, 0.045), 4)) if plate else a
            length = float(np.round(r.uniform(0.05, 0.08), 4))
            shape = {"kind": "box", "size": [a, b, length]}
            # stiff enough that its own weight is at most a quarter of its buckling load
            # (rho g A L = 7.837 E I / L^2 at buckling): softer thin plates barely swing back
            e = max(e, 80e3, float(np.round(rho * 9.81 * length ** 3 * 12 / (7.837 * a ** 2 * 0.25), -2)))
            out.append({
                "name": "case_%02d" % k, "kind": "free_motion", "seed": case_seed, "shape": shape,
                "fine_lc": float(np.round(max(0.004, a / 2.5), 4)), "coarse_lc": float(np.round(max(0.007, a / 1.5), 4)),
                "frame_rate_hz": float(r.choice([30, 45, 60])), "duration_s": 1.2,
                "material": {"law": law, "youngs_modulus": e, "poisson_ratio": nu, "density": rho},
                "tip_load_n": tip_load_for(shape, e, float(np.round(r.uniform(0.05, 0.12) * length, 4))),
                "gravity_m_s2": [0.0, 0.0, -9.81],
                "rayleigh_alpha": float(np.round(r.uniform(0.3, 3.0), 2)),
                "rayleigh_beta": float(np.round(r.uniform(5e-4, 4e-3), 5)),
                "camera": dict(cam, target_height_fraction=0.6), "sensor": sensor(r),
            })
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--samples", metavar="DIR", help="write the committed samples into DIR")
    g.add_argument("--family", metavar="DIR", help="write a family of --cases cases into DIR")
    ap.add_argument("--cases", type=int, default=12)
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--only", help="comma list of case names to (re)make")
    ap.add_argument("--cache", help="CalculiX result cache (default: DIR/.calculix_cache)")
    args = ap.parse_args()
    root = args.samples or args.family
    specs = samples() if args.samples else family(args.seed, args.cases)
    cache = args.cache or os.path.join(root, ".calculix_cache")
    os.makedirs(cache, exist_ok=True)
    dropped = []
    for spec in specs:
        if args.only and spec["name"] not in args.only.split(","):
            continue
        out = os.path.join(root, spec["name"])
        try:
            truth = depth_world.make_case(spec, out, cache)
        except RuntimeError as err:  # CalculiX did not finish: the case is dropped, never resized
            if args.samples:
                raise
            dropped.append({"name": spec["name"], "reason": str(err).strip().split("\n")[-1]})
            print(f"{spec['name']}: dropped ({dropped[-1]['reason']})", flush=True)
            continue
        print(f"{spec['name']}: {spec['kind']}, E {spec['material']['youngs_modulus']:.0f} Pa, "
              f"{len(truth['frame_t'])} frames, {truth['solver']['coarse_nodes']} coarse / "
              f"{truth['solver']['fine_nodes']} fine nodes", flush=True)
    if dropped:
        with open(os.path.join(root, "dropped.json"), "w") as f:
            json.dump(dropped, f, indent=1)
            f.write("\n")
    with open(os.path.join(root, "specs.json"), "w") as f:
        json.dump(specs, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
