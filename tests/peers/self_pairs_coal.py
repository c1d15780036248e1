"""coal 3 on the robot's link pairs, for tests/self_collision.rs: which pairs of convex link parts
collide in each state, and which lie within the 1e-6 m band where verdicts may differ.

Usage: self_pairs_coal.py DIR   (DIR holds meta.json and the raw arrays the Rust side wrote:
part{i}_vertices.f64, part{i}_triangles.u32 (a part's convex hull; spheres, capsules and
cylinders as meta.json's "kinds" give them), poses.f64 (states x parts x
12: row-major rotation, then translation), pairs.u32 (the part pairs to check))
Writes DIR/coal.json: per state, the indices into pairs that collide, and those in the band.
A bounding-ball test (numpy) skips pairs whose balls are more than 1 mm apart; every other pair
goes to coal.collide (GJK/EPA), and to coal.distance (gjk_tolerance 1e-9) for the band.
"""
import json
import sys
from pathlib import Path

import coal
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from hull_parts import coal_convex, read_part  # noqa: E402

BAND = 1e-6

d = Path(sys.argv[1])
meta = json.loads((d / "meta.json").read_text())
S, P = meta["states"], meta["parts"]
poses = np.fromfile(d / "poses.f64", dtype="<f8").reshape(S, P, 12)
pairs = np.fromfile(d / "pairs.u32", dtype="<u4").reshape(-1, 2).astype(np.int64)
shapes, centres, radii = [], [], []
for i in range(P):
    kind = meta["kinds"][i]
    # Primitives in the part's frame, along z as the Rust side defines them (coal's too).
    if isinstance(kind, dict) and "sphere" in kind:
        shapes.append(coal.Sphere(kind["sphere"]))
        centres.append(np.zeros(3))
        radii.append(kind["sphere"])
        continue
    if isinstance(kind, dict) and "capsule" in kind:
        r, hh = kind["capsule"]
        shapes.append(coal.Capsule(r, 2 * hh))
        centres.append(np.zeros(3))
        radii.append(hh + r)
        continue
    if isinstance(kind, dict) and "cylinder" in kind:
        r, hh = kind["cylinder"]
        shapes.append(coal.Cylinder(r, 2 * hh))
        centres.append(np.zeros(3))
        radii.append(float(np.hypot(hh, r)))
        continue
    pv, pt = read_part(d, i)
    shapes.append(coal_convex(pv, pt))
    c = pv.mean(axis=0)
    centres.append(c)
    radii.append(float(np.max(np.linalg.norm(pv - c, axis=1))))
centres, radii = np.asarray(centres), np.asarray(radii)
R = poses[:, :, :9].reshape(S, P, 3, 3)
t = poses[:, :, 9:]
world_centres = np.einsum("spij,pj->spi", R, centres) + t  # S x P x 3
gap = np.linalg.norm(world_centres[:, pairs[:, 0]] - world_centres[:, pairs[:, 1]], axis=2) - (radii[pairs[:, 0]] + radii[pairs[:, 1]])
near = gap < 1e-3  # S x pairs
creq = coal.CollisionRequest()
creq.enable_contact = True
dreq = coal.DistanceRequest()
dreq.gjk_tolerance = 1e-9
out = []
checked = 0
for s in range(S):
    hits, band = [], []
    tf = {}
    for k in np.nonzero(near[s])[0]:
        a, b = int(pairs[k, 0]), int(pairs[k, 1])
        for p in (a, b):
            if p not in tf:
                tf[p] = coal.Transform3s(R[s, p].copy(), t[s, p].copy())
        res = coal.CollisionResult()
        coal.collide(shapes[a], tf[a], shapes[b], tf[b], creq, res)
        checked += 1
        if res.isCollision():
            depth = res.getContact(0).penetration_depth
            # coal reports penetration as a negative distance
            if abs(depth) < BAND:
                band.append(int(k))
            else:
                hits.append(int(k))
        else:
            dres = coal.DistanceResult()
            coal.distance(shapes[a], tf[a], shapes[b], tf[b], dreq, dres)
            if dres.min_distance < BAND:
                band.append(int(k))
    out.append({"hits": hits, "band": band})
(d / "coal.json").write_text(json.dumps({"states": out, "coal_calls": checked}))
