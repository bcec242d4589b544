"""``specref cache``: inspect or empty the persistent map cache."""

from __future__ import annotations

from validation.cli.parser import folder_name


def _cmd_cache(args) -> int:
    from pathlib import Path

    from reference.errors import require
    from shrm.cache import Cache

    if args.cache_dir is not None:  # a file or a device has no entries to show or clear
        folder = Path(args.cache_dir)
        require(not folder.exists() or folder.is_dir(), f"--cache-dir: {folder}: not a folder")
    cache = Cache(args.cache_dir)
    if args.action == "clear":
        count = cache.clear()
        print(f"deleted {count} entries from {cache.directory}")
        return 0
    info = cache.info()
    print(f"location: {info.directory}")
    size, limit = info.total_bytes / 1e6, info.max_bytes / 1e6
    print(f"entries: {info.entries} ({size:.1f} MB of {limit:.0f} MB)")
    for name, what in info.others.items():
        print(f"also here: {name}: {what} (not map entries; kept)")
    if info.foreign:
        print(f"foreign files (ignored, never deleted): {', '.join(info.foreign)}")
    return 0


def add_parser(sub) -> None:
    """Add ``specref cache`` and its options to the subcommand parsers ``sub``."""
    p = sub.add_parser("cache", help="inspect or empty the persistent map cache")
    p.add_argument("action", choices=["info", "clear"], help="show the cache or delete its entries")
    p.add_argument(
        "--cache-dir",
        type=folder_name,
        metavar="DIR",
        help="cache folder (default: $SPECREF_CACHE_DIR, else $XDG_CACHE_HOME/specref, else "
        "~/.cache/specref)",
    )
    p.set_defaults(func=_cmd_cache)
