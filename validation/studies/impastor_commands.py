"""Library side of ``specref impastor``: checked inputs and formatted tables."""

from __future__ import annotations

import json

import numpy as np

from impastor.multispectral import MIN_CHANNELS, MULTISPECTRAL_DESIGNS
from reference.errors import require

__all__ = [
    "MAX_PATH_BYTES",
    "MAX_PATH_FRAMES",
    "format_table1",
    "render_for_cli",
    "render_path_for_cli",
    "table1_for_cli",
]

#: Frames a path may have (a 20 s animation at 30 frames per second).
MAX_PATH_FRAMES = 600
#: The animation's frames are held until the APNG is written: at most 2 GiB of them (600 frames
#: of 1024², or 40 of 4096²).
MAX_PATH_BYTES = 2 << 30


def table1_for_cli(
    design: str, n_channels: int, white_luminance: float, display_file=None, scheduler=None
):
    """Validate the CLI's arguments and compute :func:`validation.studies.impastor.table1`.

    Examples
    --------
    >>> table1_for_cli("optimized", 2, 200.0)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: --channels: channel count must be >= 3, got 2
    """
    from reference.display.model import load_display_measurements, virtual_display
    from validation.studies.impastor import table1

    MULTISPECTRAL_DESIGNS.lookup(design)
    require(
        n_channels >= MIN_CHANNELS,
        f"--channels: channel count must be >= {MIN_CHANNELS}, got {n_channels}",
    )
    display = load_display_measurements(display_file) if display_file else virtual_display()
    peak = float(display.white_XYZ[1])
    require(
        np.isfinite(white_luminance) and 0 < white_luminance <= peak,
        f"--white-luminance: the white diffuser's luminance must be in (0, {peak:.4g}] cd/m², "
        f"what the display's white reaches; got {white_luminance!r}",
    )
    return table1(design, n_channels, white_luminance, display, scheduler=scheduler)


def format_table1(result: dict) -> str:
    """Table 1 as text: six-channel simulation and screen output, ΔE00 statistics per row.

    Examples
    --------
    >>> row = {"label": "D65 (24)", "simulation": dict(mean=0.2, std=0.1, p90=0.3, max=0.4),
    ...        "screen": dict(mean=0.5, std=0.2, p90=0.8, max=1.0)}
    >>> print(format_table1({"design": "optimized", "n_channels": 6, "rows": [row],
    ...                      "lights": {"D65": {"out_of_gamut": []}}}).splitlines()[3])
    D65 (24)    0.20  0.10  0.30  0.40 |  0.50  0.20  0.80  1.00
    """
    lines = [
        f"Table 1 (Ferwerda 2015): CIEDE2000 against the 5 nm spectral truth, "
        f"{result['n_channels']}-channel {result['design']} design",
        f"{'':10} {'six-channel simulation':^24} | {'screen output':^24}",
        f"{'':10} {'mean':>5} {'std':>5} {'90th':>5} {'max':>5} | "
        f"{'mean':>5} {'std':>5} {'90th':>5} {'max':>5}",
    ]
    for row in result["rows"]:
        sim, scr = row["simulation"], row["screen"]
        left = f"{sim['mean']:5.2f} {sim['std']:5.2f} {sim['p90']:5.2f} {sim['max']:5.2f}"
        right = (
            f"{scr['mean']:5.2f} {scr['std']:5.2f} {scr['p90']:5.2f} {scr['max']:5.2f}"
            if scr
            else "  —"
        )
        lines.append(f"{row['label']:10} {left} | {right}")
    for light, info in result["lights"].items():
        names = ", ".join(info["out_of_gamut"]) or "none"
        lines.append(f"out of gamut under {light}: {len(info['out_of_gamut'])} ({names})")
    return "\n".join(lines)


#: The booth light's centre in screen coordinates (m): above and behind an observer at 0.6 m.
DEFAULT_LIGHT_POSITION = (0.0, 1.2, 0.9)


def render_for_cli(
    light: str,
    size: int,
    method: str,
    out,
    counts_out=None,
    observer=(0.0, 0.0, 0.6),
    tilt_deg: float = 0.0,
    screen_lux: float = 1000.0,
    light_position=DEFAULT_LIGHT_POSITION,
    light_luminance: float | None = None,
    progress=None,
    tolerance: float | str | None = None,
    painting=None,
    light_map=None,
) -> str:
    """Render a painting (the demo one by default) and write it as a PNG; return a one-line summary.

    ``painting`` is a painting folder or its ``painting.toml`` (``docs/impastor.md``, "Painting
    files"), read before any work; ``light_map`` an HDR panorama of a room, shown through the
    booth's ceiling (:func:`impastor.painting.booth_plane_light_from_map`).

    ``progress`` (a stream) gets a line per stage of the render with its time. With
    ``tolerance``, N, K, S and the fail-safe come from it (:mod:`impastor.settings`; ``"fixed"``:
    the cheapest settings no worse than the fixed ones); the
    settings used and the promised bound are in the summary and in the PNG's ``specref`` text
    chunk (JSON) either way.

    With ``counts_out``, the painting's XYZ also goes through the display per pixel (Eq. (1),
    Ferwerda: ``L_factor`` at the observer's angle from each screen point; the screen's diffuse
    flare under ``screen_lux`` of the booth light and its specular flare, §3.4.3, Ferwerda: the
    booth light at ``light_position`` (m, screen coordinates) of ``light_luminance`` cd/m²,
    default the booth ceiling's mean luminance, mirrored by the screen, subtracted;
    :mod:`reference.display.pipeline`) and the 11-bit counts are written as a 16-bit PNG.

    Examples
    --------
    >>> render_for_cli("D65", 16, "nearest", "x.png")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: unknown lighting method 'nearest'; allowed: fis, hybrid,
    median_cut, variance_min
    """
    from impastor.painting import PAINTING_LIGHTING_METHODS, booth_light_spectrum
    from reference.errors import require_positive_int
    from reference.images.formats import write_png

    PAINTING_LIGHTING_METHODS.lookup(method)
    size = require_positive_int(size, "--size", 4096)
    _check_before_render(tolerance, out, counts_out)
    _check_flare_options(observer, light_position, screen_lux, light_luminance)
    booth_light_spectrum(light)  # an unknown key or a bad lamp file fails before any work
    if counts_out is not None:
        geometry, lamp, light_luminance = _counts_setup(
            light, tilt_deg, observer, light_position, light_luminance
        )
    tilt = np.radians(tilt_deg)  # the display's tilt turns the painting it shows (§3.4)
    result = _render(light, size, method, tolerance, painting, progress, tilt, light_map)
    write_png(out, result["sRGB"], {"specref": json.dumps(result["settings"])})
    seconds = sum(result["seconds"].values())
    summary = f"wrote {out} ({size}×{size}, {light}, {method}, shading {seconds:.2f} s"
    summary += f"; {_describe_settings(result['settings'])})"
    if counts_out is not None:
        flare = {"screen_lux": screen_lux, "position": lamp, "luminance": light_luminance}
        summary += "; " + _write_counts(result["XYZ"], counts_out, geometry, observer, flare)
    return summary


def _render(light, size, method, tolerance, painting, progress, tilt=0.0, light_map=None) -> dict:
    """The painting (read from its folder, else the demo) at fixed or tolerance-chosen settings."""
    from impastor.painting import render_painting

    painting = _check_pose_inputs(painting, tilt, light_map)
    options = {"progress": progress, "tilt": tilt, "light_map": light_map}
    if tolerance is None:
        return render_painting(light, size, method, painting, **options)
    from impastor.settings import render_painting_to_tolerance

    return render_painting_to_tolerance(light, size, tolerance, method, painting, **options)


def _check_pose_inputs(painting, tilt: float, light_map):
    """The painting read, the tilt and the light map checked, before any work (one-line errors)."""
    from impastor.painting import booth_plane_light_from_map, check_pose

    check_pose(tilt=tilt)  # a canvas turned away from the viewer
    if light_map is not None:
        booth_plane_light_from_map(light_map, 16, 8)  # unreadable, not RGB, dark where it matters
    if painting is not None:
        from impastor.painting_files import read_painting

        painting = read_painting(painting)
    return painting


def render_path_for_cli(
    light: str,
    size: int,
    method: str,
    out,
    eye_from,
    eye_to,
    frames: int,
    painting=None,
    fps: float = 12.0,
    progress=None,
    tilt_from: float = 0.0,
    tilt_to: float = 0.0,
    light_map=None,
) -> str:
    """Render the painting from a path of poses; write an animated PNG (APNG).

    The viewer moves in a straight line from ``eye_from`` to ``eye_to`` (m, the booth's frame)
    and the canvas turns from ``tilt_from`` to ``tilt_to`` (degrees, as the display that shows it;
    :func:`impastor.painting.booth_in_canvas_frame`) over ``frames`` frames; the camera, the
    shading and the specular term follow the pose, while the horizon map (pose-independent,
    §3.5.3, Ferwerda) is computed once for all frames. Every pose is checked, and the output
    proved writable, before the first frame.

    Examples
    --------
    >>> render_path_for_cli("D65", 16, "median_cut", "x.png", (0, 0.45, 0.6), (0, -1, 0.6), 2)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: --to: (0, -1, 0.6) m is behind the canvas (its plane is y = 0,
    facing +y)
    """
    import imageio.v3 as iio

    from impastor.painting import PAINTING_LIGHTING_METHODS, check_eye, check_pose
    from reference.errors import SpecrefError, require, require_positive_int
    from reference.files import atomic_path, check_output_file

    PAINTING_LIGHTING_METHODS.lookup(method)
    size = require_positive_int(size, "--size", 4096)
    frames = require_positive_int(frames, "--frames", MAX_PATH_FRAMES)
    held = frames * size * size * 3  # the frames are held until the APNG is written
    require(
        held <= MAX_PATH_BYTES,
        f"--frames {frames} at --size {size}: the animation holds {held / 2**30:.1f} GiB of "
        f"frames, more than {MAX_PATH_BYTES / 2**30:g} GiB; lower --size or --frames",
    )
    # APNG stores a frame's delay as a 16-bit fraction of a second: at most 65 s a frame
    require(np.isfinite(fps) and 0.1 <= fps <= 120, f"--fps: must be in [0.1, 120], got {fps!r}")
    start, end = check_eye(eye_from, "--from"), check_eye(eye_to, "--to")
    for option, value in (("--tilt-from", tilt_from), ("--tilt-to", tilt_to)):
        require(np.isfinite(value), f"{option}: must be a finite angle in degrees, got {value!r}")
    tilts = np.radians(np.linspace(tilt_from, tilt_to, frames))
    eyes = [start + (end - start) * (k / max(frames - 1, 1)) for k in range(frames)]
    for k, (eye, tilt) in enumerate(zip(eyes, tilts, strict=True)):
        try:
            check_pose(eye, tilt)
        except SpecrefError as error:
            raise SpecrefError(f"frame {k + 1} of the path: {error}") from None
    check_output_file(out)
    painting = _check_pose_inputs(painting, 0.0, light_map)
    images = []
    for k, (eye, tilt) in enumerate(zip(eyes, tilts, strict=True)):
        result = _render_pose(light, size, method, painting, eye, tilt, light_map)
        images.append(np.round(np.clip(result["sRGB"], 0, 1) * 255).astype(np.uint8))
        if progress is not None:
            seconds = sum(result["seconds"].values())
            eye_text = ", ".join(f"{c:.3f}" for c in eye)
            progress.write(
                f"frame {k + 1}/{frames} from ({eye_text}) m, tilt {np.degrees(tilt):.1f}°: "
                f"{seconds:.2f} s\n"
            )
            progress.flush()
    with atomic_path(out, suffix=".png") as tmp:
        iio.imwrite(tmp, np.stack(images), extension=".png", duration=1000.0 / fps, loop=0)
    return f"wrote {out}: {frames} frames of {size}×{size} at {fps:g} frames per second (APNG)"


def _render_pose(light, size, method, painting, eye, tilt=0.0, light_map=None) -> dict:
    from impastor.painting import render_painting

    return render_painting(light, size, method, painting, eye=eye, tilt=tilt, light_map=light_map)


#: Bounds of the display options, whether or not --counts uses them: the booth is a room (positions
#: within 100 m), a screen's illuminance at most bright sunlight's, a lamp's luminance at most the
#: sun's.
MAX_POSITION_M, MAX_SCREEN_LUX, MAX_LUMINANCE = 100.0, 2e5, 2e9


def _check_flare_options(observer, light_position, screen_lux, light_luminance) -> None:
    """The display and flare options, finite and within :data:`MAX_POSITION_M` etc. (one line)."""
    for flag, point in (("--observer", observer), ("--light-position", light_position)):
        point = np.asarray(point, dtype=np.float64)
        require(
            point.shape == (3,) and bool(np.isfinite(point).all())
            and float(np.abs(point).max()) <= MAX_POSITION_M,
            f"{flag}: must be x,y,z in metres, finite and within {MAX_POSITION_M:g} m, got "
            f"{', '.join(f'{c:g}' for c in np.ravel(point))}",
        )  # fmt: skip
    require(
        np.isfinite(screen_lux) and 0 <= screen_lux <= MAX_SCREEN_LUX,
        f"--screen-lux: must be in [0, {MAX_SCREEN_LUX:g}] lux, got {screen_lux!r}",
    )
    require(
        light_luminance is None
        or (np.isfinite(light_luminance) and 0 <= light_luminance <= MAX_LUMINANCE),
        f"--light-luminance: must be in [0, {MAX_LUMINANCE:g}] cd/m², got {light_luminance!r}",
    )


def _counts_setup(light, tilt_deg, observer, light_position, light_luminance):
    """The display's geometry, the lamp and its luminance for --counts, checked before work."""
    from reference.display.pipeline import ScreenGeometry, screen_view_angles
    from reference.errors import require_finite

    geometry = ScreenGeometry(tilt=np.radians(tilt_deg))
    screen_view_angles(geometry, observer, 2, 2)  # an observer behind the screen fails first
    lamp = require_finite(light_position, "--light-position")
    require(
        lamp.shape == (3,) and lamp @ geometry.normal > 0,
        f"--light-position: ({', '.join(f'{c:g}' for c in np.ravel(lamp))}) m must be x,y,z "
        "in front of the screen (the side it faces), or it is not mirrored by it",
    )
    if light_luminance is None:
        from impastor.painting import booth_lamp_kind, booth_light_image

        light_luminance = float(booth_light_image(booth_lamp_kind(light)).mean())
    return geometry, lamp, light_luminance


def _check_before_render(tolerance, out, counts_out) -> None:
    """The tolerance, and outputs proved writable, before the render (the pilot takes seconds)."""
    from reference.files import check_output_file

    if tolerance is not None:
        from impastor.settings import NO_WORSE_THAN_FIXED, check_tolerance

        if tolerance != NO_WORSE_THAN_FIXED:
            check_tolerance(tolerance)
    for path in (out, counts_out):
        if path is not None:
            check_output_file(path)


def _describe_settings(settings: dict) -> str:
    """``N=32 K=32 S=36 fail-safe on``, and the tolerance's promise when there is one."""
    text = (
        f"N={settings['n_lights']} K={settings['n_samples']} S={settings['n_sectors']} "
        f"fail-safe {'on' if settings['failsafe'] else 'off'}"
    )
    if settings.get("shares"):  # the α groups that took the point lights or FIS alone
        text += ", pixels on point lights / FIS / hybrid {:.0f} / {:.0f} / {:.0f} %".format(
            *(100 * x for x in settings["shares"])
        )
    if settings.get("baseline"):  # chosen as no worse than the fixed settings
        text += (
            f", pilot error {100 * settings['pilot_error']:.2f} % no worse than the fixed "
            f"settings' {100 * settings['tolerance']:.2f} % (chosen in "
            f"{settings['choose_seconds']:.1f} s)"
        )
    elif settings.get("tolerance") is not None:
        verdict = "within" if settings["met"] else "MISSES"
        text += (
            f", pilot error {100 * settings['pilot_error']:.2f} % {verdict} the tolerance "
            f"{100 * settings['tolerance']:g} % (chosen in {settings['choose_seconds']:.1f} s)"
        )
    return text


def painting_on_display(XYZ, geometry, observer, flare: dict, compensate: bool = True) -> dict:
    """The painting through the virtual display per pixel, with the booth light's screen flare.

    Eq. (1), Ferwerda, with the diffuse and specular flare of §3.4.3, Ferwerda
    (:func:`reference.display.pipeline.image_to_display_counts`): ``flare`` holds
    ``screen_lux`` (illuminance on the screen), ``position`` (the light's centre, m) and
    ``luminance`` (cd/m²), the light taken at the display white's chromaticity.

    Examples
    --------
    >>> from reference.display.pipeline import ScreenGeometry
    >>> flare = {"screen_lux": 1000.0, "position": (0.0, 1.2, 0.9), "luminance": 2000.0}
    >>> out = painting_on_display(np.full((2, 2, 3), 80.0), ScreenGeometry(), (0, 0, 0.6), flare)
    >>> bool(np.allclose(out["seen_XYZ"], 80.0, rtol=5e-3))
    True
    """
    from reference.display.model import virtual_display
    from reference.display.pipeline import image_to_display_counts

    display = virtual_display()
    white = display.white_XYZ / display.white_XYZ[1]
    return image_to_display_counts(
        XYZ,
        display,
        geometry,
        observer,
        E_XYZ=flare["screen_lux"] * white,
        light_position=flare["position"],
        light_XYZ=flare["luminance"] * white,
        compensate=compensate,
    )


def _write_counts(XYZ, path, geometry, observer, flare: dict) -> str:
    """The painting through the virtual display, per pixel; the counts as a 16-bit PNG."""
    import imagecodecs

    from reference.display.model import screen_flare_XYZ, virtual_display
    from reference.display.pipeline import off_mirror_angle_deg
    from reference.files import write_bytes_atomic

    out = painting_on_display(XYZ, geometry, observer, flare)
    write_bytes_atomic(path, imagecodecs.png_encode(out["counts"].astype(np.uint16)))
    lit = XYZ[..., 1] > 1.0
    error = np.abs(out["seen_XYZ"][..., 1][lit] / XYZ[..., 1][lit] - 1.0)
    # §3.4.3, Ferwerda: the specular part of the flare subtracted, at its largest on the screen
    mirror = off_mirror_angle_deg(geometry, observer, flare["position"], *XYZ.shape[:2])
    display = virtual_display()
    diffuse = screen_flare_XYZ(display, [0.0, flare["screen_lux"], 0.0])[1]
    specular = screen_flare_XYZ(display, np.zeros(3), [0.0, flare["luminance"], 0.0], mirror)
    return (
        f"wrote {path} (11-bit counts; θ up to {np.degrees(out['theta'].max()):.1f}°, "
        f"flare subtracted: diffuse {diffuse:.2f} cd/m², specular up to "
        f"{specular[..., 1].max():.2f} cd/m²; "
        f"{int((~out['in_gamut'] & lit).sum())} of {int(lit.sum())} lit pixels out of gamut, "
        f"seen Y within "
        f"{100 * np.median(error):.2f} % of intended, median)"
    )
