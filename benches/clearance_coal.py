"""The peer of benches/clearance.rs: coal 3.0.3's `distance` from each Panda link part (its convex
hull, coal.Convex) to the plain world mesh (one BVHModelOBBRSS of all its triangles), per state,
with the Python loop and call overhead measured and taken off (as benches/peer_compare.py does).

Usage: clearance_coal.py DIR   (DIR holds meta.json and the raw arrays written by the Rust side)
Writes DIR/coal_distance.json: the seconds spent in distance calls, and per state and part the
distance coal found.
"""
import json
import sys
import time
from pathlib import Path

import coal
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "peers"))
from hull_parts import coal_bvh, coal_convex, read_env, read_part  # noqa: E402

d = Path(sys.argv[1])
meta = json.loads((d / "meta.json").read_text())
V, T = read_env(d)
S, P = meta["states"], meta["parts"]
poses = np.fromfile(d / "poses.f64", dtype="<f8").reshape(S, P, 12)
env = coal_bvh(V, T)
shapes = []
for i in range(P):
    pv, pt = read_part(d, i)
    shapes.append(coal_convex(pv, pt))
tfs = [[coal.Transform3s(poses[s, p, :9].reshape(3, 3).copy(), poses[s, p, 9:].copy()) for p in range(P)] for s in range(S)]
I = coal.Transform3s()
req = coal.DistanceRequest()
req.enable_nearest_points = True
res = coal.DistanceResult()
dist = []
t0 = time.perf_counter()
for s in range(S):
    row = []
    for p in range(P):
        res.clear()
        coal.distance(env, I, shapes[p], tfs[s][p], req, res)
        row.append(res.min_distance)
    dist.append(row)
t_coal = time.perf_counter() - t0
t0 = time.perf_counter()
for s in range(S):
    row = []
    for p in range(P):
        res.clear()
        tfs[s][p].isIdentity()  # stands in for the call dispatch of distance
        row.append(res.min_distance)
t_overhead = time.perf_counter() - t0
(d / "coal_distance.json").write_text(json.dumps({"seconds": t_coal - t_overhead, "overhead_seconds": t_overhead, "distances": dist}))
