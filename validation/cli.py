"""The ``specref`` command: argument parsing and dispatch to library functions, nothing else.

Every subcommand is a small function that calls the library. Bad input raises
:class:`~reference.errors.SpecrefError` in the library; :func:`main` prints its one-line message to
stderr and exits with code 2, without a traceback.
"""

from __future__ import annotations

import argparse
import sys

from reference.errors import SpecrefError

__all__ = ["build_parser", "main"]


class _Parser(argparse.ArgumentParser):
    """argparse with one-line usage errors and exit code 2 (argparse's code for usage errors)."""

    def error(self, message):
        self.exit(2, f"specref: error: {message} (see specref {self.prog.split()[-1]} --help)\n")


def _cmd_report(args) -> int:
    from validation.report import run_report

    run_report(
        out_dir=args.out,
        quick=args.quick,
        only=args.only,
        bench_json=args.bench,
        markdown=args.markdown,
        markdown_image_prefix=args.markdown_image_prefix,
    )
    print(f"wrote {args.out}/index.html and {args.out}/results.json")
    return 0


def _write_json(path, result) -> None:
    import json

    from reference.images import write_text_atomic
    from validation.report import to_jsonable

    write_text_atomic(path, json.dumps(to_jsonable(result), indent=1))
    print(f"wrote {path}")


def _cmd_phong(args) -> int:
    from reference.errors import SpecrefError
    from validation import phong

    if args.action == "table1":
        result = phong.run_table1(args.resolution, args.entries, args.repeats, progress=True)
        print(f"Table 1 (Wang et al.), {args.resolution}x{args.resolution}, {args.entries} entries")
        print(phong.format_rows(result["rows"]))
        print("\nTargets")
        print(phong.format_targets(result["targets"]))
    else:
        if args.material is None:
            raise SpecrefError("specref phong: give table1 or --material FILE.toml")
        result = phong.run_material(
            args.material,
            args.view,
            args.entries,
            args.placement,
            args.interp,
            args.segments,
            args.tolerance,
            args.resolution,
            args.repeats,
        )
        print(phong.format_rows(result["rows"]))
        if result["tolerance"] is not None:
            print(phong.format_tolerance(result["tolerance"]))
    if args.json:
        _write_json(args.json, result)
    return 0


def _add_phong_parser(sub) -> None:
    p = sub.add_parser(
        "phong",
        help="spectral Phong tables: Table 1 of Wang et al., or one material file",
        description="specref phong table1 [--json FILE] | specref phong --material FILE.toml "
        "--view far|near --entries M --placement P --interp I [--segments S] [--tolerance T] "
        "[--json FILE]",
    )
    p.add_argument("action", nargs="?", choices=["table1"], help="reproduce Table 1")
    p.add_argument("--material", metavar="FILE.toml", help="a material file (docs/phong-tables.md)")
    p.add_argument("--view", default="far", help="far (whole sphere) or near (the highlight)")
    p.add_argument("--entries", type=int, default=200, help="table entries m (default 200)")
    p.add_argument("--placement", default="error", help="uniform, importance or error")
    p.add_argument(
        "--interp", default="monotone", help="linear, parabolic, parabolic_w or monotone"
    )
    p.add_argument("--segments", type=int, help="importance segments p (must divide m)")
    p.add_argument("--tolerance", type=float, help="pick the smallest table with RMS <= T")
    p.add_argument("--resolution", type=int, default=512, help="image size (default 512)")
    p.add_argument("--repeats", type=int, default=9, help="timing repetitions (minimum kept)")
    p.add_argument("--json", metavar="FILE", help="write the records as JSON")
    p.set_defaults(func=_cmd_phong)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser for all subcommands.

    Examples
    --------
    >>> build_parser().parse_args(["report", "--quick"]).quick
    True
    """
    parser = _Parser(prog="specref", description="specref: a spectral rendering reference.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    p = sub.add_parser(
        "report", help="run the main job: every section's figures, charts and images"
    )
    p.add_argument("--out", default="report", help="output folder (default: report)")
    p.add_argument("--quick", action="store_true", help="small sizes; under a minute")
    p.add_argument("--only", nargs="+", metavar="SECTION", help="run only these sections")
    p.add_argument("--bench", metavar="JSON", help="pytest-benchmark JSON from make bench")
    p.add_argument(
        "--markdown", metavar="MD", help="also write a Markdown rendering (docs/results.md)"
    )
    p.add_argument(
        "--markdown-image-prefix",
        default="",
        help="path from the Markdown file to the report folder",
    )
    p.set_defaults(func=_cmd_report)
    _add_phong_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the ``specref`` command; return the exit code (2 for bad input).

    Examples
    --------
    >>> main(["report", "--only", "no-such-section", "--out", "/tmp/specref-doctest"])
    2
    """
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except SpecrefError as error:
        print(f"specref: error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("specref: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
