"""lca: an experiment and ablation platform for learned humanoid locomotion."""

import ctypes.util
import os
import sys

__version__ = "0.1.0"


def _headless_gl() -> None:
    """MuJoCo fixes its OpenGL backend when first imported, and its default (GLFW) needs a
    display: without one, pick EGL or OSMesa, whichever is installed whole (a backend whose
    libraries are missing would break `import mujoco` itself). An explicit MUJOCO_GL is left
    alone."""
    if sys.platform != "linux" or "MUJOCO_GL" in os.environ:
        return
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return
    found = ctypes.util.find_library
    if found("EGL") and (found("OpenGL") or found("GL")):  # PyOpenGL needs both
        os.environ["MUJOCO_GL"] = "egl"
    elif found("OSMesa"):
        os.environ["MUJOCO_GL"] = "osmesa"


_headless_gl()
