"""coal's side of benches/self_collision.rs: `collide` on every enabled pair of link parts (convex
hulls) in every state, timed, with the Python loop's own cost measured and taken off.

Usage: self_collision_coal.py DIR (meta.json, part{i}_vertices.f64, part{i}_triangles.u32,
poses.f64 (states x parts x 12), pairs.u32). Prints JSON: seconds, overhead_seconds,
colliding_states.
"""
import json
import sys
import time
from pathlib import Path

import coal
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "peers"))
from hull_parts import coal_convex, read_part  # noqa: E402

d = Path(sys.argv[1])
meta = json.loads((d / "meta.json").read_text())
S, P = meta["states"], meta["parts"]
poses = np.fromfile(d / "poses.f64", dtype="<f8").reshape(S, P, 12)
pairs = [(int(a), int(b)) for a, b in np.fromfile(d / "pairs.u32", dtype="<u4").reshape(-1, 2)]
shapes = []
for i in range(P):
    pv, pt = read_part(d, i)
    shapes.append(coal_convex(pv, pt))
tfs = [[coal.Transform3s(poses[s, p, :9].reshape(3, 3).copy(), poses[s, p, 9:].copy()) for p in range(P)] for s in range(S)]
req = coal.CollisionRequest()
res = coal.CollisionResult()
colliding = 0
t0 = time.perf_counter()
for s in range(S):
    hit = False
    tf = tfs[s]
    for a, b in pairs:
        res.clear()
        coal.collide(shapes[a], tf[a], shapes[b], tf[b], req, res)
        hit = hit or res.isCollision()
    colliding += hit
t_coal = time.perf_counter() - t0
t0 = time.perf_counter()
for s in range(S):
    hit = False
    tf = tfs[s]
    for a, b in pairs:
        res.clear()
        tf[a].isIdentity()  # stands in for the call dispatch of collide
        hit = hit or res.isCollision()
t_overhead = time.perf_counter() - t0
print(json.dumps({"seconds": t_coal - t_overhead, "overhead_seconds": t_overhead, "colliding_states": colliding}))
