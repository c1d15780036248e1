"""OMPL RRTConnect on the Panda among thin sheets, with this package's validators beside coal with
OMPL's default discrete motion validation (issue 35). Command (from the repository):

    $TC_PYTHON -m maturin develop --release -m python/Cargo.toml
    OPENBLAS_NUM_THREADS=1 $TC_PYTHON benches/ompl_plans.py [QUERIES] [TIMEOUT_S]   # 100 and 5 by default

The world is the bundled workcell's environment (a table, a corrugated guard sheet, an open shelf
of sheet metal, a bent panel: single-layer meshes, thin surfaces with 2-3 cm of cells) with the
Panda of example-robot-data (its SRDF) at the origin, 5 mm above the table. Queries: start and
goal drawn with a fixed seed, free for both checkers; OMPL's RNG seeded per query, the same seed
for both setups.

Start and goal each have some link within 5 cm of a sheet (queries among the sheets).

- ours: `StateValidityChecker` and the guaranteed `MotionValidator` (environment and self pairs);
- coal: a state is valid when no link's hull (the same hulls, at the same link poses) meets the
  bare triangles or the table (coal 3, OBBRSS), self pairs not checked; OMPL's default
  `DiscreteMotionValidator` at the default resolution (0.01 of the space's extent).

Every returned path is judged densely (steps at which no point of the arm moves more than 5 mm,
with the 1.2 m lever bound; every Panda link is thicker than that): on the bare meshes (coal on
each sample: a link meets a triangle) and on the cells (this package's check, environment contacts
only: a link inside the 2-3 cm behind a sheet). Prints a markdown table.
"""

import math
import pathlib
import site
import sys
import time

import coal
import numpy as np
import yourdfpy
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou
from scipy.spatial import ConvexHull

import thickness_collision as tc
from thickness_collision import ompl as tco

ROOT = pathlib.Path(__file__).resolve().parents[1]
QUERIES = int(sys.argv[1]) if len(sys.argv) > 1 else 100
TIMEOUT = float(sys.argv[2]) if len(sys.argv) > 2 else 5.0
STEP = 0.005  # metres at the fastest point, for the oracle
REACH = 1.2
SHEETS = {"guard_sheet", "shelf", "bent_panel"}
ou.setLogLevel(ou.LOG_ERROR)


def erd():
    for p in site.getsitepackages():
        share = pathlib.Path(p) / "cmeel.prefix" / "share" / "example-robot-data"
        if share.is_dir():
            return share
    raise SystemExit("example-robot-data is not installed (scripts/setup_venv.sh)")


def panda_checker(tmp):
    share = erd()
    env = ROOT / "config" / "example_workcell" / "environment.urdf"
    params = tmp / "panda.yaml"
    params.write_text(
        "/**/thickness_collision:\n  ros__parameters:\n"
        f"    robot_description_file: {share}/robots/panda_description/urdf/panda.urdf\n"
        f"    environment_file: {env}\n"
        f"    robot_semantic_file: {share}/robots/panda_description/srdf/panda.srdf\n"
        "    robot_base_pose: [0.0, 0.0, 0.005, 0.0, 0.0, 0.0]\n"
        f"    package_map: [\"example-robot-data={share}\"]\n"
    )
    return tc.Checker.from_params(params), env


def coal_world(env_urdf):
    """The environment's collision geometry, bare, in the world: one coal object per geometry."""
    urdf = yourdfpy.URDF.load(str(env_urdf), load_collision_meshes=True, build_collision_scene_graph=True, load_meshes=False)
    scene = urdf.collision_scene
    objects = []
    for node in scene.graph.nodes_geometry:
        transform, name = scene.graph[node]
        mesh = scene.geometry[name]
        V = np.asarray(mesh.vertices, dtype=float)
        T = np.asarray(mesh.faces, dtype=np.int64)
        bvh = coal.BVHModelOBBRSS()
        bvh.beginModel(len(T), len(V))
        bvh.addVertices(V)
        bvh.addTriangles(T)
        bvh.endModel()
        objects.append((bvh, coal.Transform3s(np.asarray(transform[:3, :3], dtype=float).copy(), np.asarray(transform[:3, 3], dtype=float).copy())))
    return objects


def coal_links(checker):
    """Each checked link's hulls (the same points this package checks) as coal.Convex."""
    parts = []
    for link, shapes in checker.collision_geometry().items():
        for kind, points, offset in shapes:
            assert kind == "hull", kind
            pts = (offset[:3, :3] @ np.asarray(points).T).T + offset[:3, 3]
            hull = ConvexHull(pts)
            verts = coal.StdVec_Vec3s()
            for v in pts[hull.vertices]:
                verts.append(np.asarray(v, dtype=float))
            index = {int(k): i for i, k in enumerate(hull.vertices)}
            tris = coal.StdVec_Triangle()
            for a, b, c in hull.simplices:
                tris.append(coal.Triangle(index[int(a)], index[int(b)], index[int(c)]))
            parts.append((link, coal.Convex(verts, tris)))
    return parts


class CoalState:
    """The coal setup's state check: any link hull meeting a bare triangle or the table."""

    def __init__(self, checker, world, links):
        self.checker, self.world, self.links = checker, world, links
        self.req, self.res = coal.CollisionRequest(), coal.CollisionResult()
        self.calls = 0

    def collides(self, q):
        poses = self.checker.link_poses(q)
        for link, shape in self.links:
            p = poses[link]
            tf = coal.Transform3s(p[:3, :3].copy(), p[:3, 3].copy())
            for geom, gtf in self.world:
                self.res.clear()
                self.calls += 1
                if coal.collide(geom, gtf, shape, tf, self.req, self.res):
                    return True
        return False


class CoalValidity(ob.StateValidityChecker):
    def __init__(self, si, coal_state, dof):
        super().__init__(si)
        self.coal_state, self.dof = coal_state, dof

    def isValid(self, state):
        return not self.coal_state.collides([state[i] for i in range(self.dof)])


def set_state(space, values):
    s = space.allocState()
    for i, v in enumerate(values):
        s[i] = float(v)
    return s


def plan(checker, coal_state, start, goal, ours):
    space = tco.state_space(checker)
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()
    dof = len(checker.joint_names)
    if ours:
        ss.setStateValidityChecker(tco.StateValidityChecker(si, checker))
        si.setMotionValidator(tco.MotionValidator(si, checker))
    else:
        ss.setStateValidityChecker(CoalValidity(si, coal_state, dof))  # DiscreteMotionValidator, default resolution
    ss.setStartAndGoalStates(set_state(space, start), set_state(space, goal))
    ss.setPlanner(og.RRTConnect(si))
    started = time.perf_counter()
    solved = ss.solve(TIMEOUT)
    seconds = time.perf_counter() - started
    if not solved or not ss.haveExactSolutionPath():
        return None, seconds
    path = ss.getSolutionPath()
    return np.array([[path.getState(k)[i] for i in range(dof)] for k in range(path.getStateCount())]), seconds


def dense(path):
    for a, b in zip(path[:-1], path[1:]):
        n = max(1, math.ceil(REACH * float(np.abs(b - a).sum()) / STEP))
        for k in range(n + 1):
            yield a + (b - a) * (k / n)


def judge(checker, coal_state, path):
    """(meets a bare triangle, enters the cells) somewhere along the path, sampled densely."""
    samples = np.array(list(dense(path)))
    flags = checker.check_batch(samples)
    cells = any(any(c.object_type == "environment" for c in checker.check(q).contacts) for q in samples[flags])
    bare = any(coal_state.collides(q) for q in samples)
    return bare, cells, len(samples)


def main():
    tmp = ROOT / "target" / "ompl_plans"
    tmp.mkdir(parents=True, exist_ok=True)
    checker, env = panda_checker(tmp)
    coal_state = CoalState(checker, coal_world(env), coal_links(checker))
    rng = np.random.default_rng(35)
    # OMPL's RNG is seeded once, before any sampling: the queries then run in a fixed order.
    ou.RNG.setSeed(35)
    lo, hi = checker.limits
    near = tc.Checker(params=tmp / "panda.yaml", clearance_threshold=0.05)

    def free():
        """A state free for both checkers with some link within 5 cm of a thin sheet (queries
        among the sheets, not in open space)."""
        while True:
            q = lo + (hi - lo) * rng.random(len(lo))
            r = near.check(q)
            if r.in_collision or not any(c.object_name in SHEETS for c in r.clearances):
                continue
            if not coal_state.collides(q):
                return q

    rows = {True: [], False: []}
    planning_calls = {True: 0, False: 0}
    for k in range(QUERIES):
        start, goal = free(), free()
        for ours in (True, False):
            calls = coal_state.calls
            path, seconds = plan(checker, coal_state, start, goal, ours)
            planning_calls[ours] += coal_state.calls - calls
            verdict = judge(checker, coal_state, path) if path is not None else None
            rows[ours].append((seconds, path is not None, verdict))
        print(f"query {k}: ours {rows[True][-1][0]:.3f} s {rows[True][-1][2]}, coal {rows[False][-1][0]:.3f} s {rows[False][-1][2]}", file=sys.stderr)

    def line(name, rs):
        solved = [r for r in rs if r[1]]
        bare = sum(1 for r in solved if r[2][0])
        cells = sum(1 for r in solved if r[2][1])
        mean = sum(r[0] for r in rs) / len(rs)
        med = sorted(r[0] for r in rs)[len(rs) // 2]
        samples = sum(r[2][2] for r in solved)
        return f"| {name} | {len(solved)} of {len(rs)} | **{bare}** | **{cells}** | {mean:.3f} s (median {med:.3f} s) | {samples} |"

    print(f"Panda (SRDF) among the bundled workcell's thin sheets, {QUERIES} RRTConnect queries, {TIMEOUT} s each, seeds fixed:\n")
    print("| setup | solved | returned paths meeting a bare triangle | returned paths entering the cells | planning time per query | oracle samples |")
    print("|---|---|---|---|---|---|")
    print(line("this package: `StateValidityChecker` + guaranteed `MotionValidator` (environment and self pairs)", rows[True]))
    print(line("coal on the bare meshes, OMPL's `DiscreteMotionValidator` at its default resolution (environment only)", rows[False]))
    ours_t = sum(r[0] for r in rows[True])
    coal_t = sum(r[0] for r in rows[False])
    print(f"\nplanning time, this package / coal: {ours_t / coal_t:.3f}; coal collide calls while planning: {planning_calls[False]}")


if __name__ == "__main__":
    main()
