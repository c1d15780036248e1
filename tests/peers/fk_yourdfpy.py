"""Independent forward kinematics with yourdfpy, for tests/model_robots.rs.

stdin: {"urdf": path, "base": link, "links": [names], "configs": [{"joint": value, ...}, ...]}
stdout: [[4x4 row-major world transforms of each link], ...] per config, as JSON.
"""
import io
import json
import re
import sys

import numpy as np
import yourdfpy

req = json.load(sys.stdin)
# yourdfpy does not know <capsule>; geometry plays no part in kinematics.
text = re.sub(r"<capsule\b", "<cylinder", open(req["urdf"]).read())
robot = yourdfpy.URDF.load(io.BytesIO(text.encode()), load_meshes=False, load_collision_meshes=False,
                           build_scene_graph=True, build_collision_scene_graph=False)
names = [j for j in robot.actuated_joint_names]
out = []
for cfg in req["configs"]:
    q = np.array([cfg.get(n, 0.0) for n in names], dtype=float)
    robot.update_cfg(q)
    poses = []
    for link in req["links"]:
        T = robot.get_transform(frame_to=link, frame_from=robot.base_link)
        poses.append(np.asarray(T, dtype=float).reshape(-1).tolist())
    out.append(poses)
json.dump(out, sys.stdout)
