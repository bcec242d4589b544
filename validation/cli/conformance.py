"""``specref conformance list|references|export|check``: specref as other renderers' oracle."""

from __future__ import annotations

import sys

from validation.cli.parser import folder_name, input_file, output_file


def _say(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


def _cmd_list(args) -> int:
    from validation.conformance.scenes import CONFORMANCE_SCENES

    for scene in CONFORMANCE_SCENES.values():
        cannot = ", ".join(f"not in {k}: {v}" for k, v in scene.cannot_export.items())
        print(f"{scene.name}\n  tests: {scene.tests}\n  catches: {', '.join(scene.catches)}")
        if cannot:
            print(f"  {cannot}")
    return 0


def _cmd_references(args) -> int:
    from validation.conformance.references import ensure_references, reference_folder

    folder = args.out or reference_folder()
    manifest = ensure_references(args.scene or None, folder, _say, force=args.force)
    print(f"{len(manifest['scenes'])} references in {folder} (manifest.json)")
    return 0


def _cmd_export(args) -> int:
    from validation.conformance.export import export_scenes

    index = export_scenes(args.out, args.format, args.spp)
    print(f"wrote {len(index['scenes'])} scenes ({args.format}) to {args.out}")
    for name, why in index["cannot_express"].items():
        print(f"  not exported: {name}: {why}")
    return 0


def _cmd_check(args) -> int:
    from validation.conformance.check import check_folder, check_outputs, summary_table, write_json

    # refuse an unusable output, or one that would overwrite an input, before any rendering
    check_outputs(args.renders, args.references, [args.json, args.html])
    result = check_folder(args.renders, args.references, args.colourspace, _say)
    print(summary_table(result))
    if args.json:
        write_json(result, args.json)
    if args.html:
        from validation.conformance.html import write_html

        write_html(result, args.html, args.references, args.colourspace)
    return 0 if result["failed"] == 0 else 1


def add_parser(sub) -> None:
    """Add ``specref conformance`` and its subcommands to ``sub``."""
    from validation.cli.parser import Parser
    from validation.conformance.export import EXPORT_FORMATS

    p = sub.add_parser(
        "conformance",
        help="canonical scenes with references: export them, check another renderer's images",
        description="The conformance suite (docs/conformance.md): small scenes, each testing one "
        "thing, with references rendered by specref's oracle path; check a renderer's images "
        "against them, with a diagnosis of the usual mistakes.",
    )
    cmd = p.add_subparsers(dest="action", required=True, parser_class=Parser)
    q = cmd.add_parser("list", help="the scenes, what each tests and the mistakes it catches")
    q.set_defaults(func=_cmd_list)
    q = cmd.add_parser("references", help="render the references (into the cache by default)")
    q.add_argument(
        "--out",
        type=folder_name,
        metavar="DIR",
        help="the folder (default <cache>/conformance/v<N>)",
    )
    q.add_argument("--scene", action="append", metavar="NAME", help="only this scene (repeat)")
    q.add_argument("--force", action="store_true", help="render even the references present")
    q.set_defaults(func=_cmd_references)
    q = cmd.add_parser("export", help="write the scenes in specref's or Mitsuba 3's format")
    q.add_argument("out", type=folder_name, metavar="DIR")
    q.add_argument("--format", choices=EXPORT_FORMATS, default="specref")
    q.add_argument("--spp", type=int, default=256, help="Mitsuba's samples per pixel (256)")
    q.set_defaults(func=_cmd_export)
    q = cmd.add_parser(
        "check",
        help="check a folder of renders (<scene>.exr) against the references",
        description="Exit code 0 when every render passes, 1 when one fails, 2 on bad input.",
    )
    q.add_argument("renders", type=input_file, metavar="RENDERS_DIR")
    q.add_argument(
        "--references",
        type=input_file,
        metavar="DIR",
        help="the references' folder (default cache)",
    )
    q.add_argument("--colourspace", help="of renders with R, G, B channels (default: the file's "
                   "specref metadata, else sRGB)")  # fmt: skip
    q.add_argument(
        "--json", type=output_file, metavar="OUT.json", help="also write the figures as JSON"
    )
    q.add_argument(
        "--html",
        type=output_file,
        metavar="OUT.html",
        help="also write a page with difference images",
    )
    q.set_defaults(func=_cmd_check)
