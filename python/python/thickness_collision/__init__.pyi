from ._native import Checker as Checker, Clearance as Clearance, Contact as Contact, Error as Error, Report as Report, Scene as Scene, areas as areas
from .messages import attached_object as attached_object, collision_object as collision_object, pose as pose
