"""ICC display profiles: built by ArgyllCMS's ``colprof`` from a ``.ti3``, checked with littlecms.

"Profiling is done as the software measures and characterizes the current state of the display after
calibration" (§6, Herbert et al.). specref writes the measurements (``.ti3``,
:mod:`reference.display.cgats`) and leaves the profile to the tools users have:
:func:`build_icc_profile` runs ``colprof`` (Debian package ``argyll``) for a shaper/matrix profile,
and :func:`check_icc_profile` converts the measured device values through it with littlecms's
``transicc`` (Debian package ``liblcms2-utils``) and compares them with the measurements in
CIEDE2000 (both in the D50 profile connection space, the measurements adapted from their white with
Bradford, as ICC v2 display profiles are).

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004, §6.
- ICC.1:2010, the ICC profile format; ArgyllCMS colprof; Little CMS 2.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np

from reference.display.cgats import read_ti3
from reference.errors import SpecrefError, require

__all__ = [
    "INSTALL_HINT",
    "build_icc_profile",
    "check_icc_profile",
    "icc_tools_missing",
    "require_icc_tools",
]

#: How to get the tools (what CI's ``.ci/run`` does).
INSTALL_HINT = "install them with: apt-get install -y argyll liblcms2-utils"


def icc_tools_missing() -> list[str]:
    """The ICC tools (``colprof``, ``transicc``) that are not on PATH.

    Examples
    --------
    >>> isinstance(icc_tools_missing(), list)
    True
    """
    return [tool for tool in ("colprof", "transicc") if shutil.which(tool) is None]


def require_icc_tools() -> None:
    """Refuse, in one line, to go on when an ICC tool is missing (before anything is written).

    Examples
    --------
    >>> require_icc_tools() if not icc_tools_missing() else None
    """
    for tool in icc_tools_missing():
        _require_tool(tool)


def _require_tool(tool: str) -> str:
    path = shutil.which(tool)
    require(path is not None, f"{tool}: not found on PATH; {INSTALL_HINT}")
    return path


def build_icc_profile(ti3_path, description: str | None = None) -> Path:
    """Build a shaper/matrix ICC display profile from a ``.ti3`` with ArgyllCMS ``colprof``.

    Parameters
    ----------
    ti3_path : str or Path
        Measurements (:func:`reference.display.cgats.write_ti3`); the profile is written beside it
        with the suffix ``.icc``.
    description : str, optional
        The profile's description tag (default: the file's stem).

    Returns
    -------
    Path

    Raises
    ------
    SpecrefError
        ``colprof`` missing (with the install hint) or failing (its last message line).

    Examples
    --------
    >>> build_icc_profile("/nonexistent/d65.ti3")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent/d65.ti3: file not found
    """
    ti3_path = Path(ti3_path)
    require(ti3_path.exists(), f"{ti3_path}: file not found")
    require(ti3_path.suffix == ".ti3", f"{ti3_path}: colprof reads a .ti3 file")
    colprof = _require_tool("colprof")
    stem = ti3_path.with_suffix("")
    # Erratum E55: a shaper/matrix profile, not the paper's LUT-type profile with the calibration
    command = [colprof, "-qm", "-as", "-D", description or stem.name, str(stem)]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    icc = ti3_path.with_suffix(".icc")
    if done.returncode != 0 or not icc.exists():
        lines = (done.stderr or done.stdout).strip().splitlines() or ["no output"]
        raise SpecrefError(f"{ti3_path}: colprof failed: {lines[-1]}")
    return icc


def check_icc_profile(icc_path, ti3_path) -> dict:
    """ΔE00 between a profile's prediction (littlecms ``transicc``) and the measurements.

    Parameters
    ----------
    icc_path : str or Path
        A display profile.
    ti3_path : str or Path
        The measurements: device RGB and XYZ (Y = 100 at white).

    Returns
    -------
    dict
        ``delta_E00`` (n,), ``mean``, ``max``.

    Raises
    ------
    SpecrefError
        ``transicc`` missing (with the install hint) or failing.

    Examples
    --------
    >>> check_icc_profile("/nonexistent/d65.icc", "/nonexistent/d65.ti3")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent/d65.icc: file not found
    """
    import colour

    require(Path(icc_path).exists(), f"{icc_path}: file not found")
    RGB, XYZ = read_ti3(ti3_path)
    transicc = _require_tool("transicc")
    lines = "\n".join(" ".join(f"{255.0 * v:.6f}" for v in row) for row in RGB) + "\n"
    done = subprocess.run(
        [transicc, "-i", str(icc_path), "-o", "*Lab", "-t", "1", "-n"],
        input=lines,
        capture_output=True,
        text=True,
        check=False,
    )
    values = []
    for line in done.stdout.splitlines():
        parts = line.split()
        try:
            numbers = [float(p) for p in parts]
        except ValueError:
            continue
        if len(numbers) == 3:
            values.append(numbers)
    if done.returncode != 0 or len(values) != len(RGB):
        raise SpecrefError(f"{icc_path}: transicc failed ({done.stderr.strip()[:120]})")
    predicted = np.array(values)
    # the measurements in the D50 connection space: relative to their white, Bradford-adapted
    white = XYZ[int(np.argmax(RGB.sum(axis=1)))] / 100.0
    D50 = colour.xy_to_XYZ(colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D50"])
    adapted = colour.adaptation.chromatic_adaptation_VonKries(
        XYZ / 100.0 / white[1], white / white[1], D50, transform="Bradford"
    )
    measured = colour.XYZ_to_Lab(adapted, colour.XYZ_to_xy(D50))
    dE = colour.delta_E(measured, predicted, method="CIE 2000")
    return {"delta_E00": dE, "mean": float(dE.mean()), "max": float(dE.max())}
