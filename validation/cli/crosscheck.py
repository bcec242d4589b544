"""``specref crosscheck``: small scenes rendered in specref and Mitsuba 3, compared per pixel."""

from __future__ import annotations

import sys

from validation.cli.parser import input_file, output_file


def _cmd_crosscheck(args) -> int:
    from validation.studies.crosscheck import (
        FULL,
        QUICK,
        crosscheck_summary,
        run_crosscheck,
    )

    if args.json:  # refuse an unusable output before minutes of rendering
        from pathlib import Path

        from reference.errors import require
        from reference.files import check_output_folder

        json_path = Path(args.json)
        require(not json_path.is_dir(), f"--json: {json_path} is a folder; give a file name")
        check_output_folder(json_path.parent)
    settings = QUICK if args.quick else FULL
    data = args.data
    result = run_crosscheck(
        data, settings, progress=lambda name: print(name, file=sys.stderr), only=args.case
    )
    rows = crosscheck_summary(result)
    print(f"{'case':44} {'values':>6} {'mean ΔY/Y':>10} {'RMS z':>6} {'max |z|':>8} {'|z|>4':>6}")
    for r in rows:
        print(
            f"{r['name']:44} {r['values']:6d} {r['mean_rel_Y']:10.4f} {r['rms_z']:6.2f} "
            f"{r['max_abs_z']:8.2f} {r['frac_abs_z_over_4']:6.3f}"
        )
    print(
        f"expected if they agree (Student's t, {settings.seeds - 1} dof): RMS z "
        f"{rows[0]['expected_rms_z']:.2f}, |z|>4 {rows[0]['expected_frac_over_4']:.3f}"
    )
    if args.json:
        from validation.cli.parser import write_json

        write_json(args.json, {"settings": vars(settings), "cases": rows})
    return 0


def add_parser(sub) -> None:
    """Add ``specref crosscheck`` and its options to the subcommand parsers ``sub``."""
    p = sub.add_parser(
        "crosscheck",
        help="render small scenes in specref and Mitsuba 3 and compare per pixel (z-scores)",
        description="Lambertian spheres under each shipped environment, a measured reflectance and "
        "the ColorChecker under D65 and A, rendered in specref (brute force) and in Mitsuba 3 "
        "(scalar_spectral, several seeds); reports z-scores against Mitsuba's standard error. "
        "Needs the optional extra: pip install '.[mitsuba]'.",
    )
    p.add_argument("--quick", action="store_true", help="tiny renders (seconds), for tests")
    p.add_argument(
        "--data",
        type=input_file,
        metavar="FOLDER",
        help="a folder laid out as the shipped data (environments/, spectra/); default the data "
        "shipped with specref",
    )
    p.add_argument("--case", metavar="TEXT", help="run only the cases whose name contains TEXT")
    p.add_argument(
        "--json",
        type=output_file,
        metavar="OUT.json",
        help="also write the per-case summary as JSON",
    )
    p.set_defaults(func=_cmd_crosscheck)
