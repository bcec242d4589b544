"""User-defined sweeps (``specref sweep FILE.toml``): a grid of methods × materials, as Dask tasks.

A sweep file names a kind of study (:data:`SWEEP_KINDS`) and the grid to run it over; every cell
of the grid is one independent task, run through :func:`reference.tasks.run_tasks` (a local Dask
cluster, a remote scheduler, or serially), and the output is a tidy table: one row per cell, one
column per grid key and per figure, written as CSV.

The ``phong`` kind (Wang, Chern & Lee): the table error of every placement × interpolation ×
entry count on every material × view, against the exact render::

    kind = "phong"
    [grid]
    materials = ["R1", "R3", "my-material.toml"]   # Phong scene keys or material files
    views = ["near", "far"]
    placements = ["uniform", "importance", "error"]
    interpolations = ["linear", "parabolic"]
    entries = [25, 100, 200]
    resolution = 64                                 # one value, not a list

Only figures that do not depend on the machine (errors, entry counts, overshoot) are written, so a
distributed run gives the same table as a serial one, byte for byte.
"""

from __future__ import annotations

import csv
import functools
import io
import itertools
from dataclasses import dataclass
from pathlib import Path

from reference.errors import format_allowed, require, require_positive_int
from reference.images import write_text_atomic
from reference.registry import Registry
from reference.scene import read_toml_file
from reference.tasks import run_tasks

__all__ = ["SWEEP_KINDS", "SweepKind", "load_sweep", "run_sweep", "sweep_csv"]


@dataclass(frozen=True)
class SweepKind:
    """A kind of sweep: its grid keys and their allowed values, and the function of one cell.

    ``lists`` are the keys that take a list (the grid's axes); ``scalars`` take one value and
    are passed to every cell; ``run_cell(cell: dict) -> dict`` returns the cell's figures.
    """

    name: str
    lists: dict
    scalars: dict
    run_cell: object
    about: str = ""


def _phong_materials():
    from phong_table.scenes import SCENES

    return SCENES.names()


@functools.lru_cache(maxsize=8)
def _phong_state(material: str, view: str, resolution: int):
    # One exact render per (material, view, resolution) per worker process, shared by its cells.
    from phong_table.materialfile import load_material_file
    from phong_table.scenes import SCENES
    from validation.phong import view_state

    known = material in SCENES
    model = SCENES.lookup(material).build() if known else load_material_file(material)
    return view_state(model, view, resolution)


def phong_cell(cell: dict) -> dict:
    """One cell of a ``phong`` sweep: the table error of one method on one material and view.

    Examples
    --------
    >>> row = phong_cell({"materials": "R1", "views": "near", "placements": "error",
    ...                   "interpolations": "monotone", "entries": 64, "resolution": 16})
    >>> row["rms"] < 1e-2, row["overshoot"]
    (True, 0.0)
    """
    from validation.phong import table_error_row

    state = _phong_state(cell["materials"], cell["views"], cell["resolution"])
    row = table_error_row(state, cell["placements"], cell["interpolations"], cell["entries"])
    return {k: row[k] for k in ("segments", "rms_display", "rms_linear", "rms", "overshoot")}


def _phong_kind() -> SweepKind:
    from phong_table.interpolation import INTERPOLATION_METHODS
    from phong_table.placement import PLACEMENT_METHODS
    from phong_table.scenes import VIEWS

    return SweepKind(
        "phong",
        lists={
            "materials": None,  # scene keys or material files, checked when loaded
            "views": list(VIEWS),
            "placements": PLACEMENT_METHODS.names(),
            "interpolations": INTERPOLATION_METHODS.names(),
            "entries": int,
        },
        scalars={"resolution": int},
        run_cell=phong_cell,
        about="table error of placements × interpolations × entries on materials × views",
    )


#: The kinds of sweep ``specref sweep`` runs, by the sweep file's ``kind``.
SWEEP_KINDS = Registry("sweep kind")
SWEEP_KINDS.register(_phong_kind(), "phong")


def _check_values(file: str, key: str, values, allowed) -> list:
    require(
        isinstance(values, list) and values,
        f"{file}: grid.{key}: must be a non-empty list, got {values!r}",
    )
    for value in values:
        if allowed is int:
            require_positive_int(value, f"{file}: grid.{key}", 1 << 20)
        elif isinstance(allowed, list):
            require(
                value in allowed,
                f"{file}: grid.{key}: unknown {value!r}; allowed: {format_allowed(allowed)}",
            )
        else:
            require(isinstance(value, str), f"{file}: grid.{key}: must be strings, got {value!r}")
    return values


def load_sweep(path) -> tuple[SweepKind, list[dict]]:
    """Read a sweep file: its kind and the grid's cells (every combination, in file order).

    Raises
    ------
    SpecrefError
        Unreadable file, malformed TOML, unknown kind or key, an empty or invalid grid (one line
        naming the file and the key).

    Examples
    --------
    >>> load_sweep("/nonexistent/sweep.toml")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent/sweep.toml: file not found
    """
    path = Path(path)
    doc = read_toml_file(path)
    file = str(path)
    unknown = sorted(set(doc) - {"kind", "grid"})
    require(not unknown, f"{file}: unknown keys {unknown}; allowed: grid, kind")
    require("kind" in doc, f"{file}: kind: missing; allowed: {format_allowed(SWEEP_KINDS)}")
    require(
        doc["kind"] in SWEEP_KINDS,
        f"{file}: kind: unknown {doc['kind']!r}; allowed: {format_allowed(SWEEP_KINDS)}",
    )
    kind = SWEEP_KINDS.lookup(doc["kind"])
    grid = doc.get("grid")
    require(isinstance(grid, dict) and grid, f"{file}: grid: missing or empty")
    keys = {**kind.lists, **kind.scalars}
    unknown = sorted(set(grid) - set(keys))
    require(not unknown, f"{file}: grid: unknown keys {unknown}; allowed: {format_allowed(keys)}")
    missing = sorted(set(keys) - set(grid))
    require(not missing, f"{file}: grid: missing keys {missing}")
    axes = {
        key: _check_values(file, key, grid[key], allowed) for key, allowed in kind.lists.items()
    }
    scalars = {}
    for key in kind.scalars:
        scalars[key] = require_positive_int(grid[key], f"{file}: grid.{key}", 4096)
    cells = [
        {**dict(zip(axes, combo, strict=True)), **scalars}
        for combo in itertools.product(*axes.values())
    ]
    return kind, cells


def run_sweep(path, scheduler: str | None = None, progress: bool = True, client=None) -> list[dict]:
    r"""Run every cell of a sweep file; rows of the grid keys and the cell's figures, in order.

    Examples
    --------
    >>> import tempfile, os
    >>> text = ('kind = "phong"\n[grid]\nmaterials = ["R1"]\nviews = ["near"]\n'
    ...         'placements = ["error"]\ninterpolations = ["monotone"]\nentries = [32, 64]\n'
    ...         'resolution = 12\n')
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = open(os.path.join(d, "s.toml"), "w").write(text)
    ...     rows = run_sweep(os.path.join(d, "s.toml"), scheduler="serial", progress=False)
    >>> [(r["entries"], r["rms"] < 0.05) for r in rows]
    [(32, True), (64, True)]
    """
    kind, cells = load_sweep(path)
    figures = run_tasks(
        kind.run_cell, cells, scheduler=scheduler, client=client, progress=progress, desc="sweep"
    )
    return [{**cell, **found} for cell, found in zip(cells, figures, strict=True)]


def sweep_csv(rows: list[dict], out=None) -> str:
    """The rows as CSV text (floats at full precision); written atomically to ``out`` if given.

    Examples
    --------
    >>> print(sweep_csv([{"entries": 25, "rms": 0.5}]), end="")
    entries,rms
    25,0.5
    """
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: repr(v) if isinstance(v, float) else v for k, v in row.items()})
    text = buffer.getvalue()
    if out is not None:
        write_text_atomic(out, text)
    return text
