"""``specref report``: the main job (every section's figures, charts, images and checks)."""

from __future__ import annotations

from validation.cli.parser import folder_name, input_file, output_file, registry_option


def _cmd_report(args) -> int:
    import os

    from reference.errors import require_positive_int
    from reference.files import check_output_folder
    from validation.report.runner import run_report

    jobs = min(2, os.cpu_count() or 1) if args.jobs is None else args.jobs
    check_output_folder(args.out)  # a file in the way is refused before minutes of sections
    check_output_folder(os.path.join(args.out, "images"))

    effort = "quick" if args.quick else "full" if args.full else "default"
    results = run_report(
        out_dir=args.out,
        effort=effort,
        only=args.only,
        bench_json=args.bench,
        markdown=args.markdown,
        markdown_image_prefix=args.markdown_image_prefix,
        screenshot=not args.no_screenshot,
        scheduler=args.scheduler,
        jobs=require_positive_int(jobs, "--jobs", 64),
    )
    print(f"wrote {args.out}/index.html and {args.out}/results.json")
    shot = results["meta"].get("screenshot")
    if shot == "written":
        print(f"wrote {args.out}/first-screen.png (the first screen in headless Chromium)")
    elif shot:
        print(f"first-screen.png {shot}")
    return 0


def add_parser(sub) -> None:
    """Add ``specref report`` and its options to the subcommand parsers ``sub``."""
    from reference.tasks import SERIAL, add_scheduler_option
    from validation.report.runner import REPORT_SECTIONS

    p = sub.add_parser(
        "report",
        help="run the main job: every section's figures, charts and images",
        description="Every section's figures, charts, images and target checks, each section at "
        "the settings its checks need (the full-resolution studies and long sweeps at their "
        "quick settings: --full runs them in full). index.html is rewritten after every "
        "section, so a stopped run leaves a readable page. Measured on shared two-core "
        "machines with nothing else running: 2 min 19 s with the default two processes and an "
        "empty kernel cache (3 min 51 s of CPU; 1 min 55 s – 2 min 51 s on a slower machine); "
        "--full 25 min (with make bench, 38 min; 50-66 min on a slower machine), 1 h 48 min "
        "beside other work.",
    )
    p.add_argument(
        "--out", type=folder_name, default="report", help="output folder (default: report)"
    )
    effort = p.add_mutually_exclusive_group()
    effort.add_argument(
        "--quick",
        action="store_true",
        help="every section at its quick settings (a first look; what the tests run)",
    )
    effort.add_argument(
        "--full",
        action="store_true",
        help="every section at its full settings: the full-resolution maps and long sweeps "
        "(make results; 38 min to 1 h 48 min on two cores)",
    )
    registry_option(
        p, "--only", REPORT_SECTIONS, "run only these sections", nargs="+", metavar="SECTION"
    )
    p.add_argument(
        "--bench", type=input_file, metavar="JSON", help="pytest-benchmark JSON from make bench"
    )
    p.add_argument(
        "--markdown",
        type=output_file,
        metavar="MD",
        help="also write a Markdown rendering (docs/results.md)",
    )
    p.add_argument(
        "--markdown-image-prefix",
        default="",
        help="path from the Markdown file to the report folder",
    )
    p.add_argument(
        "--no-screenshot",
        action="store_true",
        help="do not write first-screen.png (written with headless Chromium where installed)",
    )
    p.add_argument(
        "--jobs",
        type=int,
        default=None,
        help="sections side by side in this many processes (default: the cores, at most 2; "
        "ignored with --scheduler, whose cluster runs each section as a task, side by side)",
    )
    add_scheduler_option(p, default=SERIAL)
    p.set_defaults(func=_cmd_report)
