"""The geometry core without a robot: cells from arrays, and a scene with trimesh's habits."""

import numpy as np
import pytest

import thickness_collision as tc
from meshes import grid_sheet


def sheet(n=10, size=1.0):
    return grid_sheet(n, size)


def cube(half):
    return np.array([[x, y, z] for x in (-half, half) for y in (-half, half) for z in (-half, half)])


def at(x, y, z):
    t = np.eye(4)
    t[:3, 3] = (x, y, z)
    return t


def test_areas_put_a_cell_of_the_thickness_behind_every_triangle():
    v, f = sheet()
    cells = tc.areas(v, f, thickness=0.03)
    assert cells["back_cap"].shape == (len(f), 3, 3) and cells["normal"].shape == (len(f), 3)
    assert sorted(cells["triangle"]) == list(range(len(f)))
    np.testing.assert_allclose(cells["normal"], np.tile([0, 0, 1.0], (len(f), 1)), atol=1e-12)
    np.testing.assert_allclose(cells["back_cap"][:, :, 2], -0.03, atol=1e-12)
    np.testing.assert_allclose(cells["front_cap"][:, :, 2], 0.0, atol=1e-12)
    front = tc.areas(v, f, thickness=0.03, side="front")
    np.testing.assert_allclose(front["front_cap"][:, :, 2], 0.03, atol=1e-12)


def test_scene_sees_a_box_behind_a_sheet_and_follows_its_moves():
    v, f = sheet()
    scene = tc.Scene()
    scene.add_object("sheet", v, f, thickness=0.02)
    behind = at(0.5, 0.5, -0.025)  # wholly behind the surface, inside its cells
    box = cube(0.02)
    assert scene.in_collision_single(box, behind)
    assert scene.in_collision_single(box, behind, return_names=True) == (True, {"sheet"})
    assert not scene.in_collision_single(box, at(0.5, 0.5, 0.05))
    scene.set_transform("sheet", at(0.0, 0.0, 1.0))
    assert not scene.in_collision_single(box, behind)
    assert scene.in_collision_single(box, at(0.5, 0.5, 0.975))
    scene.add_object("block", cube(0.1), thin=False, transform=at(3, 0, 0))
    assert scene.names == ["sheet", "block"] and len(scene) == 2
    assert scene.in_collision_single(box, at(3.05, 0, 0), return_names=True) == (True, {"block"})
    scene.remove_object("sheet")
    assert scene.names == ["block"] and not scene.in_collision_single(box, at(0.5, 0.5, 0.975))
    with pytest.raises(ValueError, match="no object named 'sheet'"):
        scene.remove_object("sheet")
    with pytest.raises(ValueError, match="not a rotation"):
        scene.set_transform("block", np.diag([2.0, 1, 1, 1]))


def test_scene_takes_a_trimesh():
    import trimesh  # in the test venv (scripts/setup_venv.sh, through yourdfpy)

    v, f = sheet()
    scene = tc.Scene()
    scene.add_object("sheet", trimesh.Trimesh(vertices=v, faces=f, process=False))
    assert scene.in_collision_single(trimesh.creation.box(extents=[0.04] * 3), at(0.5, 0.5, -0.025))
