"""``specref env``: an RGB → spectrum regression, spectralized panoramas (Herbert §4), previews."""

from __future__ import annotations

from validation.cli.parser import Parser, input_file, number_in, output_file, registry_option

#: The most rows a block or chunk may hold (the libraries' own bound).
MAX_ROWS = 1 << 20


def _cmd_env_fit(args) -> int:
    from validation.studies.spectral_env import fit_file

    report = fit_file(
        args.out,
        args.target,
        args.spectra,
        args.camera,
        args.illuminant,
        args.features,
        args.degree,
        args.ridge,
        args.noise,
        args.loss,
        args.spectral_weight,
        args.augment,
    )
    for line in report["lines"]:
        print(line)
    return 0


def _cmd_env_spectralize(args) -> int:
    from reference.colour.spectra import DEFAULT_GRID
    from reference.colour.spectral_regression import load_regression
    from reference.colour.upsampling import DEFAULT_REGRESSION_MODEL
    from reference.images.spectral import spectralize_file

    path = DEFAULT_REGRESSION_MODEL if args.model == "default" else args.model
    model = load_regression(path, DEFAULT_GRID.wavelengths_nm)
    info = spectralize_file(args.panorama, model, args.out, args.rows)
    print(
        f"wrote {info['out']}: {info['height']}x{info['width']}, {info['bands']} bands, "
        f"{info['blocks']} row blocks"
    )
    projected = info["projected"]
    if projected["values"]:
        print(
            f"projected {projected['values']} negative band values in {projected['pixels']} "
            f"pixels (most negative {projected['min']:.4g}) onto non-negative spectra of the same "
            "colour (erratum E106)"
        )
    return 0


def _cmd_env_preview(args) -> int:
    import sys

    from reference.images.preview import image_preview

    info = image_preview(args.image, args.out, args.width, args.exposure, progress=sys.stderr)
    rows, columns = info["preview"]
    print(
        f"wrote {info['out']}: {columns}×{rows} sRGB preview of a {info['width']}×"
        f"{info['height']} {info['kind']} image (box filter {info['factor']}×{info['factor']}, "
        f"exposure {info['exposure_ev']:+.2f} EV, {100 * info['clipped']:.1f} % of values clipped)"
    )
    return 0


def _cmd_env_convert(args) -> int:
    from reference.images.spectral import convert_to_zarr

    info = convert_to_zarr(args.input, args.out, args.rows, args.compression)
    print(
        f"wrote {info['out']}: {info['height']}×{info['width']}, {info['channels']} channels, "
        f"{info['chunks']} chunks of {info['rows_per_chunk']} rows, {info['compression']} "
        f"({info['ratio']:.2f}× smaller than float32)"
    )
    return 0


def add_parser(sub) -> None:
    """Add ``specref env fit|spectralize|convert|preview`` to the subcommand parsers ``sub``."""
    from reference.colour.spectral_regression import (
        DEFAULT_LOSS,
        MAX_RIDGE,
        REGRESSION_FEATURES,
        REGRESSION_LOSSES,
    )
    from reference.colour.spectral_target import CAMERAS, TARGET_AUGMENTATIONS

    p = sub.add_parser("env", help="spectral environments: camera-target regression (Herbert §4)")
    env = p.add_subparsers(dest="env_command", required=True, parser_class=Parser)
    f = env.add_parser("fit", help="fit and save an RGB -> spectrum model; print its figures")
    f.add_argument(
        "--target",
        type=input_file,
        default=None,
        help="target CSV (R, G, B and wavelength columns)",
    )
    f.add_argument(
        "--spectra", type=input_file, default=None, help="spectra CSV when --target holds only RGB"
    )
    registry_option(f, "--camera", CAMERAS, "synthetic target camera", default="Nikon 5100 (NPL)")
    f.add_argument("--illuminant", default="D65", help="capture illuminant (colour-science key)")
    registry_option(
        f, "--features", REGRESSION_FEATURES, "regression features", default="root_polynomial"
    )
    f.add_argument("--degree", type=int, default=4, help="1-5 (polynomial), 1-4 (root)")
    registry_option(f, "--loss", REGRESSION_LOSSES, "fitted loss (E44)", default=DEFAULT_LOSS)
    f.add_argument(
        "--ridge",
        type=number_in(0.0, MAX_RIDGE),
        default=None,
        help=f"fixed ridge strength, 0 to {MAX_RIDGE:g} (default: CV)",
    )
    f.add_argument(
        "--spectral-weight",
        type=float,
        default=None,
        help="β of the colorimetric loss (default: CV)",
    )
    registry_option(
        f,
        "--augment",
        TARGET_AUGMENTATIONS,
        "augmentation of the synthetic target, weight by CV (E44; default products, none with "
        "--target)",
        default=None,
    )
    f.add_argument("--noise", action="store_true", help="add 0.5 %% + 0.1 %% camera noise")
    f.add_argument("-o", "--out", type=output_file, required=True, help="output model .json")
    f.set_defaults(func=_cmd_env_fit)
    s = env.add_parser(
        "spectralize", help="expand an HDR panorama to a spectral .exr, .tif or .zarr"
    )
    s.add_argument(
        "panorama",
        type=input_file,
        help="linear HDR panorama: .hdr, RGB .exr, float RGB .tif or RGB .zarr",
    )
    s.add_argument(
        "--model", type=input_file, required=True, help="model .json from `env fit`, or 'default'"
    )
    s.add_argument(
        "--rows",
        type=number_in(1, MAX_ROWS, integer=True),
        default=None,
        help="rows per block (default: 2^17 pixels)",
    )
    s.add_argument(
        "-o", "--out", type=output_file, required=True, help="output .exr, .tif or .zarr"
    )
    s.set_defaults(func=_cmd_env_spectralize, streamed=True)
    _add_convert(env)
    _add_preview(env)


def _add_preview(env) -> None:
    """Add ``specref env preview`` to the ``env`` subcommands."""
    v = env.add_parser(
        "preview",
        help="an sRGB PNG of a spectral, XYZ or RGB image (e.g. a 41-band panorama) to look at",
    )
    v.add_argument(
        "image",
        type=input_file,
        help="linear image: .exr (spectral, XYZ or RGB), .hdr, .tif, .zarr",
    )
    v.add_argument("-o", "--out", type=output_file, required=True, help="the preview .png")
    v.add_argument("--width", type=int, default=2048, help="widest preview in pixels (2048)")
    v.add_argument(
        "--exposure",
        type=float,
        default=None,
        metavar="EV",
        help="stops applied before display (default: the median luminance to 18 %% grey)",
    )
    v.set_defaults(func=_cmd_env_preview, streamed=True)


def _add_convert(env) -> None:
    """Add ``specref env convert`` to the ``env`` subcommands."""
    from reference.images.zarr_store import ZARR_COMPRESSIONS

    c = env.add_parser(
        "convert", help="convert a panorama (.exr, .hdr, .tif) to a chunked Zarr store"
    )
    c.add_argument("input", type=input_file, help="lat-long panorama: .exr, .hdr or spectral .tif")
    c.add_argument(
        "out",
        type=output_file,
        metavar="OUT.zarr",
        help="the Zarr store to write (docs/scale-out.md)",
    )
    c.add_argument(
        "--rows",
        type=number_in(1, MAX_ROWS, integer=True),
        default=None,
        help="rows per chunk (default: about 21.5 MB of float32 per chunk)",
    )
    registry_option(c, "--compression", ZARR_COMPRESSIONS, "chunk compression", default="blosc-lz4")
    c.set_defaults(func=_cmd_env_convert, streamed=True)
