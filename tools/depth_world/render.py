"""Depth by z-buffer: triangles and one plane seen by a pinhole camera.

Camera frame as pliant's depth front end uses it (docs/vision_depth.md): x right, y down,
z forward; integer pixel coordinates are pixel centres; a pixel's depth is the z of the nearest
surface along the ray through its centre, ((u - cx) / fx, (v - cy) / fy, 1). Triangles are
rasterised in groups of similar screen size, all candidate pixels of a group at once; the depth
of a pixel inside a triangle is the exact intersection of its ray with the triangle's plane.
"""
import numpy as np


class Camera:
    """Pinhole intrinsics (px) and the pose x_world = R x_camera + t."""

    def __init__(self, fx, fy, cx, cy, width, height, rotation, position):
        self.fx, self.fy, self.cx, self.cy = float(fx), float(fy), float(cx), float(cy)
        self.width, self.height = int(width), int(height)
        self.R, self.t = np.asarray(rotation, dtype=float), np.asarray(position, dtype=float)

    def to_camera(self, x_world):
        return (np.asarray(x_world) - self.t) @ self.R

    def rays(self):
        u, v = np.meshgrid(np.arange(self.width), np.arange(self.height))
        return np.stack([(u - self.cx) / self.fx, (v - self.cy) / self.fy, np.ones(u.shape)], axis=-1)

    def shifted(self, offset_camera, pad=0):
        """The same intrinsics at a position moved by offset_camera (in this camera's axes), on a
        canvas enlarged by pad pixels on every side (the projector of a structured-light sensor)."""
        return Camera(self.fx, self.fy, self.cx + pad, self.cy + pad, self.width + 2 * pad, self.height + 2 * pad,
                      self.R, self.t + self.R @ np.asarray(offset_camera, dtype=float))


def look_at(target, distance, elevation_deg, azimuth_deg):
    """Rotation and position of a camera `distance` from target, `elevation_deg` above the
    horizontal, on the -y side for azimuth 0 (positive azimuth swings it toward +x), image up
    toward +z."""
    el, az = np.radians(elevation_deg), np.radians(azimuth_deg)
    pos = np.asarray(target, dtype=float) + distance * np.array(
        [np.cos(el) * np.sin(az), -np.cos(el) * np.cos(az), np.sin(el)])
    z = np.asarray(target, dtype=float) - pos
    z /= np.linalg.norm(z)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.stack([x, y, z], axis=1), pos


def quaternion(R):
    """(qx, qy, qz, qw) of a rotation matrix, qw >= 0."""
    m = R
    tr = np.trace(m)
    if tr > 0:
        s = 2 * np.sqrt(tr + 1)
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4]
    else:
        i = int(np.argmax(np.diag(m)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2 * np.sqrt(1 + m[i, i] - m[j, j] - m[k, k])
        q = [0.0, 0.0, 0.0, (m[k, j] - m[j, k]) / s]
        q[i], q[j], q[k] = s / 4, (m[j, i] + m[i, j]) / s, (m[k, i] + m[i, k]) / s
    q = np.array(q)
    return q if q[3] >= 0 else -q


def _candidates(cam, tri, size):
    """Pixels covered by triangles (k, 3, 3) in camera coordinates, all with screen boxes of at
    most size x size: pixel index, depth and triangle id of each covered pixel."""
    z = tri[:, :, 2]
    u = cam.fx * tri[:, :, 0] / z + cam.cx
    v = cam.fy * tri[:, :, 1] / z + cam.cy
    u0 = np.clip(np.ceil(u.min(axis=1)), 0, cam.width - 1).astype(np.int64)
    v0 = np.clip(np.ceil(v.min(axis=1)), 0, cam.height - 1).astype(np.int64)
    u1 = np.minimum(np.floor(u.max(axis=1)), cam.width - 1).astype(np.int64)
    v1 = np.minimum(np.floor(v.max(axis=1)), cam.height - 1).astype(np.int64)
    ou, ov = np.meshgrid(np.arange(size), np.arange(size))
    pu = u0[:, None] + ou.ravel()[None, :]
    pv = v0[:, None] + ov.ravel()[None, :]
    keep = (pu <= u1[:, None]) & (pv <= v1[:, None])
    # edge functions in the image: inside when all three have one sign (zero counts as inside)
    e = []
    for a, b in ((0, 1), (1, 2), (2, 0)):
        e.append((u[:, b, None] - u[:, a, None]) * (pv - v[:, a, None]) - (v[:, b, None] - v[:, a, None]) * (pu - u[:, a, None]))
    e = np.stack(e)
    keep &= np.all(e >= 0, axis=0) | np.all(e <= 0, axis=0)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    rx, ry = (pu - cam.cx) / cam.fx, (pv - cam.cy) / cam.fy
    den = n[:, 0, None] * rx + n[:, 1, None] * ry + n[:, 2, None]
    num = np.einsum("ij,ij->i", n, tri[:, 0])[:, None]
    ok = keep & (np.abs(den) > 1e-12 * np.linalg.norm(n, axis=1)[:, None])
    depth = np.where(ok, num / np.where(ok, den, 1.0), np.inf)
    ok &= depth > 0
    ids = np.broadcast_to(np.arange(len(tri))[:, None], pu.shape)
    return (pv * cam.width + pu)[ok], depth[ok], ids[ok]


def render(cam, triangles, plane=None, near=0.05):
    """Depth (h, w; inf where nothing), id of the nearest triangle (-1: the plane, -2: nothing)
    and the cosine between the surface normal and the ray at every pixel.
    triangles: (m, 3, 3) in world coordinates; plane: (point, normal) in world coordinates."""
    tri = cam.to_camera(triangles.reshape(-1, 3)).reshape(-1, 3, 3)
    front = np.all(tri[:, :, 2] > near, axis=1)
    zbuf = np.full(cam.width * cam.height, np.inf)
    ident = np.full(cam.width * cam.height, -2, dtype=np.int64)
    if front.any():
        ids_all = np.nonzero(front)[0]
        t = tri[front]
        z = t[:, :, 2]
        u = cam.fx * t[:, :, 0] / z
        v = cam.fy * t[:, :, 1] / z
        extent = np.maximum(u.max(1) - u.min(1), v.max(1) - v.min(1)) + 2
        idx_parts, z_parts, id_parts = [], [], []
        lo = 0.0
        size = 4
        while lo < extent.max():
            sel = np.nonzero((extent > lo) & (extent <= size))[0]
            chunk = max(1, 2_000_000 // (size * size))
            for s in range(0, len(sel), chunk):
                part = sel[s:s + chunk]
                i, d, k = _candidates(cam, t[part], size)
                idx_parts.append(i)
                z_parts.append(d)
                id_parts.append(ids_all[part][k])
            lo, size = size, 2 * size
        idx, depth, tid = np.concatenate(idx_parts), np.concatenate(z_parts), np.concatenate(id_parts)
        order = np.lexsort((depth, idx))
        idx, depth, tid = idx[order], depth[order], tid[order]
        first = np.ones(len(idx), dtype=bool)
        first[1:] = idx[1:] != idx[:-1]
        zbuf[idx[first]] = depth[first]
        ident[idx[first]] = tid[first]
    zbuf, ident = zbuf.reshape(cam.height, cam.width), ident.reshape(cam.height, cam.width)
    rays = cam.rays()
    normals = np.zeros((cam.height, cam.width, 3))
    tn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    tn /= np.maximum(np.linalg.norm(tn, axis=1, keepdims=True), 1e-300)
    hit = ident >= 0
    normals[hit] = tn[ident[hit]]
    if plane is not None:
        p0 = cam.to_camera(plane[0])
        n = np.asarray(plane[1], dtype=float) @ cam.R
        n /= np.linalg.norm(n)
        den = rays @ n
        with np.errstate(divide="ignore", invalid="ignore"):
            zp = np.where(np.abs(den) > 1e-12, (p0 @ n) / den, np.inf)
        zp[zp <= near] = np.inf
        closer = zp < zbuf
        zbuf[closer], ident[closer] = zp[closer], -1
        normals[closer] = n
    cosang = np.abs(np.einsum("hwc,hwc->hw", normals, rays)) / np.linalg.norm(rays, axis=-1)
    return zbuf, ident, cosang
