"""Test-wide settings: headless rendering, and MuJoCo warnings are failures."""

import os

os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
