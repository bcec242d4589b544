"""The CLI's shared pieces: the argument parser class and the JSON writer."""

from __future__ import annotations

import argparse
import json

__all__ = ["Parser", "write_json"]


class Parser(argparse.ArgumentParser):
    """argparse with one-line usage errors and exit code 2 (argparse's code for usage errors)."""

    def error(self, message):
        """Print a one-line usage error naming the subcommand's help, and exit with code 2."""
        self.exit(2, f"specref: error: {message} (see specref {self.prog.split()[-1]} --help)\n")


def write_json(path, result) -> None:
    """Write ``result`` (NumPy values converted) as JSON to ``path``, atomically, and say so.

    Examples
    --------
    >>> import json, pathlib, tempfile
    >>> import numpy as np
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = pathlib.Path(folder) / "r.json"
    ...     write_json(path, {"rms": np.float64(0.5)})
    ...     json.loads(path.read_text())
    wrote .../r.json
    {'rms': 0.5}
    """
    from reference.images import write_text_atomic
    from validation.report import to_jsonable

    write_text_atomic(path, json.dumps(to_jsonable(result), indent=1))
    print(f"wrote {path}")
