"""Offscreen rendering of the twin (OSMesa by default; ``MUJOCO_GL`` overrides).

A :class:`TwinRenderer` owns one GL context; use it as a context manager (or call
:meth:`TwinRenderer.close`) so the context is freed deterministically, not at
interpreter exit. Frames are ``(height, width, 3)`` uint8 arrays; :func:`save_png` and
:func:`save_gif` write them with Pillow, :func:`save_mp4` as H.264 with the ffmpeg that
the ``imageio-ffmpeg`` wheel ships.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import mujoco
import numpy as np
from PIL import Image

from ..errors import InputError, check_choice
from ..files import atomic_write
from ..plant import Record

__all__ = ["TwinRenderer", "save_png", "save_gif", "save_mp4", "render_record"]


class TwinRenderer:
    """Offscreen renderer for a compiled twin model.

    Parameters
    ----------
    model : mujoco.MjModel
        The model to draw (e.g. ``Twin(...).model``).
    width, height : int
        Image size in pixels (at most the model's offscreen buffer, 640 x 480).
    """

    def __init__(self, model: mujoco.MjModel, width: int = 320, height: int = 240) -> None:
        max_w, max_h = int(model.vis.global_.offwidth), int(model.vis.global_.offheight)
        if not (16 <= int(width) <= max_w and 16 <= int(height) <= max_h):
            raise InputError(f"image size {width} x {height} is outside [16, {max_w}] x [16, {max_h}] pixels")
        self.model = model
        self.cameras = tuple(model.camera(i).name for i in range(model.ncam))
        self._data = mujoco.MjData(model)
        self._renderer: mujoco.Renderer | None = mujoco.Renderer(model, int(height), int(width))

    def __enter__(self) -> TwinRenderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Free the GL context (idempotent)."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

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
        if self._renderer is None:
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
        self._renderer.update_scene(data, camera=camera)
        return self._renderer.render().copy()


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
    """Write RGB frames as an H.264 MP4 at ``fps`` frames per second (sizes padded to even by ffmpeg)."""
    import imageio_ffmpeg

    if len(frames) == 0:
        raise InputError("save_mp4 needs at least one frame")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    h, w = np.asarray(frames[0]).shape[:2]
    writer = imageio_ffmpeg.write_frames(
        str(path), (w, h), fps=float(fps), codec="libx264", quality=8, macro_block_size=2, ffmpeg_log_level="error"
    )
    writer.send(None)
    try:
        for f in frames:
            writer.send(np.ascontiguousarray(np.asarray(f, np.uint8)))
    finally:
        writer.close()
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
