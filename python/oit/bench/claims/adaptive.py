"""The claims of Adaptive Transparency (Salvi et al. 2011), each measured on this engine (docs/claims.md)."""

from __future__ import annotations

from ... import Renderer
from ... import scenes as scene_lib
from ..harness import image_errors
from .common import FAILS, HOLDS, Claim, median_ms


def adaptive_quality() -> tuple[str, str]:
    built = scene_lib.smoke(particles=200)
    r = Renderer(64, 64)
    exact = r.render(built.scene, built.camera, "abuffer")
    covered = exact.depth_complexity > 0
    errs = {}
    for n in (4, 16):
        image = r.render(built.scene, built.camera, "adaptive", nodes=n).image
        errs[n] = image_errors(image, exact.image, covered, flip=False)["mean_err"]
    text = (", ".join(f"{n} nodes {e:.4f}" for n, e in errs.items()) + " mean error against the A-buffer (smoke, 64²); "
            "'close': within 1/255 (0.0039)")
    return text, HOLDS if max(errs.values()) <= 1 / 255 else FAILS


def adaptive_vs_abuffer_time() -> tuple[str, str]:
    out, ratios = [], []
    for name in ("smoke", "hair", "foliage"):
        built = scene_lib.SCENES[name]()
        r = Renderer(*built.size)
        a = median_ms(r, built, "abuffer")
        try:
            t = median_ms(r, built, "adaptive", nodes=8)
        except RuntimeError as e:
            out.append(f"{name}: adaptive failed ({str(e).splitlines()[0][:60]}...)")
            continue
        ratios.append(a / t)
        out.append(f"{name}: abuffer {a:.0f} ms, adaptive 8 nodes {t:.0f} ms ({a / t:.2f}×)")
    ok = bool(ratios) and min(ratios) >= 7
    return "; ".join(out), HOLDS if ok else FAILS


def adaptive_vs_stochastic_time() -> tuple[str, str]:
    out, ratios = [], []
    for name in ("smoke", "foliage", "hair"):
        built = scene_lib.SCENES[name]()
        r = Renderer(*built.size)
        s = median_ms(r, built, "stochastic", samples=8)
        t = median_ms(r, built, "adaptive", nodes=8)
        ratios.append(s / t)
        out.append(f"{name}: stochastic 8 samples {s:.0f} ms, adaptive 8 nodes {t:.0f} ms ({s / t:.2f}×)")
    return "; ".join(out), HOLDS if min(ratios) >= 2 else FAILS


CLAIMS: list[Claim] = [
    Claim("AT-quality", "Salvi et al. 2011, results slides", "\"high image quality\" (read as: close to the A-buffer with 4 to 16 "
          "nodes)", True, adaptive_quality),
    Claim("AT-speed", "Salvi et al. 2011, results slides", "\"up to 40x faster than A-buffer\": smoke 30×, forest 7×, hair 40×", False,
          adaptive_vs_abuffer_time),
    Claim("AT-stoch", "Salvi et al. 2011, results slides", "\"2.5x faster than Stoc. Transp.\" (smoke), 2× (forest, hair)", False,
          adaptive_vs_stochastic_time),
]
