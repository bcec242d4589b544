"""The ``specref`` command: argument parsing and dispatch to library functions, nothing else.

Every subcommand is a small function that calls the library. Bad input raises
:class:`~reference.errors.SpecrefError` in the library; :func:`main` prints its one-line message to
stderr and exits with code 2, without a traceback.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

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


def _cmd_render(args) -> int:
    import phong_table  # noqa: F401  (registers its shaders, if any)
    import shrm  # noqa: F401  (registers the environment-light shaders, if any)
    from reference.render import render_scene_file

    result = render_scene_file(
        args.scene,
        png=args.output,
        exr=args.exr,
        width=args.width,
        height=args.height,
        supersample=args.supersample,
        oracle=args.oracle,
    )
    r = result.scene.render
    outputs = " and ".join(str(p) for p in (args.output, args.exr) if p is not None)
    print(
        f"wrote {outputs} ({r.width}×{r.height}, supersample {r.supersample}, "
        f"{result.timings['total']:.2f} s)"
    )
    return 0


def _cmd_cache(args) -> int:
    from shrm.cache import Cache

    cache = Cache(args.cache_dir)
    if args.action == "clear":
        count = cache.clear()
        print(f"deleted {count} entries from {cache.directory}")
        return 0
    info = cache.info()
    print(f"location: {info.directory}")
    size, limit = info.total_bytes / 1e6, info.max_bytes / 1e6
    print(f"entries: {info.entries} ({size:.1f} MB of {limit:.0f} MB)")
    if info.foreign:
        print(f"foreign files (ignored, never deleted): {', '.join(info.foreign)}")
    return 0


def _add_cache_parser(sub) -> None:
    p = sub.add_parser("cache", help="inspect or empty the persistent map cache")
    p.add_argument("action", choices=["info", "clear"], help="show the cache or delete its entries")
    p.add_argument(
        "--cache-dir",
        metavar="DIR",
        help="cache folder (default: $SPECREF_CACHE_DIR, else $XDG_CACHE_HOME/specref, else "
        "~/.cache/specref)",
    )
    p.set_defaults(func=_cmd_cache)


def _cmd_brdf_tabulate(args) -> int:
    from reference.brdf_table import tabulate_registered_brdf, write_brdf_table

    table = tabulate_registered_brdf(args.model, args.theta_step, args.phi_step)
    write_brdf_table(args.out, table, {"source": f"specref brdf tabulate {args.model}"})
    print(f"wrote {args.out}: {table.values.shape[:3]} angles x {table.n_bands} bands")
    return 0


def _cmd_brdf_check(args) -> int:
    from reference.brdf_table import read_brdf_table

    t = read_brdf_table(args.file)
    print(
        f"{args.file}: {t.theta_i_deg.size} theta_i x {t.theta_o_deg.size} theta_s x "
        f"{t.phi_d_deg.size} phi_s, {t.n_bands} wavelengths "
        f"({t.wavelengths_nm[0]:g}-{t.wavelengths_nm[-1]:g} nm), BRDF max {t.values.max():.4g} 1/sr"
    )
    return 0


def _cmd_sh_project(args) -> int:
    from shrm.files import project_file

    info = project_file(args.env, args.order, args.out, args.window, args.bands, args.backend)
    print(f"wrote {info['out']}: {info['channels']} channels to order {info['order']}")
    return 0


def _cmd_sh_prefilter(args) -> int:
    from shrm.files import prefilter_file

    info = prefilter_file(
        args.env, args.kernel, args.out, args.tol, args.format, args.size, args.bands
    )
    print(
        f"wrote {info['out']}: {info['kernel']} at order {info['order']} (tail {info['tail']:.2g})"
    )
    return 0


def _add_render_parser(sub) -> None:
    p = sub.add_parser(
        "render",
        help="render a scene file to a display-encoded PNG (and optionally a linear EXR)",
        description="Render a TOML scene (docs/scene-format.md). Relative paths in the scene are "
        "relative to its folder.",
    )
    p.add_argument("scene", metavar="SCENE.toml", help="the scene file")
    p.add_argument(
        "-o", "--output", required=True, metavar="OUT.png", help="display-encoded 8-bit PNG"
    )
    p.add_argument(
        "--exr", metavar="OUT.exr", help="also write linear display RGB (before exposure) as EXR"
    )
    p.add_argument("--width", type=int, help="override render.width (alone: keep the aspect)")
    p.add_argument("--height", type=int, help="override render.height (alone: keep the aspect)")
    p.add_argument("--supersample", type=int, help="override render.supersample")
    p.add_argument(
        "--oracle",
        action="store_true",
        help='brute-force environment lighting (ShadingContext.options["environment"] = '
        '"bruteforce"), the reference the SH engine is checked against; slow',
    )
    p.set_defaults(func=_cmd_render)


def _add_brdf_parser(sub) -> None:
    p = sub.add_parser("brdf", help="tabulate isotropic BRDFs and check BRDF table files")
    brdf = p.add_subparsers(dest="brdf_command", required=True, parser_class=_Parser)
    t = brdf.add_parser("tabulate", help="tabulate a registered BRDF (docs/brdf-format.md)")
    t.add_argument("model", help="a key of reference.brdf.BRDF_METHODS, e.g. ggx")
    t.add_argument("-o", "--out", required=True, help="output text file")
    t.add_argument("--theta-step", type=float, default=5.0, help="polar step, degrees")
    t.add_argument("--phi-step", type=float, default=15.0, help="azimuth step, degrees")
    t.set_defaults(func=_cmd_brdf_tabulate)
    c = brdf.add_parser("check", help="read a BRDF table file and summarize it")
    c.add_argument("file")
    c.set_defaults(func=_cmd_brdf_check)


def _cmd_shrm_orbit(args) -> int:
    from shrm.cache import Cache
    from shrm.orbit import demo_state, render_orbit, scene_state
    from shrm.session import RenderSession

    quick = {"env_height": 16, "size": 8, "resolution": 48, "F_max": 12, "P_max": 6}
    orders = {k: v for k, v in (("tol", args.tol), ("F", args.F), ("P", args.P)) if v is not None}
    if args.scene is not None:
        from reference.scene import load_scene

        for flag, value in (("--brdf", args.brdf), ("--env", args.env), ("--quick", args.quick)):
            if value:
                raise SpecrefError(
                    f"{args.scene}: {flag} is for the built-in scene, not a scene file"
                )
        state = scene_state(load_scene(args.scene), **orders)
    else:
        state = demo_state(
            args.env, brdf=args.brdf or "effect_pigment", **(quick if args.quick else {}), **orders
        )
    session = RenderSession(state, cache=Cache(args.cache_dir, enabled=not args.no_cache))
    rows = render_orbit(session, args.frames, args.out)
    total = [sum(r.values()) for r in rows]
    print(
        f"wrote {args.frames} frames and timings.csv to {args.out}; first frame "
        f"{total[0]:.3f} s, later frames {np.mean(total[1:]) if len(total) > 1 else 0:.3f} s"
    )
    return 0


def _add_shrm_parser(sub) -> None:
    p = sub.add_parser("shrm", help="SH reflection maps (Herbert et al. §5.5-5.6)")
    shrm = p.add_subparsers(dest="shrm_command", required=True, parser_class=_Parser)
    o = shrm.add_parser("orbit", help="render a camera orbit; PNG frames and per-stage timings")
    o.add_argument("scene", nargs="?", metavar="SCENE.toml", help="scene file (default: built-in)")
    o.add_argument("--frames", type=int, default=8, help="frames of a full turn (default 8)")
    o.add_argument("-o", "--out", required=True, help="output folder")
    o.add_argument("--brdf", help="isotropic BRDF of the built-in sphere (effect_pigment)")
    o.add_argument("--env", help="lat-long environment (.hdr/.exr); default venice_sunset_1k")
    o.add_argument("--quick", action="store_true", help="small maps and images")
    o.add_argument("--tol", type=float, help="order tolerance (default 0.05, an L2 tail)")
    o.add_argument("--F", type=int, help="lighting order (default: from --tol)")
    o.add_argument("--P", type=int, help="view order, 2-10 (default: from --tol)")
    o.add_argument("--cache-dir", metavar="DIR", help="persistent cache folder")
    o.add_argument("--no-cache", action="store_true", help="do not use the persistent cache")
    o.set_defaults(func=_cmd_shrm_orbit)


def _add_sh_parser(sub) -> None:
    p = sub.add_parser("sh", help="spherical harmonics: project and prefilter environment maps")
    sh = p.add_subparsers(dest="sh_command", required=True, parser_class=_Parser)
    q = sh.add_parser("project", help="SH coefficients of a lat-long map (.npz)")
    q.add_argument("env", help="lat-long map, .hdr or .exr (RGB or spectral)")
    q.add_argument("--order", type=int, required=True, help="SH order L")
    q.add_argument("--window", default=None, help="none, hanning, lanczos, gaussian[:SIGMA]")
    q.add_argument("--bands", choices=("spectral", "rgb"), default=None, help="convert first")
    q.add_argument("--backend", default="ducc0", help="numpy, numba or ducc0")
    q.add_argument("-o", "--out", required=True, help="output .npz")
    q.set_defaults(func=_cmd_sh_project)
    r = sh.add_parser("prefilter", help="frequency-space prefiltered cube or lat-long map (.exr)")
    r.add_argument("env", help="lat-long map, .hdr or .exr")
    r.add_argument("--kernel", required=True, help="lambert, phong:S or table:FILE")
    r.add_argument("--out", required=True, help="output .exr")
    r.add_argument("--tol", type=float, default=1e-2, help="adaptive-order tolerance")
    r.add_argument("--format", choices=("cube", "latlong"), default="cube")
    r.add_argument("--size", type=int, default=64, help="cube face size")
    r.add_argument("--bands", choices=("spectral", "rgb"), default=None, help="convert first")
    r.set_defaults(func=_cmd_sh_prefilter)


def _cmd_impastor_table1(args) -> int:
    import json

    from validation.impastor_cli import format_table1, table1_for_cli

    result = table1_for_cli(args.design, args.channels, args.white_luminance, args.display)
    print(format_table1(result))
    if args.json:
        from reference.images import write_text_atomic

        write_text_atomic(args.json, json.dumps(result, indent=1) + "\n")
        print(f"wrote {args.json}")
    return 0


def _cmd_impastor_render(args) -> int:
    from validation.impastor_cli import render_for_cli

    print(render_for_cli(args.light, args.size, args.method, args.out))
    return 0


def _add_impastor_parser(sub) -> None:
    p = sub.add_parser("impastor", help="ImpastoR (Ferwerda 2015): Table 1 and the demo painting")
    isub = p.add_subparsers(dest="impastor_command", required=True, parser_class=_Parser)
    t = isub.add_parser("table1", help="Table 1: ColorChecker simulation and screen output")
    t.add_argument("--json", metavar="FILE", help="also write the table as JSON")
    t.add_argument("--design", default="optimized", help="channel design (box, optimized)")
    t.add_argument("--channels", type=int, default=6, help="channel count (3-10)")
    t.add_argument(
        "--white-luminance", type=float, default=200.0, help="white diffuser luminance, cd/m²"
    )
    t.add_argument("--display", metavar="JSON", help="display measurement file (default: virtual)")
    t.set_defaults(func=_cmd_impastor_table1)
    r = isub.add_parser("render", help="render the demo painting under a booth light to a PNG")
    r.add_argument("--light", default="D65", help="illuminant key (D65, D50, A, FL2, ...)")
    r.add_argument("--size", type=int, default=512, help="image side in pixels")
    r.add_argument("--method", default="hybrid", help="median_cut, variance_min, fis, hybrid")
    r.add_argument("--out", default="impastor.png", help="output PNG")
    r.set_defaults(func=_cmd_impastor_render)


def _write_json(path, result) -> None:
    import json

    from reference.images import write_text_atomic
    from validation.report import to_jsonable

    write_text_atomic(path, json.dumps(to_jsonable(result), indent=1))
    print(f"wrote {path}")


def _cmd_phong(args) -> int:
    from reference.errors import SpecrefError
    from validation import phong, phong_table1

    if args.action == "table1":
        result = phong_table1.run_table1(args.resolution, args.entries, args.repeats, progress=True)
        print(f"Table 1 (Wang et al.), {args.resolution}x{args.resolution}, {args.entries} entries")
        print(phong_table1.format_rows(result["rows"]))
        print("\nTargets")
        print(phong_table1.format_targets(result["targets"]))
    else:
        if args.material is None:
            raise SpecrefError("specref phong: give table1 or --material FILE.toml")
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
        )
        print(phong_table1.format_rows(result["rows"]))
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
    p.add_argument(
        "--material",
        metavar="FILE.toml",
        help="a material file (docs/scene-format.md, Phong material files)",
    )
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
    _add_render_parser(sub)
    _add_cache_parser(sub)
    _add_brdf_parser(sub)
    _add_shrm_parser(sub)
    _add_sh_parser(sub)
    _add_impastor_parser(sub)
    _add_phong_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the ``specref`` command; return the exit code (2 for bad input).

    Examples
    --------
    >>> main(["report", "--only", "no-such-section", "--out", "/tmp/specref-doctest"])
    2
    """
    import shrm  # noqa: F401  (registers the environment-light shaders before any rendering)

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
