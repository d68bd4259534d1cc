"""The public API, gathered from the modules that hold it: the scene (`_scene`), cameras
(`_camera`), and rendering with its frames, stats and reference (`_render`). Arguments are
converted there into what the native layer takes (dtypes, shapes, Python types), with errors that
name the argument; every check of their values (ranges, finiteness, index bounds, counts) happens
once, in the core, whose errors say what to do."""

from ._camera import Camera, FileCamera
from ._render import ANTIALIAS, Frame, Renderer, Stats, constants, memory_bytes, methods, reference
from ._scene import Scene, load_file

__all__ = ["ANTIALIAS", "Camera", "FileCamera", "Frame", "Renderer", "Scene", "Stats", "constants", "load_file",
           "memory_bytes", "methods", "reference"]
