"""``specref sh``: SH projection and frequency-space prefiltering of environment maps."""

from __future__ import annotations

import sys

from validation.cli.parser import Parser, input_file, output_file, registry_option


def _cmd_sh_project(args) -> int:
    from shrm.files import project_file

    info = project_file(
        args.env, args.order, args.out, args.window, args.bands, args.backend, sys.stderr
    )
    print(f"wrote {info['out']}: {info['channels']} channels to order {info['order']}")
    return 0


def _kernel_table(args) -> list[str]:
    """A ``table:FILE`` kernel's file, an input of ``sh prefilter`` (the write policy)."""
    kernel = str(args.kernel)
    return [kernel.split(":", 1)[1]] if kernel.startswith("table:") else []


def _cmd_sh_prefilter(args) -> int:
    from shrm.files import prefilter_file

    info = prefilter_file(
        args.env, args.kernel, args.out, args.tol, args.format, args.size, args.bands, sys.stderr
    )
    print(
        f"wrote {info['out']}: {info['kernel']} at order {info['order']} (tail {info['tail']:.2g})"
    )
    return 0


def add_parser(sub) -> None:
    """Add ``specref sh`` and its options to the subcommand parsers ``sub``."""
    from shrm.lobes import PREFILTER_KERNELS
    from shrm.transform import SH_BACKENDS
    from shrm.windows import WINDOWS

    p = sub.add_parser("sh", help="spherical harmonics: project and prefilter environment maps")
    sh = p.add_subparsers(dest="sh_command", required=True, parser_class=Parser)
    q = sh.add_parser("project", help="SH coefficients of a lat-long map (.npz)")
    q.add_argument("env", type=input_file, help="lat-long map, .hdr or .exr (RGB or spectral)")
    q.add_argument("--order", type=int, required=True, help="SH order L")
    registry_option(q, "--window", WINDOWS, "window against ringing")
    q.add_argument("--bands", choices=("spectral", "rgb"), default=None, help="convert first")
    registry_option(q, "--backend", SH_BACKENDS, "SH transform engine", default="ducc0")
    q.add_argument("-o", "--out", type=output_file, required=True, help="output .npz")
    q.set_defaults(func=_cmd_sh_project, streamed=True)
    r = sh.add_parser("prefilter", help="frequency-space prefiltered cube or lat-long map (.exr)")
    r.add_argument("env", type=input_file, help="lat-long map, .hdr or .exr")
    registry_option(r, "--kernel", PREFILTER_KERNELS, "prefilter kernel", required=True)
    r.add_argument("-o", "--out", type=output_file, required=True, help="output .exr")
    r.add_argument("--tol", type=float, default=1e-2, help="adaptive-order tolerance")
    r.add_argument("--format", choices=("cube", "latlong"), default="cube")
    r.add_argument("--size", type=int, default=64, help="cube face size")
    r.add_argument("--bands", choices=("spectral", "rgb"), default=None, help="convert first")
    r.set_defaults(func=_cmd_sh_prefilter, sibling_inputs=_kernel_table)
