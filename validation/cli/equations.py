"""``specref equations``: generate or check the equation index (``docs/equations.md``)."""

from __future__ import annotations

import sys
from pathlib import Path

from validation.cli.parser import output_file


def _cmd_equations(args) -> int:
    from reference.errors import SpecrefError, require
    from reference.files import check_output_file, write_text_atomic
    from validation.report.equations import (
        REGENERATE,
        collect_citations,
        equation_problems,
        render_equation_index,
    )

    if args.out and not args.check:
        check_output_file(args.out)  # before the index's seconds of parsing
    path = Path(args.out or "docs/equations.md")
    # outside a checkout (an installed wheel) there is nothing to compare: say so, not "out of date"
    require(
        not args.check or path.is_file(),
        f"{path}: not found; --check compares a checkout's docs/equations.md (run it in the "
        "repository, or give -o FILE)",
    )
    if args.check:  # the file compared, read before the index's seconds of parsing
        try:
            current = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            raise SpecrefError(
                f"{path}: not UTF-8 text; --check compares an equation index"
            ) from None
    # seconds of parsing: a line per stage on stderr (stdout may be the index itself)
    print("specref equations: reading the code, its tests and the errata", file=sys.stderr)
    citations = collect_citations()
    print("specref equations: writing the index", file=sys.stderr)
    text = render_equation_index(citations=citations)
    if args.check:
        problems = equation_problems(citations)
        if current != text:
            problems.append(f"{path} is out of date; regenerate it with `{REGENERATE}`")
        for problem in problems:
            print(f"specref equations: {problem}", file=sys.stderr)
        return 1 if problems else 0
    if args.out:
        write_text_atomic(args.out, text)
        print(f"wrote {args.out}")
    else:
        sys.stdout.write(text)
    return 0


def add_parser(sub) -> None:
    """Add ``specref equations`` and its options to the subcommand parsers ``sub``."""
    p = sub.add_parser(
        "equations",
        help="the equation index: each paper's equations, the code citing them, tests, errata",
    )
    p.add_argument(
        "-o",
        "--out",
        type=output_file,
        metavar="FILE",
        help="write the Markdown to FILE (default: standard output)",
    )
    p.add_argument(
        "--check",
        action="store_true",
        help="exit 1 if FILE (default docs/equations.md) differs from a fresh index, or if code "
        "cites an equation the index lacks",
    )
    p.set_defaults(func=_cmd_equations)
