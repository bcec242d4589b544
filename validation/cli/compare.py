"""``specref compare``: per-pixel differences of a render against a reference."""

from __future__ import annotations

from validation.cli.parser import input_file, output_file, output_file_or_stdout


def _cmd_compare(args) -> int:
    import json

    from reference.scene.compare import compare_files, summary_line

    summary = compare_files(args.a, args.b, args.mask, args.json, args.diff)
    print(json.dumps(summary, indent=2) if args.json == "-" else summary_line(summary))
    return 0


def add_parser(sub) -> None:
    """Add ``specref compare`` and its options to the subcommand parsers ``sub``."""
    p = sub.add_parser(
        "compare",
        help="per-pixel differences of an image against a reference (Y error, ΔE00, Δu'v', z)",
        description="Compare A against the reference B over B's lit pixels (Y >= 1 %% of the "
        "peak): relative error of Y, CIEDE2000, chromaticity difference Δu'v' and, where B has "
        "a Y.stderr channel, z-scores. EXR with X/Y/Z, spectral (S0.<nm>nm) or R/G/B channels, "
        "or Radiance HDR. docs/render-outputs.md.",
    )
    p.add_argument("a", type=input_file, metavar="A.exr", help="the image to check")
    p.add_argument("b", type=input_file, metavar="B.exr", help="the reference")
    p.add_argument(
        "--mask", type=input_file, metavar="M", help="image of the same size: compare where > 0.5"
    )
    p.add_argument(
        "--json",
        type=output_file_or_stdout,
        metavar="OUT.json",
        help="write the summary as JSON ('-' prints it)",
    )
    p.add_argument(
        "--diff", type=output_file, metavar="OUT.exr", help="write the per-pixel differences as EXR"
    )
    p.set_defaults(func=_cmd_compare)
