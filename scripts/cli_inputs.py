"""Writes the inputs of scripts/cli_outputs.sh into one folder, once: the text files the CLI
tests write (tests/cli_check.rs, cli_areas.rs, hostile_input.rs, input_panics.rs, real_inputs.rs)
and the bags they write with rosbags (tests/peers/bag_tool.py, bag_compress.py; replay_bags.rs,
replay_compressed.rs). Every random state comes from a seeded generator, so the folder is the same
each time it is made; the comparison reuses one copy for every binary.

usage: $TC_PYTHON scripts/cli_inputs.py INPUTS_DIR REPO_ROOT
"""
import io
import json
import math
import os
import random
import re
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

IN, ROOT = Path(sys.argv[1]).resolve(), Path(sys.argv[2]).resolve()
PEERS = ROOT / "tests" / "peers"
T0 = 1_700_000_000_000_000_000

# The bundled arm's actuated joints with the ranges the tests draw from (limits clamped to +-3).
ARM = [("shoulder_pan_joint", -3.0, 3.0), ("shoulder_lift_joint", -2.0, 2.0), ("elbow_joint", -2.6, 2.6),
       ("wrist_1_joint", -3.0, 3.0), ("wrist_2_joint", -2.0, 2.0), ("wrist_3_joint", -3.0, 3.0),
       ("finger_left_joint", 0.0, 0.04)]
NAMES = [n for n, _, _ in ARM]
ARM8 = NAMES + ["finger_right_joint"]
LINKS = ["base_link", "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link",
         "gripper_link", "finger_left_link", "finger_right_link"]


def peer(script, req):
    r = subprocess.run([sys.executable, str(PEERS / script)], input=json.dumps(req).encode(), capture_output=True)
    if r.returncode != 0:
        sys.exit(f"{script} {req.get('op')}: {r.stderr.decode()}")
    return json.loads(r.stdout)


def w(rel, data):
    p = IN / rel
    p.parent.mkdir(parents=True, exist_ok=True)
    if isinstance(data, str):
        p.write_text(data)
    else:
        p.write_bytes(data)
    return p


def mkfifo(rel):
    p = IN / rel
    p.parent.mkdir(parents=True, exist_ok=True)
    os.mkfifo(p, 0o600)


def symlink(rel, target):
    p = IN / rel
    p.parent.mkdir(parents=True, exist_ok=True)
    os.symlink(target, p)


def states(n, seed):
    rng = random.Random(seed)
    return [[lo + (hi - lo) * rng.random() for _, lo, hi in ARM] for _ in range(n)]


def joint_messages(qs, names=NAMES, stamp_offset=-1234):
    return [{"t": T0 + k * 10_000_000, "stamp": T0 + k * 10_000_000 + stamp_offset, "name": names, "position": q} for k, q in enumerate(qs)]


def state_lines(msgs):
    return "".join(json.dumps({"name": m["name"], "position": m["position"], "stamp": m["stamp"]}) + "\n" for m in msgs)


def bag(rel, storage, messages, description=None):
    peer("bag_tool.py", {"op": "write", "path": str(IN / rel), "storage": storage, "messages": messages, "robot_description": description})
    return IN / rel


def compress(op, rel, **extra):
    return peer("bag_compress.py", {"op": op, "path": str(IN / rel), **extra})


def copy_bag(a, b):
    shutil.copytree(IN / a, IN / b)


def storage_file(rel, ext):
    return next(p for p in sorted((IN / rel).iterdir()) if p.name.endswith(ext))


def params(rel, body):
    return w(rel, "thickness_collision:\n  ros__parameters:\n" + body)


def nested(o, c, n):
    return o * n + c * n


# --- the configuration, fixtures and helpers ---------------------------------------------------
shutil.copytree(ROOT / "config", IN / "config")
shutil.copytree(ROOT / "tests" / "fixtures" / "moveit_resources", IN / "fixtures")
erd = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix" / "share" / "example-robot-data"
symlink("erd", erd)
GRIPPER = IN / "config" / "example_workcell" / "gripper.obj"
URDF = (IN / "config" / "example_workcell" / "robot.urdf").read_text().replace('filename="gripper.obj"', f'filename="file://{GRIPPER}"')

# --- check (tests/cli_check.rs) ---------------------------------------------------------------
c = "cli/"
w(c + "states.jsonl", json.dumps({"name": ARM8[:7] + ["other_robot_joint"], "position": [0, 0, 0, 0, 0, 0, 0, 1.0]}) + "\n"
  + json.dumps({"name": NAMES[:3], "position": [0, 1.2, 0.3]}) + "\n")
w(c + "behind.jsonl", json.dumps({"transforms": [{"link": "wrist_1_link", "translation": [0.62, 0.0, 0.4], "rotation": [0, 0, 0, 1]}]}))
params(c + "wrist_only.yaml", "    checked_links: [wrist_1_link]\n")
w(c + "bad.urdf", "<robot name='x'><link name='a'></robot>")
w(c + "pkg.urdf", '<robot name="x"><link name="a"><collision><geometry><mesh filename="package://no_such_pkg/m.stl"/></geometry></collision></link></robot>')
w(c + "missing.urdf", '<robot name="x"><link name="a"><collision><geometry><mesh filename="nowhere.stl"/></geometry></collision></link></robot>')
w(c + "nan.obj", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n")
w(c + "nan.urdf", '<robot name="x"><link name="a"><collision><geometry><mesh filename="nan.obj"/></geometry></collision></link></robot>')
params(c + "typo.yaml", "    default_thicknes: 0.01\n")
w(c + "bad.jsonl", '{"name": ["elbow_joint"], "position": [0.1]}\n{"hello": 1}\n')
w(c + "unequal.jsonl", '{"name": ["elbow_joint"], "position": [0.1, 0.2]}\n')
params(c + "reject.yaml", "    missing_joint: reject\n")
(IN / c / "pkg").mkdir(parents=True)
params(c + "escape_params.yaml", f'    package_map: ["pkg={IN / c / "pkg"}"]\n')
w(c + "escape.urdf", '<robot name="escape"><link name="base"/><link name="arm"><collision><geometry><mesh filename="package://pkg/../../etc/passwd.stl"/></geometry></collision></link>\n'
  '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')
params(c + "rate.yaml", "    marker_rate: 1.0e-300\n")
params(c + "clearance.yaml", "    clearance_threshold: 0.1\n")
params(c + "padding.yaml", '    padding:\n      links: ["forearm_link"]\n      values: [0.05]\n    allowed_collisions: []\n')
params(c + "parallel_bad.yaml", '    thin_surfaces:\n      patterns: ["guard_*", "shelf"]\n      thickness: [0.03]\n      side: [back]\n')
w(c + "arm.srdf", '<robot name="arm"><disable_collisions link1="upper_arm_link" link2="forearm_link" reason="Adjacent"/>'
  '<disable_collisions link1="finger_left_link" link2="finger_right_link" reason="Never"/></robot>')
# A path of waypoints, and random states as the replay bags hold them.
path = [[0.0, 0.2 * k, 0.3, 0.0, 0.0, 0.0, 0.0] for k in range(8)]
w(c + "path.jsonl", state_lines(joint_messages(path)))
JS = joint_messages(states(300, 7))
w(c + "random.jsonl", state_lines(JS))


# --- /tf: link poses by yourdfpy's forward kinematics -------------------------------------------
def quat(m):
    # Rotation matrix to (x, y, z, w), Shepperd's method.
    t = m[0][0] + m[1][1] + m[2][2]
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        return [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s]
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(1.0 + m[i][i] - m[j][j] - m[k][k]) * 2
    q = [0.0] * 4
    q[i] = 0.25 * s
    q[j] = (m[j][i] + m[i][j]) / s
    q[k] = (m[k][i] + m[i][k]) / s
    q[3] = (m[k][j] - m[j][k]) / s
    return q


import numpy as np  # noqa: E402
import yourdfpy  # noqa: E402

text = re.sub(r"<capsule\b", "<cylinder", (IN / "config" / "example_workcell" / "robot.urdf").read_text())
robot = yourdfpy.URDF.load(io.BytesIO(text.encode()), load_meshes=False, load_collision_meshes=False, build_scene_graph=True, build_collision_scene_graph=False)
tf_msgs, tf_lines = [], []
for k, q in enumerate(states(120, 11)):
    cfg = dict(zip(NAMES, q))
    robot.update_cfg(np.array([cfg.get(n, 0.0) for n in robot.actuated_joint_names]))
    tfs, line = [], []
    for link in LINKS:
        T = np.asarray(robot.get_transform(frame_to=link, frame_from=robot.base_link), dtype=float)
        tr = [float(x) for x in T[:3, 3]]
        r = [float(x) for x in quat(T[:3, :3].tolist())]
        tfs.append({"parent": "world", "child": link, "translation": tr, "rotation": r})
        line.append({"link": link, "translation": tr, "rotation": r})
    t = T0 + k * 10_000_000
    tf_msgs.append({"t": t, "stamp": t, "transforms": tfs})
    tf_lines.append(json.dumps({"transforms": line, "stamp": t}) + "\n")
w(c + "tf.jsonl", "".join(tf_lines))

# --- areas (tests/cli_areas.rs) ----------------------------------------------------------------
a = "areas/"
import struct  # noqa: E402

stl = bytearray(b"solid but binary".ljust(80, b" "))
tris = [[[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 0, 0], [1, 0, 0], [1, 1, 0]], [[0, 0, 0], [1, 1, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0], [0, 0, 0]]]
stl += struct.pack("<I", len(tris))
for t in tris:
    stl += bytes(12) + b"".join(struct.pack("<3f", *v) for v in t) + bytes(2)
w(a + "square.stl", bytes(stl))
w(a + "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
w(a + "garbage.stl", "not a mesh at all")
w(a + "nan.obj", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n")
w(a + "empty.obj", "# nothing\n")
w(a + "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")
w(a + "mesh.txt", "x")
w(a + "mixed_corners.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\nf 2 4 3\n")

# --- hostile input (tests/hostile_input.rs) ----------------------------------------------------
h = "hostile/"
TETRA = "v 0 0 -0.05\nv 0.1 0 -0.05\nv 0 0.1 -0.05\nv 0 0 0.05\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
DAE = """<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<library_geometries><geometry id="g"><mesh>
<source id="p"><float_array id="pa" count="12">0 0 -0.05 0.1 0 -0.05 0 0.1 -0.05 0 0 0.05</float_array>
<technique_common><accessor source="#pa" count="4" stride="3"><param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
<triangles count="4"><input semantic="VERTEX" source="#v" offset="0"/><p>0 2 1 0 1 3 0 3 2 1 2 3</p></triangles>
</mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s"><node><instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>
<scene><instance_visual_scene url="#s"/></scene></COLLADA>
"""


def probe(name, geometry, joint_extra="", axis="0 0 1"):
    return w(h + name, f'<robot name="probe"><link name="base"/><link name="probe"><collision><origin xyz="0.2 0 0"/><geometry>{geometry}</geometry></collision></link>\n'
             f'<joint name="j" type="revolute"><parent link="base"/><child link="probe"/><axis xyz="{axis}"/><limit lower="-1" upper="1" effort="1" velocity="1"/>{joint_extra}</joint></robot>')


def mesh_robot(name, mesh):
    return probe(name, f'<mesh filename="{IN / h / mesh}"/>')


w(h + "deep.urdf", f'<robot name="r"><link name="a"/>{nested("<x>", "</x>", 20_000)}</robot>')
w(h + "deep.dae", DAE.replace("<mesh>", "<mesh>" + nested("<extra>", "</extra>", 20_000)))
mesh_robot("deep_dae.urdf", "deep.dae")
lol = "".join(f'<!ENTITY l{i} "{("&l%d;" % (i - 1)) * 10}">' for i in range(1, 9))
w(h + "bomb.dae", DAE.replace("<COLLADA", f'<!DOCTYPE COLLADA [<!ENTITY l0 "lol">{lol}]>\n<COLLADA', 1).replace("0 0 -0.05 0.1", "&l8; 0 -0.05 0.1"))
mesh_robot("bomb_dae.urdf", "bomb.dae")
w(h + "bomb.urdf", f'<!DOCTYPE robot [<!ENTITY l0 "lol">{lol}]>\n<robot name="&l8;"><link name="a"/></robot>')
for i, g in enumerate(['<cylinder radius="1e300" length="1"/>', '<cylinder radius="0.1" length="1e155"/>', '<cylinder radius="0.1" length="1e14"/>',
                       '<capsule radius="1e154" length="1"/>', '<box size="1e80 1 1"/>', '<sphere radius="1e-9"/>']):
    probe(f"huge_{i}.urdf", g)
for i, g in enumerate(['<cylinder radius="0.05" length="1e4"/>', '<box size="1e4 1e4 0.1"/>', '<cylinder radius="1e4" length="0.1"/>', '<box size="1 1 1e-6"/>']):
    probe(f"edge_{i}.urdf", g)
probe("ok.urdf", '<box size="0.1 0.1 0.1"/>')
probe("axis_big.urdf", '<box size="0.3 0.05 0.1"/>', axis="1e160 0 0")
probe("axis_unit.urdf", '<box size="0.3 0.05 0.1"/>', axis="1 0 0")
mkfifo(h + "pipe.stl")
mesh_robot("fifo.urdf", "pipe.stl")
symlink(h + "zero.stl", "/dev/zero")
mesh_robot("zero.urdf", "zero.stl")
with open(IN / h / "sparse.stl", "wb") as f:
    f.truncate(2 << 30)
mesh_robot("sparse.urdf", "sparse.stl")
mkfifo(h + "states.jsonl")
mkfifo(h + "mtl_pipe.mtl")
symlink(h + "mtl_zero.mtl", "/dev/zero")
for mtl in ["mtl_pipe.mtl", "mtl_zero.mtl"]:
    w(h + f"with_{mtl}.obj", f"mtllib {mtl}\nusemtl steel\n{TETRA}")
    mesh_robot(f"mtl_{mtl}.urdf", f"with_{mtl}.obj")
mkfifo(h + "robot_pipe.urdf")
w(h + "good.dae", DAE)
mesh_robot("good_dae.urdf", "good.dae")
for name, (old, new) in {"index_past": ("1 2 3</p>", "1 2 9</p>"), "stride_zero": ('stride="3"', 'stride="0"'), "stride_huge": ('stride="3"', 'stride="4000000000"'),
                         "missing_source": ('source="#v"', 'source="#nowhere"'), "count_huge": ('<triangles count="4"', '<triangles count="4000000000"'),
                         "array_count_huge": ('count="12"', 'count="4000000000"')}.items():
    w(h + f"{name}.dae", DAE.replace(old, new))
    mesh_robot(f"{name}.urdf", f"{name}.dae")
w(h + "short.stl", bytes(80) + struct.pack("<I", 2) + bytes(50))
mesh_robot("short_stl.urdf", "short.stl")
for name, face in [("zero", "f 0 1 2"), ("negative", "f -9 1 2"), ("past", "f 1 2 99")]:
    w(h + f"face_{name}.obj", f"{TETRA}{face}\n")
    mesh_robot(f"face_{name}.urdf", f"face_{name}.obj")
w(h + "tetra.obj", TETRA)
g = '<box size="0.1 0.1 0.1"/>'
for name, extra in [("mimic_nan", '<mimic joint="j" multiplier="nan"/>'), ("mimic_inf", '<mimic joint="j" offset="inf"/>')]:
    w(h + f"{name}.urdf", f'<robot name="m"><link name="base"/><link name="probe"><collision><geometry>{g}</geometry></collision></link><link name="f"><collision><geometry>{g}</geometry></collision></link>\n'
      f'<joint name="j" type="revolute"><parent link="base"/><child link="probe"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n'
      f'<joint name="k" type="revolute"><parent link="probe"/><child link="f"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>{extra}</joint></robot>')
w(h + "limits_nan.urdf", '<robot name="l"><link name="base"/><link name="probe"/><joint name="j" type="revolute"><parent link="base"/><child link="probe"/><axis xyz="0 0 1"/><limit lower="nan" upper="1" effort="1" velocity="1"/></joint></robot>')
probe("limits_order.urdf", g)
p = IN / h / "limits_order.urdf"
p.write_text(p.read_text().replace('lower="-1" upper="1"', 'lower="2" upper="1"'))
w(h + "dup.jsonl", '{"name": ["j", "j"], "position": [0.1, 0.2]}\n')
pose = {"link": "probe", "translation": [0.2, 0.0, 0.0], "rotation": [0.0, 0.0, 0.0, 1.0]}
w(h + "dup_tf.jsonl", json.dumps({"transforms": [pose, pose]}) + "\n")
(IN / h / "pkg").mkdir()
params(h + "pkg_params.yaml", f'    package_map: ["pkg={IN / h / "pkg"}"]\n')
probe("escape_1.urdf", '<mesh filename="package://pkg/../../../etc/passwd.stl"/>')
probe("escape_2.urdf", '<mesh filename="package://pkg//etc/passwd.stl"/>')
probe("empty_geometry.urdf", "")
probe("two_shapes.urdf", '<box size="1 1 1"/><sphere radius="1"/>')
w(h + "hex.urdf", '<robot name="h"><link name="a"><collision><origin xyz="0x10 0 0"/><geometry><sphere radius="1"/></geometry></collision></link></robot>')
probe("missing_mesh.urdf", '<mesh filename="/nonexistent/part.stl"/>')
w(h + "roots.urdf", '<robot name="r">' + "".join(f'<link name="root_{i}"/>' for i in range(100_000)) + "</robot>")
w(h + "shape.jsonl", '{"joints": {"j": 1}}\n')
w(h + "bom.jsonl", '\ufeff{"name": ["j"], "position": [0.3]}\n')
w(h + "alias.yaml", 'a: &a ["x", "x"]\nb: &b [*a, *a]\nthickness_collision:\n  ros__parameters:\n    checked_links: *b\n')
params(h + "deep.yaml", f"    x: {'[' * 10_000}{']' * 10_000}\n")

# --- real inputs (tests/real_inputs.rs) ---------------------------------------------------------
r = "real/"
(IN / r).mkdir()
shutil.copy(IN / "fixtures" / "panda.urdf.xacro", IN / r / "panda_config.urdf")
params(r + "panda.yaml", f'    package_map: ["example-robot-data={erd}"]\n')
shutil.copy(IN / "fixtures" / "panda_arm.xacro", IN / r / "panda_arm.xacro")
w(r + "panda_arm_local.srdf.xacro", '<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="panda">\n'
  '  <xacro:include filename="panda_arm.xacro"/>\n  <xacro:panda_arm/>\n</robot>\n')
x = subprocess.run([sys.executable, "-c", "import sys, xacro; sys.argv[0] = 'xacro'; xacro.main()", str(IN / r / "panda_arm_local.srdf.xacro"), "-o", str(IN / r / "panda_arm.srdf")],
                   capture_output=True)
if x.returncode != 0:
    sys.exit(f"xacro: {x.stderr.decode()}")
w(r + "visual_only.urdf", """<robot name="shown_only">
  <link name="base"><visual><geometry><box size="0.2 0.2 0.2"/></geometry></visual></link>
  <link name="arm"><visual><geometry><cylinder radius="0.05" length="0.5"/></geometry></visual></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>""")
params(r + "nothing.yaml", '    checked_links: ["no_such_link*"]\n')
params(r + "visual.yaml", "    use_visual_when_no_collision: true\n")
w(r + "foreign.jsonl", json.dumps({"name": ["panda_joint1", "panda_joint2"], "position": [0.0, 0.3]}) + "\n" + json.dumps({"name": [], "position": []}) + "\n"
  + json.dumps({"name": ARM8, "position": [0.0] * 8}) + "\n")
w(r + "split.jsonl", json.dumps({"name": ARM8[:3], "position": [0.0, 1.2, 0.3]}) + "\n" + json.dumps({"name": ARM8[3:], "position": [0.0] * 5}) + "\n")
w(r + "whole.jsonl", json.dumps({"name": ARM8, "position": [0.0, 1.2, 0.3, 0.0, 0.0, 0.0, 0.0, 0.0]}) + "\n")
params(r + "upper.yaml", "    checked_links: [upper_arm_link]\n")
params(r + "zero.yaml", "    missing_joint: zero\n")
renamed = (URDF.replace('<link name="', '<link name="r2_').replace('<joint name="', '<joint name="r2_')
           .replace(' link="', ' link="r2_').replace(' joint="', ' joint="r2_'))
w(r + "r2.srdf", '<robot name="r2_arm"><disable_collisions link1="r2_base_link" link2="r2_shoulder_link" reason="Adjacent"/></robot>')
w(r + "wrong.srdf", '<robot name="x"><disable_collisions link1="panda_link0" link2="panda_link1"/></robot>')
# An installed binary: bin/ beside share/thickness_collision/config (the binary is copied per run).
share = IN / "prefix" / "share" / "thickness_collision" / "config"
shutil.copytree(IN / "config" / "example_workcell", share / "example_workcell")
shutil.copy(IN / "config" / "params.yaml", share / "params.yaml")
(IN / "prefix" / "bin").mkdir()

# --- bags (tests/replay_bags.rs, replay_compressed.rs, hostile_input.rs, real_inputs.rs) ---------
b = "bags/"
for storage in ["mcap", "sqlite3"]:
    bag(b + f"js_{storage}", storage, JS)
    bag(b + f"tf_{storage}", storage, tf_msgs)
    und = joint_messages(states(400, 5))
    und[200] = {"t": und[200]["t"], "raw": [0, 1, 0, 0, 255, 255, 255]}
    bag(b + f"undecodable_{storage}", storage, und)
bag(b + "desc", "mcap", joint_messages(states(50, 3)), URDF)
bag(b + "cut", "mcap", joint_messages(states(1000, 5)))
f = storage_file(b + "cut", ".mcap")
data = f.read_bytes()
f.write_bytes(data[: len(data) * 6 // 10])
bag(b + "corrupt_db", "sqlite3", joint_messages(states(10, 5)))
storage_file(b + "corrupt_db", ".db3").write_bytes(b"this is not a database, it only has the name of one")
w(b + "notes.txt", "x")
bag(b + "small", "mcap", joint_messages(states(5, 1)))
plain = [{"t": 1_000_000_000 + i * 100_000_000, "stamp": i, "name": NAMES, "position": [0.0, 1.2 * i / 4.0, 0.3, 0.0, 0.0, 0.0, 0.0]} for i in range(5)]
bag(b + "plain_bag", "mcap", plain)
(IN / b / "twice_bag").mkdir()
meta = (IN / b / "plain_bag" / "metadata.yaml").read_text()
f = storage_file(b + "plain_bag", ".mcap")
shutil.copy(f, IN / b / "twice_bag" / f.name)
(IN / b / "twice_bag" / "metadata.yaml").write_text(meta.replace(f"- {f.name}", f"- {f.name}\n  - {f.name}", 1))
bag(b + "deep_bag", "mcap", plain, f'<robot name="r">{nested("<x>", "</x>", 20_000)}</robot>')
bag(b + "panda_bag", "mcap", joint_messages([[0.0, 0.1], [0.2, 0.3], [0.4, 0.5]], ["panda_joint1", "panda_joint2"], 0))
bag(b + "j1_bag", "mcap", joint_messages([[0.0], [0.5]], ["j1"], 0))
bag(b + "arm_bag", "mcap", joint_messages([[0.0] * 8, [0.1] * 8], ARM8, 0), (IN / r / "visual_only.urdf").read_text())
bag(b + "r2_bag", "mcap", joint_messages([[0.0] * 8, [0.05] * 8], ["r2_" + j for j in ARM8], 0), renamed)
# Compressed as rosbag2 writes them, and by rosbags' writer.
for storage, ext in [("mcap", ".mcap"), ("sqlite3", ".db3")]:
    for mode in ["message", "file"]:
        copy_bag(b + f"js_{storage}", b + f"{mode}_{storage}")
        compress(mode, b + f"{mode}_{storage}")
        compress("rosbags", b + f"js_{storage}", out=str(IN / b / f"rosbags_{mode}_{storage}"), mode=mode)
    copy_bag(b + f"file_{storage}", b + f"file_cut_{storage}")
    z = storage_file(b + f"file_cut_{storage}", ext + ".zstd")
    data = z.read_bytes()
    z.write_bytes(data[: len(data) // 2])
small = joint_messages(states(5, 3), stamp_offset=-1234)
bag(b + "cplain", "mcap", small)
copy_bag(b + "cplain", b + "ros1")
compress("encoding", b + "ros1", topic="/joint_states", encoding="ros1")
copy_bag(b + "cplain", b + "lz4")
compress("message", b + "lz4")
compress("format", b + "lz4", format="lz4")
junk = [{"t": m["t"], "raw": [0, 1, 0, 0, 255, 255, 255]} for m in small]
for storage in ["mcap", "sqlite3"]:
    bag(b + f"junk_{storage}", storage, junk)
    mixed = list(junk)
    mixed[2] = small[2]
    bag(b + f"mixed_{storage}", storage, mixed)
bag(b + "one_junk", "mcap", junk[:1])
bag(b + "tf_only", "sqlite3", [{"t": T0, "stamp": T0, "transforms": []}])
# Each bag's storage file under a fixed name, for the commands that take a bare file.
for name, ext in [("js_mcap", ".mcap"), ("js_sqlite3", ".db3"), ("message_mcap", ".mcap"), ("message_sqlite3", ".db3"),
                  ("file_mcap", ".mcap.zstd"), ("file_sqlite3", ".db3.zstd")]:
    shutil.copy(storage_file(b + name, ext), IN / b / f"bare_{name}{ext}")

# --- more edges: a robot with no actuated joint, rcl's sections, bad metadata, outputs ----------
w(c + "fixed.urdf", '<robot name="fixed_only"><link name="base"/><link name="arm"><collision><origin xyz="0.2 0 0"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>\n'
  '<joint name="f" type="fixed"><parent link="base"/><child link="arm"/></joint></robot>')
w(c + "fixed.jsonl", '{"name": ["f"], "position": [0]}\n{"name": [], "position": []}\n{"name": ["other"], "position": [1]}\n')
w(c + "sections.yaml", "/**:\n  ros__parameters:\n    default_thickness: 0.05\n    use_sim_time: true\n"
  "thickness_collision:\n  ros__parameters:\n    default_side: both\n"
  "/**/thickness_collision:\n  ros__parameters:\n    motion_tolerance: 0.002\n"
  "other_node:\n  ros__parameters:\n    default_thickness: 0.9\n")
meta = (IN / b / "small" / "metadata.yaml").read_text()
small_file = storage_file(b + "small", ".mcap")
for name, text in [("meta_bad_yaml", "rosbag2_bagfile_information: [unclosed\n"),
                   ("meta_no_paths", re.sub(r"relative_file_paths:\n(\s+- .*\n)+", "relative_file_paths: []\n", meta)),
                   ("meta_escape", meta.replace(f"- {small_file.name}", "- ../small/" + small_file.name, 1)),
                   ("meta_unknown_storage", re.sub(r"storage_identifier: \w+", "storage_identifier: rosbag_v1", meta)),
                   ("meta_missing_file", meta.replace(f"- {small_file.name}", "- missing.mcap", 1)),
                   ("meta_bad_mode", re.sub(r"compression_mode: ?.*", "compression_mode: SOMETIMES", meta).replace("compression_format: ''", "compression_format: zstd"))]:
    (IN / b / name).mkdir()
    shutil.copy(small_file, IN / b / name / small_file.name)
    (IN / b / name / "metadata.yaml").write_text(text)
(IN / b / "empty_dir").mkdir()
w(b + "garbage.mcap", "not an mcap file at all")
w(b + "garbage.db3", "not a database file at all")
w(b + "garbage.mcap.zstd", "not a zstd file at all")
w("exists/bag/keep.txt", "an existing output folder\n")
