"""The claims of Kerzner et al. 2013 (primitive-allocated linked lists and the compact
A-buffer), each measured on this engine (docs/claims.md)."""

from __future__ import annotations

from ... import Renderer
from ... import scenes as scene_lib
from .common import FAILS, HOLDS, Claim, median_ms, render


def list_memory_linear() -> tuple[str, str]:
    points = []
    for layers in (4, 16, 64):
        built = scene_lib.stacks(layers=layers, size=(16, 16), seed=8)
        f = render(built, "abuffer")
        points.append((f.stats["fragments"], f.stats["memory_bytes"]))
    slopes = [(m2 - m1) / (f2 - f1) for (f1, m1), (f2, m2) in zip(points, points[1:])]
    text = ", ".join(f"{f} fragments: {m / 1024:.0f} KiB" for f, m in points)
    text += f"; {slopes[0]:.1f} and {slopes[1]:.1f} bytes a fragment more"
    return text, HOLDS if all(abs(s - 24) < 1e-9 for s in slopes) else FAILS


def pall_memory() -> tuple[str, str]:
    built = scene_lib.glass(detail=16)
    r = Renderer(64, 64)
    pall = r.render(built.scene, built.camera, "pall").stats["memory_bytes"]
    lists = r.render(built.scene, built.camera, "abuffer").stats["memory_bytes"]
    text = f"glass at 64²: pall {pall / 1024:.0f} KiB, abuffer {lists / 1024:.0f} KiB ({pall / lists:.1f}×)"
    return text, HOLDS if pall > lists else FAILS


def compact_memory() -> tuple[str, str]:
    out, smaller, larger = [], False, False
    for name, built in (("8 full-screen layers", scene_lib.stacks(layers=8, size=(1, 1), seed=4)), ("hair", scene_lib.hair(strands=300))):
        r = Renderer(64, 64)
        compact = r.render(built.scene, built.camera, "compact_abuffer")
        plain = r.render(built.scene, built.camera, "abuffer")
        per_tri = compact.stats["fragments"] / max(built.scene.triangle_count, 1)
        ratio = compact.stats["memory_bytes"] / plain.stats["memory_bytes"]
        out.append(f"{name}: {per_tri:.1f} fragments a triangle, compact {ratio:.2f}× the A-buffer's memory")
        smaller |= per_tri > 15 and ratio < 1
        larger |= per_tri < 15 and ratio > 1
    verdict = HOLDS if smaller and larger else FAILS
    return "; ".join(out) + " (smaller past 176/12 ≈ 15 fragments a triangle)", verdict


def pall_vs_lists_time() -> tuple[str, str]:
    built = scene_lib.glass()
    r = Renderer(*built.size)
    a = median_ms(r, built, "abuffer")
    p = median_ms(r, built, "pall")
    frags = r.render(built.scene, built.camera, "abuffer").stats["fragments"]
    return (f"glass {built.size[0]}x{built.size[1]}, {frags / 1e6:.2f} M fragments: abuffer {a:.0f} ms, pall {p:.0f} ms "
            f"({a / p:.2f}×)"), HOLDS if p < a else FAILS


CLAIMS: list[Claim] = [
    Claim("KZ-linear", "Kerzner et al. 2013", "a linked-list A-buffer's memory grows linearly with the fragment count", True,
          list_memory_linear),
    Claim("KZ-mem", "Kerzner et al. 2013", "PALL uses more memory than per-pixel linked lists", True, pall_memory),
    Claim("KZ-compact", "Kerzner et al. 2013, Fig. 1", "the compact A-buffer uses less memory than the regular one when "
          "fragments outnumber primitives", True, compact_memory),
    Claim("KZ-time", "Kerzner et al. 2013", "PALL is faster than per-pixel linked lists (4.95 against 5.36 ms at 1.4 M "
          "fragments)", False, pall_vs_lists_time),
]
