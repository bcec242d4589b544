"""The page of ``specref phong edit``: a Bokeh server app over :mod:`phong_table.editor.state`.

Bokeh is the browser library because its server keeps the model in Python (the material, the
tables and the renders are NumPy, as in the rest of specref) and syncs plot data to the browser
over one websocket: dragging a point is Bokeh's own ``PointDrawTool``, no JavaScript of ours; it is
a NumFOCUS project with regular releases, and ``bokeh.server.server.Server`` embeds in one process
bound to 127.0.0.1.

Each session (browser tab) has its own :class:`EditorPage`: every edit of a curve sends the table
render to a :class:`phong_table.editor.state.LatestWorker` (stale requests are dropped); the exact
render goes to a second worker when no edit has arrived for :data:`EXACT_DELAY_MS` (the drag has
ended). Page elements carry Bokeh ``name``s (``<curve>_points``, ``rms``, ``frame``, ``error``,
``path``, ``save``, ``open``) that the browser test and the screenshot read.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np

from phong_table.editor.state import (
    CURVES,
    EditorState,
    LatestWorker,
    difference_rgba,
    illuminant_presets,
    measured_presets,
    render_exact_frame,
    render_table_frame,
)
from phong_table.interpolation import INTERPOLATION_METHODS
from phong_table.placement import PLACEMENT_METHODS
from reference.errors import SpecrefError

__all__ = ["EXACT_DELAY_MS", "EditorPage", "serve_editor"]

#: The exact image is rendered once no edit has arrived for this long (the drag has ended).
EXACT_DELAY_MS = 300


def _presets(key: str) -> dict:
    if key == "light":
        return {f"illuminant {k}": v for k, v in illuminant_presets().items()}
    if key == "n":
        return {f"constant {v:g}": np.full(41, float(v)) for v in (5, 20, 100, 500, 2000)}
    measured = {f"measured {k}": v for k, v in measured_presets().items()}
    return {**{f"constant {v:g}": np.full(41, v) for v in (0.0, 0.1, 0.3, 0.5, 0.8)}, **measured}


class EditorPage:
    """One browser session of the editor (see the module docstring)."""

    def __init__(self, path=None, view="far", resolution=256):
        self.view, self.resolution = view, resolution
        self.protected = set()  # files that failed to open: never overwritten
        self.error = ""
        self.state = EditorState.default()
        self.path = "" if path is None else str(path)
        if path is not None:
            self._open(path)
        self.version = 0
        self.table = self.exact = None
        self._exact_timer = None

    def _open(self, path) -> bool:
        try:
            self.state = EditorState.open(path)
        except SpecrefError as error:
            self.error = str(error).splitlines()[0]
            self.protected.add(Path(path).resolve())
            return False
        self.error = ""
        return True

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
        controls = self._controls()
        doc.title = "specref phong edit"
        doc.add_root(
            column(
                self.controls_row(controls),
                row(*images),
                row(self._nodes_plot(), column(self.rms_div, self.times_div, self.frame_div)),
                row(*editors[:2]),
                row(*editors[2:]),
            )
        )
        self._request(exact_now=True)

    def controls_row(self, controls):
        """The option widgets in a row, the message line under them."""
        from bokeh.layouts import column, row

        return column(row(*controls[:6]), self.error_div)

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
        grid = self.state.grid.wavelengths_nm
        line = ColumnDataSource({"x": grid, "y": self.state.curve(key)}, name=f"{key}_curve")
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
        select = Select(title="preset", options=["—", *presets], value="—", width=200)
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
            ("diff", "|difference| × 8"),
        ):
            plot = figure(title=title, frame_width=280, frame_height=280, x_range=(0, size),
                          y_range=(0, size), tools="", toolbar_location=None)  # fmt: skip
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
        self.path_input = TextInput(title="material file", value=self.path, name="path", width=360)
        open_button = Button(label="open", name="open", width=70)
        save_button = Button(label="save", name="save", width=70, button_type="primary")
        open_button.on_click(self._on_open)
        save_button.on_click(self._on_save)
        self.error_div = Div(text=self._error_html(), name="error", width=900)
        self.rms_div = Div(
            text="RMS: rendering (a new server compiles its kernels first)", name="rms", width=380
        )
        self.times_div = Div(text="", name="times", width=380)
        self.frame_div = Div(text="frame 0", name="frame", width=380)
        return [self.placement, self.interp, self.entries, self.path_input, open_button,
                save_button, *self.toggles]  # fmt: skip

    def _error_html(self) -> str:
        from html import escape

        return f'<span style="color:#b00">{escape(self.error)}</span>' if self.error else ""

    # -- events -------------------------------------------------------------------------------
    def _on_points(self, key, _attr, _old, new):
        x, y = list(new["x"]), list(new["y"])
        if len(y) != self.state.control_nm.size:  # a point added or removed: put them back
            self._sync_points(key)
            return
        for i, value in enumerate(y):
            self.state.set_point(key, i, value)
        if x != self.state.control_nm.tolist():  # points stay on their wavelengths
            self._sync_points(key)
        self.sources[key][1].data = {
            "x": self.state.grid.wavelengths_nm,
            "y": self.state.curve(key),
        }
        self._request(exact_now=False)

    def _sync_points(self, key):
        points = self.sources[key][0]
        points.data = {"x": self.state.control_nm.tolist(), "y": self.state.points[key].tolist()}

    def _on_preset(self, key, presets, _attr, _old, new):
        if new in presets:
            self.state.set_curve(key, presets[new])
            self._sync_points(key)
            self.sources[key][1].data = {
                "x": self.state.grid.wavelengths_nm,
                "y": self.state.curve(key),
            }
            self._request(exact_now=False)

    def _on_open(self):
        path = self.path_input.value.strip()
        if self._open(path):
            for key in CURVES:
                self._sync_points(key)
                self.sources[key][1].data = {
                    "x": self.state.grid.wavelengths_nm,
                    "y": self.state.curve(key),
                }
            self._request(exact_now=True)
        self.error_div.text = self._error_html()

    def _on_save(self):
        path = self.path_input.value.strip()
        try:
            if path and Path(path).resolve() in self.protected:
                raise SpecrefError(
                    f"{path}: not overwritten: it failed to open; save under another name"
                )
            written = self.state.save(path)
            self.error = ""
            self.error_div.text = f'<span style="color:#060">saved {written}</span>'
        except (SpecrefError, OSError) as error:
            self.error = str(error).splitlines()[0]
            self.error_div.text = self._error_html()

    # -- rendering ----------------------------------------------------------------------------
    def _request(self, exact_now: bool) -> None:
        self.version += 1
        model, version = self.state.model(), self.version
        options = (self.placement.value, self.interp.value, int(self.entries.value))
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
            self.error = str(result).splitlines()[0]
            self.error_div.text = self._error_html()
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
        self.image_sources["diff"].data = {
            "image": [difference_rgba(table, self.exact[2]).view(np.uint32)[..., 0]]
        }

    def _stop(self):
        self.table_worker.stop()
        self.exact_worker.stop()


def serve_editor(path=None, port: int = 5006, announce=None, view="far", resolution=256) -> None:
    """Serve the editor on ``http://127.0.0.1:PORT/`` until interrupted; ``announce(url line)``.

    Raises
    ------
    SpecrefError
        The port is in use or not allowed (one line).

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
    from bokeh.server.server import Server

    def make(doc):
        EditorPage(path, view, resolution).attach(doc)

    origins = [f"127.0.0.1:{port}", f"localhost:{port}"]
    try:
        server = Server(
            {"/": Application(FunctionHandler(make))},
            address="127.0.0.1",
            port=port,
            allow_websocket_origin=origins,
        )
    except OSError as error:
        raise SpecrefError(
            f"specref phong edit: 127.0.0.1:{port}: cannot listen ({error.strerror}); "
            "choose another --port"
        ) from None
    server.start()
    if announce is not None:
        announce(f"specref phong edit: http://127.0.0.1:{port}/  (Ctrl-C to stop)")
    try:
        server.io_loop.start()
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()
