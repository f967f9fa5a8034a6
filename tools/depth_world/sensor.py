"""What a structured-light depth camera (Kinect v1 class) does to a perfect depth image.

Sources of the numbers:
- Axial and lateral noise: Nguyen, Izadi, Lovell (2012), "Modeling Kinect sensor noise for
  improved 3D reconstruction and tracking", 3DIMPVT. Their fit of the axial standard deviation
  is sigma_z = 0.0012 + 0.0019 (z - 0.4)^2 m for surfaces up to 60 deg from facing the camera,
  plus 0.0001 / sqrt(z) * theta^2 / (pi/2 - theta)^2 beyond; the lateral one (the position of an
  edge in the image) sigma_L = 0.8 + 0.035 theta / (pi/2 - theta) pixels.
- Disparity quantisation: Khoshelham and Elberink (2012), "Accuracy and resolution of Kinect
  depth data for indoor mapping applications", Sensors 12(2): depth is inferred from a disparity
  measured in steps of 1/8 pixel, z = f b / d, so the depth step grows as z^2 / (8 f b).
- The projector sits beside the camera (baseline b, 7.5 cm on the Kinect v1): surfaces the
  camera sees but the projector's pattern cannot reach (the band beside an occluding edge) have
  no depth; so have surfaces seen at grazing angles (the pattern is smeared beyond recognition),
  and a few per cent of pixels at random.

apply() takes the clean render of the camera, the clean render of the projector (from the
camera's position moved by the baseline along its x axis) and a numpy Generator, and returns
the raw 16-bit image in `units_per_metre` (0: no measurement) with the masks it applied.
"""
import numpy as np

DEFAULTS = {
    "model": "Nguyen, Izadi, Lovell 2012 (axial, lateral); Khoshelham, Elberink 2012 (disparity steps)",
    "axial_a_m": 0.0012, "axial_b_m_per_m2": 0.0019, "axial_z0_m": 0.4,
    "axial_angle_coeff_m": 0.0001, "axial_angle_from_deg": 60.0,
    "lateral_px": 0.8, "lateral_angle_coeff_px": 0.035,
    "baseline_m": 0.075, "disparity_step_px": 0.125,
    "grazing_limit_deg": 75.0, "shadow_tolerance_m": 0.002,
    "dropout_fraction": 0.02, "min_range_m": 0.4, "max_range_m": 4.0,
    "units_per_metre": 1000.0,
}


def axial_sigma(z, theta, p):
    """Nguyen et al.'s axial standard deviation (m) at depth z (m) and angle theta (rad)."""
    s = p["axial_a_m"] + p["axial_b_m_per_m2"] * (z - p["axial_z0_m"]) ** 2
    th = np.minimum(theta, np.radians(89.0))
    extra = p["axial_angle_coeff_m"] / np.sqrt(np.maximum(z, 1e-3)) * th ** 2 / (np.pi / 2 - th) ** 2
    return s + np.where(th > np.radians(p["axial_angle_from_deg"]), extra, 0.0)


def lateral_sigma_px(theta, p):
    th = np.minimum(theta, np.radians(89.0))
    return p["lateral_px"] + p["lateral_angle_coeff_px"] * th / (np.pi / 2 - th)


def quantise(z, fx, p):
    """Depth through the sensor's disparity steps: z = f b / d, d rounded to the step."""
    fb = fx * p["baseline_m"]
    d = np.round(fb / z / p["disparity_step_px"]) * p["disparity_step_px"]
    with np.errstate(divide="ignore"):
        return np.where(d > 0, fb / np.maximum(d, 1e-12), np.inf)


def shadow_mask(cam, depth, proj_cam, proj_depth, p):
    """Pixels whose surface point the projector cannot see (something nearer on its ray)."""
    rays = cam.rays()
    valid = np.isfinite(depth)
    pts = rays * np.where(valid, depth, 0.0)[..., None]
    xp = pts - np.array([p["baseline_m"], 0.0, 0.0])
    with np.errstate(divide="ignore", invalid="ignore"):
        up = np.round(proj_cam.fx * xp[..., 0] / xp[..., 2] + proj_cam.cx)
        vp = np.round(proj_cam.fy * xp[..., 1] / xp[..., 2] + proj_cam.cy)
    inside = valid & (up >= 1) & (up < proj_cam.width - 1) & (vp >= 1) & (vp < proj_cam.height - 1)
    # the farthest of the 3 x 3 projector pixels around: no false shadow from the lookup's rounding
    pad = np.pad(proj_depth, 1, constant_values=np.inf)
    h, w = proj_depth.shape
    far = np.max(np.stack([pad[1 + dv:1 + dv + h, 1 + du:1 + du + w] for dv in (-1, 0, 1) for du in (-1, 0, 1)]), axis=0)
    shadow = np.zeros(depth.shape, dtype=bool)
    iu, iv = up[inside].astype(np.int64), vp[inside].astype(np.int64)
    shadow[inside] = xp[..., 2][inside] > far[iv, iu] + p["shadow_tolerance_m"]
    return shadow


def apply(cam, depth, cosang, ident, proj_cam, proj_depth, rng, p):
    """Raw image (uint16) and the masks {'grazing', 'shadow', 'dropout'} (bool, h x w)."""
    h, w = depth.shape
    theta = np.arccos(np.clip(cosang, 0.0, 1.0))
    # lateral noise: each pixel reports the surface a Gaussian pixel offset away (edges jitter)
    sl = lateral_sigma_px(np.where(np.isfinite(depth), theta, 0.0), p)
    du = np.rint(rng.normal(0.0, 1.0, (h, w)) * sl).astype(np.int64)
    dv = np.rint(rng.normal(0.0, 1.0, (h, w)) * sl).astype(np.int64)
    vv, uu = np.meshgrid(np.arange(h), np.arange(w), indexing="ij")
    su, sv = np.clip(uu + du, 0, w - 1), np.clip(vv + dv, 0, h - 1)
    z, th = depth[sv, su], theta[sv, su]
    shadow = shadow_mask(cam, depth, proj_cam, proj_depth, p)[sv, su]
    grazing = np.isfinite(z) & (th > np.radians(p["grazing_limit_deg"]))
    dropout = rng.random((h, w)) < p["dropout_fraction"]
    noise = rng.normal(0.0, 1.0, (h, w))
    valid = np.isfinite(z) & ~shadow & ~grazing & ~dropout
    zn = np.where(valid, z + noise * axial_sigma(np.where(valid, z, 1.0), th, p), np.inf)
    zq = quantise(np.where(valid, zn, 1.0), cam.fx, p)
    zq = np.where(valid & (zq >= p["min_range_m"]) & (zq <= p["max_range_m"]), zq, 0.0)
    raw = np.clip(np.rint(zq * p["units_per_metre"]), 0, 65535).astype(np.uint16)
    return raw, {"grazing": grazing, "shadow": shadow, "dropout": dropout}
