"""The workcell: a table, fixed features (edges, corners, blocks, faces) in the world frame, the
robot and the object's start; its TOML file (docs/workcell-file.md) and the default workcell of
a scene::

    from regrasp.workcell import Workcell, default_workcell
    w = Workcell.load("workcell-ur5e.toml")   # or default_workcell(scene)
    w.contacts()                               # what it offers pushers, world frame
"""

from .default import default_workcell
from .description import Contact, Feature, ObjectStart, Robot, Table, Workcell

__all__ = ["Contact", "Feature", "ObjectStart", "Robot", "Table", "Workcell", "default_workcell"]
