"""CGATS text files as ArgyllCMS writes them: calibrations (``.cal``) and measurements (``.ti3``).

A CGATS.17 file is a type line (``CAL``, ``CTI3``), keyword lines (``DESCRIPTOR "..."``, each
non-standard keyword declared with ``KEYWORD "NAME"``), a data format (field names between
``BEGIN_DATA_FORMAT`` and ``END_DATA_FORMAT``) and rows of numbers between ``BEGIN_DATA`` and
``END_DATA``, ``NUMBER_OF_SETS`` of them. ArgyllCMS's ``dispcal`` writes a display calibration as
a ``CAL`` table with the fields ``RGB_I RGB_R RGB_G RGB_B`` (input level and the three channels'
outputs, all in [0, 1]); ``dispread`` writes measurements as a ``CTI3`` table with ``SAMPLE_ID
RGB_R RGB_G RGB_B XYZ_X XYZ_Y XYZ_Z`` (RGB in 0-100, XYZ normalised to Y = 100 of white, the
absolute white in ``LUMINANCE_XYZ_CDM2``), which ``colprof`` turns into an ICC profile.

References
----------
- ISO 28178:2009 / CGATS.17, exchange format for colour and process control data.
- ArgyllCMS file formats: https://www.argyllcms.com/doc/cal_format.html and ti3_format.html.
"""

from __future__ import annotations

import datetime as _dt
import shlex
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require
from reference.files import write_text_atomic

__all__ = [
    "read_cal",
    "read_cgats",
    "read_ti3",
    "write_cal",
    "write_cgats",
    "write_ti3",
]

_STANDARD = {"DESCRIPTOR", "ORIGINATOR", "CREATED", "NUMBER_OF_FIELDS", "NUMBER_OF_SETS"}
CAL_FIELDS = ["RGB_I", "RGB_R", "RGB_G", "RGB_B"]
TI3_FIELDS = ["SAMPLE_ID", "RGB_R", "RGB_G", "RGB_B", "XYZ_X", "XYZ_Y", "XYZ_Z"]


def write_cgats(path, file_type: str, keywords: dict, fields: list[str], rows) -> Path:
    """Write one CGATS table atomically.

    Parameters
    ----------
    path : str or Path
    file_type : str
        The first line, e.g. ``"CAL"`` or ``"CTI3"``.
    keywords : dict
        ``{name: value}``; strings are quoted, non-standard names are declared with ``KEYWORD``.
    fields : list of str
    rows : array_like, shape (n, len(fields))

    Returns
    -------
    Path

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = write_cgats(os.path.join(d, "t.txt"), "CAL", {"COLOR_REP": "RGB"}, ["A", "B"],
    ...                     [[0, 0.5], [1, 1.0]])
    ...     read_cgats(p)[2:]
    (['A', 'B'], array([[0. , 0.5],
           [1. , 1. ]]))
    """
    rows = np.asarray(rows, dtype=np.float64)
    require(
        rows.ndim == 2 and rows.shape[1] == len(fields),
        f"{path}: CGATS rows must have {len(fields)} columns, got shape {rows.shape}",
    )
    lines = [f"{file_type:<7}", ""]
    keywords = {"CREATED": _dt.datetime.now(_dt.UTC).strftime("%a %b %d %H:%M:%S %Y")} | keywords
    for name, value in keywords.items():
        if name not in _STANDARD:
            lines.append(f'KEYWORD "{name}"')
        lines.append(f'{name} "{value}"' if isinstance(value, str) else f"{name} {value}")
    lines += ["", f"NUMBER_OF_FIELDS {len(fields)}", "BEGIN_DATA_FORMAT", " ".join(fields)]
    lines += ["END_DATA_FORMAT", "", f"NUMBER_OF_SETS {len(rows)}", "BEGIN_DATA"]
    integer = [f == "SAMPLE_ID" or f == "RGB_I_INDEX" for f in fields]
    for row in rows:
        cells = [
            f"{int(v)}" if is_int else f"{v:.10g}" for v, is_int in zip(row, integer, strict=True)
        ]
        lines.append(" ".join(cells))
    lines += ["END_DATA", ""]
    return write_text_atomic(path, "\n".join(lines))


def read_cgats(path) -> tuple[str, dict, list[str], np.ndarray]:
    """Read the first table of a CGATS file: type, keywords, fields, rows.

    Raises
    ------
    SpecrefError
        A missing file, no data format or data, a row whose length differs from the fields, or
        ``NUMBER_OF_SETS`` that does not match the rows.

    Examples
    --------
    >>> read_cgats("/nonexistent.cal")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.cal: file not found
    """
    path = Path(path)
    try:
        text = path.read_text(errors="replace")
    except FileNotFoundError:
        raise SpecrefError(f"{path}: file not found") from None
    except OSError as error:
        raise SpecrefError(f"{path}: cannot read ({error})") from None
    lines = text.splitlines()
    require(lines, f"{path}: empty file, not CGATS")
    file_type = lines[0].strip()
    keywords: dict = {}
    fields: list[str] = []
    rows: list[list[str]] = []
    state = "header"
    for number, raw in enumerate(lines[1:], start=2):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        if state == "header":
            if line == "BEGIN_DATA_FORMAT":
                state = "format"
            elif line == "BEGIN_DATA":
                state = "data"
            else:
                parts = shlex.split(line)
                if parts[0] != "KEYWORD" and len(parts) >= 2:
                    keywords[parts[0]] = parts[1]
        elif state == "format":
            if line == "END_DATA_FORMAT":
                state = "header"
            else:
                fields += line.split()
        elif state == "data":
            if line == "END_DATA":
                break
            rows.append((number, line.split()))
    require(fields, f"{path}: no BEGIN_DATA_FORMAT ... END_DATA_FORMAT, not a CGATS table")
    require(rows, f"{path}: no data rows between BEGIN_DATA and END_DATA")
    for number, cells in rows:
        require(
            len(cells) == len(fields),
            f"{path}: line {number}: {len(cells)} values for {len(fields)} fields "
            f"({' '.join(fields)}): the columns differ in length",
        )
    try:
        data = np.array([[float(c) for c in cells] for _, cells in rows])
    except ValueError as error:
        raise SpecrefError(f"{path}: data rows must be numbers ({error})") from None
    if "NUMBER_OF_SETS" in keywords:
        require(
            int(float(keywords["NUMBER_OF_SETS"])) == len(data),
            f"{path}: NUMBER_OF_SETS is {keywords['NUMBER_OF_SETS']} but there are "
            f"{len(data)} rows",
        )
    return file_type, keywords, fields, data


def write_cal(path, lut, description: str = "specref display calibration") -> Path:
    """Write per-channel look-up tables as an ArgyllCMS ``.cal`` file.

    Parameters
    ----------
    path : str or Path
    lut : array_like, shape (3, n)
        R, G, B outputs for the inputs ``i/(n − 1)``, in [0, 1].
    description : str

    Returns
    -------
    Path

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     lut = np.tile(np.linspace(0, 1, 4) ** 0.5, (3, 1))
    ...     read_cal(write_cal(os.path.join(d, "x.cal"), lut)).round(3)
    array([[0.   , 0.577, 0.816, 1.   ],
           [0.   , 0.577, 0.816, 1.   ],
           [0.   , 0.577, 0.816, 1.   ]])
    """
    lut = np.asarray(lut, dtype=np.float64)
    require(lut.ndim == 2 and lut.shape[0] == 3, f"{path}: lut must have shape (3, n)")
    levels = np.linspace(0.0, 1.0, lut.shape[1])
    keywords = {
        "DESCRIPTOR": description,
        "ORIGINATOR": "specref",
        "DEVICE_CLASS": "DISPLAY",
        "COLOR_REP": "RGB",
        "VIDEO_LUT_CALIBRATION_POSSIBLE": "YES",
    }
    return write_cgats(path, "CAL", keywords, CAL_FIELDS, np.column_stack([levels, lut.T]))


def read_cal(path) -> np.ndarray:
    r"""Read an ArgyllCMS ``.cal`` file: the tables, shape (3, n).

    Raises
    ------
    SpecrefError
        Not a ``CAL`` table, missing channels, channels of different lengths, values outside
        [0, 1], inputs that do not increase.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = os.path.join(d, "bad.cal")
    ...     _ = open(p, "w").write("CAL\nBEGIN_DATA_FORMAT\nRGB_I RGB_R RGB_G RGB_B\n"
    ...         "END_DATA_FORMAT\nBEGIN_DATA\n0 0 0 0\n1 1 1\nEND_DATA\n")
    ...     read_cal(p)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: ...bad.cal: line 7: 3 values for 4 fields ...differ in length
    """
    file_type, _, fields, data = read_cgats(path)
    require(file_type.startswith("CAL"), f"{path}: not a .cal file (type {file_type!r})")
    missing = [f for f in CAL_FIELDS if f not in fields]
    require(not missing, f"{path}: missing field {missing[0] if missing else ''} of a .cal")
    columns = [fields.index(f) for f in CAL_FIELDS]
    table = data[:, columns]
    require(((table >= 0) & (table <= 1)).all(), f"{path}: .cal values must be in [0, 1]")
    require((np.diff(table[:, 0]) > 0).all(), f"{path}: RGB_I must increase")
    return table[:, 1:].T.copy()


def write_ti3(path, RGB, XYZ, white_XYZ, description: str = "specref verification") -> Path:
    """Write display measurements as an ArgyllCMS ``.ti3`` file (``colprof`` reads it).

    Parameters
    ----------
    path : str or Path
    RGB : array_like, shape (n, 3)
        Device values in [0, 1] (written as 0-100).
    XYZ : array_like, shape (n, 3)
        Measured XYZ, cd/m² (written normalised to Y = 100 of ``white_XYZ``).
    white_XYZ : array_like, shape (3,)
        The display's white, cd/m² (``LUMINANCE_XYZ_CDM2``).

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = write_ti3(os.path.join(d, "v.ti3"), [[1, 1, 1], [0, 0, 0]],
    ...                   [[95.0, 100.0, 108.0], [0.5, 0.5, 0.6]], [95.0, 100.0, 108.0])
    ...     read_ti3(p)[1].round(2)
    array([[ 95. , 100. , 108. ],
           [  0.5,   0.5,   0.6]])
    """
    RGB, XYZ = np.asarray(RGB, float), np.asarray(XYZ, float)
    white = np.asarray(white_XYZ, float)
    ids = np.arange(1, len(RGB) + 1)
    keywords = {
        "DESCRIPTOR": description,
        "ORIGINATOR": "specref",
        "DEVICE_CLASS": "DISPLAY",
        "COLOR_REP": "RGB_XYZ",
        "LUMINANCE_XYZ_CDM2": f"{white[0]:.6f} {white[1]:.6f} {white[2]:.6f}",
        "NORMALIZED_TO_Y_100": "YES",
    }
    rows = np.column_stack([ids, 100.0 * RGB, 100.0 * XYZ / white[1]])
    return write_cgats(path, "CTI3", keywords, TI3_FIELDS, rows)


def read_ti3(path) -> tuple[np.ndarray, np.ndarray]:
    """Read a display ``.ti3``: device RGB in [0, 1] and XYZ normalised to Y = 100, (n, 3) each.

    Examples
    --------
    >>> read_ti3("/nonexistent.ti3")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.ti3: file not found
    """
    file_type, _, fields, data = read_cgats(path)
    require(file_type.startswith("CTI3"), f"{path}: not a .ti3 file (type {file_type!r})")
    missing = [f for f in TI3_FIELDS[1:] if f not in fields]
    require(not missing, f"{path}: missing field {missing[0] if missing else ''} of a .ti3")
    RGB = data[:, [fields.index(f) for f in TI3_FIELDS[1:4]]] / 100.0
    XYZ = data[:, [fields.index(f) for f in TI3_FIELDS[4:]]]
    return RGB, XYZ
