"""The link parts the Rust side exported (`ConvexHull::vertices_and_triangles`, written raw as
part{i}_vertices.f64 and part{i}_triangles.u32), read back and built as coal shapes: one reader
for every coal peer, so they all check the same hulls."""
import coal
import numpy as np


def read_part(d, i):
    """(vertices n×3 float64, triangles m×3 int64) of part `i` in folder `d`."""
    pv = np.fromfile(d / f"part{i}_vertices.f64", dtype="<f8").reshape(-1, 3)
    pt = np.fromfile(d / f"part{i}_triangles.u32", dtype="<u4").reshape(-1, 3).astype(np.int64)
    return pv, pt


def coal_convex(pv, pt):
    """A coal.Convex of the hull's vertices and triangles."""
    tris = coal.StdVec_Triangle()
    for a, b, c in pt:
        tris.append(coal.Triangle(int(a), int(b), int(c)))
    verts = coal.StdVec_Vec3s()
    for v in pv:
        verts.append(np.asarray(v, dtype=float))
    return coal.Convex(verts, tris)


def read_env(d):
    """(vertices n×3 float64, triangles m×3 int64) of the world mesh the Rust side exported."""
    V = np.fromfile(d / "env_vertices.f64", dtype="<f8").reshape(-1, 3)
    T = np.fromfile(d / "env_triangles.u32", dtype="<u4").reshape(-1, 3).astype(np.int64)
    return V, T


def coal_bvh(V, T):
    """The world as coal's OBBRSS BVH model of its bare triangles (no thickness)."""
    env = coal.BVHModelOBBRSS()
    env.beginModel(len(T), len(V))
    env.addVertices(V)
    env.addTriangles(T)
    env.endModel()
    return env
