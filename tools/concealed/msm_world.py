"""msm-world: an independent meshless-shape-matching "world" for concealed diagnosis cases.

This is a second MSM simulator, written from the method's description (Mueller, Heidelberger,
Teschner, Gross 2005, "Meshless deformations based on shape matching"), not from pliant's C++
core. It exists to make recordings that the fitter in `pliant diagnose` did NOT generate, so a
diagnosis that passes on them is not just recognising its own simulator. It differs from the
fitted model the way the world differs from a model:

- its own clusters: one per particle, holding every particle within `radius_factor` (1.3-2.2)
  times the median nearest-neighbour distance of the rest shape (the fitter uses 1.5);
- masses that are not uniform (random +-30 %, or a density gradient); the recording never says;
- several MSM steps per camera frame (1-4), with the tool moving continuously inside a frame;
- overlapping cluster goals blended with a distance kernel instead of a plain average;
- rest shapes that are not perfect grids, frame clocks that jitter.

Semantics kept equal to pliant, so the truth values mean the same thing there:
- msm_beta: 0 rigid clusters (goal = R q), 1 fully affine (goal = A q); goal = ((1-b) R + b A) q + c;
  A = A_pq A_qq^-1 without volume normalisation;
- msm_alpha: each step moves a free particle the fraction alpha of the way to its goal;
- fixed particles sit at their rest position; a driven particle sits on the tool while driven and
  moves freely (with the velocity it had) after the tool lets go.

One step of length h (Mueller 2005, eqs. 10-11, goals taken from the predicted positions):
    v <- v + h f_ext / m                       (body force, e.g. an undeclared gravity)
    x* = x + h v                               (prediction)
    g  = blended cluster goals at x*
    v <- v + alpha (g - x*) / h,  x <- x + h v  (i.e. x = x* + alpha (g - x*))
The literal form with goals from x(t) keeps the velocity of every overshoot and never comes to
rest; real objects do, so the prediction form is used.

Effects (names of docs/spec/diagnosis-v1.md), each modelled here in its own way:
- plasticity: per-cluster plastic stretch S_p; when the elastic strain norm exceeds `yield`, the
  rest shape flows toward the deformed one at `creep` x overstress (Perzyna-style), volume kept;
- viscosity: either `strain_rate` damping (the symmetric part of each cluster's velocity gradient
  is removed at rate `damping`, rigid motion untouched: a Kelvin-Voigt viscosity) or
  `relaxation` (a share `fraction` of each cluster's rest shape follows its current stretch with
  time constant `tau`: a standard linear solid that creeps under load and recovers slowly);
- friction: the declared `fixed` particles are not pins but are held in their support plane and
  slide along it against Coulomb friction in position form, with stiction (a static and a
  kinetic coefficient, the normal force standing in as the plane's normal correction);
- gravity: a body force the recording does not declare, possibly tilted; the object has settled
  under it before the recording starts (as a real object would have);
- heterogeneity: the clusters centred in a region (an inclusion, a half, a layer) have another
  msm_beta;
- stiffening: each cluster's msm_beta falls with its strain, beta / (1 + (k |E|)^2) (J-shaped,
  like soft tissue), E the cluster's Biot strain of the previous step.
"""

import json
import math
import os

import numpy as np

EFFECTS = ("plasticity", "viscosity", "friction", "gravity", "heterogeneity", "stiffening")


# ----------------------------------------------------------------------------------------------
# Objects. Each builder returns a dict with the rest shape, the support, the tool contact and
# the directions a protocol needs. `up` points away from the support (gravity acts along -up).
# ----------------------------------------------------------------------------------------------

def _body(name, rest, fixed, driven, up, push, unit, description, support_normal=None):
    rest = np.asarray(rest, dtype=float)
    return {
        "name": name,
        "rest": rest,
        "dim": rest.shape[1],
        "fixed": sorted(int(i) for i in fixed),
        "driven": int(driven),
        "up": np.asarray(up, dtype=float),
        "push": np.asarray(push, dtype=float) / np.linalg.norm(push),
        "support_normal": np.asarray(up if support_normal is None else support_normal, dtype=float),
        "unit": unit,
        "description": description,
    }


def grid_block_2d(rng, spacing, unit):
    """A 2D block (foam, sponge) standing on a table, pressed on the top from above."""
    cols, rows = int(rng.integers(5, 8)), int(rng.integers(4, 7))
    pts = [(c * spacing, r * spacing) for r in range(rows) for c in range(cols)]
    rest = np.array(pts)
    up = np.array([0.0, 1.0])
    if unit == "px":  # image plane: y grows downward, the table is at the bottom of the image
        rest = np.column_stack([320 + rest[:, 0], 400 - rest[:, 1]])
        up = np.array([0.0, -1.0])
    top = [i for i in range(len(pts)) if i // cols == rows - 1]
    driven = top[len(top) // 2]
    fixed = [i for i in range(len(pts)) if i // cols == 0]
    return _body("block_2d", rest, fixed, driven, up, -up, unit,
                 f"2D block of {cols} x {rows} particles on a table, pressed from above")


def clamped_strip_2d(rng, spacing, unit):
    """A 2D strip clamped in a wall at its left end; the tool pulls the free tip down."""
    cols, rows = int(rng.integers(11, 16)), 3
    rest = np.array([(c * spacing, r * spacing) for r in range(rows) for c in range(cols)])
    fixed = [r * cols for r in range(rows)]
    driven = 1 * cols + cols - 1  # middle row, free tip
    push = np.array([0.0, -1.0]) if rng.random() < 0.7 else np.array([0.0, 1.0])
    # Gravity acts along -y; the clamp is a wall with its normal along +x (friction slides there).
    return _body("strip_2d", rest, fixed, driven, [0.0, 1.0], push, unit,
                 f"2D strip of {cols} x {rows} particles clamped at its left end, tip pulled and released",
                 support_normal=[1.0, 0.0])


def ring_on_supports_2d(rng, spacing, unit):
    """A 2D annulus (two rings of particles) standing on three support particles, squeezed at its top."""
    n_out = int(rng.integers(22, 30))
    r_out = n_out * spacing / (2 * math.pi)
    r_in = r_out - spacing
    n_in = max(8, int(round(2 * math.pi * r_in / spacing)))
    phase = rng.uniform(0, 2 * math.pi / n_in)
    outer = [(r_out * math.cos(a), r_out * math.sin(a))
             for a in -math.pi / 2 + 2 * math.pi * np.arange(n_out) / n_out]
    inner = [(r_in * math.cos(a), r_in * math.sin(a))
             for a in -math.pi / 2 + phase + 2 * math.pi * np.arange(n_in) / n_in]
    rest = np.array(outer + inner) + np.array([0.0, r_out])
    fixed = [0, 1, n_out - 1]  # the lowest outer particle and its two neighbours
    driven = n_out // 2        # the top of the outer ring
    return _body("ring_2d", rest, fixed, driven, [0.0, 1.0], [0.0, -1.0], unit,
                 f"2D ring of {n_out} + {n_in} particles standing on 3 supports, squeezed at the top and released")


def block_3d(rng, spacing, unit):
    """A 3D block on a table, bottom layer on the table, pressed on the top face."""
    nx, ny, nz = int(rng.integers(4, 6)), int(rng.integers(4, 6)), int(rng.integers(3, 5))
    rest = np.array([(i * spacing, j * spacing, k * spacing)
                     for k in range(nz) for j in range(ny) for i in range(nx)])
    top = np.where(np.isclose(rest[:, 2], (nz - 1) * spacing))[0]
    centre = rest[top].mean(axis=0)
    driven = top[np.argmin(np.linalg.norm(rest[top] - centre, axis=1))]
    fixed = np.where(np.isclose(rest[:, 2], 0.0))[0]
    return _body("block_3d", rest, fixed, driven, [0, 0, 1.0], [0, 0, -1.0], unit,
                 f"3D block of {nx} x {ny} x {nz} particles on a table, pressed on its top face")


def dome_3d(rng, spacing, unit):
    """A thick 3D dome (two hemispherical shells) on its rim, pressed at the apex."""
    r_out = spacing * rng.uniform(2.6, 3.2)
    pts = []
    for radius in (r_out, r_out - spacing):
        n_lat = max(2, int(round((math.pi / 2) * radius / spacing)))
        for k in range(n_lat + 1):
            theta = (math.pi / 2) * k / n_lat  # 0 at the rim, pi/2 at the apex
            ring_r = radius * math.cos(theta)
            n_az = max(1, int(round(2 * math.pi * ring_r / spacing)))
            for a in 2 * math.pi * (np.arange(n_az) + 0.5 * (k % 2)) / n_az:
                pts.append((ring_r * math.cos(a), ring_r * math.sin(a), radius * math.sin(theta)))
    rest = np.array(pts)
    fixed = np.where(rest[:, 2] < 1e-9)[0]
    driven = int(np.argmax(rest[:, 2]))
    return _body("dome_3d", rest, fixed, driven, [0, 0, 1.0], [0, 0, -1.0], unit,
                 f"3D dome of {len(pts)} particles on its rim, pressed at the apex")


def cylinder_3d(rng, spacing, unit):
    """An upright 3D cylinder (post) with its base on the table; the tool pushes its top sideways."""
    layers = int(rng.integers(5, 8))
    disc = [(0.0, 0.0)]
    disc += [(spacing * math.cos(a), spacing * math.sin(a)) for a in 2 * math.pi * np.arange(6) / 6]
    disc += [(2 * spacing * math.cos(a), 2 * spacing * math.sin(a))
             for a in 2 * math.pi * (np.arange(12) + 0.5) / 12]
    rest = np.array([(x, y, k * spacing) for k in range(layers) for (x, y) in disc])
    fixed = np.arange(len(disc))
    driven = (layers - 1) * len(disc)  # centre of the top disc
    angle = rng.uniform(0, 2 * math.pi)
    push = [math.cos(angle), math.sin(angle), -0.3]
    return _body("cylinder_3d", rest, fixed, driven, [0, 0, 1.0], push, unit,
                 f"3D cylinder of {layers} discs of {len(disc)} particles, top pushed sideways and released")


SHAPES = {
    "block_2d": grid_block_2d,
    "strip_2d": clamped_strip_2d,
    "ring_2d": ring_on_supports_2d,
    "block_3d": block_3d,
    "dome_3d": dome_3d,
    "cylinder_3d": cylinder_3d,
}


def jitter_rest(body, rng, fraction, spacing):
    """Real objects are not perfect lattices: move every rest position by up to `fraction` spacing."""
    if fraction > 0:
        body["rest"] = body["rest"] + rng.uniform(-fraction, fraction, body["rest"].shape) * spacing
    return body


def particle_masses(rest, rng, kind):
    """Masses the recording does not declare: uniform, random +-30 %, or a density gradient."""
    n = len(rest)
    if kind == "random":
        return rng.uniform(0.7, 1.3, n)
    if kind == "gradient":
        axis = rng.normal(size=rest.shape[1])
        s = rest @ (axis / np.linalg.norm(axis))
        s = (s - s.min()) / max(s.max() - s.min(), 1e-12)
        return 0.7 + 0.6 * s
    return np.ones(n)


# ----------------------------------------------------------------------------------------------
# Clusters
# ----------------------------------------------------------------------------------------------

def median_neighbour_distance(rest):
    d = np.linalg.norm(rest[:, None, :] - rest[None, :, :], axis=2)
    np.fill_diagonal(d, np.inf)
    return float(np.median(d.min(axis=1)))


def build_clusters(rest, radius_factor, kernel):
    """One cluster around every particle: all particles within radius_factor x median NN distance.

    Returned padded to the largest cluster: members (C, K) ids, valid (C, K) mask and the goal
    blending weight of each membership. With kernel=True a member's vote for its goal falls with
    its rest distance from the cluster's centre particle (1 at the centre, 0.4 at the radius);
    otherwise every cluster's goal counts equally (the paper's plain average).
    """
    n = len(rest)
    radius = radius_factor * median_neighbour_distance(rest)
    d = np.linalg.norm(rest[:, None, :] - rest[None, :, :], axis=2)
    lists = [np.where(d[i] <= radius * (1 + 1e-9))[0] for i in range(n)]
    k = max(len(m) for m in lists)
    members = np.zeros((n, k), dtype=int)
    valid = np.zeros((n, k), dtype=bool)
    for i, m in enumerate(lists):
        members[i, :len(m)] = m
        valid[i, :len(m)] = True
    dist = np.take_along_axis(d, members, axis=1) / radius
    vote = (1.0 - 0.6 * dist ** 2) if kernel else np.ones_like(dist)
    return {"members": members, "valid": valid, "vote": vote * valid, "radius": radius,
            "sizes": valid.sum(axis=1)}


# ----------------------------------------------------------------------------------------------
# Shape matching pieces (batched over clusters)
# ----------------------------------------------------------------------------------------------

def rotation_part(a):
    """Rotation of the polar decomposition of each matrix in a (C, D, D) stack (via SVD)."""
    u, _, vt = np.linalg.svd(a)
    flip = np.sign(np.linalg.det(u @ vt))
    u[..., :, -1] *= flip[:, None]
    return u @ vt


def cluster_frames(pos, clusters, mass_w, q):
    """Centroid, A_pq, the linear fit A and its rotation R for every cluster at positions `pos`."""
    p_all = pos[clusters["members"]]                        # (C, K, D)
    wsum = mass_w.sum(axis=1)
    com = (mass_w[..., None] * p_all).sum(axis=1) / wsum[:, None]
    p = p_all - com[:, None, :]
    apq = np.einsum("ck,cki,ckj->cij", mass_w, p, q)
    aqq = np.einsum("ck,cki,ckj->cij", mass_w, q, q)
    a = apq @ np.linalg.pinv(aqq)
    return com, p, a, rotation_part(apq)


def biot_strain(r, a):
    """Symmetric stretch of the fit minus identity, in the cluster's rest frame, and its norm."""
    u = np.swapaxes(r, 1, 2) @ a
    e = 0.5 * (u + np.swapaxes(u, 1, 2)) - np.eye(a.shape[1])
    return e, np.sqrt((e ** 2).sum(axis=(1, 2)))


# ----------------------------------------------------------------------------------------------
# The world
# ----------------------------------------------------------------------------------------------

class World:
    """State and stepping of one object, with at most one effect switched on."""

    def __init__(self, body, masses, clusters, alpha, beta, effect=None, params=None, details=None):
        self.body = body
        self.rest = body["rest"].copy()
        self.dim = body["dim"]
        self.n = len(self.rest)
        self.mass = masses
        self.cl = clusters
        self.alpha = alpha
        self.beta = beta
        self.effect = effect
        self.p = dict(params or {})
        self.details = details or {}
        self.x = self.rest.copy()
        self.v = np.zeros_like(self.x)
        self.fixed = np.zeros(self.n, dtype=bool)
        self.fixed[body["fixed"]] = True
        m = clusters["members"]
        self.mass_w = masses[m] * clusters["valid"]
        com0 = (self.mass_w[..., None] * self.rest[m]).sum(axis=1) / self.mass_w.sum(axis=1)[:, None]
        self.q0 = (self.rest[m] - com0[:, None, :]) * clusters["valid"][..., None]
        eye = np.eye(self.dim)
        self.stretch = np.repeat(eye[None], len(m), axis=0)  # plastic or relaxed rest stretch S
        self.relaxed = self.stretch.copy()                    # viscoelastic internal variable V
        self.strain_norm = np.zeros(len(m))                   # last step's |E| per cluster
        self.cluster_beta = np.full(len(m), beta)
        if effect == "heterogeneity":
            self.cluster_beta[self.details["region_clusters"]] = self.p["region_msm_beta"]
        self.gravity = np.zeros(self.dim)
        if effect == "gravity":
            self.gravity = np.asarray(self.details["gravity_vector"], dtype=float)
        self.vote_sum = np.bincount(m.ravel(), weights=clusters["vote"].ravel(), minlength=self.n)
        self.tool_id = body["driven"]
        self.slipping = np.zeros(self.n, dtype=bool)

    # -- effects acting on the rest shape ------------------------------------------------------
    def current_q(self):
        return np.einsum("cij,ckj->cki", self.stretch, self.q0)

    def flow_rest_shape(self, h, r, a, a0, r0):
        """Plastic flow or viscoelastic relaxation of each cluster's rest stretch, after a step."""
        eye = np.eye(self.dim)
        if self.effect == "plasticity":
            e, norm = biot_strain(r, a)  # elastic strain relative to the current (plastic) rest
            over = np.clip(norm - self.p["yield"], 0, None) / np.maximum(norm, 1e-12)
            rate = (h * self.p["creep"] * over)[:, None, None]
            s = (eye + rate * e) @ self.stretch
            s /= np.abs(np.linalg.det(s))[:, None, None] ** (1.0 / self.dim)  # plastic flow keeps volume
            dev = s - eye
            size = np.sqrt((dev ** 2).sum(axis=(1, 2)))
            cap = np.minimum(1.0, self.p["max"] / np.maximum(size, 1e-12))[:, None, None]
            self.stretch = eye + cap * dev
        elif self.effect == "viscosity" and self.p.get("kind") == "relaxation":
            e_total, _ = biot_strain(r0, a0)  # stretch relative to the original rest shape
            k = 1 - math.exp(-h / self.p["tau"])
            self.relaxed += k * ((eye + e_total) - self.relaxed)
            g = self.p["fraction"]
            self.stretch = (1 - g) * eye + g * self.relaxed

    def damp_strain_rate(self, h):
        """Kelvin-Voigt viscosity: remove a share of each cluster's symmetric velocity gradient."""
        m = self.cl["members"]
        w = self.mass_w
        wsum = w.sum(axis=1)[:, None]
        xc = self.x[m]
        vc = self.v[m]
        p = xc - ((w[..., None] * xc).sum(axis=1) / wsum)[:, None, :]
        u = vc - ((w[..., None] * vc).sum(axis=1) / wsum)[:, None, :]
        cov = np.einsum("ck,cki,ckj->cij", w, p, p)
        grad = np.einsum("ck,cki,ckj->cij", w, u, p) @ np.linalg.pinv(cov)
        rate = 0.5 * (grad + np.swapaxes(grad, 1, 2))
        corr = -np.einsum("cij,ckj->cki", rate, p) * self.cl["valid"][..., None]
        acc = np.stack([np.bincount(m.ravel(), weights=corr[..., d].ravel(), minlength=self.n)
                        for d in range(self.dim)], axis=1)
        count = np.bincount(m.ravel(), weights=self.cl["valid"].ravel().astype(float), minlength=self.n)
        share = min(1.0, self.p["damping"] * h)
        free = ~self.fixed
        self.v[free] += share * acc[free] / count[free, None]

    # -- the step --------------------------------------------------------------------------------
    def goals(self, xp):
        q = self.current_q()
        com, _, a, r = cluster_frames(xp, self.cl, self.mass_w, q)
        beta = self.cluster_beta
        if self.effect == "stiffening":
            beta = beta / (1.0 + (self.p["k"] * self.strain_norm) ** 2)
        g_map = (1 - beta)[:, None, None] * r + beta[:, None, None] * a
        goal = np.einsum("cij,ckj->cki", g_map, q) + com[:, None, :]
        vote = self.cl["vote"]
        m = self.cl["members"]
        blended = np.stack([np.bincount(m.ravel(), weights=(vote * goal[..., d]).ravel(), minlength=self.n)
                            for d in range(self.dim)], axis=1) / self.vote_sum[:, None]
        return blended, q, a, r

    def support_contact(self, x_new, x_old):
        """Friction effect: the support particles are not pinned but held in their support plane
        (line in 2D), through their rest position, and slide along it against Coulomb friction.

        Position form, per step: the plane's correction along its normal stands for the normal
        force (its size, whether it pushes the particle out of the table or holds it down as the
        object's weight would). A particle at rest stays put while the tangential move the
        shape matching asks for is below mu_static x that correction; once it slips, the move is
        shortened by mu_kinetic x the correction (mu_kinetic = 0.8 mu_static).
        """
        n = self.body["support_normal"] / np.linalg.norm(self.body["support_normal"])
        mu_static = self.p["mu"]
        mu_kinetic = 0.8 * mu_static
        for i in self.body["fixed"]:
            normal_push = abs(self.rest[i] @ n - x_new[i] @ n)
            x_new[i] += (self.rest[i] @ n - x_new[i] @ n) * n  # back into the plane
            move = x_new[i] - x_old[i]
            slide = move - (move @ n) * n
            length = np.linalg.norm(slide)
            sliding = self.slipping[i]
            bound = (mu_kinetic if sliding else mu_static) * normal_push
            if length <= bound:
                x_new[i] -= slide  # friction holds it
                self.slipping[i] = False
            else:
                x_new[i] -= slide * (mu_kinetic * normal_push / length)  # slides, slowed
                self.slipping[i] = True

    def step(self, h, tool_target):
        """Advance by h seconds; tool_target is the driven particle's position or None (free)."""
        if self.effect == "viscosity" and self.p.get("kind") == "strain_rate":
            self.damp_strain_rate(h)
        x_old = self.x.copy()
        self.v += h * self.gravity
        xp = self.x + h * self.v
        pinned = self.fixed if self.effect != "friction" else np.zeros(self.n, dtype=bool)
        xp[pinned] = self.rest[pinned]
        if tool_target is not None:
            xp[self.tool_id] = tool_target
        goal, q, a, r = self.goals(xp)
        x_new = xp + self.alpha * (goal - xp)
        if self.effect == "friction":
            self.support_contact(x_new, x_old)
        x_new[pinned] = self.rest[pinned]
        if tool_target is not None:
            x_new[self.tool_id] = tool_target
        self.v = (x_new - x_old) / h
        self.x = x_new
        if self.effect in ("plasticity", "stiffening") or (self.effect == "viscosity"
                                                          and self.p.get("kind") == "relaxation"):
            _, _, a_now, r_now = cluster_frames(x_new, self.cl, self.mass_w, q)
            if self.effect == "stiffening":
                self.strain_norm = biot_strain(r_now, a_now)[1]
            else:
                a0 = r0 = None
                if self.effect == "viscosity":
                    _, _, a0, r0 = cluster_frames(x_new, self.cl, self.mass_w, self.q0)
                self.flow_rest_shape(h, r_now, a_now, a0, r0)


# ----------------------------------------------------------------------------------------------
# Protocol: still, press (or pull), hold, release, recover
# ----------------------------------------------------------------------------------------------

def make_protocol(rng, body, spacing, max_duration):
    still = rng.uniform(0.3, 0.5)
    press = rng.uniform(0.6, 1.2)
    hold = rng.uniform(0.8, 1.8)
    release = body["name"] in ("strip_2d", "ring_2d", "dome_3d", "cylinder_3d") or rng.random() < 0.7
    after = rng.uniform(1.0, 2.0) if release else 0.0
    scale = min(1.0, max_duration / (still + press + hold + after))
    press, hold, after = press * scale, hold * scale, after * scale
    travel = {"block_2d": (0.6, 1.8), "strip_2d": (2.0, 4.5), "ring_2d": (1.0, 2.2),
              "block_3d": (0.6, 1.5), "dome_3d": (0.6, 1.4), "cylinder_3d": (1.0, 2.5)}[body["name"]]
    direction = body["push"].copy()
    tilt = math.radians(rng.uniform(0, 15))  # the tool is never exactly along the axis
    side = rng.normal(size=body["dim"])
    side -= (side @ direction) * direction
    direction = math.cos(tilt) * direction + math.sin(tilt) * side / np.linalg.norm(side)
    return {"still_s": still, "press_s": press, "hold_s": hold, "after_s": after,
            "release": bool(release), "travel": rng.uniform(*travel) * spacing,
            "direction": direction, "ramp": "cosine" if rng.random() < 0.6 else "linear",
            "start": body["rest"][body["driven"]].copy()}


def protocol_duration(pr):
    return pr["still_s"] + pr["press_s"] + pr["hold_s"] + pr["after_s"]


def release_time(pr):
    return pr["still_s"] + pr["press_s"] + pr["hold_s"] if pr["release"] else None


def tool_position(pr, t):
    """Where the tool (and the particle it holds) is at time t, continuous within a frame."""
    u = min(max((t - pr["still_s"]) / pr["press_s"], 0.0), 1.0)
    s = 0.5 * (1 - math.cos(math.pi * u)) if pr["ramp"] == "cosine" else u
    return pr["start"] + s * pr["travel"] * pr["direction"]


def frame_times(rng, rate, duration, jitter):
    """Camera timestamps: nominal 1/rate apart, each displaced by up to `jitter` of an interval."""
    count = int(round(duration * rate)) + 1
    t = np.arange(count) / rate
    if jitter > 0:
        t[1:] += rng.uniform(-jitter, jitter, count - 1) / rate
    return t


def settle(world, protocol, h, tolerance, max_steps=3000):
    """Let the object come to rest under its body force, the tool holding still, stepping at the
    recording's own step length (an MSM sag depends on it). Stops when no particle moves more
    than `tolerance` in a step."""
    for _ in range(max_steps):
        before = world.x.copy()
        world.step(h, protocol["start"])
        if np.abs(world.x - before).max() < tolerance:
            break
    world.v[:] = 0.0


def simulate(world, protocol, times, substeps, settle_tolerance=None):
    """Positions at every frame time. With settle_tolerance the world first settles (a real
    object has long come to rest under its weight before a recording starts)."""
    if settle_tolerance is not None:
        settle(world, protocol, float(np.median(np.diff(times))) / substeps, settle_tolerance)
    t_release = release_time(protocol)
    out = np.empty((len(times),) + world.x.shape)
    out[0] = world.x
    for f in range(1, len(times)):
        h = (times[f] - times[f - 1]) / substeps
        for s in range(substeps):
            t = times[f - 1] + (s + 1) * h
            driven = t_release is None or t <= t_release + 1e-12
            world.step(h, tool_position(protocol, t) if driven else None)
        out[f] = world.x
    return out


# ----------------------------------------------------------------------------------------------
# Observation: noise, occlusion; effect size
# ----------------------------------------------------------------------------------------------

def occlusion_mask(rng, times, n, driven, t_release, share):
    """True where observed. Runs of 3-15 missing frames; never frame 0, never the tool contact while driven."""
    seen = np.ones((len(times), n), dtype=bool)
    if share <= 0:
        return seen
    held = np.array([t_release is None or t <= t_release for t in times])
    target = int(share * len(times) * n)
    guard = 0
    while (~seen).sum() < target and guard < 100000:
        guard += 1
        i = int(rng.integers(0, n))
        start = int(rng.integers(1, len(times)))
        run = np.arange(start, min(len(times), start + int(rng.integers(3, 16))))
        if i == driven:
            run = run[~held[run]]
        seen[run, i] = False
    return seen


def effect_size(traj, reference, seen, driven, times, t_release, noise_std):
    """rms per coordinate of the effect's change of displacement (each scene from its own frame 0),
    over the observed pairs a diagnosis compares (the tool contact excluded while driven)."""
    d = (traj - traj[0]) - (reference - reference[0])
    use = seen.copy()
    held = np.array([t_release is None or t <= t_release for t in times])
    use[held, driven] = False
    diff = d[use]
    rms = float(np.sqrt(np.mean(diff ** 2)))
    return {"rms": rms, "max": float(np.linalg.norm(d, axis=2)[use].max()),
            "rms_over_noise": rms / noise_std}


# ----------------------------------------------------------------------------------------------
# Writing
# ----------------------------------------------------------------------------------------------

def write_recording(path, body, times, observed, seen, t_release):
    os.makedirs(path, exist_ok=True)
    driven = {"id": body["driven"]}
    if t_release is not None:
        driven["to"] = round(float(t_release), 6)
    rec = {
        "format": "pliant-recording",
        "version": 1,
        "dimension": body["dim"],
        "length_unit": body["unit"],
        "particles": {"count": len(body["rest"]), "fixed": body["fixed"],
                      "driven": [driven if t_release is not None else body["driven"]]},
        "files": {"particles": "particles.csv"},
        "meta": {"generator": "tools/concealed/msm_world.py", "object": body["description"]},
    }
    with open(os.path.join(path, "recording.json"), "w") as f:
        json.dump(rec, f, indent=2)
        f.write("\n")
    axes = "x,y" if body["dim"] == 2 else "x,y,z"
    lines = [f"t,id,{axes}"]
    for f_i, t in enumerate(times):
        ts = repr(round(float(t), 9))
        for i in np.where(seen[f_i])[0]:
            lines.append(ts + f",{i}," + ",".join(f"{c:.9g}" for c in observed[f_i, i]))
    with open(os.path.join(path, "particles.csv"), "w") as f:
        f.write("\n".join(lines) + "\n")


def write_truth(path, truth):
    with open(os.path.join(path, "truth.json"), "w") as f:
        json.dump(truth, f, indent=2, sort_keys=True)
        f.write("\n")
