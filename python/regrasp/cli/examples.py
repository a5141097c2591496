"""`regrasp examples`: the bundled example scenes (``regrasp.examples``), listed or copied."""

from __future__ import annotations

from .. import examples
from ..errors import ArgumentError
from . import OK, add_command


def cmd_examples(a) -> int:
    names = [a.name] if a.name else examples.names()
    if a.copy:
        if not a.name:
            raise ArgumentError("invalid `--copy`: name the example to copy (regrasp examples NAME --copy DIR); "
                                f"the examples: {', '.join(examples.names())}", "--copy")
        dest = examples.copy(a.name, a.copy, field="--copy")
        extra = examples.meshes(a.name)
        print(f"wrote {dest}" + (f" and {', '.join(extra)} beside it" if extra else ""))
        return OK
    width = max(len(n) for n in names)
    for n in names:
        print(f"{n:{width}s}  {examples.dimension(n)}-D  {examples.description(n)}")
    if a.name:
        print(f"file: {examples.path(a.name)}")
    return OK


def add_parsers(sub) -> None:
    e = add_command(sub, "examples", "list the bundled example scenes, or copy one (and its meshes) into a folder",
                    "regrasp examples\nregrasp examples pivot-3d --copy my-scenes", cmd_examples)
    e.add_argument("name", nargs="?", help="one example (default: list them all)")
    e.add_argument("--copy", metavar="DIR", help="write the scene file of NAME and the meshes it uses into DIR "
                   "(created if needed; existing files are not overwritten; default: none, only list)")
