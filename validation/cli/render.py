"""``specref render``: render a scene file."""

from __future__ import annotations

from reference.geometry.envmap import TEXEL_PLACEMENTS
from validation.cli.parser import (
    output_file,
    output_file_or_stdout,
    registry_option,
    toml_input,
)


def _cmd_render(args) -> int:
    import json
    import sys

    import phong_table  # noqa: F401  (registers its shaders, if any)
    import shrm  # noqa: F401  (registers the environment-light shaders, if any)
    from reference.errors import require
    from reference.scene.render import render_scene_file

    require(
        args.exr_output is None or args.exr is not None,
        f"--exr-output {args.exr_output}: says what the EXR holds; give --exr OUT.exr too",
    )
    result = render_scene_file(
        args.scene,
        png=args.output,
        exr=args.exr,
        width=args.width,
        height=args.height,
        supersample=args.supersample,
        oracle=args.oracle,
        texel_placement=args.texel_placement,
        exr_output=args.exr_output or "display",
        accuracy=args.accuracy,
        json=args.json,
        progress=sys.stderr,
    )
    if args.json == "-":
        print(json.dumps(result.metadata, indent=2))
        return 0
    r = result.scene.render
    outputs = " and ".join(str(p) for p in (args.output, args.exr, args.json) if p is not None)
    orders = [
        f"{key} order {choice['order']}"
        for key, choice in result.metadata["methods"].get("environment", {}).items()
        if "order" in choice
    ]
    print(
        f"wrote {outputs} ({r.width}×{r.height}, supersample {r.supersample}, "
        f"{result.timings['total']:.2f} s{''.join('; ' + o for o in orders)})"
    )
    return 0


def add_parser(sub) -> None:
    """Add ``specref render`` and its options to the subcommand parsers ``sub``."""
    from reference.scene.metadata import DEFAULT_ACCURACY, RENDER_OUTPUTS

    p = sub.add_parser(
        "render",
        help="render a scene file to a display-encoded PNG (and optionally a linear EXR)",
        description="Render a TOML scene (docs/scene-format.md). Relative paths in the scene are "
        "relative to its folder; data:<path> names a file shipped with specref "
        "(data:examples/<name>.toml, data:environments/...). Outputs and metadata: "
        "docs/render-outputs.md.",
    )
    p.add_argument(
        "scene",
        metavar="SCENE.toml",
        type=toml_input,
        help="the scene file, or data:examples/<name>.toml",
    )
    p.add_argument(
        "-o",
        "--output",
        type=output_file,
        required=True,
        metavar="OUT.png",
        help="display-encoded 8-bit PNG",
    )
    p.add_argument(
        "--exr",
        type=output_file,
        metavar="OUT.exr",
        help="also write a linear EXR (what it holds: --exr-output)",
    )
    registry_option(
        p,
        "--exr-output",
        RENDER_OUTPUTS,
        "what the --exr file holds (default display), see docs/render-outputs.md",
    )
    p.add_argument(
        "--accuracy",
        metavar="TOL",
        help=f"mean relative error of Y over lit pixels that fast environment lighting promises "
        f"(max 4×TOL), default {DEFAULT_ACCURACY:g}; the SH order follows from it",
    )
    p.add_argument(
        "--json",
        type=output_file_or_stdout,
        metavar="OUT.json",
        help="write the render's metadata (orders chosen, bounds promised, units) as JSON; "
        "'-' prints it",
    )
    p.add_argument("--width", type=int, help="override render.width (alone: keep the aspect)")
    p.add_argument("--height", type=int, help="override render.height (alone: keep the aspect)")
    p.add_argument("--supersample", type=int, help="override render.supersample")
    p.add_argument(
        "--oracle",
        action="store_true",
        help='brute-force environment lighting (ShadingContext.options["environment"] = '
        '"bruteforce"), the reference the SH engine is checked against; slow',
    )
    registry_option(
        p,
        "--texel-placement",
        TEXEL_PLACEMENTS,
        "read every environment map with this lat-long texel placement (overrides the scene's "
        "texel_placement; mitsuba puts rows at v = j/(H-1), as Mitsuba 3 does)",
    )
    p.set_defaults(func=_cmd_render)
