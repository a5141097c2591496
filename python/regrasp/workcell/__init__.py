"""The workcell: a table, fixed features (edges, corners, blocks, faces) in the world frame, the
robot and the object's start, and its TOML file (docs/workcell-file.md): a description (the
default workcell of a scene is laid out by :func:`regrasp.execution.default_workcell`, beside
the assignment of features to pushers)::

    from regrasp.workcell import Workcell
    w = Workcell.load(bundled("workcell-ur5e"))
    w.contacts()                               # what it offers pushers, world frame
    shapes(w)                                  # its physical bodies (collisions, MuJoCo geoms)
"""

from .. import _moved
from .description import Contact, Feature, ObjectStart, Robot, Table, Workcell
from .file import bundled
from .shapes import Shape, shapes

__all__ = ["Contact", "Feature", "ObjectStart", "Robot", "Shape", "Table", "Workcell", "bundled", "shapes"]

#: ``regrasp.workcell.default_workcell`` (before 0.2): now ``regrasp.execution.default_workcell``.
__getattr__ = _moved.attribute_aliases(__name__, {"default_workcell": "execution.layout"})
