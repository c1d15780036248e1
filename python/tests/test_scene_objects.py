"""MoveIt's planning-scene objects applied to a Checker at run time, as the node applies the
`collision_object` and `attached_collision_object` topics: added, moved, removed, attached and
detached, each in force for the next check."""

import numpy as np
import pytest

import thickness_collision as tc
from meshes import grid_sheet
from thickness_collision.messages import MOVE, REMOVE


def sheet(n=4, size=0.12):
    return grid_sheet(n, size, centred=True)


@pytest.fixture()
def panda_scene(panda_params):
    return tc.Checker.from_params(panda_params)


def free_states(checker, n, seed):
    rng = np.random.default_rng(seed)
    lo, hi = checker.limits
    out = []
    while len(out) < n:
        q = lo + (hi - lo) * rng.random(len(lo))
        if not checker.check(q).in_collision:
            out.append(q)
    return out


def test_objects_are_added_moved_and_removed(panda_scene):
    c = panda_scene
    q = free_states(c, 1, 11)[0]
    v, f = sheet()
    # A thin sheet placed at the hand (a robot link frame: placed at the joint state given).
    c.apply_collision_object(tc.collision_object("sheet", vertices=v, faces=f, frame_id="panda_hand"), q=q)
    assert c.scene_object_count == (1, 0)
    r = c.check(q)
    assert r.in_collision and any(k.object_name == "sheet" for k in r.contacts), r.to_dict()
    # Moved far away: free again; the triangle indices are the mesh's.
    c.apply_collision_object(tc.collision_object("sheet", pose=tc.pose((5.0, 5.0, 5.0)), operation=MOVE))
    assert not c.check(q).in_collision
    c.apply_collision_object(tc.collision_object("sheet", pose=tc.pose(), frame_id="panda_hand", operation=MOVE), q=q)
    hits = [k for k in c.check(q).contacts if k.object_name == "sheet"]
    assert hits and all(0 <= k.triangle < len(f) for k in hits)
    c.apply_collision_object(tc.collision_object("sheet", operation=REMOVE))
    assert c.scene_object_count == (0, 0) and not c.check(q).in_collision


def test_an_attached_box_moves_with_the_hand(panda_scene):
    c = panda_scene
    states = free_states(c, 60, 12)
    tray = tc.collision_object("tray", box=(0.4, 0.4, 0.02), pose=tc.pose((0.0, 0.0, 0.12)), frame_id="panda_hand")
    c.apply_attached_collision_object(tc.attached_object("panda_hand", tray, ["panda_hand", "panda_leftfinger", "panda_rightfinger"]), q=states[0])
    assert c.scene_object_count == (0, 1)
    hit = [q for q in states if any(k.link_name == "tray" for k in c.check(q).contacts)]
    assert hit, "a 40 cm tray on the hand meets something in some of 60 states"
    # The motion check carries it too.
    assert c.check_motion(states[0], hit[0]).in_collision
    # Detached (REMOVE), it stays in the world where it is at the current state.
    c.apply_attached_collision_object(tc.attached_object("panda_hand", {"id": "tray", "operation": REMOVE}), q=states[0])
    assert c.scene_object_count == (1, 0)


def test_bad_scene_messages_raise(panda_scene):
    c = panda_scene
    with pytest.raises(ValueError, match="has no field 'mehses'"):
        c.apply_collision_object({"id": "x", "mehses": []})
    with pytest.raises(ValueError, match="frame"):
        c.apply_collision_object(tc.collision_object("x", box=(0.1, 0.1, 0.1), frame_id="no_such_frame"))
    with pytest.raises(ValueError, match="panda_link3"):
        c.apply_collision_object(tc.collision_object("panda_link3", box=(0.1, 0.1, 0.1)))
    assert c.scene_object_count == (0, 0)
