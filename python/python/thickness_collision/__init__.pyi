from ._native import Checker as Checker, Clearance as Clearance, Contact as Contact, Error as Error, Report as Report, Scene as Scene, areas as areas
