"""``trms render``: a twin Record -> PNG (last frame), GIF or MP4."""

from __future__ import annotations

import argparse

__all__ = ["NAME", "HELP", "DESCRIPTION", "EPILOG", "add_arguments", "run"]

NAME = "render"
HELP = "render a twin Record to PNG, GIF or MP4"
DESCRIPTION = "Render a Record of the twin offscreen: the last frame as PNG, or every n-th sample as a GIF or MP4."
EPILOG = """examples:
  trms render run125/record.npz --out run125/rig.gif --every 2
  trms render prbs.npz --out last.png --camera front
  trms render run125/record.npz --out run125/rig.mp4
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``trms render``."""
    p.add_argument("record", help="a twin Record file (.npz) with its qpos channel")
    p.add_argument("--out", default="render.gif", help=".png (last frame), .gif or .mp4 (default render.gif)")
    p.add_argument(
        "--config", default=None, choices=["1dof", "2dof", "yaw"], help="configuration (default: the record's)"
    )
    p.add_argument("--camera", default="oblique", choices=["front", "oblique", "top"], help="camera (default oblique)")
    p.add_argument("--every", type=int, default=2, help="GIF: every n-th sample (default 2)")
    p.add_argument("--width", type=int, default=320, help="pixels (default 320)")
    p.add_argument("--height", type=int, default=240, help="pixels (default 240)")


def run(args: argparse.Namespace) -> int:
    """Run ``trms render``; return the exit status."""
    from trms.rig.exports import load_record
    from trms.twin.record_render import render_saved_record

    rec = load_record(args.record)
    path, config = render_saved_record(
        rec,
        args.out,
        args.config,
        label=args.record,
        camera=args.camera,
        every=args.every,
        width=args.width,
        height=args.height,
    )
    print(f"rendered {len(rec)} samples ({config}, camera {args.camera})\nwrote {path}")
    return 0
