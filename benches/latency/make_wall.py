"""A 1,002,528-triangle wavy wall (708 x 708 quads over 7 x 7 m, 5 cm waves) as binary STL, and an
environment URDF with it as a thin surface (guard_*) away from the arm, for benches/run_large_messages.sh.

    python benches/latency/make_wall.py OUT_DIR [N]
"""
import sys, numpy as np
out = sys.argv[1]
n = int(sys.argv[2]) if len(sys.argv) > 2 else 708
xs = np.linspace(0, 7, n + 1); ys = np.linspace(0, 7, n + 1)
X, Y = np.meshgrid(xs, ys, indexing="ij")
Z = 0.05 * np.sin(2 * np.pi * X / 0.5) * np.cos(2 * np.pi * Y / 0.5)
V = np.stack([X, Y, Z], -1).reshape(-1, 3).astype(np.float32)
i = np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]
a, b, c, d = i.ravel(), (i + n + 1).ravel(), (i + n + 2).ravel(), (i + 1).ravel()
T = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
P = V[T]
N = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]); N /= np.linalg.norm(N, axis=1, keepdims=True)
rec = np.zeros(len(T), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
rec["n"] = N; rec["v"] = P
with open(out + "/wall_1m.stl", "wb") as f:
    f.write(b"binary STL: thickness_collision large-message wall".ljust(80, b" "))
    f.write(np.uint32(len(T)).tobytes()); f.write(rec.tobytes())
open(out + "/environment.urdf", "w").write(f"""<?xml version="1.0"?>
<robot name="wall_1m">
  <link name="world"/>
  <link name="guard_wall"><collision><geometry><mesh filename="wall_1m.stl"/></geometry></collision></link>
  <joint name="world_wall" type="fixed"><parent link="world"/><child link="guard_wall"/>
    <origin xyz="-2 -3.5 -1" rpy="0 -1.5707963267948966 0"/></joint>
</robot>
""")
print(len(T), "triangles")
