"""Collision checking that sees behind thin surfaces.

A ``Checker`` loads a robot and its environment from URDF (the bundled workcell when none is
given) and checks states, batches of states and motions; ``areas`` and ``Scene`` give the geometry
core without a robot. OMPL validators are in ``thickness_collision.ompl`` (``pip install
thickness_collision[ompl]``). See docs/python.md.
"""

from ._native import Checker, Clearance, Contact, Error, Report, Scene, areas
from .messages import attached_object, collision_object, pose

__all__ = ["Checker", "Clearance", "Contact", "Error", "Report", "Scene", "areas", "attached_object", "collision_object", "pose"]
