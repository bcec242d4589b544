"""``python -m phong_table.editor [FILE] [--port N] [--save-dir DIR]``: the editor server alone.

``specref phong edit`` is the command users run; this entry point starts the same server without
the ``specref`` command line, so that :mod:`phong_table.editor.browser` needs nothing outside
Wang's package. Bad input is one line on stderr and exit code 2.
"""

import argparse
import sys

from phong_table.editor.app import serve_editor
from reference.errors import SpecrefError


def _announce(line: str) -> None:
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


parser = argparse.ArgumentParser(prog="python -m phong_table.editor")
parser.add_argument("file", nargs="?", help="a material file (TOML) to open")
parser.add_argument("--port", type=int, default=5006, help="port on 127.0.0.1 (default 5006)")
parser.add_argument("--save-dir", help="the folder saves go to")
parser.add_argument("--resolution", type=int, default=256, help="sphere image size (256)")
parser.add_argument("--idle-seconds", type=float, default=5.0, help="close a page left this long")
args = parser.parse_args()
try:
    serve_editor(
        args.file,
        args.port,
        _announce,
        resolution=args.resolution,
        save_dir=args.save_dir,
        idle_seconds=args.idle_seconds,
    )
except SpecrefError as error:
    sys.stderr.write(f"python -m phong_table.editor: {error}\n")
    sys.exit(2)
