#!/usr/bin/python3
"""The tracked-video chain on presses pliant did not simulate and did not render.

Issue 15 asks that `pliant track` followed by `pliant estimate` recover msm_beta within 0.03 on
rendered presses across msm_beta 0.2-0.8, with msm_alpha 0.3-1 and 1-4 MSM steps per frame.
Our own check (tests/vision/webcam/webcam_truth_test.cpp) renders presses simulated by pliant's
core with msm_alpha 1 and one step per frame, with its own renderer. This script replaces both:

- the press is simulated by msm-world (tools/concealed/msm_world.py, an MSM written apart from
  pliant's core): a 4 x 8 particle block on a table in the image plane, 40 px apart, pressed
  from above by a tool on one top particle (tilted up to 15 deg, cosine or linear ramp, held,
  released in most cases), msm_alpha 0.3-1 and 1-4 steps per frame drawn per case, cluster
  radius 1.5 and equal masses (the other ways the world differs are the msm-world family's);
- the frames are rendered here, in numpy, differently from our renderer: the object's texture
  is band-limited noise (random phases, wavelengths 7-40 px, made by FFT) sampled bilinearly,
  the displacement field is the bilinear interpolation of the particles' displacements over the
  lattice cells (our renderer uses Catmull-Rom splines and a sum of sinusoids), each pixel x
  shows the texture at the rest point u with u + D(u) = x (fixed-point iteration), the object
  covers half a spacing around its particles, and the background is a second, static texture;
  grey noise of 1.5 levels sd, 8-bit, 640 x 480 PNG frames at 30 frames/s.

Then, as a user would: `pliant track FRAMES --roi (the object's rest rectangle) --grid 4x8
--fps 30` and `pliant estimate` with default options on the tracked recording, and msm_beta is
compared with the truth. For each case the simulated trajectory itself is also estimated (0.05
px noise, every particle seen: what `estimate` finds without the camera), and the tracking error
(rms distance of tracked from simulated particles) is printed, so a miss can be put on the
camera chain or on the estimator. Prints one line per case and the summaries (cases within 0.03,
median and largest error). Always exits 0.

    /usr/bin/python3 tools/concealed/rendered_press_chain.py build/bin/pliant /tmp/rendered_chain
    options: --count N (default 8) --seed S (default 5) --keep (keep the frames)
             --support SPEC (passed to pliant track; default auto)

Needs numpy (Debian python3-numpy). One to three minutes per case on the shared 2-core machine.
"""
import argparse
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import time
import zlib

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import msm_world as mw  # noqa: E402

WIDTH, HEIGHT = 640, 480
SPACING = 40.0
ROWS, COLS = 4, 8
RATE = 30.0
GREY_NOISE = 1.5


def write_png(path, grey):
    """An 8-bit greyscale PNG (no filtering), written with zlib only."""
    h, w = grey.shape
    raw = b"".join(b"\x00" + grey[r].tobytes() for r in range(h))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 6)))
        f.write(chunk(b"IEND", b""))


def band_limited_texture(rng, shape, shortest, longest):
    """Noise with random phases and a flat spectrum between two wavelengths (px), grey 30-225."""
    h, w = shape
    fy = np.fft.fftfreq(h)[:, None]
    fx = np.fft.rfftfreq(w)[None, :]
    f = np.hypot(fx, fy)
    band = (f >= 1.0 / longest) & (f <= 1.0 / shortest)
    spectrum = band * np.exp(2j * math.pi * rng.random(f.shape))
    tex = np.fft.irfft2(spectrum, s=shape)
    tex = (tex - tex.mean()) / tex.std()
    return np.clip(127.5 + 40.0 * tex, 30, 225)


def bilinear(image, x, y):
    """Image sampled at real pixel coordinates (x right, y down), clamped at the border."""
    h, w = image.shape
    x = np.clip(x, 0, w - 1.001)
    y = np.clip(y, 0, h - 1.001)
    x0 = np.floor(x).astype(int)
    y0 = np.floor(y).astype(int)
    sx, sy = x - x0, y - y0
    top = image[y0, x0] * (1 - sx) + image[y0, x0 + 1] * sx
    bottom = image[y0 + 1, x0] * (1 - sx) + image[y0 + 1, x0 + 1] * sx
    return top * (1 - sy) + bottom * sy


class PressRenderer:
    """Renders the block at one frame's particle positions (rows x cols lattice, row 0 at the
    bottom of the object, in image pixels)."""

    def __init__(self, rest, rng):
        self.rest = rest.reshape(ROWS, COLS, 2)
        self.x_min = self.rest[..., 0].min()
        self.y_top = self.rest[..., 1].min()  # image y grows downward: the top row has the smallest y
        self.object_texture = band_limited_texture(rng, (HEIGHT, WIDTH), 7.0, 40.0)
        self.background = 0.6 * band_limited_texture(rng, (HEIGHT, WIDTH), 10.0, 60.0) + 40.0
        ys, xs = np.mgrid[0:HEIGHT, 0:WIDTH]
        self.px = xs.astype(float)
        self.py = ys.astype(float)

    def displacement(self, disp, u, v):
        """Bilinear interpolation of the lattice displacements at rest points (u, v); held
        constant beyond the outer particles."""
        c = np.clip((u - self.x_min) / SPACING, 0, COLS - 1.0001)
        r = np.clip((v - self.y_top) / SPACING, 0, ROWS - 1.0001)  # lattice row 0 = top row here
        c0 = np.floor(c).astype(int)
        r0 = np.floor(r).astype(int)
        sc, sr = (c - c0)[..., None], (r - r0)[..., None]
        d = disp[::-1]  # rows from the top of the image down
        return ((d[r0, c0] * (1 - sc) + d[r0, c0 + 1] * sc) * (1 - sr)
                + (d[r0 + 1, c0] * (1 - sc) + d[r0 + 1, c0 + 1] * sc) * sr)

    def render(self, positions, rng):
        disp = positions.reshape(ROWS, COLS, 2) - self.rest
        half = 0.5 * SPACING
        # Only pixels the object can cover are mapped back (its rest box grown by the largest
        # displacement); the rest of the frame is background.
        reach = half + np.abs(disp).max() + 2.0
        x_lo, x_hi = self.x_min - reach, self.x_min + (COLS - 1) * SPACING + reach
        y_lo, y_hi = self.y_top - reach, self.y_top + (ROWS - 1) * SPACING + reach
        c0, c1 = max(0, int(x_lo)), min(WIDTH, int(x_hi) + 2)
        r0, r1 = max(0, int(y_lo)), min(HEIGHT, int(y_hi) + 2)
        px, py = self.px[r0:r1, c0:c1], self.py[r0:r1, c0:c1]
        u, v = px.copy(), py.copy()
        for _ in range(12):  # u = x - D(u)
            d = self.displacement(disp, u, v)
            u, v = px - d[..., 0], py - d[..., 1]
        inside = ((u >= self.x_min - half) & (u <= self.x_min + (COLS - 1) * SPACING + half)
                  & (v >= self.y_top - half) & (v <= self.y_top + (ROWS - 1) * SPACING + half))
        image = self.background.copy()
        image[r0:r1, c0:c1] = np.where(inside, bilinear(self.object_texture, u, v), image[r0:r1, c0:c1])
        image = image + rng.normal(0.0, GREY_NOISE, image.shape)
        return np.clip(np.rint(image), 0, 255).astype(np.uint8)


def make_case(seed):
    rng = np.random.default_rng(seed)
    pts = [(c * SPACING, r * SPACING) for r in range(ROWS) for c in range(COLS)]
    rest = np.column_stack([120 + np.array(pts)[:, 0], 330 - np.array(pts)[:, 1]])
    up = np.array([0.0, -1.0])
    top = [i for i in range(len(pts)) if i // COLS == ROWS - 1]
    body = mw._body("block_2d", rest, range(COLS), top[len(top) // 2], up, -up, "px",
                    "2D block on a table in the image plane, pressed from above")
    beta = float(rng.uniform(0.2, 0.8))
    alpha = float(rng.uniform(0.3, 1.0))
    steps = int(rng.integers(1, 5))
    clusters = mw.build_clusters(body["rest"], 1.5, False)
    world = mw.World(body, np.ones(len(rest)), clusters, alpha, beta)
    protocol = mw.make_protocol(rng, body, SPACING, 4.0)
    protocol["travel"] = float(rng.uniform(0.4, 0.9)) * SPACING  # the paper's press: 0.6 spacing
    duration = mw.protocol_duration(protocol)
    times = np.arange(int(round(duration * RATE)) + 1) / RATE
    frames = mw.simulate(world, protocol, times, steps)
    truth = {"msm_beta": beta, "msm_alpha": alpha, "steps_per_frame": steps, "cluster_radius": 1.5,
             "frames": len(times), "rate_hz": RATE, "travel_px": float(protocol["travel"]),
             "release": bool(protocol["release"]), "seed": seed}
    return body, times, frames, truth, rng


def write_simulated(path, body, times, frames, rng):
    """The simulated trajectory itself as a recording (0.05 px noise, every particle seen): what
    `pliant estimate` finds without the camera."""
    seen = np.ones(frames.shape[:2], dtype=bool)
    observed = frames + rng.normal(0.0, 0.05, frames.shape)
    mw.write_recording(path, body, times, observed, seen, None)


def tracking_error_px(tracked_csv, frames):
    """Rms distance of the tracked particles from the simulated ones (tracker ids run row by row
    from the top of the image; msm-world's from the bottom)."""
    data = np.genfromtxt(tracked_csv, delimiter=",", names=True)
    times = np.unique(data["t"])
    sq = []
    for row in data:
        f = int(np.searchsorted(times, row["t"]))
        tid = int(row["id"])
        body_id = (ROWS - 1 - tid // COLS) * COLS + tid % COLS
        if f < len(frames):
            sq.append(np.sum((frames[f, body_id] - np.array([row["x"], row["y"]])) ** 2))
    return float(np.sqrt(np.mean(sq))) if sq else float("nan")


def estimated(pliant, recording):
    code, log = run([pliant, "estimate", recording, "--json", "-"])
    if code != 0:
        return float("nan"), float("nan"), f"estimate failed ({code}): {log[-400:]}"
    params = json.loads(log[log.find("{"):]).get("parameters", {})
    return float(params.get("msm_beta", float("nan"))), float(params.get("msm_alpha", float("nan"))), ""


def run(cmd):
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return proc.returncode, proc.stdout


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("pliant")
    ap.add_argument("out")
    ap.add_argument("--count", type=int, default=8)
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--support", default="auto", help="pliant track --support (default auto, as a user would)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    errors, sim_errors = [], []
    print(f"{'case':>4} {'beta':>6} {'alpha':>6} {'steps':>5} {'sim_err':>9} {'track_px':>8} {'estimate':>9} "
          f"{'alpha_est':>9} {'error':>7} {'seconds':>7}  support")
    for k in range(args.count):
        t0 = time.time()
        body, times, frames, truth, rng = make_case(args.seed * 1000 + k)
        case = os.path.join(args.out, f"case_{k + 1:02d}")
        shutil.rmtree(case, ignore_errors=True)
        os.makedirs(os.path.join(case, "frames"))
        renderer = PressRenderer(body["rest"], rng)
        for f, positions in enumerate(frames):
            write_png(os.path.join(case, "frames", f"f_{f:04d}.png"), renderer.render(positions, rng))
        with open(os.path.join(case, "truth.json"), "w") as fh:
            json.dump(truth, fh, indent=1)
        x0 = body["rest"][:, 0].min() - SPACING / 2
        y0 = body["rest"][:, 1].min() - SPACING / 2
        roi = f"{x0:.0f},{y0:.0f},{COLS * SPACING:.0f},{ROWS * SPACING:.0f}"
        simulated = os.path.join(case, "simulated")
        write_simulated(simulated, body, times, frames, rng)
        sim_beta, _, note = estimated(args.pliant, simulated)
        tracked = os.path.join(case, "tracked")
        code, log = run([args.pliant, "track", os.path.join(case, "frames", "f_%04d.png"), "--roi", roi,
                         "--grid", f"{ROWS}x{COLS}", "--fps", str(RATE), "--support", args.support, "-q",
                         "-o", tracked])
        estimate, alpha_est, track_rms = float("nan"), float("nan"), float("nan")
        if code == 0:
            estimate, alpha_est, note = estimated(args.pliant, tracked)
            track_rms = tracking_error_px(os.path.join(tracked, "particles.csv"), frames)
            support = json.load(open(os.path.join(tracked, "recording.json")))["meta"]["track"]["support"]
        else:
            note, support = f"track failed ({code}): {log[-400:]}", "-"
        error = estimate - truth["msm_beta"]
        errors.append(error)
        sim_errors.append(sim_beta - truth["msm_beta"])
        print(f"{k + 1:>4} {truth['msm_beta']:6.3f} {truth['msm_alpha']:6.3f} {truth['steps_per_frame']:5d} "
              f"{sim_beta - truth['msm_beta']:+9.4f} {track_rms:8.3f} {estimate:9.4f} {alpha_est:9.3f} {error:+7.4f} "
              f"{time.time() - t0:7.1f}  {support} {note}", flush=True)
        if not args.keep:
            shutil.rmtree(os.path.join(case, "frames"), ignore_errors=True)
    s = np.abs(np.array(sim_errors))
    print(f"estimate on the simulated trajectories: within 0.03: {int((s <= 0.03).sum())} of {len(s)}; "
          f"largest {np.nanmax(s):.4f}")
    e = np.abs(np.array(errors))
    finite = e[np.isfinite(e)]
    print(f"track then estimate: within 0.03: {int((finite <= 0.03).sum())} of {len(e)}; median |error| "
          f"{np.median(finite) if len(finite) else float('nan'):.4f}; largest {finite.max() if len(finite) else float('nan'):.4f}")


if __name__ == "__main__":
    main()
