"""The hybrid paper's Figure 7 on the GPU (`python -m oit bench --figure7`): per-pixel stacks,
mean RGB distance to the exact A-buffer for wavg and for hybrid, ktab and adaptive at each k."""

from __future__ import annotations

from .. import scenes as scene_lib
from .._api import Renderer
from .harness import mean_rgb_distance

FIGURE7_KS = (1, 2, 4, 8, 16)


def figure7_errors(renderer: Renderer, layers: int, alphas: str, seed: int = 0) -> dict[tuple[str, int], float]:
    """The hybrid paper's Figure 7 on the GPU: one stack per pixel of the renderer's frame
    (oit.scenes.stacks, black background), mean RGB distance to the exact A-buffer for wavg
    (k = 0) and for hybrid, ktab and adaptive at each k in FIGURE7_KS."""
    built = scene_lib.stacks(layers=layers, alphas=alphas, size=(renderer.width, renderer.height), seed=seed)
    render = lambda m, **p: renderer.render(built.scene, built.camera, m, background=(0.0, 0.0, 0.0), **p).image  # noqa: E731
    exact = render("abuffer")
    errors = {("wavg", 0): mean_rgb_distance(render("wavg"), exact)}
    for k in FIGURE7_KS:
        errors[("hybrid", k)] = mean_rgb_distance(render("hybrid", k=k), exact)
        errors[("ktab", k)] = mean_rgb_distance(render("ktab", k=k), exact)
        errors[("adaptive", k)] = mean_rgb_distance(render("adaptive", nodes=k), exact)
    return errors


def figure7_table(size: int = 20) -> str:
    """Markdown table of figure7_errors for 20 and 100 fragments and every distribution."""
    r = Renderer(size, size)
    lines = ["| layers | alphas | wavg | " + " | ".join(f"{m} k={k}" for k in FIGURE7_KS for m in ("hybrid", "ktab", "adaptive")) + " |"]
    lines.append("|" + "---|" * (3 + 3 * len(FIGURE7_KS)))
    for layers in (20, 100):
        for alphas in scene_lib.ALPHA_KINDS:
            e = figure7_errors(r, layers, alphas, seed=layers + len(alphas))
            cells = [f"{e[(m, k)]:.4f}" for k in FIGURE7_KS for m in ("hybrid", "ktab", "adaptive")]
            lines.append(f"| {layers} | {alphas} | {e[('wavg', 0)]:.4f} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
