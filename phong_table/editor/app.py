"""The page of ``specref phong edit``: a Bokeh server app over :mod:`phong_table.editor.state`.

Bokeh is the browser library because its server keeps the model in Python (the material, the
tables and the renders are NumPy, as in the rest of specref) and syncs plot data to the browser
over one websocket: dragging a point is Bokeh's own ``PointDrawTool``, no JavaScript of ours; it is
a NumFOCUS project with regular releases, and ``bokeh.server.server.Server`` embeds in one process
bound to 127.0.0.1.

Each session (browser tab) has its own :class:`EditorPage`: every edit of a curve sends the table
render to a :class:`phong_table.editor.state.LatestWorker` (stale requests are dropped); the exact
render goes to a second worker when no edit has arrived for :data:`EXACT_DELAY_MS` (the drag has
ended). Page elements carry Bokeh ``name``s (``<curve>_points``, ``<curve>_preset``, ``rms``,
``frame``, ``error``, ``path``, ``save``, ``open``, ``difference``, ``diff_plot``) that the browser
test and the screenshot read.

The server is a local web app and is built as one (docs/phong-tables.md, "The editor as a local
web app"): it listens on 127.0.0.1 only; a request whose ``Host`` header is not
``127.0.0.1:PORT`` or ``localhost:PORT`` is refused (a page elsewhere that re-binds its DNS name to
127.0.0.1 cannot read it), as is a websocket from another origin; every message is shown as text,
never as HTML; a save writes only ``.toml`` files inside one folder (``--save-dir``, or the folder
of the file opened on the command line, or the current one) and overwrites a file only when save
is pressed twice; curve points and options that are not finite numbers or known names are
refused on the page; at most :data:`MAX_SESSIONS` pages are served at once (two render threads
each), and a page left for :data:`UNUSED_SESSION_S` seconds is closed.
"""

from __future__ import annotations

import math
import threading
from functools import partial
from pathlib import Path

import numpy as np

from phong_table.editor.state import (
    CURVES,
    EditorState,
    LatestWorker,
    difference_gain,
    difference_rgba,
    illuminant_presets,
    measured_presets,
    render_exact_frame,
    render_table_frame,
)
from phong_table.interpolation import INTERPOLATION_METHODS
from phong_table.placement import PLACEMENT_METHODS
from reference.colour.spectra import DEFAULT_GRID
from reference.errors import SpecrefError, require

__all__ = [
    "EXACT_DELAY_MS",
    "MAX_SESSIONS",
    "UNUSED_SESSION_S",
    "EditorPage",
    "checked_points",
    "save_target",
    "serve_editor",
]

#: The exact image is rendered once no edit has arrived for this long (the drag has ended).
EXACT_DELAY_MS = 300

#: Pages one server serves at once; each has two render threads. A further page is refused.
MAX_SESSIONS = 8

#: A page whose browser tab has gone is closed (its threads ended) after this many seconds.
UNUSED_SESSION_S = 5

_COLOURS = {"error": "#b00", "ok": "#060", "warn": "#a60"}


def _presets(key: str) -> dict:
    """A curve's presets: ``label -> (wavelengths in nm, values)``."""
    wl = DEFAULT_GRID.wavelengths_nm
    if key == "light":
        return {f"illuminant {k}": v for k, v in illuminant_presets().items()}
    if key == "n":
        return {
            f"constant {v:g}": (wl, np.full(wl.size, float(v))) for v in (5, 20, 100, 500, 2000)
        }
    constants = {f"constant {v:g}": (wl, np.full(wl.size, v)) for v in (0.0, 0.1, 0.3, 0.5, 0.8)}
    return {**constants, **{f"measured {k}": (wl, v) for k, v in measured_presets().items()}}


def checked_points(key: str, values, count: int) -> list[float]:
    """The values of a curve's control points as the page sent them, or a one-line refusal.

    Raises
    ------
    SpecrefError
        A point added or removed, or a value that is not a finite number (a string, None, NaN,
        an infinity); the message names the curve and the point.

    Examples
    --------
    >>> checked_points("k_s", [0.5, 0.25], 2)
    [0.5, 0.25]
    >>> checked_points("k_s", [0.5, float("nan")], 2)
    Traceback (most recent call last):
    reference.errors.SpecrefError: k_s: point 1 is nan, not a finite number; the curve is unchanged
    >>> checked_points("n", ["<b>", 3], 2)
    Traceback (most recent call last):
    reference.errors.SpecrefError: n: point 0 is '<b>', not a finite number; the curve is unchanged
    """
    values = list(values)
    require(
        len(values) == count,
        f"{key}: {len(values)} points sent, the curve has {count}; the curve is unchanged",
    )
    out = []
    for i, value in enumerate(values):
        number = value if isinstance(value, (int, float)) and not isinstance(value, bool) else None
        shown = repr(value) if isinstance(value, str) else value
        require(
            number is not None and math.isfinite(number),
            f"{key}: point {i} is {shown}, not a finite number; the curve is unchanged",
        )
        out.append(float(number))
    return out


def save_target(name, folder) -> Path:
    """The file a save writes: ``name`` (relative to ``folder``) resolved, ``.toml``, inside it.

    Symbolic links and ``..`` are resolved first, so a name cannot lead out of the folder.

    Raises
    ------
    SpecrefError
        An empty name, a name not ending in ``.toml``, or a file outside ``folder``.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     print(save_target("a.toml", d).name)
    ...     try:
    ...         save_target("../b.toml", d)
    ...     except SpecrefError as error:
    ...         print(str(error).replace(str(Path(d).resolve()), "D")[:38])
    a.toml
    ../b.toml: save: outside D, the folder
    """
    text = str(name).strip()
    require(text != "", "save: give a file name ending in .toml")
    folder = Path(folder).resolve()
    path = Path(text).expanduser()
    resolved = (path if path.is_absolute() else folder / path).resolve()
    require(resolved.suffix == ".toml", f"{text}: save: the name must end in .toml")
    require(
        folder in resolved.parents,
        f"{text}: save: outside {folder}, the folder this editor saves to "
        "(start it with --save-dir to choose another)",
    )
    return resolved


class EditorPage:
    """One browser session of the editor (see the module docstring).

    ``save_dir`` is the folder saves go to (default: the opened file's folder, else the current
    one); names typed on the page are relative to it and may not leave it (:func:`save_target`).
    """

    def __init__(self, path=None, view="far", resolution=256, save_dir=None):
        self.view, self.resolution = view, resolution
        self.protected = set()  # files that failed to open: never overwritten
        self.error = ""
        self.state = EditorState.default()
        self.path = "" if path is None else str(path)
        if save_dir is None:
            save_dir = Path(path).parent if path is not None else Path.cwd()
        self.save_dir = Path(save_dir).resolve()
        self._confirm = None  # the existing file a first press of save asked about
        if path is not None:
            self._open(path)
        self.version = 0
        self.table = self.exact = None
        self._exact_timer = None
        self._good_options = ("error", "monotone", 200)

    def _open(self, path) -> bool:
        try:
            self.state = EditorState.open(path)
        except SpecrefError as error:
            self.error = str(error).splitlines()[0]
            self.protected.add(Path(path).resolve())
            return False
        self.error = ""
        return True

    def _message(self, text: str, kind: str = "error") -> None:
        """Show one line under the controls, as text (never HTML), coloured by ``kind``."""
        self.error = text.splitlines()[0] if text else ""
        self.error_div.text = self.error
        self.error_div.styles = {"color": _COLOURS[kind]}

    # -- layout -------------------------------------------------------------------------------
    def attach(self, doc) -> None:
        """Build the page into a Bokeh document and start its workers."""
        from bokeh.layouts import column, row

        self.doc = doc
        self.table_worker = LatestWorker(partial(self._deliver, "table"))
        self.exact_worker = LatestWorker(partial(self._deliver, "exact"))
        doc.on_session_destroyed(lambda _ctx: self._stop())
        editors = [self._curve_editor(key) for key in CURVES]
        images = self._images()
        options, files = self._controls()
        doc.title = "specref phong edit"
        doc.add_root(
            column(
                row(*options),
                row(*files),
                self.error_div,
                row(*images),
                row(self._nodes_plot(), column(self.rms_div, self.times_div, self.frame_div)),
                row(*editors[:2]),
                row(*editors[2:]),
            )
        )
        self._request(exact_now=True)

    def _curve_editor(self, key: str):
        from bokeh.layouts import column
        from bokeh.models import ColumnDataSource, PointDrawTool, Select
        from bokeh.plotting import figure

        label, low, high, log = CURVES[key]
        plot = figure(
            name=f"{key}_plot", title=label, width=380, height=220,
            y_axis_type="log" if log else "linear", x_range=(370, 790),
            y_range=(low * 0.9 if log else low, high), tools="", x_axis_label="λ (nm)",
        )  # fmt: skip
        line = ColumnDataSource(self._curve_data(key), name=f"{key}_curve")
        points = ColumnDataSource(
            {"x": self.state.control_nm.tolist(), "y": self.state.points[key].tolist()},
            name=f"{key}_points",
        )
        plot.line("x", "y", source=line, line_width=2)
        dots = plot.scatter("x", "y", source=points, size=10, color="firebrick")
        tool = PointDrawTool(renderers=[dots], add=False, drag=True)
        plot.add_tools(tool)
        plot.toolbar.active_tap = tool
        plot.toolbar.active_drag = tool
        points.on_change("data", partial(self._on_points, key))
        presets = _presets(key)
        select = Select(
            title=f"preset for {label}", options=["—", *presets], value="—", width=240,
            name=f"{key}_preset",
        )  # fmt: skip
        select.on_change("value", partial(self._on_preset, key, presets))
        self.sources = getattr(self, "sources", {})
        self.sources[key] = (points, line)
        return column(plot, select)

    def _images(self):
        from bokeh.models import ColumnDataSource, Toggle
        from bokeh.plotting import figure

        self.image_sources = {}
        plots = []
        size = self.resolution
        for key, title in (
            ("table", "table path"),
            ("exact", "exact"),
            ("diff", "|table − exact| (gain set when both images are in)"),
        ):
            plot = figure(title=title, frame_width=280, frame_height=280, x_range=(0, size),
                          y_range=(0, size), tools="", toolbar_location=None,
                          name=f"{key}_plot")  # fmt: skip
            plot.axis.visible = False
            plot.grid.visible = False
            blank = np.zeros((size, size), dtype=np.uint32)
            source = ColumnDataSource({"image": [blank]}, name=f"{key}_image")
            plot.image_rgba("image", x=0, y=0, dw=size, dh=size, source=source)
            self.image_sources[key] = source
            plots.append(plot)
        self.diff_plot = plots[2]
        toggle = Toggle(label="difference image", active=True, name="difference", width=160)
        toggle.on_change("active", lambda _a, _o, new: setattr(self.diff_plot, "visible", new))
        self.toggles = [toggle]
        return plots

    def _nodes_plot(self):
        from bokeh.models import ColumnDataSource
        from bokeh.plotting import figure

        title = "table nodes over f_sp(t) (Fig. 4, Wang et al.)"
        plot = figure(title=title, width=600, height=260, x_axis_label="t = cos α",
                      tools="pan,wheel_zoom,reset")  # fmt: skip
        self.fsp_source = ColumnDataSource({"t": [], "r": [], "g": [], "b": []})
        self.node_source = ColumnDataSource({"t": [], "r": [], "g": [], "b": []}, name="nodes")
        for channel, colour in (("r", "red"), ("g", "green"), ("b", "blue")):
            plot.line("t", channel, source=self.fsp_source, color=colour)
            plot.scatter("t", channel, source=self.node_source, color=colour, size=4)
        return plot

    def _controls(self):
        """The table options (with the difference toggle) and the file row."""
        from bokeh.models import Button, Div, Select, Spinner, TextInput

        self.placement = Select(
            name="placement",
            title="placement",
            value="error",
            options=PLACEMENT_METHODS.names(),
            width=120,
        )
        self.interp = Select(
            name="interpolation",
            title="interpolation",
            value="monotone",
            options=INTERPOLATION_METHODS.names(),
            width=120,
        )
        self.entries = Spinner(
            name="entries", title="entries m", value=200, low=4, high=4000, step=1, width=100
        )
        for widget in (self.placement, self.interp, self.entries):
            widget.on_change("value", lambda _a, _o, _n: self._request(exact_now=False))
        self.path_input = TextInput(
            title=f"material file (saved in {self.save_dir})", value=self.path, name="path",
            width=480,
        )  # fmt: skip
        open_button = Button(label="open", name="open", width=70)
        save_button = Button(label="save", name="save", width=70, button_type="primary")
        open_button.on_click(self._on_open)
        save_button.on_click(self._on_save)
        text = {"render_as_text": True, "width": 900}
        self.error_div = Div(text="", name="error", **text)
        self._message(self.error)
        self.rms_div = Div(text="RMS: rendering", name="rms", **text)
        self.times_div = Div(text="", name="times", **text)
        self.frame_div = Div(text="frame 0", name="frame", **text)
        options = [self.placement, self.interp, self.entries, *self.toggles]
        return options, [self.path_input, open_button, save_button]

    # -- events -------------------------------------------------------------------------------
    def _curve_data(self, key: str) -> dict:
        return {"x": self.state.curve_wavelengths(key), "y": self.state.curve(key)}

    def _on_points(self, key, _attr, _old, new):
        count = self.state.control_nm.size
        try:
            values = checked_points(key, new.get("y", []), count)
        except SpecrefError as error:
            self._message(str(error))
            self._sync_points(key)
            return
        for i, value in enumerate(values):
            self.state.set_point(key, i, value)
        moved = list(new.get("x", [])) != self.state.control_nm.tolist()
        if moved or values != self.state.points[key].tolist():
            self._sync_points(key)  # points stay on their wavelengths and within the bounds
        self.sources[key][1].data = self._curve_data(key)
        self._request(exact_now=False)

    def _sync_points(self, key):
        points = self.sources[key][0]
        points.data = {"x": self.state.control_nm.tolist(), "y": self.state.points[key].tolist()}

    def _on_preset(self, key, presets, _attr, _old, new):
        if new in presets:
            wavelengths, values = presets[new]
            self.state.set_curve(key, values, wavelengths)
            self._sync_points(key)
            self.sources[key][1].data = self._curve_data(key)
            self._request(exact_now=False)

    def _on_open(self):
        path = self.path_input.value.strip()
        if self._open(path):
            for key in CURVES:
                self._sync_points(key)
                self.sources[key][1].data = self._curve_data(key)
            self._request(exact_now=True)
            self._message(f"opened {path}", "ok")
        else:
            self._message(self.error)

    def _on_save(self):
        try:
            target = save_target(self.path_input.value, self.save_dir)
            if target in self.protected:
                raise SpecrefError(
                    f"{target}: not overwritten: it failed to open; save under another name"
                )
            if target.exists() and self._confirm != target:
                self._confirm = target
                self._message(f"{target} exists: press save again to overwrite it", "warn")
                return
            written = self.state.save(target)
            self._confirm = None
            self._message(f"saved {written}", "ok")
        except (SpecrefError, OSError) as error:
            self._confirm = None
            self._message(str(error))

    # -- rendering ----------------------------------------------------------------------------
    def _options(self):
        """The table options of the widgets, checked; a bad one is refused and put back."""
        placement, interp, entries = self.placement.value, self.interp.value, self.entries.value
        try:
            require(
                placement in PLACEMENT_METHODS.names(),
                f"placement: {placement!r} is not one of {', '.join(PLACEMENT_METHODS.names())}",
            )
            require(
                interp in INTERPOLATION_METHODS.names(),
                f"interpolation: {interp!r} is not one of "
                f"{', '.join(INTERPOLATION_METHODS.names())}",
            )
            number = isinstance(entries, (int, float)) and not isinstance(entries, bool)
            require(
                number and math.isfinite(entries) and entries == int(entries)
                and 4 <= entries <= 4000,
                f"entries m: {entries!r} is not a whole number from 4 to 4000",
            )  # fmt: skip
        except SpecrefError as error:
            self._message(str(error))
            self.placement.value, self.interp.value, self.entries.value = self._good_options
            return None
        self._good_options = (placement, interp, int(entries))
        return self._good_options

    def _request(self, exact_now: bool) -> None:
        options = self._options()
        if options is None:
            return
        self.version += 1
        model, version = self.state.model(), self.version
        view, res = self.view, self.resolution
        self.table_worker.submit(
            lambda: (version, model, render_table_frame(model, view, res, *options))
        )
        if self._exact_timer is not None:
            self.doc.remove_timeout_callback(self._exact_timer)
            self._exact_timer = None
        job = lambda: (version, model, render_exact_frame(model, view, res))  # noqa: E731
        if exact_now:
            self.exact_worker.submit(job)
        else:
            self._exact_timer = self.doc.add_timeout_callback(
                lambda: self._exact_after_drag(job), EXACT_DELAY_MS
            )

    def _exact_after_drag(self, job):
        self._exact_timer = None
        self.exact_worker.submit(job)

    def _deliver(self, kind, result, _sequence):
        self.doc.add_next_tick_callback(partial(self._show, kind, result))

    def _show(self, kind, result):
        if isinstance(result, SpecrefError):
            self._message(str(result))
            return
        version, model, frame = result
        if kind == "table":
            self.table = (version, model, frame)
            self._show_nodes(model, frame)
            number = int(self.frame_div.text.split()[-1]) + 1
            self.frame_div.text = f"frame {number}"
        else:
            self.exact = (version, model, frame)
        self.image_sources[kind].data = {"image": [frame.rgba.view(np.uint32)[..., 0]]}
        self._show_errors()

    def _show_nodes(self, model, frame):
        t = np.linspace(0.0, 1.0, 400)
        f = model.specular(t)
        self.fsp_source.data = {"t": t, "r": f[:, 0], "g": f[:, 1], "b": f[:, 2]}
        v = frame.info["values"]
        self.node_source.data = {"t": frame.info["nodes"], "r": v[:, 0], "g": v[:, 1], "b": v[:, 2]}

    def _show_errors(self):
        from phong_table.render import rms_8bit

        if self.table is None:
            return
        table = self.table[2]
        build, shade = table.info["build_s"] * 1e3, table.info["shade_s"] * 1e3
        times = f"table build {build:.2f} ms, shade {shade:.2f} ms"
        if self.exact is not None:
            times += f"; exact shade {self.exact[2].info['shade_s'] * 1e3:.2f} ms"
        self.times_div.text = times
        if self.exact is None or self.exact[0] != self.table[0]:
            self.rms_div.text = "RMS: exact render pending (after the drag)"
            return
        rms = max(rms_8bit(table.linear, self.exact[2].linear))
        self.rms_div.text = f"RMS {rms:.4g} (8-bit units, max of display and linear)"
        gain = difference_gain(table, self.exact[2])
        self.diff_plot.title.text = f"|table − exact| × {gain:.3g} (99.5th percentile white)"
        self.image_sources["diff"].data = {
            "image": [difference_rgba(table, self.exact[2], gain).view(np.uint32)[..., 0]]
        }

    def _stop(self):
        self.table_worker.stop()
        self.exact_worker.stop()


def _loopback_hosts(port: int):
    """A Bokeh auth provider that serves only requests whose ``Host`` is this server's address.

    A page elsewhere whose DNS name is re-bound to 127.0.0.1 sends its own name as ``Host``: it
    is sent to ``/host-refused``, a plain-text 403 (Bokeh's documented authentication hooks, so
    every page, session and websocket request is checked before a document is made).
    """
    from bokeh.server.auth_provider import AuthProvider
    from tornado.web import RequestHandler

    hosts = {f"127.0.0.1:{port}", f"localhost:{port}"}

    class HostRefused(RequestHandler):
        def get(self):
            self.set_status(403)
            self.set_header("Content-Type", "text/plain; charset=utf-8")
            self.finish(f"specref phong edit serves http://127.0.0.1:{port}/ only\n")

    class LoopbackHosts(AuthProvider):
        @property
        def get_user(self):
            return lambda handler: "local" if handler.request.host.lower() in hosts else None

        @property
        def login_url(self):
            return "/host-refused"

        @property
        def login_handler(self):
            return HostRefused

    return LoopbackHosts()


def _warm_kernels() -> None:
    """Load (or compile once) every table kernel and the exact one, so no frame pays for it."""
    model = EditorState.default().model()
    render_exact_frame(model, resolution=16)
    for placement in PLACEMENT_METHODS.names():
        for interpolation in INTERPOLATION_METHODS.names():
            render_table_frame(model, "far", 16, placement, interpolation, 32)


def _page_maker(path, view, resolution, save_dir):
    """The Bokeh app function: an :class:`EditorPage` per session, at most MAX_SESSIONS."""
    from bokeh.models import Div

    slots = threading.BoundedSemaphore(MAX_SESSIONS)

    def make(doc):
        if not slots.acquire(blocking=False):
            doc.title = "specref phong edit"
            text = (
                f"specref phong edit: {MAX_SESSIONS} pages are open, the most one editor serves; "
                "close one and reload this page"
            )
            doc.add_root(Div(text=text, name="error", render_as_text=True))
            return
        doc.on_session_destroyed(lambda _ctx: slots.release())
        EditorPage(path, view, resolution, save_dir).attach(doc)

    return make


def serve_editor(
    path=None,
    port: int = 5006,
    announce=None,
    view="far",
    resolution=256,
    save_dir=None,
    idle_seconds: float = UNUSED_SESSION_S,
) -> None:
    """Serve the editor on ``http://127.0.0.1:PORT/`` until interrupted; ``announce(url line)``.

    ``port`` 0 takes a free port; the announced line names the port listened on. The kernels
    are loaded before the line is announced. ``save_dir`` is the one folder saves go to
    (default: the folder of ``path``, else the current folder); a page whose tab has gone is
    closed after ``idle_seconds``.

    Raises
    ------
    SpecrefError
        The port is in use or not allowed, or ``save_dir`` is not a folder (one line).

    Examples
    --------
    >>> import socket
    >>> with socket.socket() as busy:
    ...     busy.bind(("127.0.0.1", 0))
    ...     busy.listen()
    ...     try:
    ...         serve_editor(port=busy.getsockname()[1])
    ...     except SpecrefError as error:
    ...         print(str(error).split("; ")[-1])
    choose another --port
    """
    from bokeh.application import Application
    from bokeh.application.handlers.function import FunctionHandler
    from bokeh.server.server import BaseServer
    from bokeh.server.tornado import BokehTornado
    from bokeh.server.util import bind_sockets
    from tornado.httpserver import HTTPServer
    from tornado.ioloop import IOLoop

    if save_dir is not None:
        require(Path(save_dir).is_dir(), f"{save_dir}: --save-dir: not a folder")
    try:
        sockets, port = bind_sockets("127.0.0.1", port)
    except OSError as error:
        raise SpecrefError(
            f"specref phong edit: 127.0.0.1:{port}: cannot listen ({error.strerror}); "
            "choose another --port"
        ) from None
    app = BokehTornado(
        {"/": Application(FunctionHandler(_page_maker(path, view, resolution, save_dir)))},
        extra_websocket_origins=[f"127.0.0.1:{port}", f"localhost:{port}"],
        auth_provider=_loopback_hosts(port),
        check_unused_sessions_milliseconds=int(min(1000, 500 * idle_seconds)),
        unused_session_lifetime_milliseconds=int(idle_seconds * 1000),
    )
    http = HTTPServer(app)
    http.add_sockets(sockets)
    server = BaseServer(IOLoop.current(), app, http)
    _warm_kernels()
    server.start()
    if announce is not None:
        announce(f"specref phong edit: http://127.0.0.1:{port}/  (Ctrl-C to stop)")
    try:
        server.io_loop.start()
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()
