"""``specref impastor``: Table 1 of Ferwerda 2015 and the demo painting."""

from __future__ import annotations

import argparse
import sys

from reference.tasks import SERIAL, add_scheduler_option
from validation.cli.parser import (
    Parser,
    input_file,
    key_or_input_file,
    output_file,
    painting_input,
    registry_option,
)


def _cmd_impastor_table1(args) -> int:
    import json

    from validation.studies.impastor_commands import format_table1, table1_for_cli

    result = table1_for_cli(
        args.design, args.channels, args.white_luminance, args.display, args.scheduler
    )
    print(format_table1(result))
    if args.json:
        from reference.files import write_text_atomic

        write_text_atomic(args.json, json.dumps(result, indent=1) + "\n")
        print(f"wrote {args.json}")
    return 0


def _vector(text: str, option: str) -> tuple:
    import math

    from reference.errors import require

    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    # a booth is a room: positions within 100 m (validation.studies.impastor_commands)
    require(
        len(values) == 3 and all(math.isfinite(v) and abs(v) <= 100.0 for v in values),
        f"{option}: must be x,y,z in metres, finite and within 100 m, got {text!r}",
    )
    return values


def _tolerance(text: str):
    """``--tolerance``: a relative error, or ``fixed`` (no worse than the fixed settings)."""
    from impastor.settings import NO_WORSE_THAN_FIXED

    if text == NO_WORSE_THAN_FIXED:
        return text
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"must be a relative error in (0, 1) (0.02 is 2 %) or '{NO_WORSE_THAN_FIXED}', "
            f"got {text!r}"
        ) from None


def _cmd_impastor_render(args) -> int:
    from validation.studies.impastor_commands import render_for_cli

    observer = _vector(args.observer, "--observer")
    lamp = _vector(args.light_position, "--light-position")
    print(
        render_for_cli(
            args.light,
            args.size,
            args.method,
            args.out,
            args.counts,
            observer,
            args.tilt,
            args.screen_lux,
            lamp,
            args.light_luminance,
            progress=sys.stderr,
            tolerance=args.tolerance,
            painting=args.painting,
            light_map=args.light_map,
        )
    )
    return 0


def _cmd_impastor_path(args) -> int:
    from validation.studies.impastor_commands import render_path_for_cli

    summary = render_path_for_cli(
        args.light,
        args.size,
        args.method,
        args.out,
        _vector(args.eye_from, "--from"),
        _vector(args.eye_to, "--to"),
        args.frames,
        painting=args.painting,
        fps=args.fps,
        progress=sys.stderr,
        tilt_from=args.tilt_from,
        tilt_to=args.tilt_to,
        light_map=args.light_map,
    )
    print(summary)
    return 0


def _cmd_impastor_painting(args) -> int:
    from impastor.painting import impasto_painting
    from impastor.painting_files import write_painting
    from reference.errors import require, require_positive_int
    from reference.files import check_output_folder

    size = require_positive_int(args.size, "--size", 4096)
    require(args.seed >= 0, f"--seed: must be an integer >= 0, got {args.seed}")
    check_output_folder(args.out, marker="painting.toml")  # before the painting is made
    written = write_painting(args.out, impasto_painting(size, seed=args.seed), f"demo-{args.seed}")
    print(f"wrote {written} and its images: the demo painting, {size}×{size}, seed {args.seed}")
    return 0


def add_parser(sub) -> None:
    """Add ``specref impastor`` and its options to the subcommand parsers ``sub``."""
    from impastor.multispectral import MULTISPECTRAL_DESIGNS

    p = sub.add_parser("impastor", help="ImpastoR (Ferwerda 2015): Table 1 and the demo painting")
    isub = p.add_subparsers(dest="impastor_command", required=True, parser_class=Parser)
    t = isub.add_parser("table1", help="Table 1: ColorChecker simulation and screen output")
    t.add_argument("--json", type=output_file, metavar="FILE", help="also write the table as JSON")
    registry_option(t, "--design", MULTISPECTRAL_DESIGNS, "channel design", default="optimized")
    t.add_argument("--channels", type=int, default=6, help="channel count (3-10)")
    t.add_argument(
        "--white-luminance", type=float, default=200.0, help="white diffuser luminance, cd/m²"
    )
    t.add_argument(
        "--display",
        type=input_file,
        metavar="JSON",
        help="display measurement file (default: virtual)",
    )
    add_scheduler_option(t, default=SERIAL)
    t.set_defaults(func=_cmd_impastor_table1)
    w = isub.add_parser(
        "painting", help="write the demo painting as a painting folder (docs/impastor.md)"
    )
    w.add_argument("out", metavar="DIR", help="the folder to write (painting.toml and images)")
    w.add_argument("--size", type=int, default=256, help="texels per side (default 256)")
    w.add_argument("--seed", type=int, default=1, help="the demo painting's seed (default 1)")
    w.set_defaults(func=_cmd_impastor_painting)
    _add_path(isub)
    _add_render(isub)


def _light_map_option(parser) -> None:
    parser.add_argument(
        "--light-map",
        type=input_file,
        metavar="HDR",
        help="an HDR panorama of a room (.hdr or RGB .exr, y up), seen through the booth's ceiling "
        "as its light; --light still gives the lamp's spectrum (docs/impastor.md)",
    )


def _add_path(isub) -> None:
    """``specref impastor path``: the painting from a moving viewer, as an animated PNG."""
    from impastor.painting import PAINTING_LIGHTING_METHODS

    a = isub.add_parser(
        "path", help="render the painting from a path of viewer positions as an animated PNG"
    )
    a.add_argument(
        "--from",
        dest="eye_from",
        default="-0.25,0.45,0.6",
        help="the viewer's first position x,y,z in metres (default -0.25,0.45,0.6)",
    )
    a.add_argument(
        "--to",
        dest="eye_to",
        default="0.25,0.45,0.6",
        help="the viewer's last position x,y,z in metres (default 0.25,0.45,0.6)",
    )
    a.add_argument("--frames", type=int, default=24, help="frames along the path (default 24)")
    a.add_argument("--fps", type=float, default=12.0, help="frames per second (default 12)")
    a.add_argument(
        "--tilt-from",
        type=float,
        default=0.0,
        metavar="DEG",
        help="the canvas's first tilt about x, degrees, as the display showing it (default 0)",
    )
    a.add_argument(
        "--tilt-to", type=float, default=0.0, metavar="DEG", help="its last tilt (default 0)"
    )
    a.add_argument("--painting", type=painting_input, metavar="DIR", help="a painting folder")
    _light_map_option(a)
    a.add_argument(
        "--light",
        type=key_or_input_file,
        default="D65",
        help="illuminant key (D65, D50, A, FL2, ...) or a measured lamp's spectrum file",
    )
    a.add_argument("--size", type=int, default=256, help="image side in pixels (default 256)")
    registry_option(a, "--method", PAINTING_LIGHTING_METHODS, "specular lighting", default="hybrid")
    a.add_argument("-o", "--out", type=output_file, required=True, help="the animated PNG")
    a.set_defaults(func=_cmd_impastor_path)  # fmt: skip


def _add_render(isub) -> None:
    """``specref impastor render``: one frame of a painting under a booth light."""
    from impastor.painting import PAINTING_LIGHTING_METHODS

    r = isub.add_parser("render", help="render a painting (the demo one by default) to a PNG")
    r.add_argument(
        "--painting",
        type=painting_input,
        metavar="DIR",
        help="a painting folder or its painting.toml (docs/impastor.md); default the demo",
    )
    _light_map_option(r)
    r.add_argument(
        "--light",
        type=key_or_input_file,
        default="D65",
        help="illuminant key (D65, D50, A, FL2, ...) or a measured lamp's spectrum file "
        "(wavelength and power per line; docs/impastor.md)",
    )
    r.add_argument("--size", type=int, default=512, help="image side in pixels")
    registry_option(r, "--method", PAINTING_LIGHTING_METHODS, "specular lighting", default="hybrid")
    r.add_argument("-o", "--out", type=output_file, default="impastor.png", help="output PNG")
    r.add_argument(
        "--counts",
        type=output_file,
        metavar="PNG",
        help="also write the display's 11-bit counts (16-bit PNG)",
    )
    r.add_argument(
        "--observer",
        default="0,0,0.6",
        help="eye position x,y,z in metres from the screen centre (default 0,0,0.6)",
    )
    r.add_argument(
        "--tilt",
        type=float,
        default=0.0,
        help="display tilt about x, degrees: the painting turns with the display under the "
        "booth's light, and the display's compensation follows it",
    )
    r.add_argument(
        "--screen-lux", type=float, default=1000.0, help="booth illuminance on the screen, lux"
    )
    r.add_argument(
        "--light-position",
        default="0,1.2,0.9",
        help="booth light centre x,y,z in metres from the screen centre (specular screen flare)",
    )
    r.add_argument(
        "--light-luminance",
        type=float,
        default=None,
        help="booth light luminance, cd/m² (default: the booth ceiling's mean)",
    )
    r.add_argument(
        "--tolerance",
        type=_tolerance,
        metavar="T",
        help="choose the lights N, samples K, horizon sectors and the hybrid's fail-safe from a "
        "relative RMS error T of the frame against brute force (0.02 is 2 %%) instead of the "
        "fixed 32/32/36 with the fail-safe, or 'fixed': the cheapest settings no worse than "
        "those; the PNG records the settings and the promised bound",
    )
    r.set_defaults(func=_cmd_impastor_render)
