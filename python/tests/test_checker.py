"""The Python package against the CLI's `check --json` (the same library, through its own door),
and its own promises: batches equal single checks, bad input raises, the GIL is released, one
Checker serves many threads."""

import math
import threading
import time

import numpy as np
import pytest

import thickness_collision as tc
from conftest import cli_json

STATES = 300


def random_states(checker, n, seed):
    rng = np.random.default_rng(seed)
    lo, hi = checker.limits
    return lo + (hi - lo) * rng.random((n, len(lo)))


def assert_same_report(got, want, what):
    assert got["in_collision"] == want["in_collision"], what
    assert got["error"] == want["error"], what
    assert got.get("fraction") == want.get("fraction"), what
    key = lambda c: (c["link_name"], c["object_name"])
    assert sorted(map(key, got["contacts"])) == sorted(map(key, want["contacts"])), what
    for a, b in zip(sorted(got["contacts"], key=key), sorted(want["contacts"], key=key)):
        assert a["triangle"] == b["triangle"], what
        assert abs(a["depth"] - b["depth"]) <= 1e-9, what


def test_check_equals_check_json(panda, panda_params):
    q = random_states(panda, STATES, 1)
    names = panda.joint_names
    want = cli_json(["--params-file", str(panda_params)], [{"name": names, "position": list(map(float, r))} for r in q])
    assert len(want) == STATES
    colliding = 0
    for i, (row, w) in enumerate(zip(q, want)):
        r = panda.check(row)
        d = r.to_dict()
        assert_same_report(d, w, f"state {i}")
        # The attributes say what the dict says.
        assert r.in_collision == d["in_collision"] and len(r.contacts) == len(d["contacts"])
        for c, cd in zip(r.contacts, d["contacts"]):
            assert (c.link_name, c.object_name, c.object_type, c.triangle, c.depth) == (cd["link_name"], cd["object_name"], cd["object_type"], cd["triangle"], cd["depth"])
            assert (c.link, c.object, c.point) == (c.link_name, c.object_name, tuple(cd["position"]) if cd["position"] else None)
            assert c.normal == tuple(cd["normal"])
        colliding += r.in_collision
    assert STATES // 10 < colliding < STATES, f"{colliding} of {STATES} states collide: both outcomes are needed"


def test_positions_as_list_array_and_dict_agree(panda):
    row = random_states(panda, 1, 2)[0]
    by_name = dict(zip(panda.joint_names, map(float, row)))
    reports = [panda.check(row).to_dict(), panda.check(list(row)).to_dict(), panda.check(by_name).to_dict()]
    assert reports[0] == reports[1] == reports[2]


def test_check_batch_equals_check(panda):
    q = random_states(panda, 400, 3)
    flags = panda.check_batch(q)
    assert flags.dtype == np.bool_ and flags.shape == (400,)
    flags2, depths = panda.check_batch(q, depths=True)
    for i, row in enumerate(q):
        r = panda.check(row)
        assert flags[i] == flags2[i] == r.in_collision, i
        assert depths[i] == pytest.approx(max((c.depth for c in r.contacts), default=0.0), abs=1e-12), i
    assert 0 < flags.sum() < 400


def test_check_motion_equals_check_motion_json(panda, panda_params):
    rng = np.random.default_rng(4)
    q0 = random_states(panda, 60, 5)
    q1 = np.clip(q0 + rng.uniform(-0.6, 0.6, q0.shape), *panda.limits)
    names = panda.joint_names
    lines = []
    for a, b in zip(q0, q1):
        lines += [{"name": names, "position": list(map(float, a))}, {"name": names, "position": list(map(float, b))}]
    want = cli_json(["--params-file", str(panda_params), "--motion"], lines)
    flags, fractions = panda.check_motions(q0, q1)
    colliding = 0
    for i, (a, b) in enumerate(zip(q0, q1)):
        w = want[2 * i + 1]
        assert w["motion"]
        r = panda.check_motion(a, b)
        assert r.motion and r.in_collision == w["in_collision"], i
        assert_same_report(r.to_dict(), w, f"motion {i}")
        assert flags[i] == r.in_collision
        assert (math.isnan(fractions[i]) and r.fraction is None) or fractions[i] == r.fraction
        colliding += r.in_collision
    assert 0 < colliding < 60
    # A path stops at its first edge in collision.
    path = np.vstack([q0[0], q1[0], q0[1], q1[1]])
    reports = panda.check_path(path)
    assert 1 <= len(reports) <= 3 and all(not r.in_collision for r in reports[:-1])


def test_bad_input_raises_with_a_clear_message(panda):
    n = len(panda.joint_names)
    with pytest.raises(ValueError, match=f"q has {n - 1} values; joint_names has {n}"):
        panda.check(np.zeros(n - 1))
    bad = np.zeros(n)
    bad[2] = np.nan
    with pytest.raises(ValueError, match=rf"q\[2\] \({panda.joint_names[2]}\) is NaN"):
        panda.check(bad)
    with pytest.raises(ValueError, match="no_such_joint"):
        panda.check({"no_such_joint": 0.1})
    with pytest.raises(ValueError, match=r"Q\[1\]"):
        panda.check_batch(np.array([[0.0] * n, [0.0] * (n - 1) + [math.inf]]))
    with pytest.raises(ValueError, match="vertices\\[1\\]"):
        tc.areas(np.array([[0, 0, 0], [np.nan, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]))
    with pytest.raises(ValueError, match="faces\\[0\\]"):
        tc.areas(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 7]]))
    with pytest.raises(tc.Error, match="clearance_threshold"):
        panda.clearance(np.zeros(n))
    with pytest.raises(tc.Error, match="no_such.urdf"):
        tc.Checker(robot="no_such.urdf")
    with pytest.raises(ValueError, match="thickness"):
        tc.Checker(thickness=-1.0)


def test_check_batch_releases_the_gil(panda):
    q = random_states(panda, 20000, 6)
    ticks = 0
    done = threading.Event()

    def count():
        nonlocal ticks
        while not done.is_set():
            ticks += 1
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    started = time.perf_counter()
    panda.check_batch(q)
    took = time.perf_counter() - started
    done.set()
    t.join()
    # Held, the counter would not run at all until the batch returns.
    assert took > 0.05 and ticks >= 10, f"{ticks} ticks in {took:.3f} s"


def test_one_checker_serves_many_threads(panda):
    q = random_states(panda, 200, 7)
    want = [panda.check(r).to_dict() for r in q]
    got = [None] * len(q)

    def work(k):
        for i in range(k, len(q), 4):
            got[i] = panda.check(q[i]).to_dict()

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for g, w in zip(got, want):
        g.pop("check_seconds", None), w.pop("check_seconds", None)
        assert g == w


def test_clearance(panda_params):
    c = tc.Checker(params=panda_params, clearance_threshold=0.3)
    found = 0
    for row in random_states(c, 50, 8):
        cl = c.clearance(row)
        report = c.check(row)
        # Signed: minus the depth for a link in contact, the gap for one within the threshold.
        assert [x.link_name for x in cl] == [x.link_name for x in report.clearances]
        for x in cl:
            touching = any(k.link_name == x.link_name and k.object_type == "environment" for k in report.contacts)
            assert x.distance <= 0.3 and (x.distance <= 0.0) == touching, x
        found += len(cl)
    assert found > 0


def test_joint_names_and_limits(panda):
    assert panda.joint_names == [f"panda_joint{i}" for i in range(1, 8)] + ["panda_finger_joint1"]
    lo, hi = panda.limits
    assert lo.shape == hi.shape == (8,) and np.all(lo < hi)
    assert lo[3] == pytest.approx(-3.0718) and hi[3] == pytest.approx(-0.0698)


def test_bundled_workcell():
    c = tc.Checker()
    assert len(c.joint_names) == 7 and "workcell" in repr(c)
    assert not c.check(np.zeros(7)).in_collision


def test_link_poses_match_yourdfpy(panda, panda_urdf):
    import yourdfpy  # an independent URDF parser and FK (scripts/setup_venv.sh)

    robot = yourdfpy.URDF.load(str(panda_urdf), load_meshes=False, build_scene_graph=True, load_collision_meshes=False)
    base = np.eye(4)
    base[2, 3] = 0.005  # panda_params' robot_base_pose
    for row in random_states(panda, 20, 13):
        robot.update_cfg({n: float(v) for n, v in zip(panda.joint_names, row) if n in robot.actuated_joint_names})
        ours = panda.link_poses(row)
        for link in ["panda_link3", "panda_link7", "panda_hand", "panda_leftfinger"]:
            np.testing.assert_allclose(ours[link], base @ robot.get_transform(link), atol=1e-9)


def test_collision_geometry_is_what_is_checked(panda):
    geometry = panda.collision_geometry()
    assert "panda_hand" in geometry and all(len(parts) >= 1 for parts in geometry.values())
    kind, points, offset = geometry["panda_hand"][0]
    assert kind == "hull" and points.shape[1] == 3 and offset.shape == (4, 4)
