#!/usr/bin/python3
"""Checks of the depth-world samples (examples/depth_world) that can fail; they read only the
committed files (no CalculiX needed).

- pliant's own readers accept every sample: `pliant track-depth` reads the depth list, the PNGs
  and the plan recording (mesh, wrench) and tracks it (PLIANT_EXE; skipped without it);
- frame 0's depth, back-projected with the stated intrinsics and pose, lies on the user mesh's
  surface (moved by the truth's frame-0 displacement) within the stated noise: bias, rms and
  the 99.9th percentile against the noise model;
- where the probe hides the object, the image holds the probe's depth, nearer than the object's;
- the wrench stream agrees with the truth's contact force within the stated force noise;
- the renderer against closed-form depth (a plane and a sphere), CalculiX against uniaxial
  compression (validation.json, written by tools/depth_world/validate_calculix.py), and the
  free-motion sample's vibration against beam theory (frequency) and the Rayleigh damping it was
  given (decay).

Run: /usr/bin/python3 tests/depth_world/test_depth_world.py (ctest depth_world_samples); with
DEPTH_WORLD_DIR=DIR (and PLIANT_EXE), the same checks on a family make_depth_world.py wrote.
"""
import csv
import json
import os
import re
import subprocess
import sys
import tempfile
import unittest

import numpy as np

ROOT = os.environ.get("PLIANT_SOURCE_DIR", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
# DEPTH_WORLD_DIR: run the same checks on a generated family instead of the committed samples
SAMPLES = os.environ.get("DEPTH_WORLD_DIR", os.path.join(ROOT, "examples", "depth_world"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools", "depth_world"))
import depth_world_checks as chk  # noqa: E402
import png16  # noqa: E402

CASES = sorted(d for d in os.listdir(SAMPLES) if os.path.isfile(os.path.join(SAMPLES, d, "truth.json")))


def truth_of(case):
    with open(os.path.join(SAMPLES, case, "truth.json")) as f:
        return json.load(f)


def frame_image(case, k):
    fr = chk.read_frames(os.path.join(SAMPLES, case))[k]
    img = png16.read(os.path.join(SAMPLES, case, fr["file"])).astype(float) * float(fr["depth_scale_m"])
    return img, [float(fr[x]) for x in ("fx", "fy", "cx", "cy")]


def labelled(case, truth, k, edge_px=3):
    """Measured depth, predicted depth, label (0 table, 1 object, 2 probe), expected sigma, an
    'edge_px or more from any edge between surfaces' mask and the three surfaces' depths, for
    the valid pixels of frame k."""
    img, (fx, fy, cx, cy) = frame_image(case, k)
    rows, cols = np.indices(img.shape).reshape(2, -1)
    obj, tool, table = chk.scene_depth(os.path.join(SAMPLES, case), truth, k, rows, cols, fx, fy, cx, cy)
    depths = np.stack([table[0], obj[0], tool[0]])
    cosines = np.stack([table[1], obj[1], tool[1]])
    lab = np.argmin(depths, axis=0)
    pad = np.pad(lab.reshape(img.shape), edge_px, mode="edge")
    win = np.lib.stride_tricks.sliding_window_view(pad, (2 * edge_px + 1, 2 * edge_px + 1))
    interior = (win.max(axis=(2, 3)) == win.min(axis=(2, 3))).ravel()
    valid = img.ravel() > 0
    lab, depths, interior = lab[valid], depths[:, valid], interior[valid]
    pred = depths[lab, np.arange(len(lab))]
    cos = cosines[:, valid][lab, np.arange(len(lab))]
    sigma = chk.expected_sigma(pred, cos, truth["sensor"], fx)
    return img.ravel()[valid], pred, lab, sigma, interior, depths


class Samples(unittest.TestCase):
    def test_three_samples(self):
        if "DEPTH_WORLD_DIR" in os.environ:
            self.skipTest("a generated family")
        kinds = [truth_of(c)["kind"] for c in CASES]
        self.assertEqual(kinds.count("indentation"), 2)
        self.assertEqual(kinds.count("free_motion"), 1)

    def test_pliant_reads_and_tracks_every_sample(self):
        exe = os.environ.get("PLIANT_EXE")
        if not exe:
            self.skipTest("PLIANT_EXE not set")
        for case in CASES:
            d = os.path.join(SAMPLES, case)
            with open(os.path.join(d, "camera_pose.txt")) as f:
                pose = f.read().strip()
            n = len(chk.read_frames(d))
            with tempfile.TemporaryDirectory() as out:
                proc = subprocess.run([exe, "track-depth", d, os.path.join(d, "depth_frames.csv"), "-o", out,
                                       "--camera-pose", pose, "--noise", "0.0015"],
                                      stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
                self.assertEqual(proc.returncode, 0, proc.stdout)
                self.assertIn(f"read {n} frames (pliant record depth_frames.csv)", proc.stdout)
                found = re.search(r"first frame: (\d+) of (\d+) surface particles found", proc.stdout)
                self.assertIsNotNone(found, proc.stdout)
                self.assertGreater(int(found.group(1)), 0, proc.stdout)
                with open(os.path.join(out, "particles.csv")) as f:
                    times = {row["t"] for row in csv.DictReader(f)}
                self.assertEqual(len(times), n)
                # the plan's mesh and wrench went through pliant's recording reader and writer
                self.assertEqual(chk.read_vtk(os.path.join(out, "mesh.vtk"))[0].shape,
                                 chk.read_vtk(os.path.join(d, "mesh.vtk"))[0].shape)
                if os.path.exists(os.path.join(d, "wrench.csv")):
                    w_in = np.loadtxt(os.path.join(d, "wrench.csv"), delimiter=",", skiprows=1)
                    w_out = np.loadtxt(os.path.join(out, "wrench.csv"), delimiter=",", skiprows=1)
                    np.testing.assert_allclose(w_out, w_in, rtol=1e-5, atol=1e-9)

    def test_frame0_lies_on_the_mesh_surface_within_the_noise(self):
        for case in CASES:
            truth = truth_of(case)
            z, pred, lab, sigma, interior, _ = labelled(case, truth, 0)
            for label, name in ((1, "object"), (0, "table")):
                m = interior & (lab == label)
                self.assertGreater(m.sum(), 150, f"{case} {name}")
                r = z[m] - pred[m]
                s = sigma[m]
                # in units of each pixel's stated sd (a few pixels seen almost edge-on, where the
                # stated sd explodes, would otherwise dominate an rms in millimetres)
                zrms = np.sqrt(np.mean((r / s) ** 2))
                rms, expected = np.sqrt(np.mean(r ** 2)), np.sqrt(np.mean(s ** 2))
                print(f"{case}: frame 0 {name}: {m.sum()} px, rms {1e3 * rms:.3f} mm against {1e3 * expected:.3f} mm "
                      f"stated ({zrms:.3f} sd), bias {np.mean(r / s):.3f} sd, p99.9 {np.percentile(np.abs(r / s), 99.9):.2f} sd")
                self.assertLess(abs(np.mean(r / s)), 0.25, f"{case} {name} bias")
                self.assertLess(zrms, 1.2, f"{case} {name} rms")
                self.assertGreater(zrms, 0.8, f"{case} {name} rms")
                self.assertLess(np.percentile(np.abs(r / s), 99.9), 4.5, f"{case} {name} tail")

    def test_deformed_frames_lie_on_the_moved_mesh_within_the_noise(self):
        # the truth's displacements describe what the camera saw: at the deepest press (or, for
        # free motion, a quarter period after the release) the object's depth lies on the user's
        # mesh moved by them; looser than frame 0, since the coarse mesh's flat facets cannot
        # follow the fine mesh's curved dent under the probe's rim
        for case in CASES:
            truth = truth_of(case)
            if truth["kind"] == "indentation":
                k = int(np.argmax(truth["tool"]["travel_m"]))
            else:
                k = int(round(0.25 / 6.0 * truth["spec"]["frame_rate_hz"]))
            z, pred, lab, sigma, interior, _ = labelled(case, truth, k)
            m = interior & (lab == 1)
            r = z[m] - pred[m]
            rn = r / sigma[m]
            rms, expected = np.sqrt(np.mean(r ** 2)), np.sqrt(np.mean(sigma[m] ** 2))
            print(f"{case}: frame {k} object: {m.sum()} px, rms {1e3 * rms:.3f} mm against {1e3 * expected:.3f} mm "
                  f"stated ({np.sqrt(np.mean(rn ** 2)):.3f} sd), bias {np.mean(rn):.3f} sd, "
                  f"p99.9 {np.percentile(np.abs(rn), 99.9):.2f} sd")
            self.assertGreater(m.sum(), 150, case)
            self.assertLess(abs(np.mean(rn)), 0.3, case)
            self.assertLess(np.sqrt(np.mean(rn ** 2)), 1.25, case)
            self.assertLess(np.percentile(np.abs(rn), 99.9), 5, case)

    def test_probe_is_nearer_where_it_hides_the_object(self):
        for case in CASES:
            truth = truth_of(case)
            if truth["kind"] != "indentation":
                continue
            k = int(np.argmax(truth["tool"]["travel_m"]))
            z, pred, lab, sigma, interior, depths = labelled(case, truth, k, edge_px=2)
            # pixels where the probe is clearly (4 sd) in front of the object
            with np.errstate(invalid="ignore"):
                hides = interior & (lab == 2) & np.isfinite(depths[1]) & (depths[1] - depths[2] > 4 * sigma)
            self.assertGreater(hides.sum(), 30, case)
            self.assertTrue(np.all(depths[2][hides] < depths[1][hides]))
            near_probe = np.abs(z[hides] - depths[2][hides]) < 4 * sigma[hides]
            behind = z[hides] < depths[1][hides] - 2 * sigma[hides]
            print(f"{case}: frame {k}: probe over the object at {hides.sum()} px, "
                  f"{100 * near_probe.mean():.1f} % within 4 sd of the probe, {100 * behind.mean():.1f} % nearer than the object")
            self.assertGreater(near_probe.mean(), 0.95, case)
            self.assertGreater(behind.mean(), 0.95, case)

    def test_wrench_agrees_with_the_contact_force(self):
        for case in CASES:
            truth = truth_of(case)
            if truth["kind"] != "indentation":
                continue
            with open(os.path.join(SAMPLES, case, "wrench.csv")) as f:
                w = np.array([[float(v) for v in row.values()] for row in csv.DictReader(f)])
            t, f_meas = w[:, 0], w[:, 1:4]
            tk, fk = np.array(truth["frame_t"]), np.array(truth["contact_force_n"])
            # cubic Hermite with central slopes between the frames
            slope = np.gradient(fk, tk, axis=0)
            i = np.clip(np.searchsorted(tk, t, side="right") - 1, 0, len(tk) - 2)
            h = tk[i + 1] - tk[i]
            s = ((t - tk[i]) / h)[:, None]
            f_true = ((2 * s ** 3 - 3 * s ** 2 + 1) * fk[i] + (s ** 3 - 2 * s ** 2 + s) * h[:, None] * slope[i]
                      + (-2 * s ** 3 + 3 * s ** 2) * fk[i + 1] + (s ** 3 - s ** 2) * h[:, None] * slope[i + 1])
            r = f_meas - f_true
            sd = truth["wrench"]["force_noise_std_n"]
            print(f"{case}: {len(t)} wrench samples, residual sd {r.std():.4f} N against {sd:.4f} N stated, "
                  f"peak {np.abs(fk[:, 2]).max():.2f} N")
            self.assertLess(abs(r.std() / sd - 1), 0.15, case)
            self.assertLess(np.abs(r.mean(axis=0)).max(), 4 * sd / np.sqrt(len(t)), case)
            self.assertGreater(np.abs(fk[:, 2]).max(), 20 * sd, case)


class Generator(unittest.TestCase):
    def test_renderer_against_closed_form_depth(self):
        import render
        R, t = render.look_at([0, 0, 0.02], 0.6, 50, 20)
        cam = render.Camera(560, 560, 321.3, 238.7, 640, 480, R, t)
        n, rad, c = 90, 0.025, np.array([0.01, -0.005, 0.03])
        th, ph = np.meshgrid(np.linspace(0, np.pi, n), np.linspace(0, 2 * np.pi, 2 * n), indexing="ij")
        p = c + rad * np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
        quads = [(p[i, j], p[i + 1, j], p[i + 1, j + 1], p[i, j + 1]) for i in range(n - 1) for j in range(2 * n - 1)]
        tris = np.array([(a, b, cc) for a, b, cc, d in quads] + [(a, cc, d) for a, b, cc, d in quads])
        z, ident, cosang = render.render(cam, tris, (np.zeros(3), np.array([0, 0, 1.0])))
        rays = cam.rays()
        # the plane z = 0 (world): exact
        n_c = R.T @ np.array([0, 0, 1.0])
        zp = (cam.to_camera(np.zeros(3)) @ n_c) / (rays @ n_c)
        m = ident == -1
        self.assertGreater(m.sum(), 100000)
        self.assertLess(np.abs(z[m] - zp[m]).max(), 1e-9)
        # the sphere: within the facets' sagitta along the ray, away from its silhouette
        cc = cam.to_camera(c)
        b, a = rays @ cc, np.einsum("hwc,hwc->hw", rays, rays)
        disc = b * b - a * (cc @ cc - rad ** 2)
        zs = np.where(disc > 0, (b - np.sqrt(np.maximum(disc, 0))) / a, np.inf)
        m = (ident >= 0) & np.isfinite(zs) & (cosang > 0.3)
        sagitta = rad * (1 - np.cos(np.pi / (n - 1)))
        self.assertGreater(m.sum(), 1000)
        err = np.abs(z[m] - zs[m]) * cosang[m]
        print(f"renderer: plane exact to {np.abs(z[ident == -1] - zp[ident == -1]).max():.1e} m; sphere within "
              f"{1e6 * err.max():.1f} um of the closed form along the normal (facet sagitta {1e6 * sagitta:.1f} um)")
        self.assertLess(err.max(), 1.5 * sagitta)
        # the facets are inscribed: every pixel drawn as sphere has a ray that meets the true sphere,
        # and every ray through the sphere's middle (the inscribed polyhedron's) is drawn as sphere
        self.assertFalse(np.any((ident >= 0) & (disc < 0)))
        inner = disc > 0.2 * np.max(disc)
        self.assertTrue(np.all(ident[inner] >= 0))

    def test_calculix_against_uniaxial_compression(self):
        if not os.path.exists(os.path.join(SAMPLES, "validation.json")) and "DEPTH_WORLD_DIR" in os.environ:
            self.skipTest("no validation.json in a generated family")
        with open(os.path.join(SAMPLES, "validation.json")) as f:
            v = json.load(f)
        reference = v["youngs_modulus"] * v["side_m"] ** 2 * v["strain"]
        print(f"CalculiX ({v['program']}): platen force {-v['force_z_n']:.5f} N against E A delta / H = {reference:.5f} N")
        self.assertLess(abs(-v["force_z_n"] / reference - 1), 0.01)

    def test_free_vibration_against_beam_theory_and_the_damping(self):
        for case in CASES:
            truth = truth_of(case)
            if truth["kind"] != "free_motion":
                continue
            spec, par = truth["spec"], truth["parameters"]
            pts, _ = chk.read_vtk(os.path.join(SAMPLES, case, "mesh.vtk"))
            a, b, length = spec["shape"]["size"]
            top = np.abs(pts[:, 2] - length) < 1e-7
            x = np.array(truth["displacement_m"])[:, top, 0].mean(axis=1)
            t = np.array(truth["frame_t"])
            # zero crossings (linear between frames) give the damped period
            s = np.nonzero(np.sign(x[:-1]) != np.sign(x[1:]))[0]
            tc = t[s] - x[s] * (t[s + 1] - t[s]) / (x[s + 1] - x[s])
            self.assertGreaterEqual(len(tc), 4, case)
            period = 2 * np.mean(np.diff(tc))
            e, rho, g = par["youngs_modulus"], par["density"], 9.81
            ei_over_ra = e * a ** 2 / 12 / rho  # E I / (rho A) for bending about y
            f_eb = 1.875104 ** 2 / (2 * np.pi * length ** 2) * np.sqrt(ei_over_ra)
            # own weight along the axis softens it: f^2 ~ f_eb^2 (1 - W / W_cr), W_cr = 7.837 E I / L^2
            w_ratio = rho * g * length ** 3 / (7.837 * e * a ** 2 / 12)
            f_ref = f_eb * np.sqrt(1 - w_ratio)
            f_meas = 1 / period
            # the decay over the record against the Rayleigh damping of the first mode
            omega = 2 * np.pi * f_meas
            zeta = par["rayleigh_alpha"] / (2 * omega) + par["rayleigh_beta"] * omega / 2
            peaks = [np.max(np.abs(x[s[i] + 1:s[i + 1] + 1])) for i in range(len(s) - 1)]
            decay = np.log(peaks[0] / peaks[-1]) / ((len(peaks) - 1) * period / 2)
            print(f"{case}: vibration {f_meas:.3f} Hz against {f_ref:.3f} Hz (Euler-Bernoulli {f_eb:.3f} Hz, "
                  f"own weight {100 * w_ratio:.1f} % of buckling); decay rate {decay:.3f} 1/s against "
                  f"zeta omega = {zeta * omega:.3f} 1/s")
            self.assertLess(abs(f_meas / f_ref - 1), 0.10, case)
            self.assertLess(abs(decay / (zeta * omega) - 1), 0.35, case)


if __name__ == "__main__":
    unittest.main(verbosity=2)
