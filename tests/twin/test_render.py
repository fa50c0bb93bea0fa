"""Offscreen rendering: real pixels that follow the rig's pose, a renderer closed deterministically, and the
OpenGL backend chosen at the first render, never at import."""

import os
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from trms.errors import ConfigurationError, InputError
from trms.twin.render import DEFAULT_GL_BACKEND, TwinRenderer, gl_backend, render_record, save_gif, save_png


def _shield_rows(frame):
    """Row centroid of the blue shield pixels in each image half (main rotor is on the right)."""
    r, g, b = (frame[..., i].astype(int) for i in range(3))
    blue = (b > 120) & (b > r + 50) & (b > g + 30)
    half = frame.shape[1] // 2
    rows = np.arange(frame.shape[0])[:, None]
    return [float((rows * blue[:, s]).sum() / blue[:, s].sum()) for s in (slice(half, None), slice(None, half))]


def test_the_beam_image_moves_with_pitch(twin_factory):
    twin = twin_factory("1dof")
    q = twin.trim.qpos.copy()
    pitch = twin.model.joint("pitch").qposadr[0]
    with TwinRenderer(twin.model, 320, 240) as r:
        flat = r.frame(q, "front")
        q_up = q.copy()
        q_up[pitch] = 0.4
        up = r.frame(q_up, "front")
        again = r.frame(q, "front")
    assert flat.shape == (240, 320, 3) and flat.dtype == np.uint8
    assert np.array_equal(flat, again)  # rendering is a function of the pose
    main_flat, tail_flat = _shield_rows(flat)
    main_up, tail_up = _shield_rows(up)
    # Pitch up: the main rotor (right) rises in the image, the tail rotor (left) sinks.
    assert main_up < main_flat - 20 and tail_up > tail_flat + 10
    assert np.mean(np.any(flat != up, axis=2)) > 0.01


def test_renderer_closes_deterministically(twin_factory):
    twin = twin_factory("1dof")
    r = TwinRenderer(twin.model, 64, 48)
    r.close()
    r.close()  # idempotent
    with pytest.raises(InputError, match="closed"):
        r.frame()


def test_bad_render_requests(twin_factory):
    twin = twin_factory("1dof")
    with pytest.raises(InputError, match="outside"):
        TwinRenderer(twin.model, 5000, 100)
    with TwinRenderer(twin.model, 64, 48) as r:
        with pytest.raises(InputError, match="unknown camera 'side'"):
            r.frame(camera="side")
        with pytest.raises(InputError, match="qpos must have shape"):
            r.frame(np.zeros(3))


def test_png_and_gif_export(tmp_path, twin_factory):
    twin = twin_factory("1dof")
    rec = twin.run(np.tile(twin.operating_point.inputs + 1.5, (30, 1)))
    gif = render_record(twin.model, rec, tmp_path / "run.gif", camera="oblique", every=5, width=96, height=72)
    png = render_record(twin.model, rec, tmp_path / "last.png", width=96, height=72)
    with Image.open(gif) as im:
        assert im.n_frames == 6 and im.size == (96, 72)
        im.seek(0)
        first = np.asarray(im.convert("RGB"))
        im.seek(5)
        last = np.asarray(im.convert("RGB"))
    assert not np.array_equal(first, last)  # the beam climbed
    assert Image.open(png).size == (96, 72)
    with pytest.raises(InputError, match="must end in .png, .gif or .mp4"):
        render_record(twin.model, rec, tmp_path / "x.bmp")
    with pytest.raises(InputError, match="at least one frame"):
        save_gif([], tmp_path / "e.gif")
    assert save_png(np.zeros((4, 4, 3)), tmp_path / "z.png").exists()


def test_mp4_export_holds_the_frames(tmp_path, twin_factory):
    import imageio_ffmpeg

    twin = twin_factory("1dof")
    rec = twin.run(np.tile(twin.operating_point.inputs + 1.5, (30, 1)))
    path = render_record(twin.model, rec, tmp_path / "run.mp4", camera="front", every=3, width=96, height=72)
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = reader.__next__()
    frames = [np.frombuffer(f, np.uint8).reshape(72, 96, 3) for f in reader]
    assert meta["size"] == (96, 72) and len(frames) == 10
    with TwinRenderer(twin.model, 96, 72) as r:
        first = r.frame(rec.extras["qpos"][0], "front").astype(int)
    assert np.mean(np.abs(frames[0].astype(int) - first)) < 6  # lossy H.264, same picture


def test_mp4_without_the_video_extra_is_one_line_and_an_old_file_survives_a_failed_write(
    tmp_path, twin_factory, monkeypatch
):
    from trms.twin.render import save_mp4

    old = tmp_path / "run.mp4"
    old.write_bytes(b"old video")
    frames = [np.zeros((8, 8, 3), np.uint8)] * 2
    with pytest.raises(InputError, match=r"frame 1 has shape \(4, 4, 3\); every frame must be"):
        save_mp4([frames[0], np.zeros((4, 4, 3), np.uint8)], old)  # ffmpeg would write a broken video
    assert old.read_bytes() == b"old video" and sorted(p.name for p in tmp_path.iterdir()) == ["run.mp4"]
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)
    with pytest.raises(ConfigurationError, match=r"pip install 'trms\[video\]'") as info:
        save_mp4(frames, old)
    assert "\n" not in str(info.value) and old.read_bytes() == b"old video"


# Run in a fresh interpreter without MUJOCO_GL or PYOPENGL_PLATFORM: every trms module imported, then a render.
_FRESH_PROCESS = """
import os, re, sys
import numpy as np
import trms, trms.twin, trms.envs.gym, trms.envs.suite, trms.twin.render, trms.envs.tasks
GL_LIBRARY = re.compile(r"libOSMesa|libEGL|libGLX|libGL\\.so")
assert not {"MUJOCO_GL", "PYOPENGL_PLATFORM"} & set(os.environ), "an import set a GL variable"
assert not GL_LIBRARY.search(open("/proc/self/maps").read()), "an import loaded a GL library"
from trms.twin import Twin
from trms.twin.render import TwinRenderer
twin = Twin("1dof", 0.1)
with TwinRenderer(twin.model, 96, 72) as r:
    frame = r.frame(twin.trim.qpos, "front")
assert "libOSMesa" in open("/proc/self/maps").read(), "the default backend is OSMesa"
assert not {"MUJOCO_GL", "PYOPENGL_PLATFORM"} & set(os.environ), "rendering left a GL variable behind"
env = trms.envs.suite.load("PitchTracking", {"random": 0})
env.reset()
physics_frame = env.physics.render(72, 96, camera_id="front")
np.save(sys.argv[1], frame)
np.save(sys.argv[2], physics_frame)
np.save(sys.argv[3], env.twin.data.qpos)
"""


def test_imports_choose_no_gl_backend_and_the_first_renderer_loads_osmesa(tmp_path, twin_factory):
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "PYOPENGL_PLATFORM")}
    paths = [tmp_path / f"{name}.npy" for name in ("frame", "physics", "qpos")]
    out = subprocess.run(
        [sys.executable, "-c", _FRESH_PROCESS, *map(str, paths)], env=env, capture_output=True, text=True
    )
    assert out.returncode == 0, out.stderr[-2000:]
    frame, physics_frame, qpos = (np.load(p) for p in paths)
    twin = twin_factory("1dof")
    with TwinRenderer(twin.model, 96, 72) as r:
        here = r.frame(twin.trim.qpos, "front")
        pose = r.frame(qpos, "front")
    assert frame.shape == (72, 96, 3) and frame.std() > 10
    assert np.array_equal(frame, here)  # the same picture as this process's OSMesa draws
    # dm_control's renderer draws the same rig in the same pose (its own GL context, same MuJoCo code).
    assert physics_frame.shape == (72, 96, 3) and np.mean(np.abs(physics_frame.astype(int) - pose)) < 1.0


def test_the_backend_is_mujoco_gl_when_set_and_a_bad_one_is_refused(monkeypatch, twin_factory):
    monkeypatch.delenv("MUJOCO_GL", raising=False)
    assert gl_backend() == DEFAULT_GL_BACKEND == "osmesa"
    monkeypatch.setenv("MUJOCO_GL", " OSMesa ")
    assert gl_backend() == "osmesa"
    monkeypatch.setenv("MUJOCO_GL", "vulkan")
    with pytest.raises(
        ConfigurationError, match="unknown MUJOCO_GL backend 'vulkan'; allowed: 'osmesa', 'egl', 'glfw'"
    ):
        TwinRenderer(twin_factory("1dof").model, 64, 48)
    assert os.environ["MUJOCO_GL"] == "vulkan"  # the user's setting is left as it was


def test_a_renderer_leaves_the_gl_variables_as_it_found_them(monkeypatch, twin_factory):
    monkeypatch.setenv("MUJOCO_GL", "osmesa")
    monkeypatch.delenv("PYOPENGL_PLATFORM", raising=False)
    with TwinRenderer(twin_factory("1dof").model, 64, 48) as r:
        assert r.frame().std() > 0
    assert os.environ["MUJOCO_GL"] == "osmesa" and "PYOPENGL_PLATFORM" not in os.environ
