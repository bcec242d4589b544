"""``specref brdf``: tabulate isotropic BRDFs and check BRDF table files."""

from __future__ import annotations

from validation.cli.parser import Parser, input_file, output_file, registry_option


def _cmd_brdf_tabulate(args) -> int:
    from reference.materials.table import tabulate_registered_brdf, write_brdf_table

    table = tabulate_registered_brdf(args.model, args.theta_step, args.phi_step)
    write_brdf_table(args.out, table, {"source": f"specref brdf tabulate {args.model}"})
    print(f"wrote {args.out}: {table.values.shape[:3]} angles x {table.n_bands} bands")
    return 0


def _cmd_brdf_check(args) -> int:
    from reference.materials.table import read_brdf_table

    t = read_brdf_table(args.file)
    print(
        f"{args.file}: {t.theta_i_deg.size} theta_i x {t.theta_o_deg.size} theta_s x "
        f"{t.phi_d_deg.size} phi_s, {t.n_bands} wavelengths "
        f"({t.wavelengths_nm[0]:g}-{t.wavelengths_nm[-1]:g} nm), BRDF max {t.values.max():.4g} 1/sr"
    )
    return 0


def add_parser(sub) -> None:
    """Add ``specref brdf`` and its options to the subcommand parsers ``sub``."""
    from reference.materials.brdf import BRDF_METHODS
    from reference.materials.table import tabulable_brdf_names

    p = sub.add_parser("brdf", help="tabulate isotropic BRDFs and check BRDF table files")
    brdf = p.add_subparsers(dest="brdf_command", required=True, parser_class=Parser)
    t = brdf.add_parser("tabulate", help="tabulate a registered BRDF (docs/brdf-format.md)")
    tabulable = tabulable_brdf_names()
    registry_option(t, "model", BRDF_METHODS, "the BRDF", where=lambda key, _: key in tabulable)
    t.add_argument("-o", "--out", type=output_file, required=True, help="output text file")
    t.add_argument("--theta-step", type=float, default=5.0, help="polar step, degrees")
    t.add_argument("--phi-step", type=float, default=15.0, help="azimuth step, degrees")
    t.set_defaults(func=_cmd_brdf_tabulate)
    c = brdf.add_parser("check", help="read a BRDF table file and summarize it")
    c.add_argument("file", type=input_file)
    c.set_defaults(func=_cmd_brdf_check)
