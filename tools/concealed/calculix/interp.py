"""Transfer of the fine quadratic solution onto the coarse mesh's nodes.

Every coarse node is located in a fine 10-node tetrahedron by its barycentric coordinates
(the fine tetrahedra have straight edges, so the map is affine); the displacement there is
the C3D10 interpolation, corners lambda_i (2 lambda_i - 1), midside nodes 4 lambda_i lambda_j.
A node just outside every fine element (curved surfaces are faceted differently in the two
meshes) takes the element it is least outside of, with clamped coordinates.
"""
import numpy as np

from .mesh import TET10_EDGES


def locate(points_fine, tets10, query):
    """For each query point: the fine element and the 10 weights of its nodes."""
    a = points_fine[tets10[:, 0]]
    m = np.stack([points_fine[tets10[:, k]] - a for k in (1, 2, 3)], axis=2)  # (e, 3, 3)
    minv = np.linalg.inv(m)
    elems = np.empty(len(query), dtype=np.int64)
    weights = np.empty((len(query), 10))
    for q, p in enumerate(query):
        l123 = np.einsum("eij,ej->ei", minv, p - a)
        lam = np.hstack([1 - l123.sum(axis=1, keepdims=True), l123])
        e = int(np.argmax(lam.min(axis=1)))
        lv = np.clip(lam[e], 0.0, None)
        lv /= lv.sum()
        w = np.empty(10)
        w[:4] = lv * (2 * lv - 1)
        for k, (i, j) in enumerate(TET10_EDGES):
            w[4 + k] = 4 * lv[i] * lv[j]
        elems[q] = e
        weights[q] = w
    return elems, weights


def transfer(u_fine, tets10, elems, weights):
    """Displacements (frames, n_fine, 3) -> (frames, n_query, 3)."""
    nodes = tets10[elems]  # (q, 10)
    return np.einsum("qk,fqkd->fqd", weights, u_fine[:, nodes, :])
