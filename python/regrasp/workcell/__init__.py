"""The workcell: a table, fixed features (edges, corners, blocks, faces) in the world frame, the
robot and the object's start; its TOML file (docs/workcell-file.md) and the default workcell of
a scene::

    from regrasp.workcell import Workcell, default_workcell
    w = Workcell.load(bundled("workcell-ur5e"))   # or default_workcell(scene)
    w.contacts()                               # what it offers pushers, world frame
    shapes(w)                                  # its physical bodies (collisions, MuJoCo geoms)
"""

from .default import default_workcell
from .description import Contact, Feature, ObjectStart, Robot, Table, Workcell
from .file import bundled
from .shapes import Shape, shapes

__all__ = ["Contact", "Feature", "ObjectStart", "Robot", "Shape", "Table", "Workcell", "bundled", "default_workcell",
           "shapes"]
