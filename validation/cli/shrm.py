"""``specref shrm``: SH reflection maps (Herbert et al. §5.5-5.6): a camera orbit."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require, require_positive_int
from validation.cli.parser import Parser, input_file, registry_option


def _check_arguments(args) -> None:
    """The arguments that need no data, before any work (docs/bad-input.md)."""
    from reference.files import check_output_folder
    from shrm.brdf_sh import P_RANGE

    require_positive_int(args.frames, "orbit --frames", 100000)
    if args.tol is not None:
        require(
            bool(np.isfinite(args.tol)) and 0.0 < args.tol < 1.0,
            f"shrm orbit: --tol: must be in (0, 1) (an L2 tail of the BRDF), got {args.tol}",
        )
    if args.P is not None:
        low, high = P_RANGE
        require(
            low <= args.P <= high,
            f"shrm orbit: --P: must be in [{low}, {high}] (§5.5, Herbert et al.), got {args.P}",
        )
    if args.F is not None:
        require(args.F >= 0, f"shrm orbit: --F: must be >= 0, got {args.F}")
    if args.env is not None:  # before the output folder is made: a refusal leaves nothing behind
        require(Path(args.env).is_file(), f"{args.env}: environment file not found (--env)")
        _check_orbit_environment(args.env)
    check_output_folder(args.out)


def _check_orbit_environment(path) -> None:
    """An HDR lat-long map of at least three channels, finite and >= 0 (one line, before work)."""
    import numpy as np

    from reference.errors import require
    from reference.images.spectral import read_environment_file

    image, names = read_environment_file(path)  # refuses 8-bit images
    require(
        image.ndim == 3 and image.shape[2] >= 3,
        f"{path}: --env: an RGB or spectral map is needed, got channels {names}",
    )
    require(
        image.shape[1] == 2 * image.shape[0],
        f"{path}: --env: a lat-long map is 2:1, got {image.shape[1]} × {image.shape[0]} pixels",
    )
    require(
        bool(np.isfinite(image).all()) and float(image.min()) >= 0.0,
        f"{path}: --env: radiance must be finite and >= 0",
    )


def _cmd_shrm_orbit(args) -> int:
    from shrm.cache import Cache
    from shrm.orbit import demo_state, render_orbit, scene_state
    from shrm.session import RenderSession

    _check_arguments(args)
    quick = {"env_height": 16, "size": 8, "resolution": 48, "F_max": 12, "P_max": 6}
    orders = {k: v for k, v in (("tol", args.tol), ("F", args.F), ("P", args.P)) if v is not None}
    if args.scene is not None:
        from reference.scene.loader import load_scene

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
    # the orders that --tol, --F and --P ask for are checked against the BRDF's coefficients
    # before the first frame (and its progress line) starts
    session.prepare("brdf_coeffs")
    rows = render_orbit(session, args.frames, args.out)
    total = [sum(r.values()) for r in rows]
    print(
        f"wrote {args.frames} frames and timings.csv to {args.out}; first frame "
        f"{total[0]:.3f} s, later frames {np.mean(total[1:]) if len(total) > 1 else 0:.3f} s"
    )
    return 0


def add_parser(sub) -> None:
    """Add ``specref shrm`` and its options to the subcommand parsers ``sub``."""
    from reference.materials.brdf import BRDF_METHODS
    from shrm.orbit import analytic_isotropic_brdf_names

    p = sub.add_parser("shrm", help="SH reflection maps (Herbert et al. §5.5-5.6)")
    shrm = p.add_subparsers(dest="shrm_command", required=True, parser_class=Parser)
    o = shrm.add_parser("orbit", help="render a camera orbit; PNG frames and per-stage timings")
    o.add_argument(
        "scene",
        nargs="?",
        type=input_file,
        metavar="SCENE.toml",
        help="scene file (default: built-in)",
    )
    o.add_argument("--frames", type=int, default=8, help="frames of a full turn (default 8)")
    o.add_argument("-o", "--out", required=True, help="output folder")
    analytic = analytic_isotropic_brdf_names()
    registry_option(
        o,
        "--brdf",
        BRDF_METHODS,
        "isotropic BRDF of the built-in sphere (default effect_pigment)",
        where=lambda key, _: key in analytic,
    )
    o.add_argument(
        "--env", type=input_file, help="lat-long environment (.hdr/.exr); default venice_sunset_1k"
    )
    o.add_argument("--quick", action="store_true", help="small maps and images")
    o.add_argument("--tol", type=float, help="order tolerance (default 0.05, an L2 tail)")
    o.add_argument("--F", type=int, help="lighting order (default: from --tol)")
    o.add_argument("--P", type=int, help="view order, 2-10 (default: from --tol)")
    o.add_argument("--cache-dir", metavar="DIR", help="persistent cache folder")
    o.add_argument("--no-cache", action="store_true", help="do not use the persistent cache")
    o.set_defaults(func=_cmd_shrm_orbit)
