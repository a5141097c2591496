"""Scenes: planar (:class:`~regrasp.Scene`, ``scene.planar``) and 3-D (:class:`~regrasp.Scene3D`,
``scene.spatial``); :func:`load_scene` reads either from its file."""

from __future__ import annotations

from .common import is_3d_text, read_scene_file
from .planar import Scene
from .spatial import Scene3D


def load_scene(path) -> Scene | Scene3D:
    """The scene of a scene file: a :class:`Scene3D` for a 3-D scene (``dimension = 3``), else a
    planar :class:`Scene` (docs/scene-file.md)."""
    p, text = read_scene_file(path)
    scene = Scene3D.from_toml(text, p.parent) if is_3d_text(text) else Scene.from_toml(text)
    scene.path = p
    return scene
