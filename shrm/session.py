"""Change-driven re-rendering: a render session that recomputes only what a change invalidates.

§5.2, Herbert et al. give the render loop as pseudo-code::

    for each frame
      for each material group
        if illuminant (il) or environment (env) changed
          color manage env for il; SH-project env; create diffuse and specular maps for env
          If SHRM for il does not exist: create SHRM for env and BRDF
        if viewpoint (vp) changed: extract reflection map from SHRM for vp
        if glossiness (gloss) changed: prefilter specular map for gloss
        set dynamic parameters into shaders
        render

"(A persistent caching scheme, which is tied into this algorithm [...] realizes map reuse.)"

specref writes the loop as **data**: :data:`HERBERT_STAGES` lists each stage with the scene-state
keys it reads and the stages whose results it uses. :class:`RenderSession` holds the state and, on
:meth:`RenderSession.render`, walks the stages in order. Each stage's result is identified by a key
that hashes its name, code version, the state it reads and the keys of its inputs
(:func:`shrm.cache.cache_key`), so a stage runs only when something it depends on changed. Results
are kept in memory (the last few per stage) and, for the expensive stages, in the persistent cache
(:class:`shrm.cache.Cache`): a change back to an earlier state, or a new session on the same
scene, is served from the cache without running the stage. Every execution, cache hit and stage
time is counted (:attr:`RenderSession.executions`, :attr:`RenderSession.hits`,
:attr:`RenderSession.frame_times`).

:data:`POLYMER_STAGES` is the same loop for the hybrid polymer (Eq. (1), Herbert et al.;
``shrm.polymer.material``): the Lambert and Phong maps, a Fresnel table for the ``index``, the
effect pigment's SHRM for the ``brdf`` (None: no effect pigment), the per-pixel angle look-ups
(``polymer_pixels``) and the per-frame shading with the dynamic parameters. Which state key each
polymer parameter lives in is :data:`POLYMER_PARAMETERS`; its stages are
``stages_depending_on(POLYMER_STAGES, key)`` (tested):

=======================================================  ==========================================
polymer parameter                                        stages that run
=======================================================  ==========================================
thickness, tio2, tint, transparency, Mod_effect, gloss   shade
gloss_exponent (state ``gloss``)                         specular_map, polymer_pixels, shade
index                                                    fresnel_lut, polymer_pixels, shade
effect (state ``brdf``)                                  brdf_coeffs, shrm_create, extract,
                                                         polymer_pixels, shade
=======================================================  ==========================================

Which stages of :data:`HERBERT_STAGES` run for each kind of change (tested):

=====================  ========================================================================
change                 stages that run
=====================  ========================================================================
illuminant, env        color_manage, sh_project, diffuse_map, specular_map, shrm_create, extract,
                       shade
viewpoint              gbuffer, extract, shade
gloss                  specular_map, shade
brdf                   brdf_coeffs, shrm_create, extract, shade
dynamic parameters     shade
=====================  ========================================================================

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004.
"""

from __future__ import annotations

import dataclasses
import time
from collections import OrderedDict
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from reference.errors import require, require_choice
from shrm.cache import Cache, cache_key, hash_inputs

__all__ = [
    "HERBERT_STAGES",
    "POLYMER_PARAMETERS",
    "POLYMER_STAGES",
    "STATE_KEYS",
    "RenderSession",
    "Stage",
    "stages_depending_on",
]

#: Scene-state keys a session holds (§5.2, Herbert et al.) and the fixed configuration it reads.
STATE_KEYS = (
    "illuminant",
    "environment",
    "viewpoint",
    "gloss",
    "brdf",
    "dynamic",
    "config",
    # The polymer's refractive index (POLYMER_STAGES): it changes only the Fresnel table
    "index",
)


@dataclass(frozen=True)
class Stage:
    """One stage of the render loop.

    Parameters
    ----------
    name : str
        Key, e.g. ``"sh_project"``.
    reads : tuple of str
        Scene-state keys (:data:`STATE_KEYS`) the stage reads.
    after : tuple of str
        Stages whose results it uses (they come earlier in the list).
    run : callable
        ``run(state: dict, inputs: dict[str, dict]) -> dict`` of results.
    version : str
        Code version, part of the result key; bump it when the stage's algorithm changes.
    persistent : bool
        Whether results go to the persistent cache (arrays only).
    """

    name: str
    reads: tuple
    after: tuple
    run: Callable
    version: str = "1"
    persistent: bool = False


def stages_depending_on(stages, key: str) -> list[str]:
    """The stages that must run when state ``key`` changes: its readers and everything after them.

    Examples
    --------
    >>> stages_depending_on(HERBERT_STAGES, "gloss")
    ['specular_map', 'shade']
    >>> stages_depending_on(HERBERT_STAGES, "dynamic")
    ['shade']
    """
    dirty: list[str] = []
    for stage in stages:
        if key in stage.reads or any(a in dirty for a in stage.after):
            dirty.append(stage.name)
    return dirty


def _canonical(value):
    """State values in a form :func:`shrm.cache.hash_inputs` accepts (dataclasses as dicts)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        fields = {f.name: _canonical(getattr(value, f.name)) for f in dataclasses.fields(value)}
        return {"__class__": type(value).__name__, **fields}
    if isinstance(value, Mapping):
        return {str(k): _canonical(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_canonical(v) for v in value]
    if isinstance(value, np.ndarray | np.generic | int | float | str | bool) or value is None:
        return value
    if hasattr(value, "values") and hasattr(value, "wavelengths_nm"):
        return {"values": np.asarray(value.values), "nm": np.asarray(value.wavelengths_nm)}
    return repr(value)


class RenderSession:
    """Scene state plus the stage graph: each frame recomputes only the stages that changed.

    §5.2, Herbert et al. (module docstring).

    Parameters
    ----------
    state : dict
        Initial values of the :data:`STATE_KEYS` the stages read.
    stages : sequence of Stage
        The graph, in execution order (default :data:`HERBERT_STAGES`).
    cache : Cache or None
        Persistent cache for the stages marked ``persistent``; None keeps results in memory only.
    memory : int
        Results kept in memory per stage (the most recent), so a change back is free.

    Examples
    --------
    >>> def add(state, inputs):
    ...     return {"x": np.asarray(state["config"]["a"] + 1.0)}
    >>> session = RenderSession({"config": {"a": 1.0}}, [Stage("add", ("config",), (), add)])
    >>> float(session.render()["add"]["x"]), session.executions["add"]
    (2.0, 1)
    >>> _ = session.render(); session.executions["add"]
    1
    """

    def __init__(self, state: dict, stages=None, cache: Cache | None = None, memory: int = 8):
        self.stages = tuple(HERBERT_STAGES if stages is None else stages)
        names = [s.name for s in self.stages]
        require(len(set(names)) == len(names), f"render session: duplicate stage in {names}")
        for i, stage in enumerate(self.stages):
            for key in stage.reads:
                require_choice(key, STATE_KEYS, f"state key of stage {stage.name!r}")
            for dep in stage.after:
                require(
                    dep in names[:i],
                    f"render session: stage {stage.name!r} uses {dep!r}, which does not come "
                    "before it",
                )
        self.cache = cache
        self.memory = memory
        self.state: dict = {}
        self._state_hash: dict = {}
        self._results: dict = {s.name: OrderedDict() for s in self.stages}
        self._current: dict = {}
        self.executions = {s.name: 0 for s in self.stages}
        self.hits = {s.name: 0 for s in self.stages}
        self.frame_times: list[dict] = []
        self._prepared: dict[str, float] = {}
        self.update(**state)

    def update(self, **changes) -> None:
        """Change scene state (:data:`STATE_KEYS`); the next frame recomputes what depends on it."""
        for key, value in changes.items():
            require_choice(key, STATE_KEYS, "scene state key")
            self.state[key] = value
            self._state_hash[key] = hash_inputs({key: _canonical(value)})

    def render(self) -> dict:
        """Run one frame; return every stage's result (``{stage: {name: array or object}}``).

        Also appends ``{stage: seconds}`` for the stages that ran to :attr:`frame_times` (0 for
        stages reused from memory, the load time for persistent-cache hits); stages run ahead by
        :meth:`prepare` count in this frame.
        """
        keys, times = self._run(self.stages)
        for name, seconds in self._prepared.items():
            times[name] = times.get(name, 0.0) + seconds
        self._prepared = {}
        self.frame_times.append(times)
        return {name: self._results[name][key] for name, key in keys.items()}

    def prepare(self, *names: str) -> None:
        """Run the named stages (and the stages they use) now, ahead of the next frame.

        Their errors (a requested order the BRDF does not allow, say) surface before any frame
        starts; their times are added to the next frame's :attr:`frame_times`.

        Examples
        --------
        >>> def one(state, inputs):
        ...     return {"x": np.asarray(1.0)}
        >>> session = RenderSession({"config": {}}, [Stage("one", ("config",), (), one)])
        >>> session.prepare("one"); session.executions["one"], session.frame_times
        (1, [])
        >>> _ = session.render(); session.executions["one"], sorted(session.frame_times[0])
        (1, ['one'])
        """
        wanted = set(names)
        for name in names:
            require_choice(name, [s.name for s in self.stages], "render session: stage")
        for stage in reversed(self.stages):
            if stage.name in wanted:
                wanted.update(stage.after)
        _, times = self._run([s for s in self.stages if s.name in wanted])
        for name, seconds in times.items():
            self._prepared[name] = self._prepared.get(name, 0.0) + seconds

    def _run(self, stages) -> tuple[dict, dict]:
        """Run ``stages`` (in graph order, each after the ones it uses): their keys and times."""
        keys: dict[str, str] = {}
        times: dict[str, float] = {}
        for stage in stages:
            missing = [k for k in stage.reads if k not in self.state]
            require(not missing, f"render session: stage {stage.name!r} needs state {missing}")
            key = cache_key(
                f"session.{stage.name}",
                stage.version,
                {
                    "state": {k: self._state_hash[k] for k in stage.reads},
                    "inputs": {d: keys[d] for d in stage.after},
                },
            )
            keys[stage.name] = key
            memory = self._results[stage.name]
            start = time.perf_counter()
            if key in memory:
                memory.move_to_end(key)
                result = memory[key]
                if self._current.get(stage.name) != key:
                    self.hits[stage.name] += 1
            else:
                result = self.cache.get(key) if (stage.persistent and self.cache) else None
                if result is not None:
                    self.hits[stage.name] += 1
                else:
                    inputs = {d: self._results[d][keys[d]] for d in stage.after}
                    result = stage.run(self.state, inputs)
                    self.executions[stage.name] += 1
                    if stage.persistent and self.cache is not None:
                        self.cache.put(key, result, {"step": f"session.{stage.name}"})
                memory[key] = result
                while len(memory) > self.memory:
                    memory.popitem(last=False)
            if self._current.get(stage.name) != key:
                times[stage.name] = time.perf_counter() - start
            self._current[stage.name] = key
        return keys, times


# --- the stages of §5.2, Herbert et al. ------------------------------------------------------


def _config(state) -> dict:
    defaults = {
        "size": 32,
        # An L2 coefficient tail of 5 %: within §5.5's P <= 10 for the synthesized BRDFs
        "tol": 0.05,
        "frame": "reflection",
        "F_max": 24,
        "P_max": 10,
        "F": None,
        "P": None,
        "light_order": 32,
        # Tolerance of the diffuse and specular prefilter orders (shrm.lobes.adaptive_order)
        "prefilter_tol": 0.01,
        "width": 96,
        "height": 96,
        "backend": "ducc0",
    }
    return {**defaults, **state.get("config", {})}


def _stage_color_manage(state, inputs):
    # §4, Herbert et al.: the spectral panorama is colour-managed for the selected illuminant
    environment = np.asarray(state["environment"], dtype=np.float64)
    illuminant = np.asarray(state["illuminant"], dtype=np.float64)
    require(
        environment.shape[-1] == illuminant.shape[-1],
        f"render session: environment has {environment.shape[-1]} bands, illuminant "
        f"{illuminant.shape[-1]}",
    )
    return {"radiance": environment * illuminant}


def _stage_sh_project(state, inputs):
    from shrm.transform import project_latlong

    c = _config(state)
    radiance = inputs["color_manage"]["radiance"]
    L = min(c["light_order"], radiance.shape[1] // 2 - 1)
    # §5.3, Herbert et al.: SH-project the environment
    return {"coeffs": project_latlong(radiance, L, backend=c["backend"], where="environment")}


def _prefiltered_cube(coeffs, kernel, c):
    from reference.geometry.cubemap import cubemap_texel_directions
    from shrm.lobes import adaptive_order, parse_kernel
    from shrm.prefilter import prefilter_coefficients
    from shrm.sh import order_of, sh_evaluate

    k = parse_kernel(kernel)
    L = min(adaptive_order(k, c["prefilter_tol"]), order_of(coeffs.shape[1]))
    # §5.4, Herbert et al.: prefiltering is a product in frequency space
    E = prefilter_coefficients(coeffs[:, : (L + 1) ** 2], k.Lambda(L))
    return sh_evaluate(E, cubemap_texel_directions(c["size"]), backend=c["backend"])


def _stage_diffuse_map(state, inputs):
    return {"cube": _prefiltered_cube(inputs["sh_project"]["coeffs"], "lambert", _config(state))}


def _stage_specular_map(state, inputs):
    spec = f"phong:{float(state['gloss']):g}"
    return {"cube": _prefiltered_cube(inputs["sh_project"]["coeffs"], spec, _config(state))}


def _stage_brdf_coeffs(state, inputs):
    from shrm.brdf_sh import brdf_sh_coefficients, default_view_fit, shrm_brdf_parts, shrm_orders

    c = _config(state)
    brdf = state["brdf"]
    method, params = brdf["name"], brdf.get("params")
    if params is None:
        from reference.materials.brdf import BRDF_METHODS

        params = dict(BRDF_METHODS.lookup(method).params)
    # R&H 2002: the Lambertian part goes to an irradiance map, the rest is expanded
    function, expand, lambert, k = shrm_brdf_parts(method, params)
    # The orders from the tails of the projection over all views; the hemisphere fit of the normal
    # frame (shrm.brdf_sh) is no worse on the seen views at the same orders, and is made at them
    rho = brdf_sh_coefficients(
        function, expand, c["F_max"], c["P_max"], c["frame"], view_power=k, view_fit="sphere"
    )
    F, P = shrm_orders(rho, c["tol"], c.get("F"), c.get("P"))
    rho = rho[:, : F + 1, : P + 1, : min(F, P) + 1]
    if default_view_fit(c["frame"]) == "hemisphere":
        rho = brdf_sh_coefficients(function, expand, F, P, c["frame"], view_power=k)
    return {
        "rho": rho,
        "lambert": np.zeros(0) if lambert is None else lambert,
        "view_power": np.array(k),
    }


def _stage_shrm_create(state, inputs):
    from shrm.shrm import shrm_create

    c = _config(state)
    b = inputs["brdf_coeffs"]
    rho, L = b["rho"], inputs["sh_project"]["coeffs"]
    F = min(rho.shape[1] - 1, round(np.sqrt(L.shape[1])) - 1)
    lambert = b["lambert"] if b["lambert"].size else None
    # §5.5, Herbert et al.: create the SHRM for environment and BRDF
    s = shrm_create(
        L, rho[:, : F + 1], c["frame"], c["size"], c["backend"], float(b["view_power"]), lambert
    )
    out = {"coeffs": s.coeffs, "orders": np.array([s.F, s.P]), "view_power": b["view_power"]}
    if lambert is not None:
        out.update(lambert=s.lambert, irradiance=s.irradiance)
    if s.mixing is not None:
        out["mixing"] = s.mixing
    return out


def _shrm_of(state, created):
    """The SHRM object of a ``shrm_create`` result."""
    from shrm.shrm import SHRM

    F, P = (int(x) for x in created["orders"])
    return SHRM(
        created["coeffs"],
        _config(state)["frame"],
        F,
        P,
        float(created["view_power"]),
        created.get("lambert"),
        created.get("irradiance"),
        created.get("mixing"),
    )


def _view_of(camera) -> np.ndarray:
    # Distant viewer (§5.5, Herbert et al.): the direction from the scene towards the eye
    return np.asarray(camera.basis()[2], dtype=np.float64)


def _stage_gbuffer(state, inputs):
    from reference.geometry.gbuffer import render_gbuffer

    c = _config(state)
    camera = state["viewpoint"]
    g = render_gbuffer(c["objects"], camera, c["width"], c["height"])
    return {"gbuffer": g}


def _stage_extract(state, inputs):
    from shrm.shrm import shrm_extract

    s = _shrm_of(state, inputs["shrm_create"])
    # §5.6, Herbert et al.: extract the reflection map for the viewpoint
    return {"map": shrm_extract(s, _view_of(state["viewpoint"]))}


def _stage_shade(state, inputs):
    from reference.geometry.cubemap import cubemap_lookup_bilinear
    from shrm.shrm import _index_directions, shade_shrm

    d = {"k_d": 0.0, "k_s": 0.0, "k_e": 1.0, **state["dynamic"]}
    g = inputs["gbuffer"]["gbuffer"]
    v = _view_of(state["viewpoint"])
    radiance = np.zeros((*g.shape, inputs["diffuse_map"]["cube"].shape[-1]))
    sel = g.mask
    n = g.normal[sel]
    r = _index_directions("reflection", n, v)
    # Set dynamic parameters into shaders (§5.2, Herbert et al.): a weighted sum of the maps
    radiance[sel] = (
        np.asarray(d["k_d"]) / np.pi * cubemap_lookup_bilinear(inputs["diffuse_map"]["cube"], n)
        + np.asarray(d["k_s"]) * cubemap_lookup_bilinear(inputs["specular_map"]["cube"], r)
        + np.asarray(d["k_e"])
        * shade_shrm(_shrm_of(state, inputs["shrm_create"]), inputs["extract"]["map"], n, v)
    )
    return {"radiance": radiance, "mask": sel}


#: The render loop of §5.2, Herbert et al., as data (module docstring).
HERBERT_STAGES = (
    Stage("color_manage", ("illuminant", "environment"), (), _stage_color_manage),
    Stage("sh_project", ("config",), ("color_manage",), _stage_sh_project, persistent=True),
    Stage("diffuse_map", ("config",), ("sh_project",), _stage_diffuse_map, persistent=True),
    Stage(
        "specular_map", ("gloss", "config"), ("sh_project",), _stage_specular_map, persistent=True
    ),
    # Version 2: the Lambertian part split off, the grazing view power factored out
    Stage("brdf_coeffs", ("brdf", "config"), (), _stage_brdf_coeffs, "3", persistent=True),
    Stage(
        "shrm_create",
        ("config",),
        ("sh_project", "brdf_coeffs"),
        _stage_shrm_create,
        "3",  # version 3: on a basis of the channels (E103)
        persistent=True,
    ),
    Stage("gbuffer", ("viewpoint", "config"), (), _stage_gbuffer),
    Stage("extract", ("viewpoint", "config"), ("shrm_create",), _stage_extract),
    Stage(
        "shade",
        ("dynamic", "viewpoint", "config"),
        ("diffuse_map", "specular_map", "shrm_create", "extract", "gbuffer"),
        _stage_shade,
    ),
)


# --- the hybrid polymer, Eq. (1), Herbert et al. ----------------------------------------------

#: Where each polymer parameter lives in the session state (§5.2, §8, Herbert et al.: "changes to
#: dynamic parameters (such as material thickness, color, TiO2 load) ... incur no speed penalty").
#: ``gloss`` is the factor of Eq. (5), Herbert et al.; ``gloss_exponent`` selects the specular
#: prefilter (E32).
POLYMER_PARAMETERS = {
    "thickness": "dynamic",
    "tio2": "dynamic",
    "tint": "dynamic",
    "transparency": "dynamic",
    "Mod_effect": "dynamic",
    "gloss": "dynamic",
    "gloss_exponent": "gloss",
    "index": "index",
    "effect": "brdf",
}


def _stage_fresnel_lut(state, inputs):
    from reference.materials.fresnel import fresnel_lut
    from shrm.polymer.kubelka_munk import saunderson_constants

    n = np.asarray(state["index"], dtype=np.float64)
    # Eq. (1), Herbert et al.: the F_r table, and the chip surface's k_1 of D_polymer (E31)
    return {"lut": fresnel_lut(n), "k_1": np.asarray(saunderson_constants(n).k_1)}


def _effect_stage(stage):
    """A stage of the effect pigment's SHRM that does nothing when the state has no ``brdf``."""

    def run(state, inputs):
        if state.get("brdf") is None:
            return {"none": np.zeros(0)}
        return stage(state, inputs)

    return run


def _stage_polymer_pixels(state, inputs):
    from shrm.polymer.hybrid import PolymerMaps
    from shrm.polymer.material import polymer_pixel_parts
    from shrm.shrm import shade_shrm

    c = _config(state)
    g = inputs["gbuffer"]["gbuffer"]
    sel = g.mask
    n = g.normal[sel]
    v = _view_of(state["viewpoint"])
    radiance = inputs["color_manage"]["radiance"]
    maps = PolymerMaps(
        inputs["diffuse_map"]["cube"],
        inputs["specular_map"]["cube"],
        radiance,
        float(state["gloss"]),
    )
    E_effect = None
    if state.get("brdf") is not None:
        s = _shrm_of(state, inputs["shrm_create"])
        E_effect = shade_shrm(s, inputs["extract"]["map"], n, v)
    # §5.1, Herbert et al.: the per-pixel (angle) look-ups, once per viewpoint and maps
    V = np.broadcast_to(v, n.shape)
    lut, mirror = inputs["fresnel_lut"]["lut"], c.get("mirror", "fresnel")
    parts = polymer_pixel_parts(n, V, maps, lut, mirror, E_effect)
    return {"parts": parts, "mask": sel, "uv": g.uv[sel]}


def _polymer_tint(tint, grid) -> np.ndarray:
    """Tint_polymer on the grid: a number, a spectrum on the grid, or a spot-colour name."""
    if isinstance(tint, str):
        from shrm.polymer.tint import read_tint_library

        library = read_tint_library()
        return np.interp(grid.wavelengths_nm, library.wavelengths_nm, library.tint(tint))
    return np.asarray(tint, dtype=np.float64)


def _stage_polymer_shade(state, inputs):
    from reference.colour.spectra import SpectralGrid
    from shrm.polymer.hybrid import PolymerLook, _spectrum01
    from shrm.polymer.material import (
        chip_lookup,
        modulation_at,
        polymer_characterization,
        polymer_shade_parts,
    )

    c = _config(state)
    d = {
        "thickness": 1.524,
        "tio2": 0.5,
        "tint": 1.0,
        "transparency": 0.0,
        "Mod_effect": 0.0,
        "gloss": 1.0,
        **state["dynamic"],
    }
    grid = SpectralGrid(*c["grid"])
    pixels = inputs["polymer_pixels"]
    fresnel = inputs["fresnel_lut"]
    # Set dynamic parameters into shaders (§5.2, Herbert et al.): the chip, once per frame
    ch = polymer_characterization(c.get("characterization"), grid)
    chip = chip_lookup(ch, d["thickness"], d["tio2"])
    nb = grid.n_bands
    gloss = _spectrum01(d["gloss"], 1, "polymer: gloss")[0]
    look = PolymerLook(
        np.clip(chip["over_black"] - fresnel["k_1"], 0.0, 1.0),  # Erratum E31: D_polymer
        chip["transmittance"],
        _spectrum01(d["transparency"], nb, "polymer: transparency"),
        _spectrum01(_polymer_tint(d["tint"], grid), nb, "polymer: tint"),
        float(gloss),
        fresnel["lut"],
        c.get("mirror", "fresnel"),
    )
    Mod = d["Mod_effect"]
    if np.ndim(Mod) == 2:
        Mod = modulation_at(Mod, pixels["uv"])
    # The radiance of the covered pixels only (N, n_bands), in the order of g.normal[mask]: no
    # image is scattered per frame (the display step reads the pixels it needs)
    shaded = polymer_shade_parts(pixels["parts"], look, Mod, compiled=True)
    return {"pixels": shaded, "mask": pixels["mask"]}


#: The render loop of §5.2, Herbert et al., for the hybrid polymer, Eq. (1), Herbert et al. (module
#: docstring). ``config`` adds ``grid`` (required), ``characterization`` (a file, default the
#: model) and ``mirror`` (default ``"fresnel"``). Its ``shade`` result is ``pixels``, the radiance
#: spectra (N, n_bands) of the covered pixels in the order of ``gbuffer.normal[mask]``, and
#: ``mask``.
POLYMER_STAGES = (
    Stage("color_manage", ("illuminant", "environment"), (), _stage_color_manage),
    Stage("sh_project", ("config",), ("color_manage",), _stage_sh_project, persistent=True),
    Stage("diffuse_map", ("config",), ("sh_project",), _stage_diffuse_map, persistent=True),
    Stage(
        "specular_map", ("gloss", "config"), ("sh_project",), _stage_specular_map, persistent=True
    ),
    Stage("fresnel_lut", ("index",), (), _stage_fresnel_lut),
    Stage("brdf_coeffs", ("brdf", "config"), (), _effect_stage(_stage_brdf_coeffs), "3"),
    Stage(
        "shrm_create",
        ("config",),
        ("sh_project", "brdf_coeffs"),
        _effect_stage(_stage_shrm_create),
        "3",
    ),
    Stage("gbuffer", ("viewpoint", "config"), (), _stage_gbuffer),
    Stage("extract", ("viewpoint", "config"), ("shrm_create",), _effect_stage(_stage_extract)),
    Stage(
        "polymer_pixels",
        ("viewpoint", "config"),
        (
            "color_manage",
            "diffuse_map",
            "specular_map",
            "fresnel_lut",
            "shrm_create",
            "extract",
            "gbuffer",
        ),
        _stage_polymer_pixels,
    ),
    Stage(
        "shade",
        ("dynamic", "config"),
        ("fresnel_lut", "polymer_pixels"),
        _stage_polymer_shade,
    ),
)
