"""`python -m oit`: the command line. One function pair per subcommand (`_add_<name>` for
its arguments, `_<name>` to run it) and one line in `SUBCOMMANDS`. Errors end with a
one-line message: exit status 2 for bad input (as argparse does), 1 for device or memory
failures."""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import warnings
from collections.abc import Iterator, Sequence
from typing import Any, Callable

EXIT_USAGE = 2


def _ensure_parent(path: str) -> None:
    parent = os.path.dirname(os.path.abspath(path))
    os.makedirs(parent, exist_ok=True)


def _positive_int(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if v <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {v}")
    return v


def _unit_float(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number in [0, 1], got {text!r}") from None
    if not 0.0 <= v <= 1.0:
        raise argparse.ArgumentTypeError(f"expected a number in [0, 1], got {v}")
    return v


def parse_param(text: str) -> tuple[str, Any]:
    """'k=v' to (k, v) with v an int, else a float, else the string."""
    key, sep, value = text.partition("=")
    if not sep or not key:
        raise argparse.ArgumentTypeError(f"parameters are written name=value, got {text!r}")
    for convert in (int, float):
        try:
            return key, convert(value)
        except ValueError:
            pass
    return key, value


# ---- demo


def _add_demo(p: argparse.ArgumentParser) -> None:
    p.add_argument("-o", "--output", default="out/demo.png", help="PNG to write (default: %(default)s)")
    p.add_argument("--size", type=_positive_int, default=384, help="width and height of each tile (default: %(default)s)")
    p.add_argument("--adapter", default=None, help="substring of the adapter name (default: OIT_ADAPTER or the best one)")


def _demo(args: argparse.Namespace) -> int:
    from . import demo
    from .imageio import write_png

    result = demo.run(args.size, adapter=args.adapter)
    _ensure_parent(args.output)
    write_png(args.output, result.mosaic)
    print(f"adapter: {result.frames['abuffer'].stats['adapter']}")
    print(demo.legend(result))
    print(f"wrote {args.output} ({result.mosaic.shape[1]} x {result.mosaic.shape[0]})")
    return 0


# ---- render


def _check_animation_writer(ext: str) -> None:
    """Refuses before any rendering, saying what to install, when the writer of a .gif (Pillow)
    or an .mp4 (imageio with imageio-ffmpeg) is not installed."""
    import importlib.util

    needs = {".gif": ("PIL",), ".mp4": ("imageio", "imageio_ffmpeg")}[ext]
    missing = [m for m in needs if importlib.util.find_spec(m) is None]
    if missing:
        what = "Pillow: pip install pillow" if ext == ".gif" else "imageio and imageio-ffmpeg: pip install imageio imageio-ffmpeg"
        raise RuntimeError(f"writing a {ext[1:].upper()} needs {what} (or pip install 'oit[video]', which has both)")


def _plural(n: int, one: str, many: str) -> str:
    return f"{n} {one if n == 1 else many}"


def describe_contents(scene: Any) -> str:
    """What a scene draws, counted by primitive kind: "2 meshes (1200 triangles), 500 particles,
    30 strands (600 points), 1000 splats": meshes as added, what they draw as many times as they are instanced."""
    totals = {"triangles": [0, 0, 0], "particles": [0, 0, 0], "strands": [0, 0, 0], "gaussians": [0, 0, 0]}
    for i, (kind, (triangles, vertices, _)) in enumerate(zip(scene.primitives(), scene._native.mesh_summary())):
        n = max(1, len(scene._native.instances(i)[0]))
        t = totals[kind]
        # Particles: a quad (2 triangles) each; strands: 2 triangles a segment, one segment fewer than points.
        t[0] += 1
        t[1] += n * (triangles if kind == "triangles" else vertices - triangles // 2 if kind == "strands" else vertices)
        t[2] += n * vertices
    parts = []
    if totals["triangles"][0]:
        parts.append(_plural(totals["triangles"][0], "mesh", "meshes") + f" ({_plural(totals['triangles'][1], 'triangle', 'triangles')})")
    if totals["particles"][0]:
        parts.append(_plural(totals["particles"][1], "particle", "particles"))
    if totals["strands"][0]:
        parts.append(_plural(totals["strands"][1], "strand", "strands") + f" ({_plural(totals['strands'][2], 'point', 'points')})")
    if totals["gaussians"][0]:
        parts.append(_plural(totals["gaussians"][1], "splat", "splats"))
    return ", ".join(parts) or "nothing to draw"


def _add_render(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="a mesh file: OBJ (with its MTL), glTF, GLB, PLY or STL (docs/loading.md)")
    p.add_argument("-m", "--method", default="abuffer", help="see `python -m oit methods` (default: %(default)s)")
    p.add_argument("--alpha", type=_unit_float, default=None,
                   help="make every mesh transparent at this alpha (default: the file's materials; when nothing in "
                        "the file is transparent, every mesh at 0.4)")
    p.add_argument("-o", "--output", default=None,
                   help="PNG to write, or with --orbit a .gif or .mp4 (default: out/<file stem>-<method>.png or .gif)")
    p.add_argument("--orbit", type=_positive_int, default=None, metavar="N",
                   help="render N views around the scene into an animation (-o out.gif or out.mp4) and report the "
                        "sequence's temporal error against the exact frames")
    p.add_argument("--fps", type=float, default=12.0, help="frames a second of the --orbit animation (default: %(default)s)")
    p.add_argument("--size", type=_positive_int, nargs=2, metavar=("W", "H"), default=(512, 512))
    p.add_argument("--background", type=_unit_float, nargs=3, metavar=("R", "G", "B"), default=(1.0, 1.0, 1.0),
                   help="linear RGB in [0, 1] (default: white)")
    p.add_argument("--param", type=parse_param, action="append", default=[], metavar="NAME=VALUE",
                   help="a method parameter; repeat for several")
    p.add_argument("--shading", choices=("smooth", "flat", "unlit"), default="smooth",
                   help="smooth (the file's vertex normals), flat or unlit (default: %(default)s; docs/shading.md)")
    p.add_argument("--light", type=float, nargs=3, action="append", default=[], metavar=("DX", "DY", "DZ"),
                   help="a white directional light travelling along DX DY DZ (world space); repeat for several "
                        "(default: a headlight along the view)")
    p.add_argument("--ambient", type=_unit_float, nargs=3, metavar=("R", "G", "B"), default=(0.1, 0.1, 0.1),
                   help="ambient light, linear RGB (default: %(default)s)")
    p.add_argument("--specular", type=float, default=0.25, help="Blinn-Phong highlight weight (default: %(default)s)")
    p.add_argument("--adapter", default=None, help="substring of the adapter name (default: OIT_ADAPTER or the best one)")


def _render(args: argparse.Namespace) -> int:
    from ._api import Renderer
    from .imageio import write_png
    from .views import fit_camera, load_for_viewing, orbit_cameras

    stem = os.path.splitext(os.path.basename(args.file))[0]
    if args.orbit is not None:
        from .sequence import check_animation_path

        output = args.output or os.path.join("out", f"{stem}-{args.method}.gif")
        _check_animation_writer(check_animation_path(output))
    else:
        output = args.output or os.path.join("out", f"{stem}-{args.method}.png")
    scene = load_for_viewing(args)
    width, height = args.size
    renderer = Renderer(width, height, adapter=args.adapter)
    params: dict[str, Any] = dict(args.param)
    lights = f"{len(args.light)} lights" if args.light else "headlight"
    if args.alpha is not None:
        alpha = f"alpha {args.alpha}"
    else:  # load_for_viewing said it when nothing in the file is transparent
        alpha = "every mesh at alpha 0.4" if getattr(args, "alpha_note", None) else "the file's alpha"
    print(f"{args.file}: {describe_contents(scene)}, {alpha}, {args.shading} shading "
          f"({lights}), {width} x {height}, method {args.method}")
    if args.orbit is not None:
        from .sequence import render_sequence, write_animation

        cameras = orbit_cameras(scene, args.orbit, aspect=width / height)
        orbit = render_sequence(renderer, scene, cameras, args.method, tuple(args.background), **params)
        _ensure_parent(output)
        write_animation(output, orbit.images, args.fps)
        t = orbit.temporal
        print(f"  {args.orbit} views; against the exact frames: mean error {t['mean_err']:.5f}, max {t['max_err']:.4f}"
              + (f"; flicker {t['flicker']:.5f} (max {t['max_flicker']:.4f}) of a frame-to-frame change of "
                 f"{t['change']:.5f}" if "flicker" in t else ""))
        print(f"wrote {output}")
        return 0
    camera = scene.cameras[0].camera(width / height) if scene.cameras else fit_camera(scene, aspect=width / height)
    frame = renderer.render(scene, camera, method=args.method, background=tuple(args.background), census=True, **params)
    _ensure_parent(output)
    write_png(output, frame.image[..., :3])
    s = frame.stats
    gpu = f"{s['gpu_time_ms']:.2f} ms" if s.get("gpu_time_ms") is not None else "n/a (no timestamp queries)"
    print(f"  params: {s['params'] or '{}'}")
    print(f"  fragments {s['fragments']}, max depth complexity {s['max_depth_complexity']}, "
          f"overflow {s['overflow_fragments']}")
    print(f"  memory {s['memory_bytes'] / 2**20:.2f} MiB, gpu {gpu}, wall {s['wall_time_ms']:.1f} ms")
    print(f"  adapter: {s['adapter']}")
    print(f"wrote {output}")
    return 0


# ---- compare


def _add_compare(p: argparse.ArgumentParser) -> None:
    from .comparison import add_arguments

    p.add_argument("file", nargs="+", help="mesh files: OBJ (with its MTL), glTF, GLB, PLY or STL (docs/loading.md); "
                                           "each row measures every view of every file")
    p.add_argument("--alpha", type=_unit_float, default=None,
                   help="make every mesh transparent at this alpha (default: the file's; 0.4 when nothing is transparent)")
    p.add_argument("--shading", choices=("smooth", "flat", "unlit"), default="smooth", help="(default: %(default)s)")
    p.add_argument("--specular", type=float, default=0.25, help="Blinn-Phong highlight weight (default: %(default)s)")
    add_arguments(p)


def _compare(args: argparse.Namespace) -> int:
    from .comparison import run_cli
    from .views import load_for_viewing

    files, scenes = args.file, []
    for f in files:  # each loaded as `render` loads it, its alpha note said
        args.file = f
        scenes.append(load_for_viewing(args))
    args.file = files
    return run_cli(args, scenes)


# ---- methods


def _add_methods(p: argparse.ArgumentParser) -> None:
    pass


def format_methods(methods: list[dict]) -> str:
    """The method table (name, exact, bounded memory, parameters), then each method's
    summary and passes."""

    def param(p: dict) -> str:
        if p["type"] == "choice":
            return f"{p['name']}={p['default']} {{{','.join(p['choices'])}}}"
        return f"{p['name']}={p['default']} [{p['min']}, {p['max']}]"

    rows = [("method", "exact", "bounded memory", "parameters (default [range])")]
    for m in methods:
        rows.append((m["name"], "yes" if m["exact"] else "no", "yes" if m["bounded_memory"] else "no",
                     "; ".join(param(p) for p in m["params"]) or "-"))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    for m in methods:
        lines += ["", f"{m['name']}: {m['summary']}", f"  passes: {' -> '.join(m['passes'])}"]
    return "\n".join(lines)


def _methods(args: argparse.Namespace) -> int:
    from ._api import methods

    print(format_methods(methods()))
    return 0


# ---- bench


def _add_bench(p: argparse.ArgumentParser) -> None:
    from .bench import cli as bench_cli

    bench_cli.add_arguments(p)


def _bench(args: argparse.Namespace) -> int:
    from .bench import cli as bench_cli

    return bench_cli.run_cli(args)


# ---- view


def _add_view(p: argparse.ArgumentParser) -> None:
    p.add_argument("files", nargs="*", metavar="FILE", help=".oitscene, OBJ, PLY, STL, glTF or GLB files")
    p.add_argument("--scene", default=None, help="a built-in scene: hair, smoke, foliage, dragons, glass, stacks")
    p.add_argument("-m", "--method", default=None, help="the method to start with (default: hybrid)")
    p.add_argument("--alpha", type=_unit_float, default=None, help="make every mesh transparent at this alpha")
    p.add_argument("--param", type=str, action="append", default=[], metavar="NAME=VALUE",
                   help="a parameter of the method; repeat for several")
    p.add_argument("--screenshot", default=None, metavar="PATH", help="save the window as PNG and exit")
    p.add_argument("--frames", type=_positive_int, default=None, help="frames to run before --screenshot (default: 3)")
    p.add_argument("--compare", choices=("off", "split", "toggle"), default=None, help="compare with abuffer")
    p.add_argument("--view", choices=("image", "complexity", "error"), default=None, help="what the view shows")
    p.add_argument("--size", type=_positive_int, nargs=2, metavar=("W", "H"), default=None, help="window size in points")
    p.add_argument("--adapter", default=None, help="substring of the adapter name (default: OIT_ADAPTER or the best one)")
    p.add_argument("--export", default=None, metavar="PATH",
                   help="write the --scene to a scene file instead of starting the viewer")


def _view(args: argparse.Namespace) -> int:
    from . import view

    if args.export is not None:
        if args.scene is None:
            raise ValueError("--export writes the --scene NAME: name a scene")
        _ensure_parent(args.export)
        view.export_scene(args.scene, args.export)
        print(f"wrote {args.export}")
        return 0
    extra: list[str] = []
    for flag, value in (("--method", args.method), ("--alpha", args.alpha), ("--screenshot", args.screenshot),
                        ("--frames", args.frames), ("--compare", args.compare), ("--view", args.view),
                        ("--size", args.size), ("--adapter", args.adapter)):
        if value is not None:
            extra += [flag, *map(str, value if isinstance(value, list) else [value])]
    for p in args.param:
        extra += ["--param", p]
    return view.run(args.files, scene=args.scene, extra=[*extra, *args.passthrough])


Subcommand = tuple[str, str, Callable[[argparse.ArgumentParser], None], Callable[[argparse.Namespace], int]]

SUBCOMMANDS: Sequence[Subcommand] = (
    ("demo", "render the built-in scene with every blending method and their errors into one PNG", _add_demo, _demo),
    ("render", "render a mesh file with one method into a PNG", _add_render, _render),
    ("compare", "every method on a mesh file of yours: time, memory, error, and the cheapest that meets your limits",
     _add_compare, _compare),
    ("methods", "list the methods with their properties and parameters", _add_methods, _methods),
    ("bench", "time, memory and error of every method against the exact A-buffer", _add_bench, _bench),
    ("view", "open meshes or a built-in scene in the interactive viewer (crates/oit-viewer)", _add_view, _view),
)


@contextlib.contextmanager
def _load_warnings_as_lines(prog: str) -> Iterator[None]:
    """Each OitLoadWarning (what a file has that oit does not draw) as one line on stderr,
    every time a file is loaded, instead of Python's two-line warning with its source line."""
    from ._load import OitLoadWarning

    def show(message: Any, category: type, filename: str, lineno: int, file: Any = None, line: Any = None) -> None:
        if issubclass(category, OitLoadWarning):
            print(f"{prog}: warning: {message}", file=sys.stderr)
        else:
            shown(message, category, filename, lineno, file, line)

    with warnings.catch_warnings():
        shown = warnings.showwarning
        warnings.showwarning = show
        warnings.simplefilter("always", OitLoadWarning)
        yield


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m oit", description="Order-independent transparency on wgpu.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, help_text, add, run in SUBCOMMANDS:
        p = sub.add_parser(name, help=help_text, description=help_text)
        add(p)
        p.set_defaults(run=run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    argv = list(sys.argv[1:] if argv is None else argv)
    # `view ... -- ARGS`: ARGS go to the viewer binary as they are.
    passthrough: list[str] = []
    if argv[:1] == ["view"] and "--" in argv:
        cut = argv.index("--")
        argv, passthrough = argv[:cut], argv[cut + 1:]
    args = parser.parse_args(argv)
    args.passthrough = passthrough
    try:
        with _load_warnings_as_lines(f"{parser.prog} {args.command}"):
            return args.run(args)
    except (ValueError, TypeError, MemoryError, RuntimeError, OSError) as e:
        # Engine and input errors carry messages that say what to do; no traceback.
        print(f"{parser.prog} {args.command}: error: {e}", file=sys.stderr)
        return EXIT_USAGE if isinstance(e, (ValueError, TypeError, FileNotFoundError)) else 1
