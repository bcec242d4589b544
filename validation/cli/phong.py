"""``specref phong``: Table 1 of Wang et al., one material file's tables, or the editor."""

from __future__ import annotations

import sys
from functools import partial

from reference.tasks import SERIAL, add_scheduler_option
from validation.cli.parser import (
    input_file,
    output_file,
    port_number,
    registry_option,
    write_json,
)


def _cmd_phong(args) -> int:
    from reference.errors import SpecrefError
    from validation.studies import phong, phong_table1

    if args.action == "edit":
        from phong_table.editor import app as editor_app
        from phong_table.editor import browser as editor_browser

        path = args.file if args.file is not None else args.material
        if args.screenshot:
            editor_browser.editor_screenshot(path, args.screenshot, args.port)
            print(f"wrote {args.screenshot}")
            return 0
        announce = partial(print, flush=True)
        editor_app.serve_editor(path, args.port, announce, save_dir=args.save_dir)
        return 0
    if args.file is not None:
        raise SpecrefError(f"specref phong: {args.file}: a file is taken by 'edit' only")
    if args.action == "table1":
        if args.images is not None:
            _write_images(args)
        result = phong_table1.run_table1(
            args.resolution, args.entries, args.repeats, progress=True, scheduler=args.scheduler
        )
        print(f"Table 1 (Wang et al.), {args.resolution}x{args.resolution}, {args.entries} entries")
        print(phong_table1.format_rows(result["rows"]))
        print("\nTargets")
        print(phong_table1.format_targets(result["targets"]))
    else:
        if args.material is None:
            raise SpecrefError("specref phong: give table1 or --material FILE.toml")
        if args.images is not None:
            raise SpecrefError("specref phong: --images goes with table1, not --material")
        result = phong_table1.run_material(
            args.material,
            args.view,
            args.entries,
            args.placement,
            args.interp,
            args.segments,
            args.tolerance,
            args.resolution,
            args.repeats,
            progress=sys.stderr,
        )
        print(phong_table1.format_rows(result["rows"]))
        if result["tolerance"] is not None:
            print(phong.format_tolerance(result["tolerance"]))
    if args.json:
        write_json(args.json, result)
    return 0


def _write_images(args) -> None:
    """``table1 --images DIR``: Figs. 2-7 of Wang et al. as ``DIR/images/phong-*.png``."""
    from pathlib import Path

    from reference.files import check_output_folder
    from validation.report import ReportContext
    from validation.studies.phong_figures import paper_figures

    folder = check_output_folder(args.images)
    ctx = ReportContext(Path(folder), section="phong")
    blocks = paper_figures(ctx, args.resolution, True, args.entries, repeats=args.repeats)
    print(f"wrote {sum(hasattr(b, 'path') for b in blocks)} figures under {folder}/images")


def add_parser(sub) -> None:
    """Add ``specref phong`` and its options to the subcommand parsers ``sub``."""
    from phong_table.interpolation import INTERPOLATION_METHODS
    from phong_table.placement import PLACEMENT_METHODS
    from phong_table.scenes import VIEWS

    p = sub.add_parser(
        "phong",
        help="spectral Phong tables: Table 1 of Wang et al., or one material file",
        description="specref phong table1 [--json FILE] [--images DIR] | specref phong edit "
        "[MATERIAL.toml] [--port N] [--save-dir DIR] | specref phong --material FILE.toml "
        "--view V --entries M --placement P --interp I [--segments S] [--tolerance T] "
        "[--json FILE]",
    )
    p.add_argument(
        "action",
        nargs="?",
        choices=["table1", "edit"],
        help="table1: reproduce Table 1; edit: the material editor in the browser",
    )
    p.add_argument("file", nargs="?", metavar="MATERIAL.toml", help="edit: the file to open")
    p.add_argument(
        "--port",
        type=port_number,
        default=5006,
        help="edit: the local port (default 5006; 0: any free port, announced)",
    )
    p.add_argument(
        "--save-dir",
        metavar="DIR",
        help="edit: the one folder the page saves to (default: the opened file's folder, else "
        "the current one)",
    )
    p.add_argument(
        "--screenshot",
        type=output_file,
        metavar="PNG",
        help="edit: write a screenshot of the page and exit",
    )
    p.add_argument(
        "--material",
        type=input_file,
        metavar="FILE.toml",
        help="a material file (docs/scene-format.md, Phong material files)",
    )
    registry_option(
        p, "--view", VIEWS, "the view of the sphere (camera field of view)", default="far"
    )
    p.add_argument("--entries", type=int, default=200, help="table entries m (default 200)")
    registry_option(p, "--placement", PLACEMENT_METHODS, "node placement", default="error")
    registry_option(p, "--interp", INTERPOLATION_METHODS, "interpolation", default="monotone")
    p.add_argument("--segments", type=int, help="importance segments p (must divide m)")
    p.add_argument("--tolerance", type=float, help="pick the smallest table with RMS <= T")
    p.add_argument("--resolution", type=int, default=512, help="image size (default 512)")
    p.add_argument("--repeats", type=int, default=9, help="timing repetitions (minimum kept)")
    p.add_argument("--json", type=output_file, metavar="FILE", help="write the records as JSON")
    add_scheduler_option(p, default=SERIAL)
    p.add_argument(
        "--images",
        metavar="DIR",
        help="table1: also write Figs. 2-7 of Wang et al. as DIR/images/phong-*.png",
    )
    p.set_defaults(func=_cmd_phong)
