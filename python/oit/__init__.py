"""oit: order-independent transparency methods on one wgpu engine, with the exact
answer (an A-buffer and a CPU float64 reference) beside them.

    import oit
    scene = oit.Scene()
    scene.add_mesh(positions, indices, colors)
    cam = oit.Camera.look_at(eye=(0, 0, 3), target=(0, 0, 0), fov_y=45.0, near=0.1, far=100.0)
    frame = oit.Renderer(512, 512).render(scene, cam, method="abuffer")
    exact = oit.reference(scene, cam, 512, 512)
"""

import os as _os
import tempfile as _tempfile

# The Vulkan loader's window-system code complains on stderr when XDG_RUNTIME_DIR is unset
# (headless machines, CI); a private directory keeps it quiet. Nothing is written there.
if not _os.environ.get("XDG_RUNTIME_DIR"):
    _runtime = _os.path.join(_tempfile.gettempdir(), f"oit-runtime-{_os.getuid()}")
    _os.makedirs(_runtime, mode=0o700, exist_ok=True)
    _os.environ["XDG_RUNTIME_DIR"] = _runtime

from ._api import Camera, FileCamera, Frame, Renderer, Scene, Stats, constants, memory_bytes, methods, reference
from ._load import OitLoadWarning
from .comparison import Comparison, compare

__all__ = ["Camera", "Comparison", "FileCamera", "Frame", "OitLoadWarning", "Renderer", "Scene", "Stats", "compare", "constants",
           "memory_bytes", "methods", "reference"]
__version__ = "0.1.0"
