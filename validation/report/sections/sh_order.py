"""Report section "Environment SH order from an accuracy": error against order, and renders.

The figures (erratum E75; ``shrm.accuracy``, ``validation.studies.env_accuracy``):

- error against order: the relative error of Y of the SH-only frequency path against the
  brute-force angular oracle (mean and max over lit directions of a Fibonacci set), per order, for
  every shipped environment and the synthetic worst cases (a single bright texel, a sun disc), for
  the Lambert and a Phong kernel, with the order the default rule picks (bright texels lit exactly
  plus SH for the residual) and its measured error;
- the default render of a Lambertian sphere (ρ = 0.5, the path of ``specref render``) against
  ``specref render --oracle``, before (order from the kernel's tail alone, tolerance 1e-2) and
  after erratum E75, with the order and exact texels each used;
- speed against accuracy: the same sphere rendered at several ``--accuracy`` tolerances, each
  render's wall time (in this process, the map's upsampled spectra already made; the SH maps of
  each order are made in the render) against its measured error, and the oracle's time.

compute → :func:`sh_order_study`; present → :func:`present`; checks → :func:`checks`.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from reference.data import environment_maps
from reference.images.formats import read_image, write_exr
from reference.scene.loader import loads_scene
from reference.scene.metadata import DEFAULT_ACCURACY, MAX_FACTOR
from validation.report import Check, ReportContext, ReportSection, SectionData, Table, Text
from validation.studies.env_accuracy import (
    SRGB_Y,
    error_by_order,
    fibonacci_directions,
    render_against_oracle,
    sphere_scene_toml,
    worst_case_maps,
)

__all__ = ["SETTINGS", "sh_order_study", "speed_against_accuracy"]

#: The kernels of the chart: irradiance and a Phong lobe.
KERNELS = ("lambert", "phong:32")
#: Orders of the error-against-order chart.
ORDERS = (2, 4, 8, 14, 24, 32, 48, 64, 96, 128, 192, 256, 384, 511)
#: The old default: order from the kernel's L2 tail alone (``shrm.lobes.DEFAULT_TOL``).
OLD_OPTIONS = {"environment_tol": 1e-2}

#: Sizes per mode. ``tiny`` is for tests: worst cases only, small maps.
SETTINGS = {
    "full": {"shipped": True, "worst_height": 512, "directions": 1500, "render_size": 24,
             "accuracies": (0.05, 0.02, 0.01, 0.005, 0.002, 0.001)},
    "quick": {"shipped": True, "worst_height": 256, "directions": 400, "render_size": 10,
              "accuracies": (0.005, 0.001)},
    "tiny": {"shipped": False, "worst_height": 32, "directions": 60, "render_size": 6,
             "accuracies": (0.02, 0.005)},
}  # fmt: skip


def _cases(folder: Path, s: dict) -> dict[str, Path]:
    """Environment files by name: the shipped maps and the worst cases (written to ``folder``)."""
    cases = {}
    if s["shipped"]:
        for path in environment_maps():
            if path.suffix.lower() in (".hdr", ".exr"):
                cases[path.name] = path
    for name, image in worst_case_maps(s["worst_height"]).items():
        cases[name] = write_exr(folder / f"{name.replace(' ', '-')}.exr", image)
    return cases


def sh_order_study(ctx: ReportContext, settings: dict | None = None) -> SectionData:
    """Error against order per map and kernel, and default renders against the oracle.

    Parameters
    ----------
    ctx : ReportContext
        ``ctx.quick`` picks the sizes.
    settings : dict, optional
        One of :data:`SETTINGS`.

    Returns
    -------
    SectionData
        ``results``: ``by_order`` (case → kernel → orders, mean, max, chosen), ``renders``
        (case → old / new → mean, max, orders) and ``speed`` (case →
        :func:`speed_against_accuracy`).

    Examples
    --------
    >>> data = sh_order_study(ReportContext(Path(".")), SETTINGS["tiny"])
    >>> sorted(data.results["by_order"]), [c.passed for c in checks(data)]
    (['single texel', 'sun disc'], [True, True, True, True, True, True, True, True])
    """
    s = settings or SETTINGS["quick" if ctx.quick else "full"]
    data = SectionData()
    directions = fibonacci_directions(s["directions"])
    by_order, renders, speed = {}, {}, {}
    with tempfile.TemporaryDirectory() as folder:
        for name, path in _cases(Path(folder), s).items():
            Y = read_image(path)[..., :3] @ SRGB_Y
            by_order[name] = {}
            for kernel in KERNELS:
                # The brute-force oracle once per map and kernel: both calls measure against it.
                alone = error_by_order(Y, kernel, ORDERS, directions, split=False)
                exact = alone.pop("exact")
                chosen = error_by_order(Y, kernel, (), directions, exact=exact)["chosen"]
                by_order[name][kernel] = {**alone, "chosen": chosen}
            scene = loads_scene(sphere_scene_toml(path, size=s["render_size"]))
            old = render_against_oracle(scene, OLD_OPTIONS)
            new = render_against_oracle(scene, None, oracle=old["oracle"])
            renders[name] = {"old": _render_summary(old), "new": _render_summary(new)}
            # the renders above compiled the kernels
            speed[name] = speed_against_accuracy(scene, s["accuracies"], warm_up=False)
    data.results["by_order"] = by_order
    data.results["renders"] = renders
    data.results["speed"] = speed
    return data


def speed_against_accuracy(scene, accuracies, warm_up: bool = True) -> dict:
    """Wall time and measured error of ``scene`` rendered at each ``--accuracy``, and the oracle's.

    Each render is what one ``specref render`` of the scene pays after start-up: it is timed in
    this process on a fresh copy of the scene's lights, so that the map's upsampled spectra and
    the SH maps of its order are made inside it (none cached from another render); a warm-up
    render on another copy compiles the kernels first (``warm_up=False`` when the process has
    rendered the scene already). The oracle (``--oracle``) is timed the same way.

    Returns
    -------
    dict
        ``oracle_s``; ``points``: per accuracy its ``accuracy``, ``order``, ``seconds``, ``mean``
        and ``max`` (relative error of Y over lit pixels against the oracle); ``covered``: the
        pixels on the sphere.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import numpy as np
    >>> from reference.images.formats import write_exr
    >>> sky = write_exr(pathlib.Path(tempfile.mkdtemp()) / "sky.exr", np.ones((32, 64, 3)))
    >>> found = speed_against_accuracy(loads_scene(sphere_scene_toml(sky, size=4)), (0.01,))
    >>> found["points"][0]["order"], found["points"][0]["max"] < 1e-3, found["oracle_s"] > 0
    (0, True, True)
    """
    import dataclasses
    import time

    from reference.scene.render import render_scene
    from validation.studies.env_accuracy import relative_errors

    def fresh():
        lights = tuple(dataclasses.replace(light) for light in scene.lights)
        return dataclasses.replace(scene, lights=lights)

    def timed(options):
        copy = fresh()
        start = time.perf_counter()
        result = render_scene(copy, options=options)
        return result, time.perf_counter() - start

    if warm_up:
        render_scene(fresh())  # compiles the kernels
    oracle, oracle_s = timed({"environment": "bruteforce"})
    mask = oracle.gbuffer.mask
    points = []
    for accuracy in accuracies:
        result, seconds = timed({"environment_accuracy": accuracy})
        mean, worst = relative_errors(result.XYZ[..., 1][mask], oracle.XYZ[..., 1][mask])
        (choice,) = result.records["environment"].values()
        points.append({"accuracy": accuracy, "order": choice["order"], "seconds": seconds,
                       "mean": mean, "max": worst})  # fmt: skip
    return {"oracle_s": oracle_s, "points": points, "covered": int(mask.sum())}


def _render_summary(found: dict) -> dict:
    (choice,) = found["records"]["environment"].values()
    return {
        "mean": found["mean"],
        "max": found["max"],
        "order": choice["order"],
        "exact_texels": choice.get("exact_texels", 0),
    }


def present(ctx: ReportContext, data: SectionData) -> list:
    """The chart and tables of the section (module docstring); draws from ``data`` only."""
    renders = data.results["renders"]
    return [
        Text(
            "specref render picks the SH order of environment lighting from a tolerance users "
            f"read per pixel (--accuracy, default {DEFAULT_ACCURACY:g}): mean relative error of Y "
            f"over pixels brighter than 1 % of the peak at most the tolerance, max at most "
            f"{MAX_FACTOR:g}×. Texels carrying ≥ 0.1 % of the power and ≥ 100× the median are lit "
            "exactly; SH carries the rest at the order the estimate (shrm.accuracy) needs."
        ),
        _order_chart(ctx, data.results["by_order"]),
        _speed_chart(ctx, data.results["speed"]),
        Table(
            ["map", "kernel", "order", "exact texels", "estimated max", "measured mean", "max"],
            [
                [
                    name,
                    k,
                    c["order"],
                    c["exact_texels"],
                    c["estimate_max"],
                    c["measured_mean"],
                    c["measured_max"],
                ]
                for name, per in data.results["by_order"].items()
                for k, c in ((k, v["chosen"]) for k, v in per.items())
            ],
            "The default rule per map: order, exact texels and the error of Y at held-out "
            "directions against brute force",
            "{:.3g}",
        ),
        Table(
            [
                "map",
                "old order",
                "old mean",
                "old max",
                "new order",
                "exact texels",
                "new mean",
                "new max",
            ],
            [
                [
                    name,
                    r["old"]["order"],
                    r["old"]["mean"],
                    r["old"]["max"],
                    r["new"]["order"],
                    r["new"]["exact_texels"],
                    r["new"]["mean"],
                    r["new"]["max"],
                ]
                for name, r in renders.items()
            ],
            "Lambertian sphere (ρ = 0.5), default render against --oracle, relative error of Y "
            "over lit pixels: the former order rule (kernel tail 1e-2) and now (erratum E75)",
            "{:.3g}",
        ),
    ]


def _speed_chart(ctx, speed: dict):
    """Render time against measured mean error per map, one dot per accuracy; oracle times."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.8), constrained_layout=True)
    for i, (name, found) in enumerate(speed.items()):
        points, colour = found["points"], f"C{i}"
        ax.loglog([p["seconds"] for p in points], [max(p["mean"], 1e-7) for p in points], "o-",
                  color=colour, label=name, ms=4)  # fmt: skip
        for p in points:
            ax.annotate(f"{p['accuracy']:g}", (p["seconds"], max(p["mean"], 1e-7)), fontsize=6,
                        xytext=(3, 2), textcoords="offset points")  # fmt: skip
        ax.axvline(found["oracle_s"], color=colour, ls=":", lw=1)
    ax.set_xlabel("render time, s (dotted: the brute-force oracle)")
    ax.set_ylabel("mean relative error of Y")
    ax.legend(fontsize=7)
    return ctx.figure("speed-vs-accuracy", fig, _speed_caption(speed))


def _speed_caption(speed: dict) -> str:
    """The speed chart's conclusion from its figures: which path is faster, and from what size.

    The brute force's time is linear in the pixels it integrates; the frequency path's is nearly
    all the map's projection, whatever the size.
    """
    rows = [
        (p["seconds"], f["oracle_s"], f["covered"])
        for f in speed.values()
        for p in f["points"]
        if p["accuracy"] == DEFAULT_ACCURACY
    ]
    if not rows:
        return "Render time against error, one dot per --accuracy (labelled)"
    fast = [r[0] for r in rows]
    oracle = [r[1] for r in rows]
    crossover = max(covered * seconds / oracle_s for seconds, oracle_s, covered in rows)
    return (
        f"On a sphere of {rows[0][2]} pixels the brute-force oracle (dotted) takes "
        f"{min(oracle):.2g}–{max(oracle):.2g} s and the frequency path at the default --accuracy "
        f"{DEFAULT_ACCURACY:g} {min(fast):.2g}–{max(fast):.2g} s: the frequency path pays each "
        "map's upsampling and projection once, whatever the size, the brute force every texel "
        f"for every pixel, so from about {crossover:,.0f} pixels (estimated, the brute force "
        "linear in pixels) the frequency path is the faster on every map. Dots: one render per "
        "--accuracy (labelled); a tighter tolerance buys its error with a higher order"
    )


def _order_chart(ctx, by_order):
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(KERNELS), figsize=(10, 3.6), sharey=True)
    for ax, kernel in zip(axes, KERNELS, strict=True):
        for i, (name, per) in enumerate(by_order.items()):
            curve, colour = per[kernel], f"C{i}"
            ax.loglog(curve["orders"], curve["max"], color=colour, label=name)
            ax.loglog(curve["orders"], curve["mean"], color=colour, ls=":", lw=1)
            chosen = curve["chosen"]
            ax.plot(max(chosen["order"], 1), chosen["measured_max"], "o", color=colour)
        ax.axhline(MAX_FACTOR * DEFAULT_ACCURACY, color="k", ls="--", lw=1)
        ax.axhline(DEFAULT_ACCURACY, color="k", ls=":", lw=1)
        ax.set_xlabel("order L")
        ax.set_title(kernel, fontsize=9)
    axes[0].set_ylabel("relative error of Y (max —, mean ···)")
    axes[0].legend(fontsize=7)
    chosen = [per[k]["chosen"] for per in by_order.values() for k in KERNELS]
    held = sum(c["measured_max"] <= MAX_FACTOR * DEFAULT_ACCURACY for c in chosen)
    return ctx.figure(
        "error-vs-order",
        fig,
        f"The default rule's orders (dots: bright texels lit exactly) keep the max error within "
        f"the promised {MAX_FACTOR * DEFAULT_ACCURACY:g} (dashed) on {held} of {len(chosen)} "
        "map–kernel pairs; lines: the SH alone against order (max —, mean ···)",
    )


def checks(data: SectionData) -> list[Check]:
    """The default render meets the promised bound on every map (erratum E75)."""
    found = []
    for name, r in data.results["renders"].items():
        new = r["new"]
        found.append(
            Check(
                f"{name}: default render vs oracle, mean",
                f"<= {DEFAULT_ACCURACY:g}",
                new["mean"],
                new["mean"] <= DEFAULT_ACCURACY,
            )
        )
        found.append(
            Check(
                f"{name}: default render vs oracle, max",
                f"<= {MAX_FACTOR * DEFAULT_ACCURACY:g}",
                new["max"],
                new["max"] <= MAX_FACTOR * DEFAULT_ACCURACY,
            )
        )
    for name, per in data.results["by_order"].items():
        for kernel, curve in per.items():
            c = curve["chosen"]
            ok = c["measured_max"] <= MAX_FACTOR * DEFAULT_ACCURACY
            found.append(
                Check(
                    f"{name}, {kernel}: chosen order at held-out directions, max",
                    f"<= {MAX_FACTOR * DEFAULT_ACCURACY:g}",
                    c["measured_max"],
                    ok,
                    "held out",  # directions the order was not chosen on
                )
            )
    return found


SECTION = ReportSection(
    "sh-order",
    "Environment SH order from an accuracy",
    sh_order_study,
    present,
    checks,
    default_effort="quick",  # the full settings take minutes: specref report --full
    basis="design",  # the shipped maps and the bright texel the rule was built on (E75)
)
