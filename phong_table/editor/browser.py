"""The editor in headless Chromium: a server process, a Selenium driver, the page's JS model.

Used by ``specref phong edit --screenshot PNG`` (the screenshot in ``docs/phong-tables.md``) and
by ``tests/phong_table/editor/test_browser.py``. The server runs as its own process
(``python -m phong_table.editor --port N``) bound to 127.0.0.1 on a free port, and is
stopped by its process id. Page elements are found by their Bokeh ``name`` through
``Bokeh.documents[0].get_model_by_name`` (see :mod:`phong_table.editor.app`).
"""

from __future__ import annotations

import contextlib
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

from reference.errors import SpecrefError, require
from reference.files import atomic_path

__all__ = ["editor_screenshot", "free_port", "wait_for"]


def free_port() -> int:
    """A TCP port on 127.0.0.1 that is free now.

    Examples
    --------
    >>> 1024 <= free_port() <= 65535
    True
    """
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def editor_server(path=None, port: int | None = None, timeout: float = 60.0, **options):
    """Run ``python -m phong_table.editor`` as a child; yield ``(url, process)``; stop it by pid.

    ``port`` None takes a free port (the server's own choice, port 0, read from its first line);
    ``options`` are that command's (``save_dir``, ``resolution``, ``idle_seconds``).
    """
    port = 0 if port is None else port
    command = [sys.executable, "-m", "phong_table.editor"]
    command += [] if path is None else [str(path)]
    command += ["--port", str(port)]
    for key, value in options.items():
        command += [f"--{key.replace('_', '-')}", str(value)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = process.stdout.readline()  # the URL, once the server listens
        if "http://" not in line:
            process.wait(timeout)
            tail = process.stderr.read().strip().splitlines()[-1:] or [""]
            raise SpecrefError(f"the editor server did not start: {tail[0]}")
        yield line.split()[3] if len(line.split()) > 3 else f"http://127.0.0.1:{port}/", process
    finally:
        if process.poll() is None:
            os.kill(process.pid, 15)
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.kill(process.pid, 9)
                process.wait()


def editor_driver(width: int = 1300, height: int = 1250):
    """A headless Chromium driven by Selenium (``reference.browser.chromium_driver``)."""
    from reference.browser import chromium_driver

    return chromium_driver(width, height, page_load_timeout=60)


_VALUE_JS = """
const doc = (window.Bokeh && Bokeh.documents.length) ? Bokeh.documents[0] : null;
if (!doc) { return null; }
const model = doc.get_model_by_name(arguments[0]);
return model ? model[arguments[1]] : null;
"""


def page_value(driver, name: str, attribute: str = "text"):
    """An attribute of the page's Bokeh model called ``name`` (None before the page is ready)."""
    return driver.execute_script(_VALUE_JS, name, attribute)


def wait_for(driver, predicate, timeout: float = 60.0, what: str = "the page"):
    """Poll ``predicate(driver)`` until truthy; return its value; SpecrefError on timeout.

    Examples
    --------
    >>> calls = []
    >>> wait_for(None, lambda d: calls.append(1) or len(calls) > 2 and len(calls))
    3
    >>> wait_for(None, lambda d: None, 0.05, "nothing")
    Traceback (most recent call last):
    reference.errors.SpecrefError: editor page: nothing did not happen within 0.05 s
    """
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = predicate(driver)
        if value:
            return value
        time.sleep(0.02)
    raise SpecrefError(f"editor page: {what} did not happen within {timeout:g} s")


def rms_shown(driver):
    """The RMS label once it holds a number, else None."""
    text = page_value(driver, "rms") or ""
    return text if text.startswith("RMS ") and "pending" not in text else None


_SET_JS = """
const model = Bokeh.documents[0].get_model_by_name(arguments[0]);
model[arguments[1]] = arguments[2];
"""

_POINT_JS = """
const source = Bokeh.documents[0].get_model_by_name(arguments[0] + '_points');
const y = Array.from(source.data.y);
y[arguments[1]] = arguments[2];
source.data = {x: Array.from(source.data.x), y: y};
"""


def set_control_point(driver, curve: str, index: int, value: float) -> None:
    """Move a control point through the page's JS model (what a drag of PointDrawTool does)."""
    driver.execute_script(_POINT_JS, curve, index, value)


_PIXELS_JS = """
const doc = Bokeh.documents[0];
const plot = doc.get_model_by_name(arguments[0] + '_plot');
const source = doc.get_model_by_name(arguments[0] + '_points');
const view = Bokeh.index.get_one(plot);
const x = source.data.x[arguments[1]], y = source.data.y[arguments[1]];
const rect = view.canvas_view.el.getBoundingClientRect();
return [rect.left + view.frame.x_scale.compute(x), rect.top + view.frame.y_scale.compute(y),
        rect.top + view.frame.y_scale.compute(arguments[2])];
"""


def drag_control_point(driver, curve: str, index: int, value: float, steps: int = 6) -> None:
    """Drag a control point with the mouse (press, move in ``steps``, release), as a user does.

    The point's pixel position comes from the plot's own scales (``Bokeh.index``); the page is
    scrolled so the point is in view first. ``PointDrawTool`` is the plot's active drag tool.
    """
    from selenium.webdriver.common.actions.action_builder import ActionBuilder

    x, y, _ = driver.execute_script(_PIXELS_JS, curve, index, value)
    driver.execute_script(f"window.scrollBy(0, {max(0.0, y - 300.0)})")
    x, y, target = driver.execute_script(_PIXELS_JS, curve, index, value)
    action = ActionBuilder(driver, duration=40)
    action.pointer_action.move_to_location(round(x), round(y)).pointer_down()
    for k in range(1, steps + 1):
        action.pointer_action.move_to_location(round(x), round(y + (target - y) * k / steps))
    action.pointer_action.release()
    action.perform()
    driver.execute_script("window.scrollTo(0, 0)")


def set_widget(driver, name: str, attribute: str, value) -> None:
    """Set a widget's attribute through the page's JS model (synced to the server)."""
    driver.execute_script(_SET_JS, name, attribute, value)


_CLICK_JS = """
function find(root, label) {
    for (const el of root.querySelectorAll('*')) {
        if (el.tagName === 'BUTTON' && el.textContent.trim() === label) { return el; }
        if (el.shadowRoot) {
            const inner = find(el.shadowRoot, label);
            if (inner) { return inner; }
        }
    }
    return null;
}
const button = find(document, arguments[0]);
if (button) { button.click(); }
return button !== null;
"""

_CHECKSUM_JS = """
const source = Bokeh.documents[0].get_model_by_name(arguments[0] + '_image');
const data = source.data.image[0];
let sum = 0;
for (let i = 0; i < data.length; i += 3) { sum = (sum * 31 + data[i]) % 1000000007; }
return sum;
"""


def click_button(driver, label: str) -> None:
    """Click the page's button with this label, as a user does (through Bokeh's shadow DOM)."""
    require(driver.execute_script(_CLICK_JS, label), f"editor page: no button {label!r}")


def image_checksum(driver, kind: str = "table") -> int:
    """A checksum of an image the page shows (``table``, ``exact``, ``diff``)."""
    return driver.execute_script(_CHECKSUM_JS, kind)


def editor_screenshot(path, out, port: int | None = None) -> None:
    """Write a PNG of the editor: 50 uniform entries, one k_s point raised (atomic write).

    Examples
    --------
    >>> editor_screenshot(None, "/nonexistent/editor.png")
    Traceback (most recent call last):
    reference.errors.SpecrefError: /nonexistent/editor.png: the folder /nonexistent does not exist
    """
    folder = Path(out).resolve().parent
    require(folder.is_dir(), f"{out}: the folder {folder} does not exist")
    with (
        editor_server(path, None if port == 5006 else port) as (url, _process),
        editor_driver() as driver,
        atomic_path(out, suffix=".png") as tmp,
    ):
        driver.get(url)
        first = wait_for(driver, rms_shown, what="the first RMS")
        set_widget(driver, "placement", "value", "uniform")
        set_widget(driver, "entries", "value", 50)
        drag_control_point(driver, "k_s", 3, 0.8)
        wait_for(driver, lambda d: (rms_shown(d) or first) != first, what="the edited RMS")
        time.sleep(1.0)  # the last renders of the edit, then the canvases paint
        wait_for(driver, rms_shown, what="the edited RMS")
        driver.save_screenshot(str(tmp))
