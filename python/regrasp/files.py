"""Writing output files: atomically, never onto an input, all of a command's outputs or none.

Every file the package writes goes through :func:`atomic_write`: the content is written to a
temporary file in the output's own folder (``.NAME.tmpXXXXXXXX.SUFFIX``, the suffix kept so that
writers that pick the format by the name still do), flushed to disk, then renamed over the output
(``os.replace``, atomic on POSIX and Windows). On any failure, ``KeyboardInterrupt`` included,
the temporary file is removed and an existing output is left as it was. :class:`Outputs` stages
several outputs this way and renames them only when every one was written.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import signal
import stat
import threading
import tomllib
import uuid
from pathlib import Path
from typing import Callable, Iterable, Mapping, Optional

import numpy as np

from .errors import ArgumentError
from .fields import MAX_FILE_BYTES, MAX_NESTING

__all__ = ["as_path", "atomic_write", "write_text", "temp_path", "check_writable", "refuse_overwrite_input", "Outputs",
           "same_file", "read_text", "parse_json", "parse_toml", "nesting", "MAX_FILE_BYTES"]

# MAX_FILE_BYTES (the core's, regrasp.fields): the most any input file may hold; a larger one —
# or an endless stream such as /dev/zero — is refused after reading this much, naming the field.
# MAX_NESTING: the deepest nesting of arrays and tables a TOML or JSON input may have.

#: what cannot hold a bracket that counts: strings and comments (TOML) / strings (JSON)
_TOML_INERT = re.compile(r'"""[\s\S]*?"""|\'\'\'[\s\S]*?\'\'\'|"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'|#[^\n]*')
_JSON_INERT = re.compile(r'"(?:[^"\\]|\\.)*"')
_BRACKETS = re.compile(r"[\[\]{}]")


def as_path(v, name: str) -> Path:
    """Argument ``name`` as a file path: a non-empty ``str`` or ``os.PathLike`` (else an
    ArgumentError naming it)."""
    if isinstance(v, os.PathLike):
        v = os.fspath(v)
    if not isinstance(v, str) or not v.strip():
        raise ArgumentError(f"invalid `{name}`: a file path, a non-empty string (got {v!r})", name)
    if "\0" in v:
        raise ArgumentError(f"invalid `{name}`: a file path without NUL characters", name)
    return Path(v)


def read_text(path, field: str, limit: Optional[int] = None) -> str:
    """The UTF-8 text of the file at ``path``, read at most ``limit`` bytes (default
    :data:`MAX_FILE_BYTES`): an ArgumentError naming ``field`` when it cannot be read, is not
    text, or holds more (nothing more is read)."""
    limit = MAX_FILE_BYTES if limit is None else limit
    p = as_path(path, field)
    try:
        with open(p, "rb") as f:
            data = f.read(limit + 1)
    except OSError as e:
        raise ArgumentError(f"invalid `{field}`: cannot read {p}: {e.strerror or e}", field) from None
    if len(data) > limit:
        raise ArgumentError(f"invalid `{field}`: {p} holds more than {limit} bytes (the most an input file may hold)",
                            field)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise ArgumentError(f"invalid `{field}`: {p} is not UTF-8 text ({e.reason} at byte {e.start})", field) from None


def nesting(text: str, toml: bool = False) -> int:
    """The deepest nesting of arrays and tables/objects in TOML or JSON ``text``, counted over its
    brackets outside strings (and comments) without parsing it: a parser would recurse."""
    marks = np.frombuffer("".join(_BRACKETS.findall((_TOML_INERT if toml else _JSON_INERT).sub("", text)))
                          .encode("ascii"), dtype=np.uint8)
    if not marks.size:
        return 0
    return int(np.cumsum(np.where((marks == ord("[")) | (marks == ord("{")), 1, -1)).max())


def _depth(value) -> int:
    """The nesting depth of a parsed value (lists and dicts), without recursion."""
    deepest, stack = 0, [(value, 0)]
    while stack:
        v, d = stack.pop()
        if isinstance(v, dict):
            v = list(v.values())
        if isinstance(v, list):
            deepest = max(deepest, d + 1)
            stack.extend((x, d + 1) for x in v if isinstance(x, (list, dict)))
    return deepest


#: why a TOML or JSON input is refused when it nests too deeply
TOO_DEEP = f"nested more than {MAX_NESTING} arrays or tables deep (the most an input file may nest)"


def _no_constant(c: str):
    raise ValueError(f"{c} is not allowed (JSON has no NaN or Infinity)")


def _parse(text: str, field: str, fail, toml: bool, constants: bool = True):
    kind = "TOML" if toml else "JSON"
    if not isinstance(text, str):
        raise ArgumentError(f"invalid `text`: the {kind} text, a str (got {type(text).__name__})", "text")
    fail = fail or (lambda why: ArgumentError(f"invalid `{field}`: {why}", field))
    if nesting(text, toml) > MAX_NESTING:
        raise fail(TOO_DEEP)
    try:
        v = tomllib.loads(text) if toml else json.loads(text, parse_constant=None if constants else _no_constant)
    except (tomllib.TOMLDecodeError, ValueError) as e:
        raise fail(f"not {kind}: {e}") from None
    except RecursionError:
        raise fail(TOO_DEEP) from None
    if _depth(v) > MAX_NESTING:
        raise fail(TOO_DEEP)
    return v


def parse_json(text: str, field: str, fail: Optional[Callable[[str], Exception]] = None, constants: bool = True):
    """The value of JSON ``text``. When it is not JSON (or, without ``constants``, holds NaN or
    Infinity), or nests deeper than :data:`MAX_NESTING` (refused before parsing), the error
    ``fail(why)`` (default: an ArgumentError naming ``field``)."""
    return _parse(text, field, fail, toml=False, constants=constants)


def parse_toml(text: str, field: str, fail: Optional[Callable[[str], Exception]] = None) -> dict:
    """The table of TOML ``text``; errors as :func:`parse_json`."""
    return _parse(text, field, fail, toml=True)


def same_file(a, b) -> bool:
    """Whether paths ``a`` and ``b`` name one file: the same existing file (``samefile``) or the
    same resolved path."""
    try:
        if os.path.samefile(a, b):
            return True
    except OSError:  # either does not exist
        pass
    return Path(a).resolve() == Path(b).resolve()


def temp_path(path) -> Path:
    """A fresh temporary name beside ``path``: ``.NAME.tmpXXXXXXXX.SUFFIX``."""
    p = Path(path)
    return p.with_name(f".{p.stem}.tmp{uuid.uuid4().hex[:8]}{p.suffix}")


def _fsync(path: Path) -> None:
    """Flushes a written file to disk (best effort where a file system cannot)."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _remove(path: Path) -> None:
    try:
        path.unlink()
    except FileNotFoundError:
        pass


def _write_temp(path: Path, write_fn: Callable[[Path], object]) -> Path:
    """Runs ``write_fn(tmp)`` on a temporary name beside ``path``; returns the written temporary
    file (removed again on any failure)."""
    tmp = temp_path(path)
    try:
        write_fn(tmp)
        if not tmp.is_file():
            raise OSError(f"nothing was written to {tmp}")
        _fsync(tmp)
    except BaseException:
        _remove(tmp)
        raise
    return tmp


def _is_stream(path) -> bool:
    """An existing output that is not a regular file or folder (``/dev/stdout``, a pipe): it
    cannot be replaced by a rename, so it is written in place."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return False
    return not stat.S_ISREG(mode) and not stat.S_ISDIR(mode)


def _target(path) -> Path:
    """Where ``path`` writes: a symbolic link's target (the link itself stays)."""
    p = Path(path)
    return Path(os.path.realpath(p)) if p.is_symlink() else p


def atomic_write(path, write_fn: Callable[[Path], object]) -> Path:
    """Writes ``path`` atomically: ``write_fn(tmp)`` writes the content to the temporary path it
    is given (same folder, same suffix), which then replaces ``path``. On failure (any exception,
    KeyboardInterrupt included) the temporary file is removed and ``path`` is untouched. A
    symbolic link is written through (its target is replaced); a device or pipe
    (``/dev/stdout``) is written in place."""
    if _is_stream(path):
        write_fn(Path(path))
        return Path(path)
    p = _target(path)
    tmp = _write_temp(p, write_fn)
    try:
        os.replace(tmp, p)
    except BaseException:
        _remove(tmp)
        raise
    return Path(path)


def write_text(path, text: str) -> Path:
    """``text`` written atomically to ``path`` (UTF-8)."""
    return atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


def check_writable(path, name: str, create_folder: bool = False) -> Path:
    """That ``path`` can be written (before a long computation): not a folder, its folder exists
    (or, with ``create_folder``, can be created) and is writable. ArgumentError naming option
    ``name``: ``invalid `--out`: cannot write PATH: REASON``."""
    p = Path(path)

    def fail(reason: str):
        raise ArgumentError(f"invalid `{name}`: cannot write {p}: {reason}", name)

    if str(path) == "" or p.name in ("", ".", ".."):
        fail("not a file name")
    if p.is_dir():
        fail("is a folder")
    if create_folder and not p.parent.exists():
        try:  # the folder is made now, so that a path that cannot be made fails before the work
            p.parent.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            fail(f"cannot make the folder {p.parent}: {e.strerror or e}")
    folder = p.parent
    if not folder.exists():
        fail(f"no folder {folder}")
    if not folder.is_dir():
        fail(f"{folder} is not a folder")
    if not os.access(folder, os.W_OK | os.X_OK):
        fail(f"the folder {folder} is not writable")
    return p


def refuse_overwrite_input(outputs: Mapping[str, Optional[object]], inputs: Iterable[Optional[object]]) -> None:
    """ArgumentError naming the option when an output (``{option: path}``; None: not asked for)
    is one of the ``inputs`` files or the same file as another output."""
    given = [(k, v) for k, v in outputs.items() if v is not None]
    ins = [i for i in inputs if i is not None]
    for k, v in given:
        for i in ins:
            if same_file(v, i):
                raise ArgumentError(f"invalid `{k}`: {v} is an input file ({i}); it is not overwritten", k)
    for n, (k, v) in enumerate(given):
        for k2, v2 in given[n + 1:]:
            if same_file(v, v2):
                raise ArgumentError(f"invalid `{k2}`: {v2} is also the output of `{k}`", k2)


@contextlib.contextmanager
def _sigint_deferred():
    """A Ctrl-C (SIGINT) during the block takes effect after it (main thread; elsewhere Python
    does not deliver signals anyway)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got = []
    old = signal.signal(signal.SIGINT, lambda signum, frame: got.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)
        if got and callable(old):
            old(signal.SIGINT, None)
        elif got and old == signal.SIG_DFL:
            raise KeyboardInterrupt


class Outputs:
    """Several outputs written all or none: :meth:`write` stages each in a temporary file beside
    it; :meth:`commit` renames them all over their outputs; :meth:`discard` (or leaving a ``with``
    block by an exception) removes the staged files, leaving every existing output untouched."""

    def __init__(self):
        self._staged: list[tuple[Path, Path]] = []

    def write(self, path, write_fn: Callable[[Path], object]) -> Path:
        """Stages ``write_fn(tmp)`` for ``path`` (see :func:`atomic_write`; a device or pipe is
        written at once)."""
        if _is_stream(path):
            write_fn(Path(path))
        else:
            p = _target(path)
            self._staged.append((_write_temp(p, write_fn), p))
        return Path(path)

    def commit(self) -> list[Path]:
        """Renames every staged file over its output (a Ctrl-C waits until all are renamed)."""
        done = []
        with _sigint_deferred():
            try:
                for tmp, p in self._staged:
                    os.replace(tmp, p)
                    done.append(p)
            finally:
                self.discard()
        return done

    def discard(self) -> None:
        """Removes the staged files not yet committed."""
        for tmp, _ in self._staged:
            _remove(tmp)
        self._staged = []

    def __enter__(self) -> "Outputs":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.commit()
        else:
            self.discard()
