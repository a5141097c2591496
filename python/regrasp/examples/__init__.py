"""The example scenes bundled with the package (scene files and the meshes they use), found from
any folder after ``pip install``::

    import regrasp
    from regrasp import examples

    examples.names()                        # ['ball-roll-3d', 'block-3d', ...]
    scene = regrasp.load_scene(examples.path("t-shape"))
    examples.copy("prism-3d", "my-scenes")  # the scene and its mesh, to edit

``regrasp examples`` lists them on the command line (``--copy DIR`` writes one into a folder).
"""

from __future__ import annotations

import shutil
import tomllib
from importlib import resources
from pathlib import Path

from ..errors import ArgumentError
from ..scene.common import is_3d_text

#: the folder of the bundled scene files (``meshes/`` beside them)
ROOT: Path = Path(str(resources.files(__name__)))


def names() -> list[str]:
    """The bundled examples' names (file names without ``.toml``), sorted."""
    return sorted(p.stem for p in ROOT.glob("*.toml"))


def path(name: str) -> Path:
    """The scene file of bundled example ``name`` (e.g. ``"t-shape"``; a ``.toml`` suffix is
    accepted); an :class:`~regrasp.ArgumentError` listing the names when there is none."""
    stem = str(name).removesuffix(".toml")
    if stem not in names():
        raise ArgumentError(f"invalid `name`: no bundled example {name!r}; the examples: {', '.join(names())}", "name")
    return ROOT / f"{stem}.toml"


def dimension(name: str) -> int:
    """2 for a planar example, 3 for a 3-D one."""
    return 3 if is_3d_text(path(name).read_text()) else 2


def planar() -> list[Path]:
    """The scene files of the planar examples, sorted by name."""
    return [path(n) for n in names() if dimension(n) == 2]


def spatial() -> list[Path]:
    """The scene files of the 3-D examples, sorted by name."""
    return [path(n) for n in names() if dimension(n) == 3]


def description(name: str) -> str:
    """One line about example ``name``: its ``description`` key, else the first sentence of the
    comment the file begins with."""
    text = path(name).read_text()
    desc = tomllib.loads(text).get("description")
    if not isinstance(desc, str):
        lead = []
        for line in text.splitlines():
            if not line.startswith("#"):
                break
            lead.append(line.lstrip("#").strip())
        desc = " ".join(lead)
        desc = desc.split(". ")[0].split("; ")[0]
    desc = " ".join(desc.split())
    return desc if len(desc) <= 100 else desc[:99].rstrip() + "…"


def meshes(name: str) -> list[str]:
    """The files example ``name`` refers to, relative to its folder (``object.mesh``)."""
    mesh = tomllib.loads(path(name).read_text()).get("object", {}).get("mesh")
    return [mesh] if isinstance(mesh, str) else []


def copy(name: str, dest_folder, field: str = "dest_folder") -> Path:
    """Copies example ``name`` and the meshes it refers to into ``dest_folder`` (created if
    needed), keeping their relative paths so that the copy loads as it is; returns the copied
    scene file. Files that exist are not overwritten (an :class:`~regrasp.ArgumentError` naming
    ``field``, the caller's name of ``dest_folder``, before anything is written); the files are
    written atomically, all or none (folders this call created are removed again on failure)."""
    from ..files import Outputs, as_path

    src = path(name)
    dest = as_path(dest_folder, field)
    rels = [src.name] + meshes(name)
    taken = [r for r in rels if (dest / r).exists()]
    if taken:
        raise ArgumentError(f"invalid `{field}`: {', '.join(str(dest / r) for r in taken)} already exist{'s' if len(taken) == 1 else ''}"
                            " (not overwritten)", field)
    created = _missing_folders(dest / r for r in rels)
    try:
        with Outputs() as outs:  # all or none
            for rel in rels:
                (dest / rel).parent.mkdir(parents=True, exist_ok=True)
                outs.write(dest / rel, lambda tmp, rel=rel: shutil.copyfile(ROOT / rel, tmp))
    except BaseException:
        for folder in created:
            _remove_empty(folder)
        raise
    return dest / src.name


def _missing_folders(files) -> list[Path]:
    """The folders above ``files`` that do not exist yet, deepest first."""
    missing = set()
    for f in files:
        for folder in Path(f).parents:
            if folder.exists():
                break
            missing.add(folder)
    return sorted(missing, key=lambda p: len(p.parts), reverse=True)


def _remove_empty(folder: Path) -> None:
    try:
        folder.rmdir()
    except OSError:  # not empty (something else wrote there) or already gone
        pass
