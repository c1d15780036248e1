"""coal on the plain mesh (no thickness), for tests/thin_wall_sweep.rs.

stdin: {"wall": {"vertices": [[x,y,z]...], "triangles": [[i,j,k]...]},
        "link": {"vertices": [...], "triangles": [...]},
        "poses": [[r00,r01,r02,r10,...,r22, tx,ty,tz], ...]}   (link pose in the wall's frame)
stdout: [bool, ...] collision per pose, from coal.collide on two BVHModelOBBRSS meshes.
"""
import json
import sys

import coal
import numpy as np


def model(mesh):
    m = coal.BVHModelOBBRSS()
    m.beginModel(len(mesh["triangles"]), len(mesh["vertices"]))
    m.addVertices(np.asarray(mesh["vertices"], dtype=float))
    m.addTriangles(np.asarray(mesh["triangles"], dtype=np.int32))
    m.endModel()
    return m


req = json.load(sys.stdin)
wall = model(req["wall"])
link = model(req["link"])
out = []
for p in req["poses"]:
    R = np.asarray(p[:9], dtype=float).reshape(3, 3)
    t = np.asarray(p[9:], dtype=float)
    res = coal.CollisionResult()
    coal.collide(wall, coal.Transform3s(), link, coal.Transform3s(R, t), coal.CollisionRequest(), res)
    out.append(bool(res.isCollision()))
json.dump(out, sys.stdout)
