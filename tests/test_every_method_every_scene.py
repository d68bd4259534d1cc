"""Every method of oit.methods() renders every built-in scene (small versions) without error,
with finite pixels and the frame's census in its stats (issue 4); the methods that take
per-pixel locks (adaptive, mlab) report that no fragment gave up on one."""

from __future__ import annotations

import numpy as np
import pytest

import oit
from oit import scenes

SMALL = {
    "hair": dict(strands=300),
    "smoke": dict(particles=80),
    "foliage": dict(leaves=300),
    "glass": dict(detail=12),
    "dragons": dict(max_triangles=1500),
    "stacks": dict(layers=12, size=(8, 8)),
    "splats": dict(count=600),
    "splat_cloud": dict(count=600),
}


@pytest.fixture(scope="module")
def built():
    return {name: scenes.SCENES[name](**SMALL.get(name, {})) for name in scenes.SCENES}


@pytest.mark.parametrize("method", [m["name"] for m in oit.methods()])
def test_method_renders_every_scene(renderer, built, method):
    r = renderer(32, 32)
    for name, b in built.items():
        frame = r.render(b.scene, b.camera, method, census=True)
        assert np.isfinite(frame.image).all(), (method, name)
        assert frame.stats["fragments"] == int(frame.depth_complexity.sum()), (method, name)
        assert frame.stats["extra"].get("lock_failures", 0) == 0, (method, name)
