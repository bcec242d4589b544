"""``specref polymer``: Herbert et al.'s polymer characterization (the chip matrix of §3.1)."""

from __future__ import annotations

from validation.cli.parser import Parser, input_file, output_file


def _numbers(text: str, name: str) -> list[float]:
    from reference.errors import SpecrefError

    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError as error:
        raise SpecrefError(f"--{name}: must be comma-separated numbers, got {text!r}") from error


def _cmd_polymer_characterize(args) -> int:
    import math
    import sys

    from reference.colour.spectra import GRIDS
    from reference.errors import require
    from shrm.polymer.characterization import (
        characterize_model,
        check_chip_count,
        write_characterization,
    )
    from shrm.polymer.kubelka_munk import polymer_constituents

    thickness, tio2 = _numbers(args.thickness, "thickness"), _numbers(args.tio2, "tio2")
    # a chip is a sheet of plastic: TiO2 a share by weight, the thickness in millimetres
    require(
        all(math.isfinite(t) and 0 <= t <= 1000 for t in thickness),
        f"--thickness: each thickness must be in [0, 1000] mm, got {args.thickness!r}",
    )
    require(
        all(math.isfinite(c) and 0 <= c <= 100 for c in tio2),
        f"--tio2: each TiO2 load must be in [0, 100] % by weight, got {args.tio2!r}",
    )
    # the grid's size before any work (docs/bad-input.md, bounded work)
    check_chip_count(len(thickness), len(tio2), GRIDS[args.grid].n_bands, args.yes)
    constituents = polymer_constituents(GRIDS[args.grid], args.constituents)
    ch = characterize_model(constituents, thickness, tio2, args.backing_white)
    write_characterization(args.out, ch, progress=sys.stderr)
    print(
        f"wrote {args.out}: {ch.meta['material']}, {ch.thickness_mm.size} thicknesses x "
        f"{ch.tio2_pct.size} TiO2 loads x {ch.wavelengths_nm.size} bands"
    )
    return 0


def add_parser(sub) -> None:
    """Add ``specref polymer`` and its options to the subcommand parsers ``sub``."""
    from reference.colour.spectra import GRIDS
    from shrm.polymer.characterization import DEFAULT_THICKNESS_MM, DEFAULT_TIO2_PCT

    p = sub.add_parser("polymer", help="polymer characterization files (Herbert et al. §3.1)")
    polymer = p.add_subparsers(dest="polymer_command", required=True, parser_class=Parser)
    q = polymer.add_parser(
        "characterize", help="write a characterization file from the Kubelka-Munk slab model"
    )
    q.add_argument(
        "-o", "--out", type=output_file, required=True, help="output .csv (docs/herbert-polymer.md)"
    )
    q.add_argument(
        "--thickness",
        default=",".join(f"{d:g}" for d in DEFAULT_THICKNESS_MM),
        help="thickness grid, mm, increasing (default: %(default)s)",
    )
    q.add_argument(
        "--tio2",
        default=",".join(f"{c:g}" for c in DEFAULT_TIO2_PCT),
        help="TiO2 grid, %% by weight, increasing (default: %(default)s)",
    )
    q.add_argument(
        "--constituents",
        type=input_file,
        default=None,
        help="K/S constituents TOML (default: HDPE-like)",
    )
    q.add_argument("--backing-white", type=float, default=0.9, help="white backing reflectance")
    q.add_argument("--grid", choices=sorted(GRIDS), default="41", help="spectral grid")
    q.add_argument(
        "--yes",
        action="store_true",
        help="make a grid of more than 10,000 chips (at most 1,000,000)",
    )
    q.set_defaults(func=_cmd_polymer_characterize)
