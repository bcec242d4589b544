"""``specref render``: render a scene file."""

from __future__ import annotations

from reference.envmap import TEXEL_PLACEMENTS
from validation.cli.parser import registry_option


def _cmd_render(args) -> int:
    import phong_table  # noqa: F401  (registers its shaders, if any)
    import shrm  # noqa: F401  (registers the environment-light shaders, if any)
    from reference.render import render_scene_file

    result = render_scene_file(
        args.scene,
        png=args.output,
        exr=args.exr,
        width=args.width,
        height=args.height,
        supersample=args.supersample,
        oracle=args.oracle,
        texel_placement=args.texel_placement,
    )
    r = result.scene.render
    outputs = " and ".join(str(p) for p in (args.output, args.exr) if p is not None)
    print(
        f"wrote {outputs} ({r.width}×{r.height}, supersample {r.supersample}, "
        f"{result.timings['total']:.2f} s)"
    )
    return 0


def add_parser(sub) -> None:
    """Add ``specref render`` and its options to the subcommand parsers ``sub``."""
    p = sub.add_parser(
        "render",
        help="render a scene file to a display-encoded PNG (and optionally a linear EXR)",
        description="Render a TOML scene (docs/scene-format.md). Relative paths in the scene are "
        "relative to its folder.",
    )
    p.add_argument("scene", metavar="SCENE.toml", help="the scene file")
    p.add_argument(
        "-o", "--output", required=True, metavar="OUT.png", help="display-encoded 8-bit PNG"
    )
    p.add_argument(
        "--exr", metavar="OUT.exr", help="also write linear display RGB (before exposure) as EXR"
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
