"""``specref display``: calibrate the simulated display to a white and a tone curve.

Herbert et al. §6; docs/display.md.
"""

from __future__ import annotations

import sys

from validation.cli.parser import (
    Parser,
    input_file,
    nonnegative_int,
    output_file,
    registry_option,
)


def _cmd_display_calibrate(args) -> int:
    from reference.display.calibration import calibrate_display
    from reference.display.calibration_files import write_calibration
    from reference.display.spectral import load_spectral_display, spectral_display

    if args.profile:  # all files or none: the profile's tools are needed before any is written
        from reference.display.icc import require_icc_tools

        require_icc_tools()
    display = load_spectral_display(args.display) if args.display else spectral_display()
    calibration = calibrate_display(
        display, args.white, args.curve, args.points, args.instrument, seed=args.seed
    )
    summary = write_calibration(args.output, display, calibration)
    v = summary["verification"]
    print(
        f"calibrated {display.name} to {calibration.white} (x, y = "
        f"{calibration.white_xy[0]:.4f}, {calibration.white_xy[1]:.4f}), "
        f"curve {calibration.curve}, {len(calibration.points['G'])} points read by the "
        f"{calibration.instrument} instrument"
    )
    print(
        f"white {calibration.Y_white:.2f} cd/m², black {calibration.Y_black:.3f} cd/m² (left alone)"
    )
    print(f"{'G':>4} {'Y cd/m²':>9} {'target':>9} {'x':>7} {'y':>7} {'Δu′v′':>8}")
    for row in v["gray"]:
        print(
            f"{row['G']:>4} {row['Y_cd_m2']:>9.3f} {row['Y_target_cd_m2']:>9.3f} "
            f"{row['x']:>7.4f} {row['y']:>7.4f} {row['duv']:>8.5f}"
        )
    chart = v["colorchecker_delta_E00"]
    print(
        "verification (reference meter: 1 nm, no band pass, no noise): max Δu′v′ above 5 % of "
        f"white "
        f"{v['max_duv_above_5pct']:.5f}, max |ΔY|/Y above 1 % "
        f"{v['max_abs_Y_error_above_1pct']:.4f}; "
        f"ColorChecker ΔE00 mean {chart['mean']:.2f}, max {chart['max']:.2f}"
    )
    if args.profile:
        from reference.display.icc import build_icc_profile, check_icc_profile

        icc = build_icc_profile(summary["files"][".ti3"])
        check = check_icc_profile(icc, summary["files"][".ti3"])
        print(
            f"wrote {icc}: littlecms against the measurements, ΔE00 mean {check['mean']:.2f}, "
            f"max {check['max']:.2f}"
        )
    print("wrote " + ", ".join(summary["files"].values()))
    if not summary["meets_targets"]:  # written and marked; the exit code says it (docs/display.md)
        from reference.display.calibration import targets_message

        json_file = summary["files"][".json"]
        print(
            f"display calibrate: {targets_message(summary['targets'])}; the files are written, "
            f"marked meets_targets: false in {json_file}",
            file=sys.stderr,
        )
        return 1
    return 0


def _calibration_files(args) -> list:
    """The files ``display calibrate`` writes beside its .cal (the write policy checks them)."""
    from pathlib import Path

    suffixes = (".cal", ".cube", ".ti3", ".json") + ((".icc",) if args.profile else ())
    out = Path(args.output)
    return [out.with_suffix(k) for k in suffixes if out.with_suffix(k) != out]


def add_parser(sub) -> None:
    """Add ``specref display`` and its options to the subcommand parsers ``sub``."""
    from reference.display.calibration import CALIBRATION_CURVES, WHITES
    from reference.display.instruments import INSTRUMENTS

    p = sub.add_parser("display", help="display calibration (Herbert et al. §6)")
    dsub = p.add_subparsers(dest="display_command", required=True, parser_class=Parser)
    c = dsub.add_parser(
        "calibrate",
        help="calibrate the simulated display; write .cal, .cube, .ti3 and .json",
        description="Iterate per point (measure, correct, re-measure) to a white and a tone "
        "curve, and verify with an independent reference meter; see docs/display.md. Exit code 1 "
        "when a target is missed (the files are written, marked meets_targets: false), 2 on bad "
        "input.",
    )
    c.add_argument(
        "--white", default="D65", help=f"{', '.join(WHITES)} or x,y chromaticity (default D65)"
    )
    registry_option(c, "--curve", CALIBRATION_CURVES, "tone curve", default="gamma2.2")
    c.add_argument("--points", type=int, default=15, help="control points, 2..64 (default 15)")
    registry_option(c, "--instrument", INSTRUMENTS, "measuring instrument", default="spectro")
    c.add_argument(
        "--display", type=input_file, metavar="FILE", help="display file (JSON, docs/display.md)"
    )
    c.add_argument("--seed", type=nonnegative_int, default=0, help="seed of the instrument noise")
    c.add_argument(
        "--profile",
        action="store_true",
        help="also build an ICC profile with ArgyllCMS colprof and check it with littlecms",
    )
    c.add_argument(
        "-o",
        "--output",
        type=output_file,
        required=True,
        metavar="CAL.cal",
        help="the .cal to write",
    )
    c.set_defaults(func=_cmd_display_calibrate, sibling_outputs=_calibration_files)
