"""MoveIt's scene objects as the dicts ``Checker.apply_collision_object`` and
``Checker.apply_attached_collision_object`` take: ``moveit_msgs/CollisionObject`` and
``AttachedCollisionObject`` with the message's field names. Fields left out keep the message's
defaults.
"""

import math

ADD, REMOVE, APPEND, MOVE = 0, 1, 2, 3
BOX, SPHERE, CYLINDER, CONE = 1, 2, 3, 4

__all__ = ["ADD", "REMOVE", "APPEND", "MOVE", "BOX", "SPHERE", "CYLINDER", "CONE", "pose", "collision_object", "attached_object"]


def pose(position=(0.0, 0.0, 0.0), orientation=(0.0, 0.0, 0.0, 1.0), matrix=None):
    """A ``geometry_msgs/Pose``: a position and an ``(x, y, z, w)`` quaternion, or a 4 x 4 matrix."""
    if matrix is not None:
        m = [[float(x) for x in row] for row in matrix]
        position = (m[0][3], m[1][3], m[2][3])
        orientation = _quaternion(m)
    x, y, z = (float(v) for v in position)
    qx, qy, qz, qw = (float(v) for v in orientation)
    return {"position": {"x": x, "y": y, "z": z}, "orientation": {"x": qx, "y": qy, "z": qz, "w": qw}}


def _quaternion(m):
    t = m[0][0] + m[1][1] + m[2][2]
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        return ((m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s)
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(1.0 + m[i][i] - m[j][j] - m[k][k]) * 2
    q = [0.0, 0.0, 0.0, 0.0]
    q[i] = 0.25 * s
    q[j] = (m[j][i] + m[i][j]) / s
    q[k] = (m[k][i] + m[i][k]) / s
    q[3] = (m[k][j] - m[j][k]) / s
    return tuple(q)


def collision_object(id, *, mesh=None, vertices=None, faces=None, box=None, sphere=None, cylinder=None, pose=None, frame_id="world", operation=ADD):
    """A ``CollisionObject``: a mesh (a ``trimesh.Trimesh``, or ``vertices`` and ``faces``: a
    mesh with a boundary is a thin surface with cells behind it), a ``box`` (sizes), a ``sphere``
    (radius) or a ``cylinder`` (height, radius), at ``pose`` (a dict from :func:`pose`, or a 4 x 4
    matrix) in ``frame_id``; ``operation`` ADD, REMOVE, APPEND or MOVE."""
    msg = {"id": id, "header": {"frame_id": frame_id}, "operation": operation}
    if pose is not None:
        msg["pose"] = pose if isinstance(pose, dict) else globals()["pose"](matrix=pose)
    elif operation in (ADD, APPEND):
        msg["pose"] = globals()["pose"]()
    if mesh is not None:
        vertices, faces = mesh.vertices, mesh.faces
    if vertices is not None:
        msg["meshes"] = [
            {
                "vertices": [{"x": float(v[0]), "y": float(v[1]), "z": float(v[2])} for v in vertices],
                "triangles": [{"vertex_indices": [int(i) for i in f]} for f in faces],
            }
        ]
        msg["mesh_poses"] = [globals()["pose"]()]
    primitives = []
    if box is not None:
        primitives.append((BOX, [float(v) for v in box]))
    if sphere is not None:
        primitives.append((SPHERE, [float(sphere)]))
    if cylinder is not None:
        primitives.append((CYLINDER, [float(v) for v in cylinder]))
    if primitives:
        msg["primitives"] = [{"type": t, "dimensions": d, "polygon": {"points": []}} for t, d in primitives]
        msg["primitive_poses"] = [globals()["pose"]() for _ in primitives]
    return msg


def attached_object(link_name, object, touch_links=()):
    """An ``AttachedCollisionObject``: ``object`` (a dict from :func:`collision_object`; its
    ``operation`` ADD attaches, REMOVE detaches) on ``link_name``, allowed to touch ``touch_links``."""
    return {"link_name": link_name, "object": object, "touch_links": list(touch_links)}
