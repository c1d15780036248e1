"""The peers of benches/peer_compare.rs: coal 3.0.3 and python-fcl 0.7 on the same robot, world
and states. Each link part is a convex hull (coal.Convex / fcl.Convex), the world one BVH model
(OBBRSS) of all its triangles; boolean collide per state and part.

Usage: peer_compare.py DIR   (DIR holds meta.json and the raw arrays written by the Rust side)
Writes DIR/peers.json: per peer a '0'/'1' string per state (one char per part) and the seconds
spent in collide calls, with the Python loop and call overhead measured and taken off.
"""
import json
import sys
import time
from pathlib import Path

import coal
import fcl
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "peers"))
from hull_parts import coal_bvh, coal_convex, read_env, read_part  # noqa: E402

d = Path(sys.argv[1])
meta = json.loads((d / "meta.json").read_text())
V, T = read_env(d)
poses = np.fromfile(d / "poses.f64", dtype="<f8").reshape(meta["states"], meta["parts"], 12)
parts = []
for i in range(meta["parts"]):
    pv, pt = read_part(d, i)
    parts.append((pv, pt))
S, P = meta["states"], meta["parts"]
out = {}

# ---- coal
env = coal_bvh(V, T)
shapes = []
for pv, pt in parts:
    shapes.append(coal_convex(pv, pt))
tfs = [[coal.Transform3s(poses[s, p, :9].reshape(3, 3).copy(), poses[s, p, 9:].copy()) for p in range(P)] for s in range(S)]
I = coal.Transform3s()
req = coal.CollisionRequest()
res = coal.CollisionResult()
flags = []
t0 = time.perf_counter()
for s in range(S):
    row = []
    for p in range(P):
        res.clear()
        coal.collide(env, I, shapes[p], tfs[s][p], req, res)
        row.append(res.isCollision())
    flags.append(row)
t_coal = time.perf_counter() - t0
t0 = time.perf_counter()
for s in range(S):
    row = []
    for p in range(P):
        res.clear()
        tfs[s][p].isIdentity()  # stands in for the call dispatch of collide
        row.append(res.isCollision())
t_overhead = time.perf_counter() - t0
out["coal"] = {"flags": ["".join("1" if f else "0" for f in row) for row in flags], "seconds": t_coal - t_overhead, "overhead_seconds": t_overhead}

# ---- python-fcl
m = fcl.BVHModel()
m.beginModel(len(V), len(T))
m.addSubModel(V, T)
m.endModel()
env_obj = fcl.CollisionObject(m, fcl.Transform())
objs = []
for pv, pt in parts:
    faces = np.hstack([np.full((len(pt), 1), 3), pt]).reshape(-1)
    objs.append(fcl.CollisionObject(fcl.Convex(pv, len(pt), faces), fcl.Transform()))
ftfs = [[fcl.Transform(poses[s, p, :9].reshape(3, 3), poses[s, p, 9:]) for p in range(P)] for s in range(S)]
freq = fcl.CollisionRequest()
flags = []
t_set = 0.0
t0 = time.perf_counter()
for s in range(S):
    row = []
    for p in range(P):
        objs[p].setTransform(ftfs[s][p])
        fres = fcl.CollisionResult()
        row.append(fcl.collide(env_obj, objs[p], freq, fres) > 0)
    flags.append(row)
t_fcl = time.perf_counter() - t0
t0 = time.perf_counter()
for s in range(S):
    row = []
    for p in range(P):
        objs[p].setTransform(ftfs[s][p])
        fres = fcl.CollisionResult()
        row.append(objs[p].getTranslation() is None)  # stands in for the call dispatch of collide
t_overhead = time.perf_counter() - t0
out["fcl"] = {"flags": ["".join("1" if f else "0" for f in row) for row in flags], "seconds": t_fcl - t_overhead, "overhead_seconds": t_overhead}
(d / "peers.json").write_text(json.dumps(out))
