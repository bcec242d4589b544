"""``specref sweep``: a user-defined grid of methods × materials as tasks (local or remote Dask)."""

from __future__ import annotations

from validation.cli.parser import output_file, toml_input


def _cmd_sweep(args) -> int:
    from validation.studies.sweep import run_sweep, sweep_csv

    rows = run_sweep(args.file, scheduler=args.scheduler, large=args.yes)
    text = sweep_csv(rows, args.out)
    if args.out:
        print(f"wrote {len(rows)} rows to {args.out}")
    else:
        print(text, end="")
    return 0


def add_parser(sub) -> None:
    """Add ``specref sweep`` and its options to the subcommand parsers ``sub``."""
    from reference.tasks import add_scheduler_option
    from validation.studies.sweep import SWEEP_KINDS

    p = sub.add_parser(
        "sweep",
        help="run a sweep file's grid as Dask tasks; a tidy CSV, one row per cell",
    )
    kinds = ", ".join(SWEEP_KINDS.names())
    file = p.add_argument(
        "file",
        type=toml_input,
        metavar="SWEEP.toml",
        help=f"the sweep file (docs/scale-out.md); kind: {kinds}",
    )
    # its help lists the kinds from the registry (as validation.cli.parser.registry_option does)
    file.registry, file.registry_keys = SWEEP_KINDS, SWEEP_KINDS.names()
    p.add_argument(
        "-o",
        "--out",
        type=output_file,
        metavar="CSV",
        help="write the table here (default: stdout)",
    )
    p.add_argument(
        "--yes",
        action="store_true",
        help="run grids of more than 10,000 cells (up to 1,000,000)",
    )
    add_scheduler_option(p)
    p.set_defaults(func=_cmd_sweep)
