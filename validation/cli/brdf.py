"""``specref brdf``: tabulate BRDFs, check tables and MERL files, convert MERL, fit five angles."""

from __future__ import annotations

import sys
from pathlib import Path

from validation.cli.parser import Parser, input_file, output_file, registry_option


def _cmd_brdf_tabulate(args) -> int:
    from reference.materials.table import tabulate_registered_brdf, write_brdf_table
    from reference.progress import ANNOUNCE_AFTER, StageTimer

    timer = StageTimer(sys.stderr, f"brdf tabulate {args.model}", ANNOUNCE_AFTER)
    with timer.stage(f"tabulating at {args.theta_step:g}° × {args.phi_step:g}°"):
        table = tabulate_registered_brdf(args.model, args.theta_step, args.phi_step)
    with timer.stage(f"writing {table.values.size} values"):
        write_brdf_table(args.out, table, {"source": f"specref brdf tabulate {args.model}"})
    print(f"wrote {args.out}: {table.values.shape[:3]} angles x {table.n_bands} bands")
    return 0


def _is_merl(path) -> bool:
    return Path(path).suffix.lower() == ".binary"


def _cmd_brdf_check(args) -> int:
    from reference.materials.table import read_brdf_table

    if _is_merl(args.file):
        return _check_merl(args.file)
    t = read_brdf_table(args.file)
    print(
        f"{args.file}: {t.theta_i_deg.size} theta_i x {t.theta_o_deg.size} theta_s x "
        f"{t.phi_d_deg.size} phi_s, {t.n_bands} wavelengths "
        f"({t.wavelengths_nm[0]:g}-{t.wavelengths_nm[-1]:g} nm), BRDF max {t.values.max():.4g} 1/sr"
    )
    return 0


def _check_merl(path) -> int:
    from reference.materials.merl import merl_albedo, read_merl_brdf

    merl = read_merl_brdf(path)
    measured = merl.measured.all(axis=-1)
    peak = merl.values.max(axis=(0, 1, 2))
    albedo = merl_albedo(merl, 0.0)
    print(
        f"{path}: MERL BRDF, 90 theta_h x 90 theta_d x 180 phi_d bins, RGB; "
        f"{int(measured.sum()):,} of {measured.size:,} bins with data; "
        f"BRDF max R {peak[0]:.4g} G {peak[1]:.4g} B {peak[2]:.4g} 1/sr; albedo at normal "
        f"incidence R {albedo[0]:.4f} G {albedo[1]:.4f} B {albedo[2]:.4f}"
    )
    return 0


def _cmd_brdf_convert(args) -> int:
    from reference.colour.spectra import SpectralGrid
    from reference.materials.merl import read_merl_brdf
    from reference.materials.table import write_brdf_table
    from shrm.orbit import merl_to_spectral_brdf_table

    grid = SpectralGrid(380.0, 780.0, args.step_nm)
    merl = read_merl_brdf(args.file)
    table = merl_to_spectral_brdf_table(merl, grid, args.theta_step, args.phi_step)
    comments = {
        "source": f"specref brdf convert {Path(args.file).name} (MERL, Matusik et al. 2003)",
        "spectra": "the MERL RGB as linear sRGB, by Mallett & Yuksel 2019's primaries",
    }
    write_brdf_table(args.out, table, comments)
    print(f"wrote {args.out}: {table.values.shape[:3]} angles x {table.n_bands} bands")
    return 0


def _cmd_brdf_fit(args) -> int:
    from reference.files import write_text_atomic
    from reference.materials.multiangle import (
        fit_ggx_five_angle,
        ggx_fit_material,
        read_five_angle_csv,
    )

    readings = read_five_angle_csv(args.file)
    fit = fit_ggx_five_angle(readings)
    # a TOML bare key: letters, digits and underscores
    name = "".join(c if c.isalnum() else "_" for c in (args.name or readings.name)) or "paint"
    header = (
        f"# GGX + Lambert fitted to {Path(args.file).name} by specref brdf fit "
        f"(docs/herbert-polymer.md §9); relative error per aspecular angle: "
        + ", ".join(
            f"{a:g}° {100 * e:.2f} %"
            for a, e in zip(readings.aspecular_deg, fit.relative_error, strict=True)
        )
    )
    write_text_atomic(args.out, header + "\n" + ggx_fit_material(fit, name))
    worst = int(fit.relative_error.argmax())
    print(
        f"wrote {args.out}: GGX α {fit.alpha:.4g}, {fit.wavelengths_nm.size} bands; the fit "
        f"misses the readings by at most {100 * fit.relative_error[worst]:.2f} % "
        f"(at {readings.aspecular_deg[worst]:g}°)"
    )
    return 0


def add_parser(sub) -> None:
    """Add ``specref brdf`` and its options to the subcommand parsers ``sub``."""
    from reference.materials.brdf import BRDF_METHODS
    from reference.materials.table import tabulable_brdf_names

    p = sub.add_parser(
        "brdf", help="tabulate isotropic BRDFs, check BRDF tables and MERL files, convert MERL"
    )
    brdf = p.add_subparsers(dest="brdf_command", required=True, parser_class=Parser)
    t = brdf.add_parser("tabulate", help="tabulate a registered BRDF (docs/brdf-format.md)")
    tabulable = tabulable_brdf_names()
    registry_option(t, "model", BRDF_METHODS, "the BRDF", where=lambda key, _: key in tabulable)
    t.add_argument("-o", "--out", type=output_file, required=True, help="output text file")
    t.add_argument("--theta-step", type=float, default=5.0, help="polar step, degrees")
    t.add_argument("--phi-step", type=float, default=15.0, help="azimuth step, degrees")
    t.set_defaults(func=_cmd_brdf_tabulate)
    c = brdf.add_parser(
        "check", help="read a BRDF table file, or a MERL file (*.binary), and summarize it"
    )
    c.add_argument("file", type=input_file)
    c.set_defaults(func=_cmd_brdf_check)
    v = brdf.add_parser(
        "convert",
        help="a MERL BRDF (*.binary) as a spectral BRDF table (docs/brdf-format.md, MERL)",
    )
    v.add_argument("file", type=input_file, help="the MERL file")
    v.add_argument("-o", "--out", type=output_file, required=True, help="output text file")
    v.add_argument("--theta-step", type=float, default=2.0, help="polar step, degrees")
    v.add_argument("--phi-step", type=float, default=4.0, help="azimuth step, degrees")
    v.add_argument(
        "--step-nm", type=float, default=20.0, help="band spacing over 380-780 nm (default 20)"
    )
    v.set_defaults(func=_cmd_brdf_convert)
    f = brdf.add_parser(
        "fit",
        help="fit GGX + Lambert to five-angle readings (docs/herbert-polymer.md §9); a material",
    )
    f.add_argument("file", type=input_file, help="the five-angle CSV file")
    f.add_argument("-o", "--out", type=output_file, required=True, help="the material (.toml)")
    f.add_argument("--name", help="the material's name (default: the readings')")
    f.set_defaults(func=_cmd_brdf_fit)
