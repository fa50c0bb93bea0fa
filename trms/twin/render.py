"""Offscreen rendering of the twin, with the OpenGL backend chosen when the first renderer is created.

Choosing the backend: set ``MUJOCO_GL`` to one of :data:`GL_BACKENDS` (``osmesa``: software
rendering, no display or GPU needed, Debian's ``libosmesa6``; ``egl``: a GPU without a display;
``glfw``: a desktop display); without it, renderers use :data:`DEFAULT_GL_BACKEND` (``osmesa``).
Nothing is decided at import: importing :mod:`trms` or any of its modules sets no environment
variable and loads no OpenGL library, so other GPU libraries imported later are unaffected. The
backend is read (:func:`gl_backend`) and its library loaded when a :class:`TwinRenderer` (or the
dm_env environment's :attr:`~trms.envs.suite.TwinEnvironment.physics`) is first created; set
``MUJOCO_GL`` before that, ideally before importing ``mujoco``, which makes its own choice at import.

A :class:`TwinRenderer` owns one GL context; use it as a context manager (or call
:meth:`TwinRenderer.close`) so the context is freed deterministically, not at
interpreter exit. Frames are ``(height, width, 3)`` uint8 arrays; :func:`save_png` and
:func:`save_gif` write them with Pillow, :func:`save_mp4` as H.264 with the ffmpeg that
the ``imageio-ffmpeg`` wheel ships.
"""

from __future__ import annotations

import contextlib
import importlib
import os
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from PIL import Image

from trms.errors import ConfigurationError, InputError, check_choice
from trms.files import atomic_write
from trms.record import Record

__all__ = [
    "DEFAULT_GL_BACKEND",
    "GL_BACKENDS",
    "TwinRenderer",
    "gl_backend",
    "has_rendered",
    "dm_control_physics",
    "save_png",
    "save_gif",
    "save_mp4",
    "render_record",
]

#: The OpenGL backends a renderer can use: the values of ``MUJOCO_GL`` it accepts.
GL_BACKENDS = ("osmesa", "egl", "glfw")
#: The backend when ``MUJOCO_GL`` is not set: OSMesa, software rendering that needs no display and no GPU.
DEFAULT_GL_BACKEND = "osmesa"
_ENV_KEYS = ("MUJOCO_GL", "PYOPENGL_PLATFORM")


def gl_backend() -> str:
    """The OpenGL backend a renderer created now uses: ``MUJOCO_GL`` if set, else :data:`DEFAULT_GL_BACKEND`.

    Returns
    -------
    str
        One of :data:`GL_BACKENDS`.

    Raises
    ------
    ConfigurationError
        ``MUJOCO_GL`` names another backend (or disables rendering).

    Examples
    --------
    >>> gl_backend() in GL_BACKENDS
    True
    """
    value = os.environ.get("MUJOCO_GL", "").strip().lower() or DEFAULT_GL_BACKEND
    return check_choice("MUJOCO_GL backend", value, GL_BACKENDS, error=ConfigurationError)


#: Whether this process has created an OpenGL context (read by :func:`has_rendered`).
_CONTEXTS = {"created": False}


def has_rendered() -> bool:
    """Whether this process has created an OpenGL context to draw (importing this module creates none): a process
    that has must not be forked (:func:`trms.processes.start_method`).

    Examples
    --------
    >>> isinstance(has_rendered(), bool)
    True
    """
    return _CONTEXTS["created"]


@contextlib.contextmanager
def _backend_environment(backend: str) -> Iterator[None]:
    """Import and create GL contexts of ``backend``: the libraries read ``MUJOCO_GL`` and ``PYOPENGL_PLATFORM``
    when first imported, so both name ``backend`` meanwhile (a ``PYOPENGL_PLATFORM`` already set is kept) and
    are restored afterwards. Failures become one :class:`ConfigurationError` line."""
    saved = {key: os.environ.get(key) for key in _ENV_KEYS}
    _CONTEXTS["created"] = True
    os.environ["MUJOCO_GL"] = backend
    if backend != "glfw":  # PyOpenGL's platform; GLFW does not go through PyOpenGL
        os.environ.setdefault("PYOPENGL_PLATFORM", backend)
    try:
        yield
    except (ImportError, OSError, AttributeError, RuntimeError) as exc:
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise ConfigurationError(
            f"cannot create an OpenGL context with MUJOCO_GL={backend!r} ({reason}); allowed backends: "
            "'osmesa' (software, needs libOSMesa: Debian's libosmesa6), 'egl' (a GPU driver), 'glfw' (a display)"
        ) from exc
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


def _gl_context(width: int, height: int) -> Any:
    """A current GL context of the chosen backend (MuJoCo's own wrappers), ``width`` x ``height`` pixels."""
    backend = gl_backend()
    with _backend_environment(backend):
        context = importlib.import_module(f"mujoco.{backend}").GLContext(width, height)
        context.make_current()
    return context


def dm_control_physics(data: mujoco.MjData) -> Any:
    """A dm_control ``mujoco.Physics`` over ``data`` (shared, not copied) that renders with :func:`gl_backend`.

    dm_control picks its OpenGL backend when its renderer is first imported: the import happens here,
    under the chosen backend (a dm_control imported earlier keeps its own choice). Building the physics
    recomputes ``data``'s derived quantities (``mj_forward``), which leaves its state
    (``mjSTATE_INTEGRATION``, warm start included) bit-identical: a simulation continues exactly as without it.

    Parameters
    ----------
    data : mujoco.MjData
        The live state to wrap (e.g. ``Twin(...).data``).

    Returns
    -------
    dm_control.mujoco.Physics
        ``physics.render(height, width, camera_id=...)`` draws ``data``; dm_control's viewer reads it as
        ``env.physics``.

    Raises
    ------
    ConfigurationError
        The backend cannot be loaded (see :func:`gl_backend`).

    Examples
    --------
    >>> from trms.twin import Twin
    >>> twin = Twin("1dof", 0.1)
    >>> physics = dm_control_physics(twin.data)
    >>> _ = twin.step([9.0])  # the physics follows the twin
    >>> bool(physics.named.data.qpos["pitch"][0] == twin.channels()["true_angles"][0])
    True
    """
    with _backend_environment(gl_backend()):
        from dm_control.mujoco import Physics, wrapper
    physics = Physics(wrapper.MjData(data))  # runs mj_forward without actuation (dm_control's after_reset)
    mujoco.mj_forward(data.model, data)  # the derived quantities of the actuated dynamics again
    return physics


class TwinRenderer:
    """Offscreen renderer for a compiled twin model.

    The OpenGL context is created here, with the backend :func:`gl_backend` names (``MUJOCO_GL``, else
    OSMesa).

    Parameters
    ----------
    model : mujoco.MjModel
        The model to draw (e.g. ``Twin(...).model``).
    width, height : int
        Image size in pixels (at most the model's offscreen buffer, 640 x 480).

    Raises
    ------
    InputError
        An image size outside the buffer.
    ConfigurationError
        The OpenGL backend cannot be loaded or create a context.

    Examples
    --------
    >>> from trms.twin import Twin
    >>> twin = Twin("1dof", 0.1)
    >>> with TwinRenderer(twin.model, 64, 48) as renderer:
    ...     frame = renderer.frame(twin.trim.qpos)
    >>> frame.shape, frame.dtype.name, bool(frame.std() > 0)
    ((48, 64, 3), 'uint8', True)
    """

    def __init__(self, model: mujoco.MjModel, width: int = 320, height: int = 240) -> None:
        max_w, max_h = int(model.vis.global_.offwidth), int(model.vis.global_.offheight)
        if not (16 <= int(width) <= max_w and 16 <= int(height) <= max_h):
            raise InputError(f"image size {width} x {height} is outside [16, {max_w}] x [16, {max_h}] pixels")
        self.model = model
        self.cameras = tuple(model.camera(i).name for i in range(model.ncam))
        self._data = mujoco.MjData(model)
        w, h = int(width), int(height)
        self._gl: Any = _gl_context(w, h)
        self._context: mujoco.MjrContext | None = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_150)
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self._context)
        self._scene = mujoco.MjvScene(model, maxgeom=10000)
        self._option = mujoco.MjvOption()
        self._camera = mujoco.MjvCamera()
        self._camera.type = mujoco.mjtCamera.mjCAMERA_FIXED
        self._rect = mujoco.MjrRect(0, 0, w, h)
        self._pixels = np.empty((h, w, 3), np.uint8)

    def __enter__(self) -> TwinRenderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Free the GL context (idempotent)."""
        if self._context is not None:
            self._gl.make_current()
            self._context.free()
            self._context = None
            self._gl.free()
            self._gl = None

    def __del__(self) -> None:
        with contextlib.suppress(Exception):  # a renderer never closed, or one whose __init__ failed
            self.close()

    def frame(
        self, qpos: np.ndarray | None = None, camera: str = "front", data: mujoco.MjData | None = None
    ) -> np.ndarray:
        """Render one frame.

        Parameters
        ----------
        qpos : numpy.ndarray, optional
            Joint positions (rad) to draw; ignored when ``data`` is given.
        camera : str
            A named camera of the model.
        data : mujoco.MjData, optional
            A live state to draw (not modified).

        Returns
        -------
        numpy.ndarray
            ``(height, width, 3)`` uint8 RGB image.
        """
        if self._context is None:
            raise InputError("this renderer is closed")
        check_choice("camera", camera, self.cameras, error=InputError)
        if data is None:
            if qpos is not None:
                q = np.asarray(qpos, float)
                if q.shape != (self.model.nq,):
                    raise InputError(f"qpos must have shape ({self.model.nq},), got {q.shape}")
                self._data.qpos[:] = q
            mujoco.mj_forward(self.model, self._data)
            data = self._data
        self._camera.fixedcamid = self.cameras.index(camera)
        self._gl.make_current()
        mujoco.mjv_updateScene(
            self.model, data, self._option, None, self._camera, mujoco.mjtCatBit.mjCAT_ALL, self._scene
        )
        mujoco.mjr_render(self._rect, self._scene, self._context)
        mujoco.mjr_readPixels(self._pixels, None, self._rect, self._context)
        return np.flipud(self._pixels).copy()  # OpenGL's rows run bottom to top


def save_png(frame: np.ndarray, path: str | os.PathLike[str]) -> Path:
    """Write an RGB frame as PNG."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return atomic_write(path, lambda fh: Image.fromarray(np.asarray(frame, np.uint8)).save(fh, format="PNG"))


def save_gif(frames: Sequence[np.ndarray], path: str | os.PathLike[str], fps: float = 10.0) -> Path:
    """Write RGB frames as a looping GIF at ``fps`` frames per second."""
    if len(frames) == 0:
        raise InputError("save_gif needs at least one frame")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    images = [Image.fromarray(np.asarray(f, np.uint8)) for f in frames]
    return atomic_write(
        path,
        lambda fh: images[0].save(
            fh, format="GIF", save_all=True, append_images=images[1:], duration=int(round(1000 / fps)), loop=0
        ),
    )


def save_mp4(frames: Sequence[np.ndarray], path: str | os.PathLike[str], fps: float = 10.0) -> Path:
    """Write RGB frames as an H.264 MP4 at ``fps`` frames per second (sizes padded to even by ffmpeg).

    The video is written beside ``path`` and moved over it when complete, so a failed or
    interrupted write leaves any old file as it was. Needs the ``video`` extra
    (``pip install 'trms[video]'``, which brings an ffmpeg binary).

    Raises
    ------
    InputError
        No frames.
    ConfigurationError
        The ``video`` extra is not installed.
    """
    try:
        import imageio_ffmpeg
    except ImportError:
        raise ConfigurationError(
            "writing MP4 needs the video extra (an ffmpeg binary): pip install 'trms[video]'; "
            "or write a .gif, which needs nothing more"
        ) from None
    if len(frames) == 0:
        raise InputError("save_mp4 needs at least one frame")
    shape = np.shape(frames[0])
    bad = next((k for k, f in enumerate(frames) if np.shape(f) != shape), None)
    if len(shape) != 3 or shape[2] != 3 or bad is not None:
        got = np.shape(frames[bad if bad is not None else 0])
        raise InputError(
            f"frame {bad or 0} has shape {got}; every frame must be (height, width, 3) RGB of one size {shape}"
        )
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    h, w = shape[:2]
    partial = path.with_name(f".{path.name}.partial.mp4")
    writer = imageio_ffmpeg.write_frames(
        str(partial), (w, h), fps=float(fps), codec="libx264", quality=8, macro_block_size=2, ffmpeg_log_level="error"
    )
    writer.send(None)
    try:
        for f in frames:
            writer.send(np.ascontiguousarray(np.asarray(f, np.uint8)))
        writer.close()
        os.replace(partial, path)
    finally:
        writer.close()
        partial.unlink(missing_ok=True)
    return path


def render_record(
    model: mujoco.MjModel,
    record: Record,
    path: str | os.PathLike[str],
    camera: str = "front",
    every: int = 1,
    width: int = 320,
    height: int = 240,
) -> Path:
    """Render a twin Record (its ``qpos`` channel) to a PNG (one frame) or GIF (``.gif``).

    Parameters
    ----------
    model : mujoco.MjModel
        The model the record came from (same configuration).
    record : Record
        Must carry the ``qpos`` extra channel (every Twin record does).
    path : path-like
        ``.png`` writes the last frame; ``.gif`` or ``.mp4`` writes every ``every``-th sample, played in
        real time.
    """
    if "qpos" not in record.extras:
        raise InputError("record has no 'qpos' channel to render (it was not produced by a Twin)")
    if int(every) < 1:
        raise InputError(f"every = {every!r} must be an integer >= 1")
    path = Path(path)
    qpos = record.extras["qpos"]
    with TwinRenderer(model, width, height) as r:
        if path.suffix.lower() == ".png":
            return save_png(r.frame(qpos[-1], camera), path)
        writers = {".gif": save_gif, ".mp4": save_mp4}
        if path.suffix.lower() not in writers:
            raise InputError(f"render output {str(path)!r} must end in .png, .gif or .mp4")
        frames = [r.frame(q, camera) for q in qpos[:: int(every)]]
    return writers[path.suffix.lower()](frames, path, fps=1.0 / (record.sample_time * int(every)))
