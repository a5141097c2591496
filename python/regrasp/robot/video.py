"""Videos of a MuJoCo run: a :class:`Recorder` renders the scene offscreen (MuJoCo's
``Renderer``; OpenGL through EGL or OSMesa, chosen before MuJoCo is imported:
:func:`regrasp.extras.default_gl`) at a fixed frame rate of simulated time, so that the video
plays in real time, and :meth:`Recorder.save` writes it as a GIF (Pillow) or an MP4 (``ffmpeg``
on ``PATH``), atomically (:func:`regrasp.files.atomic_write`).

Frames are kept in memory as ``uint8`` RGB arrays, at most :data:`MAX_BYTES` in all: a longer
run keeps every other frame (then every fourth, …) with a warning, the frame rate of the saved
video halved each time, so that it still plays in real time.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Optional, Union, cast

import numpy as np

from ..errors import ArgumentError
from ..extras import need
from ..files import as_path, atomic_write, check_writable

__all__ = ["FPS", "SIZE", "MAX_BYTES", "Camera", "Recorder", "default_camera"]

FPS = 30.0  # Hz, frames per second of simulated time
SIZE = (640, 480)  # px, (width, height)
MAX_BYTES = 1 << 30  # bytes, the most memory the kept frames take (1 GiB: 1165 frames at 640 × 480)
FIELD = "--video"  # the option (field) the video's path is named by in errors
GIF_TICK = 0.01  # s, the resolution of a GIF frame's duration


@dataclass(frozen=True)
class Camera:
    """A free camera looking at world point ``target`` [m] (None: between the robot's base and
    its TCP when the recorder is made, or the model's centre; the view stays put) from ``distance`` [m], turned ``azimuth`` [deg] about the
    world's z (0: looking along +x; 210: from the front (+x), on the +y side) and raised by
    ``elevation`` [deg] (negative: looking down)."""

    target: Optional[tuple] = None
    distance: float = 2.0
    azimuth: float = 210.0
    elevation: float = -25.0


def default_camera(model, data) -> np.ndarray:
    """The default :attr:`Camera.target` [m] (world): midway between the robot's base (body
    ``arm/base``) and its TCP (site ``tcp``), else MuJoCo's model centre (``model.stat.center``)."""
    try:
        base = data.xpos[model.body("arm/base").id]
        tcp = data.site_xpos[model.site("tcp").id]
    except KeyError:
        return np.array(model.stat.center, float)
    return (np.asarray(base, float) + np.asarray(tcp, float)) / 2.0


def _gl_error(e: BaseException) -> ArgumentError:
    """The error for a failed OpenGL context: video needs an OpenGL backend (``e`` the cause)."""
    backend = os.environ.get("MUJOCO_GL") or "unset (GLFW, needs a display)"
    return ArgumentError(
        f"invalid `{FIELD}`: a video needs an OpenGL backend (EGL or OSMesa) and MuJoCo could not render "
        f"(MUJOCO_GL={backend}: {type(e).__name__}: {e}); install EGL (Debian: libegl1) or OSMesa "
        f"(libosmesa6) and set MUJOCO_GL=egl or osmesa before MuJoCo is imported", FIELD)


class Recorder:
    """Renders ``model``/``data`` (MuJoCo) into frames of ``size`` (width, height) [px] at ``fps``
    [Hz] of simulated time, from ``camera``: a :class:`Camera` (None: ``Camera()``), or the name
    or id of a camera in the model. Call :meth:`capture` after every ``mj_step``; the first frame
    is at ``data.time`` when the recorder is made. ``shadows``: MuJoCo's shadows (about 2/3 of the
    rendering time in software OpenGL). ``slow``: the saved video plays this many times slower
    than simulated time (in [1, 100]; e.g. 5 for an action over in a fraction of a second; raise ``fps``
    with it to keep the playback smooth). An ArgumentError naming ``--video`` when no OpenGL
    context can be made. Raises the model's offscreen buffer (``vis.global_.offwidth``/
    ``offheight``) to ``size`` when smaller. Use as a context manager, or :meth:`close`."""

    def __init__(self, model, data, fps: float = FPS, size=SIZE, camera: Union[Camera, str, int, None] = None,
                 shadows: bool = True, slow: float = 1.0):
        mujoco = need("mujoco", "mujoco")
        if isinstance(slow, bool) or not isinstance(slow, (int, float)) or not 1 <= slow <= 100:
            raise ArgumentError(f"invalid `slow`: a slow-down factor in [1, 100] (got {slow!r})", "slow")
        if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not 0 < fps <= 1000:
            raise ArgumentError(f"invalid `fps`: frames per second in (0, 1000] [Hz] (got {fps!r})", "fps")
        try:
            width, height = (int(v) for v in size)
        except (TypeError, ValueError):
            raise ArgumentError(f"invalid `size`: (width, height) [px] (got {size!r})", "size") from None
        if not (16 <= width <= 8192 and 16 <= height <= 8192):
            raise ArgumentError(f"invalid `size`: width and height in [16, 8192] px (got {size!r})", "size")
        self.model, self.data, self.fps, self.size = model, data, float(fps), (width, height)
        self.slow = float(slow)
        self._camera = self._make_camera(model, camera)
        target = getattr(self._camera, "target", None)  # the default fixed now: the view does not follow the TCP
        self._target = default_camera(model, data) if target is None else np.asarray(target, float)
        vis = model.vis.global_
        vis.offwidth, vis.offheight = max(vis.offwidth, width), max(vis.offheight, height)
        try:
            self._renderer = mujoco.Renderer(model, height, width)
        except Exception as e:  # no GL backend: GLFW without a display, a missing EGL/OSMesa
            raise _gl_error(e) from e
        self._renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = bool(shadows)
        self._images: list = []
        self._stride = 1  # every how many frame times a frame is kept
        self._start = float(data.time)
        self._next = 0  # the index of the next frame time (start + next / fps)

    @staticmethod
    def _make_camera(model, camera):
        if isinstance(camera, (str, int)) and not isinstance(camera, bool):
            try:
                return model.camera(camera).id
            except (KeyError, IndexError, ValueError):
                raise ArgumentError(f"invalid `camera`: no camera {camera!r} in the model "
                                    f"({model.ncam} cameras)", "camera") from None
        camera = Camera() if camera is None else camera
        if not isinstance(camera, Camera):
            raise ArgumentError(f"invalid `camera`: a Camera, or a camera's name or id (got {camera!r})", "camera")
        target = camera.target
        if target is not None and (np.shape(target) != (3,) or not np.all(np.isfinite(np.asarray(target, float)))):
            raise ArgumentError(f"invalid `camera.target`: a world point (x, y, z) [m] (got {target!r})", "camera.target")
        if not (np.isfinite(camera.distance) and camera.distance > 0):
            raise ArgumentError(f"invalid `camera.distance`: > 0 m (got {camera.distance!r})", "camera.distance")
        return camera

    def _view(self, mujoco):
        """The camera to render from now (a free ``MjvCamera``, or the model camera's name/id)."""
        c = self._camera
        if not isinstance(c, Camera):
            return c
        cam = mujoco.MjvCamera()
        cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        cam.lookat[:] = self._target
        cam.distance, cam.azimuth, cam.elevation = c.distance, c.azimuth, c.elevation
        return cam

    @property
    def frames(self) -> int:
        """The number of frames kept."""
        return len(self._images)

    @property
    def images(self) -> list:
        """The kept frames: ``uint8`` arrays (height, width, 3), RGB (a frame repeated when the
        simulation stepped over several frame times is the same array)."""
        return list(self._images)

    @property
    def frame_rate(self) -> float:
        """The frame rate [Hz] of the kept frames: ``fps`` divided by the stride that
        :data:`MAX_BYTES` forced (1 unless the run was long)."""
        return self.fps / self._stride

    def render(self) -> np.ndarray:
        """The scene now as an image, ``uint8`` (height, width, 3)."""
        mujoco = need("mujoco", "mujoco")
        self._renderer.update_scene(self.data, self._view(mujoco))
        return self._renderer.render().copy()

    def capture(self) -> None:
        """Renders a frame when the simulated time has reached the next frame time (call after
        every ``mj_step``); when a step passed several frame times, the frame is repeated."""
        period = 1.0 / self.fps
        t = float(self.data.time) - self._start
        due = int(np.floor(t / period + 1e-6)) + 1 - self._next  # frame times passed since the last frame
        if due <= 0:
            return
        kept = [i for i in range(self._next, self._next + due) if i % self._stride == 0]
        self._next += due
        if not kept:
            return
        image = self.render()
        self._images.extend([image] * len(kept))
        if self.frames * image.nbytes > MAX_BYTES:
            self._halve()

    def _halve(self) -> None:
        """Keeps every other frame (and from now every other frame time) to stay within
        :data:`MAX_BYTES`."""
        self._stride *= 2
        self._images = self._images[::2]  # frame i was frame time i·stride/2
        warnings.warn(f"video: over {MAX_BYTES / 2**20:.3g} MiB of frames; keeping 1 frame in {self._stride} "
                      f"({self.frame_rate:.3g} frames/s)", RuntimeWarning, stacklevel=3)

    def durations(self) -> list:
        """Each kept frame's display time [s] in a GIF: ``slow / frame_rate`` rounded to GIF ticks
        (10 ms) so that the sum keeps to real time (e.g. 30 fps: 30, 40, 30 ms, …) times ``slow``."""
        ticks = np.round(np.arange(self.frames + 1) * self.slow / self.frame_rate / GIF_TICK)
        return list(np.diff(ticks) * GIF_TICK)

    def save(self, path, name: str = FIELD) -> Path:
        """Writes the frames to ``path``: ``.gif`` (Pillow: one palette of 256 colours made from the
        frames, looping; identical consecutive frames merged, their durations summed) or ``.mp4``
        (H.264 through ``ffmpeg``, found on ``PATH``), atomically. ArgumentError naming ``name``
        for another suffix, an unwritable path, no frames, or ``.mp4`` without ``ffmpeg``."""
        p = as_path(path, name)
        suffix = p.suffix.lower()
        if suffix not in (".gif", ".mp4"):
            raise ArgumentError(f"invalid `{name}`: a .gif or .mp4 file (got {p})", name)
        if not self._images:
            raise ArgumentError(f"invalid `{name}`: no frames to write to {p} (capture() after mj_step)", name)
        check_writable(p, name)
        if suffix == ".mp4":
            ffmpeg = shutil.which("ffmpeg")
            if ffmpeg is None:
                raise ArgumentError(f"invalid `{name}`: writing {p} (MP4) needs ffmpeg, not found on PATH; "
                                    f"install it or write a .gif", name)
            return atomic_write(p, lambda tmp: self._write_mp4(ffmpeg, tmp, name))
        return atomic_write(p, self._write_gif)

    def _write_gif(self, tmp: Path) -> None:
        Image = need("PIL.Image", "mujoco")
        images = self._images
        step = max(1, len(images) // 16)  # the palette from up to 16 frames spread over the run
        sample = Image.fromarray(np.concatenate(images[::step][:16], axis=0))
        palette = sample.quantize(colors=256, method=Image.Quantize.MEDIANCUT)
        cache: dict = {}
        frames = []
        for im in images:  # a repeated frame is quantised once
            if id(im) not in cache:
                cache[id(im)] = Image.fromarray(im).quantize(palette=palette, dither=Image.Dither.NONE)
            frames.append(cache[id(im)])
        durations = [int(round(d * 1000)) for d in self.durations()]
        frames[0].save(tmp, format="GIF", save_all=True, append_images=frames[1:], loop=0,
                       duration=durations, optimize=False, disposal=1)

    def _write_mp4(self, ffmpeg: str, tmp: Path, name: str) -> None:
        width, height = self.size
        cmd = [ffmpeg, "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24",
               "-s", f"{width}x{height}", "-r", f"{self.frame_rate / self.slow:.6g}", "-i", "-",
               "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p",
               "-movflags", "+faststart", str(tmp)]
        proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stderr=subprocess.PIPE)
        stdin = cast(IO[bytes], proc.stdin)
        try:
            for im in self._images:
                stdin.write(np.ascontiguousarray(im).tobytes())
            _, err = proc.communicate()
        except BrokenPipeError:
            _, err = proc.communicate()
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        if proc.returncode != 0:
            raise ArgumentError(f"invalid `{name}`: ffmpeg failed writing {tmp.name} (exit {proc.returncode}): "
                                f"{err.decode(errors='replace').strip()[-500:]}", name)

    def close(self) -> None:
        """Frees the OpenGL context (the frames are kept)."""
        if getattr(self, "_renderer", None) is not None:
            self._renderer.close()
            self._renderer = None

    def __enter__(self) -> "Recorder":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
