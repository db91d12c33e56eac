"""lca: an experiment and ablation platform for learned humanoid locomotion."""

import ctypes.util
import os
import sys

__version__ = "0.1.0"


def _headless_gl() -> None:
    """MuJoCo fixes its OpenGL backend when first imported, and its default (GLFW) needs a
    display: without one, pick EGL or OSMesa, whichever library is installed. An explicit
    MUJOCO_GL is left alone."""
    if sys.platform != "linux" or "MUJOCO_GL" in os.environ:
        return
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return
    for library, backend in (("EGL", "egl"), ("OSMesa", "osmesa")):
        if ctypes.util.find_library(library):
            os.environ["MUJOCO_GL"] = backend
            return


_headless_gl()
