"""coal 3.0.3 with MoveIt-style motion sampling, the peer of benches/motion.rs: each motion is
checked at a fixed number of discrete states (201: steps of 0.005 of the motion, as MoveIt's
`longest_valid_segment_fraction` 0.005), in order, stopping at the first colliding state; a
state is checked part by part (each link part a coal.Convex hull against one BVH model, OBBRSS,
of all the world's triangles, as in benches/peer_compare.py), stopping at the first colliding
part.

Usage: coal_motion.py DIR   (DIR holds meta.json and the raw arrays written by benches/motion.rs
or benches/trajectory.rs; meta.json's optional "counts" gives each motion's own number of states)
Writes DIR/coal_motion.json: per motion 0/1 (a sampled state collides), the seconds spent in
collide calls (the Python loop and call overhead measured and taken off), and the collide calls.
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
M, S, P = meta["motions"], meta["samples"], meta["parts"]
# Optional: how many of the S samples each motion really has (the rest is padding, never checked).
counts = meta.get("counts", [S] * M)
V, T = read_env(d)
poses = np.fromfile(d / "motion_poses.f64", dtype="<f8").reshape(M, S, P, 12)

env = coal_bvh(V, T)
shapes = []
for i in range(P):
    pv, pt = read_part(d, i)
    shapes.append(coal_convex(pv, pt))

I = coal.Transform3s()
req = coal.CollisionRequest()
res = coal.CollisionResult()
hits, seconds, overhead, calls = [], 0.0, 0.0, 0
for m in range(M):
    # Transforms built outside the timed loop (MoveIt's FK is not coal's time either).
    tfs = [[coal.Transform3s(poses[m, s, p, :9].reshape(3, 3).copy(), poses[m, s, p, 9:].copy()) for p in range(P)] for s in range(counts[m])]
    hit = False
    n = 0
    t0 = time.perf_counter()
    for s in range(counts[m]):
        for p in range(P):
            res.clear()
            coal.collide(env, I, shapes[p], tfs[s][p], req, res)
            n += 1
            if res.isCollision():
                hit = True
                break
        if hit:
            break
    seconds += time.perf_counter() - t0
    # The same loop and calls without collide, for the overhead.
    t0 = time.perf_counter()
    k = 0
    for s in range(counts[m]):
        for p in range(P):
            res.clear()
            tfs[s][p].isIdentity()  # stands in for the call dispatch of collide
            k += 1
            if k == n:
                break
        if k == n:
            break
    overhead += time.perf_counter() - t0
    calls += n
    hits.append(1 if hit else 0)
out = {"hits": hits, "seconds": seconds - overhead, "overhead_seconds": overhead, "calls": calls}
(d / "coal_motion.json").write_text(json.dumps(out))
