"""User-defined sweeps (``specref sweep FILE.toml``): a grid of methods × materials, as Dask tasks.

A sweep file names a kind of study (:data:`SWEEP_KINDS`) and the grid to run it over; every cell
of the grid is one task, run through :func:`reference.tasks.run_tasks` (a local Dask cluster, a
remote scheduler, or serially), and the output is a tidy table: one row per cell, one column per
grid key and per figure, written as CSV. Work that cells share (the ``phong`` kind's exact render
of a material and view, the ``impastor`` kind's brute force of a painting, light and α, the
``shrm`` kind's brute-force render of a sphere) is a task of its own that those cells depend on
(:class:`reference.tasks.Shared`): built once, where the cells run.

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
import math
from dataclasses import dataclass
from pathlib import Path

from reference.errors import SpecrefError, format_allowed, require, require_positive_int
from reference.files import write_text_atomic
from reference.registry import Registry
from reference.scene.loader import read_toml_file
from reference.tasks import Shared, run_tasks

__all__ = ["SWEEP_KINDS", "SweepKind", "load_sweep", "run_sweep", "sweep_csv"]


@dataclass(frozen=True)
class SweepKind:
    """A kind of sweep: its grid keys and their allowed values, and the function of one cell.

    ``lists`` are the keys that take a list (the grid's axes); ``scalars`` take one value and
    are passed to every cell; ``run_cell(cell: dict) -> dict`` returns the cell's figures, or
    ``run_cell(cell, built)`` when the kind names the work its cells share (``shared``:
    ``shared.build(shared.key(cell))``, built once per key).
    """

    name: str
    lists: dict
    scalars: dict
    run_cell: object
    about: str = ""
    shared: Shared | None = None


def _phong_materials():
    from phong_table.scenes import SCENES

    return SCENES.names()


def phong_state_key(cell: dict) -> tuple:
    """What a ``phong`` cell shares with others: its (material, view, resolution).

    Examples
    --------
    >>> phong_state_key({"materials": "R1", "views": "near", "entries": 64, "resolution": 16})
    ('R1', 'near', 16)
    """
    return (cell["materials"], cell["views"], cell["resolution"])


def phong_state(key: tuple):
    """The exact render of a material and view that the cells of a ``phong`` sweep share.

    ``key`` is :func:`phong_state_key`'s; the result is
    ``validation.studies.phong.view_state``'s (the exact spectral render and what the tables
    are measured on).

    Examples
    --------
    >>> state = phong_state(("R1", "near", 8))
    >>> cell = {"materials": "R1", "views": "near", "placements": "error",
    ...         "interpolations": "linear", "entries": 32, "resolution": 8}
    >>> phong_cell(cell, state)["rms"] < 0.05
    True
    """
    from phong_table.materialfile import load_material_file
    from phong_table.scenes import SCENES
    from validation.studies.phong import view_state

    material, view, resolution = key
    known = material in SCENES
    model = SCENES.lookup(material).build() if known else load_material_file(material)
    return view_state(model, view, resolution)


#: A cell called alone remembers the last exact renders of its process.
_phong_state = functools.lru_cache(maxsize=8)(phong_state)


def phong_cell(cell: dict, state=None) -> dict:
    """One cell of a ``phong`` sweep: the table error of one method on one material and view.

    ``state`` is the cell's :func:`phong_state` (built here when not given).

    Examples
    --------
    >>> row = phong_cell({"materials": "R1", "views": "near", "placements": "error",
    ...                   "interpolations": "monotone", "entries": 64, "resolution": 16})
    >>> row["rms"] < 1e-2, row["overshoot"]
    (True, 0.0)
    """
    from validation.studies.phong import table_error_row

    if state is None:
        state = _phong_state(phong_state_key(cell))
    row = table_error_row(state, cell["placements"], cell["interpolations"], cell["entries"])
    return {k: row[k] for k in ("segments", "rms_display", "rms_linear", "rms", "overshoot")}


def _check_phong_material(base: Path):
    def check(value, where: str) -> str:
        # loaded once here, so that a missing or bad material file names the sweep file (a
        # missing one was "R99: file not found" from the first cell, relative to the current folder)
        from phong_table.materialfile import load_material_file

        keys = _phong_materials()
        require(
            isinstance(value, str),
            f"{where}: must be Phong scene keys ({', '.join(keys)}) or material files, "
            f"got {value!r}",
        )
        if value in keys:
            return value
        path = Path(value) if Path(value).is_absolute() else base / value
        require(
            path.is_file(),
            f"{where}: {value!r}: neither a Phong scene key ({', '.join(keys)}) nor a material "
            f"file beside the sweep file",
        )
        try:
            load_material_file(path)
        except SpecrefError as error:
            raise SpecrefError(f"{where}: {error}") from None
        return str(path)

    return check


def _phong_kind() -> SweepKind:
    from phong_table.interpolation import INTERPOLATION_METHODS
    from phong_table.placement import PLACEMENT_METHODS
    from phong_table.scenes import VIEWS

    return SweepKind(
        "phong",
        lists={
            "materials": _check_phong_material,  # bound to the sweep file's folder when loaded
            "views": list(VIEWS),
            "placements": PLACEMENT_METHODS.names(),
            "interpolations": INTERPOLATION_METHODS.names(),
            "entries": int,
        },
        scalars={"resolution": int},
        run_cell=phong_cell,
        about="table error of placements × interpolations × entries on materials × views",
        shared=Shared(phong_state_key, phong_state),
    )


def impastor_reference_key(cell: dict) -> tuple:
    """What an ``impastor`` cell shares with others: (seed, light, α, points, painting size).

    Examples
    --------
    >>> impastor_reference_key({"seeds": 3, "lights": "fluorescent", "n_lights": 8,
    ...                         "n_samples": 8, "alphas": 0.1, "points": 2, "painting_size": 16})
    (3, 'fluorescent', 0.1, 2, 16)
    """
    return tuple(cell[k] for k in ("seeds", "lights", "alphas", "points", "painting_size"))


def impastor_reference(key: tuple) -> dict:
    """The brute-force renders that the ``impastor`` cells of every N and K share.

    ``key`` is :func:`impastor_reference_key`'s; the result maps α to
    ``validation.studies.impastor_hybrid.hybrid_brute_force``'s (reference, check) pair.

    Examples
    --------
    >>> built = impastor_reference((3, "fluorescent", 0.1, 2, 16))
    >>> list(built), [a.shape for a in built[0.1]]
    ([0.1], [(4,), (4,)])
    """
    from validation.studies.impastor_hybrid import hybrid_brute_force

    seed, light, alpha, points, painting_size = key
    return {alpha: hybrid_brute_force(seed, light, alpha, points, painting_size)}


def impastor_cell(cell: dict, brute_force=None) -> dict:
    """One cell of an ``impastor`` sweep: median cut, FIS and the hybrid against brute force.

    Relative RMS errors of the three specular lighting methods of the painting (§3.5, Ferwerda)
    at one α, and the hybrid's ratio to the better of the other two
    (``validation.studies.impastor_hybrid.hybrid_case_ratios``). ``brute_force`` is the cell's
    :func:`impastor_reference` (rendered here when not given).

    Examples
    --------
    >>> row = impastor_cell({"seeds": 3, "lights": "fluorescent", "n_lights": 8, "n_samples": 8,
    ...                      "alphas": 0.1, "points": 2, "painting_size": 16})
    >>> sorted(row), row["ratio"] > 0
    (['fis', 'hybrid', 'median_cut', 'ratio', 'reference_error'], True)
    """
    from validation.studies.impastor_hybrid import HybridCase, hybrid_case_ratios

    case = HybridCase(cell["seeds"], cell["lights"], cell["n_lights"], cell["n_samples"])
    found = hybrid_case_ratios(
        case, (cell["alphas"],), cell["points"], cell["painting_size"], brute_force=brute_force
    )
    return {k: found[k][0] for k in ("median_cut", "fis", "hybrid", "reference_error", "ratio")}


def _check_painting_light(value, where: str) -> str:
    # the light names of validation.studies.impastor_hybrid.HybridCase
    from validation.studies.impastor_hybrid import ENVIRONMENTS

    allowed = "fluorescent, incandescent, lamp_panel:SEED, env:MAP:AZIMUTH_DEG"
    require(isinstance(value, str), f"{where}: must be strings ({allowed}), got {value!r}")
    kind, _, rest = value.partition(":")
    if kind in ("fluorescent", "incandescent") and not rest:
        return value
    if kind == "lamp_panel" and rest.isdigit():
        return value
    name, _, azimuth = rest.rpartition(":")
    try:
        float(azimuth)
    except ValueError:
        azimuth = ""
    require(
        kind == "env" and name in ENVIRONMENTS and azimuth,
        f"{where}: unknown light {value!r}; allowed: {allowed} (MAP one of "
        f"{', '.join(ENVIRONMENTS)})",
    )
    # NaN turned the ceiling into a NaN image, refused later naming only the "plane light"
    require(
        abs(float(azimuth)) <= 360.0,
        f"{where}: {value!r}: AZIMUTH_DEG must be a number of degrees in [-360, 360], "
        f"got {azimuth}",
    )
    return value


def _impastor_kind() -> SweepKind:
    return SweepKind(
        "impastor",
        lists={
            "seeds": int,
            "lights": _check_painting_light,
            "n_lights": int,
            "n_samples": int,
            "alphas": float,
        },
        scalars={"points": int, "painting_size": int},
        run_cell=impastor_cell,
        about="median cut, FIS and the hybrid against brute force: paintings × lights × N × K × α",
        shared=Shared(impastor_reference_key, impastor_reference),
    )


def shrm_oracle_key(cell: dict) -> tuple:
    r"""What an ``shrm`` cell shares with others: its (environment, material lines, size).

    Examples
    --------
    >>> shrm_oracle_key({"environments": "sky.exr", "materials": {"brdf": "ggx", "alpha": 0.3},
    ...                  "tolerances": 0.01, "size": 4})
    ('sky.exr', 'type = "isotropic_brdf"\nbrdf = "ggx"\nalpha = 0.3', 4)
    """
    return (cell["environments"], _material_lines(cell["materials"]), cell["size"])


def _sphere_scene(key: tuple):
    from reference.scene.loader import loads_scene
    from validation.studies.env_accuracy import sphere_scene_toml

    environment, material, size = key
    return loads_scene(sphere_scene_toml(environment, material, size))


def shrm_oracle(key: tuple):
    """The brute-force render (``--oracle``) that the cells of an ``shrm`` sweep share.

    ``key`` is :func:`shrm_oracle_key`'s; the result is the ``RenderResult`` of the sphere with
    ``environment = "bruteforce"``, which does not depend on the cell's tolerance.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from reference.images.formats import write_exr
    >>> sky = write_exr(pathlib.Path(tempfile.mkdtemp()) / "sky.exr", np.ones((16, 32, 3)))
    >>> lines = _material_lines({"brdf": "ggx", "alpha": 0.3, "F_0": 1.0, "rho_d": 0.0})
    >>> shrm_oracle((str(sky), lines, 2)).XYZ.shape[:2]
    (2, 2)
    """
    import shrm  # noqa: F401  (registers the environment shaders)
    from reference.scene.render import render_scene

    return render_scene(_sphere_scene(key), options={"environment": "bruteforce"})


def shrm_cell(cell: dict, oracle=None) -> dict:
    """One cell of an ``shrm`` sweep: a sphere's default render against ``--oracle``, in Y.

    The sphere (``validation.studies.env_accuracy.sphere_scene_toml``) of one ``isotropic_brdf``
    material under one environment map, rendered with ``shrm_tol`` = the cell's tolerance and
    by brute force; mean and largest relative error of Y over the lit pixels, and what the
    shader chose and promised (``RenderResult.records["shrm"]``: the settings, and the bound
    relative to a lower bound of the peak). ``oracle`` is the cell's :func:`shrm_oracle` (rendered
    here when not given).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from reference.images.formats import write_exr
    >>> sky = write_exr(pathlib.Path(tempfile.mkdtemp()) / "sky.exr", np.ones((16, 32, 3)))
    >>> row = shrm_cell({"environments": str(sky), "tolerances": 0.01, "size": 4,
    ...                  "materials": {"brdf": "ggx", "alpha": 0.3, "F_0": 1.0, "rho_d": 0.0}})
    >>> row["max"] < 0.01, row["meets_tolerance"]
    (True, True)
    >>> row["promised_of_peak"] <= 0.01 and row["check_of_peak"] <= 0.01   # bound, spot check
    True
    """
    from validation.studies.env_accuracy import render_against_oracle

    key = shrm_oracle_key(cell)
    oracle = shrm_oracle(key) if oracle is None else oracle
    found = render_against_oracle(_sphere_scene(key), {"shrm_tol": cell["tolerances"]}, oracle)
    chose = found["records"].get("shrm", {})
    promised = (
        chose["bound_Y"] / chose["peak_lower_bound"] if chose.get("peak_lower_bound") else None
    )
    return {
        "mean": found["mean"],
        "max": found["max"],
        **{k: chose.get(k) for k in ("F", "P", "size", "env_rows", "residual_texels")},
        "promised_of_peak": promised,
        "check_of_peak": chose.get("check_error"),
        "meets_tolerance": chose.get("meets_tolerance"),
    }


def _material_lines(material: dict) -> str:
    # an inline table of the sweep file as the TOML lines of an isotropic_brdf material
    import json

    lines = ['type = "isotropic_brdf"']
    lines += [f"{key} = {json.dumps(value)}" for key, value in material.items()]
    return "\n".join(lines)


def _check_material(value, where: str) -> dict:
    # loaded once here, so that a bad material is one line naming the sweep file
    from reference.scene.loader import loads_scene
    from validation.studies.env_accuracy import sphere_scene_toml

    require(
        isinstance(value, dict) and "brdf" in value,
        f"{where}: each material is an inline table with brdf = NAME and its parameters, "
        f"got {value!r}",
    )
    for key, number in value.items():
        # NaN and infinities have no JSON spelling: refused here, not as malformed TOML
        require(
            not isinstance(number, float) or math.isfinite(number),
            f"{where}.{key}: must be finite, got {number}",
        )
    import shrm  # noqa: F401  (registers isotropic_brdf)

    scene_text = sphere_scene_toml("unused.hdr", _material_lines(value), 2).rsplit("[[lights]]")[0]
    try:
        loads_scene(scene_text, where)
    except SpecrefError as error:  # the sphere scene's material "m" is the sweep's entry
        message = str(error).replace(f"{where}: materials.m.", f"{where}.")
        raise SpecrefError(message.replace(f"{where}: materials.m: ", f"{where}: ")) from None
    return value


def _check_environment(base: Path):
    def check(value, where: str) -> str:
        require(isinstance(value, str), f"{where}: must be file names, got {value!r}")
        path = Path(value) if Path(value).is_absolute() else base / value
        require(path.is_file(), f"{where}: {value}: file not found")
        _check_environment_map(str(path), where)
        return str(path)

    return check


def _check_environment_map(path: str, where: str) -> None:
    # read once here as the cells' scenes read it, so that a map they would refuse (not 2:1,
    # not finite, channels of no colour) is one line naming the sweep file, before any cell
    from reference.scene.loader import loads_scene
    from validation.studies.env_accuracy import sphere_scene_toml

    try:
        loads_scene(sphere_scene_toml(path, size=2), where)
    except SpecrefError as error:
        raise SpecrefError(str(error).replace(f"{where}: lights[0].file: ", f"{where}: ")) from None


def _shrm_kind() -> SweepKind:
    return SweepKind(
        "shrm",
        lists={
            "environments": _check_environment,  # bound to the sweep file's folder when loaded
            "materials": _check_material,
            "tolerances": float,
        },
        scalars={"size": int},
        run_cell=shrm_cell,
        about="isotropic BRDF spheres under environment maps, default render against --oracle",
        shared=Shared(shrm_oracle_key, shrm_oracle),
    )


#: The kinds of sweep ``specref sweep`` runs, by the sweep file's ``kind``.
SWEEP_KINDS = Registry("sweep kind", SweepKind)
SWEEP_KINDS.register(_phong_kind(), "phong")
SWEEP_KINDS.register(_impastor_kind(), "impastor")
SWEEP_KINDS.register(_shrm_kind(), "shrm")


def _check_values(file: str, key: str, values, allowed) -> list:
    require(
        isinstance(values, list) and values,
        f"{file}: grid.{key}: must be a non-empty list, got {values!r}",
    )
    checked = []
    for index, value in enumerate(values):
        if callable(allowed) and allowed not in (int, float):
            checked.append(allowed(value, f"{file}: grid.{key}[{index}]"))
            continue
        checked.append(value)
        if allowed is int:
            require_positive_int(value, f"{file}: grid.{key}", 1 << 20)
        elif allowed is float:
            require(
                isinstance(value, int | float)
                and not isinstance(value, bool)
                and 0.0 < value <= 1.0,
                f"{file}: grid.{key}: must be numbers in (0, 1], got {value!r}",
            )
        elif isinstance(allowed, list):
            require(
                value in allowed,
                f"{file}: grid.{key}: unknown {value!r}; allowed: {format_allowed(allowed)}",
            )
        else:
            require(isinstance(value, str), f"{file}: grid.{key}: must be strings, got {value!r}")
    return checked


#: Cells a sweep runs without ``--yes`` (``large=True``): a typing slip in a list should not
#: start days of work; and the most it runs at all (the list of cells is held in memory).
MAX_SWEEP_CELLS = 10_000
HARD_MAX_SWEEP_CELLS = 1_000_000


def load_sweep(path, large: bool = False) -> tuple[SweepKind, list[dict]]:
    """Read a sweep file: its kind and the grid's cells (every combination, in file order).

    The number of cells is checked before any is made: at most :data:`MAX_SWEEP_CELLS`, or
    with ``large`` :data:`HARD_MAX_SWEEP_CELLS`.

    Raises
    ------
    SpecrefError
        Unreadable file, malformed TOML, unknown kind or key, an empty or invalid grid, too many
        cells (one line naming the file and the key).

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
    lists = {  # checks of file names, relative to the sweep file's folder
        key: allowed(path.parent)
        if allowed in (_check_environment, _check_phong_material)
        else allowed
        for key, allowed in kind.lists.items()
    }
    axes = {key: _check_values(file, key, grid[key], allowed) for key, allowed in lists.items()}
    scalars = {}
    for key in kind.scalars:
        scalars[key] = require_positive_int(grid[key], f"{file}: grid.{key}", 4096)
    count = math.prod(len(values) for values in axes.values())
    factors = " × ".join(f"{len(v)} {k}" for k, v in axes.items())
    limit = HARD_MAX_SWEEP_CELLS if large else MAX_SWEEP_CELLS
    require(
        count <= limit,
        f"{file}: grid: {count:,} cells ({factors}); at most {limit:,}"
        + ("" if large else f" without --yes, {HARD_MAX_SWEEP_CELLS:,} with it"),
    )
    cells = [
        {**dict(zip(axes, combo, strict=True)), **scalars}
        for combo in itertools.product(*axes.values())
    ]
    return kind, cells


def run_sweep(
    path, scheduler: str | None = None, progress: bool = True, client=None, large: bool = False
) -> list[dict]:
    r"""Run every cell of a sweep file; rows of the grid keys and the cell's figures, in order.

    ``large``: allow more than :data:`MAX_SWEEP_CELLS` cells (:func:`load_sweep`).

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
    kind, cells = load_sweep(path, large)
    figures = run_tasks(
        kind.run_cell,
        cells,
        scheduler=scheduler,
        client=client,
        progress=progress,
        desc="sweep",
        shared=kind.shared,
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
