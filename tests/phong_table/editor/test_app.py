"""The editor's page without a browser, and its server as a local web app (Erratum E28, E29).

The page is an :class:`~phong_table.editor.app.EditorPage` on a Bokeh ``Document`` (what a browser
session gets), driven by calling its event handlers with what the browser would send. The
server runs as its own process on a port it chooses (``--port 0``), bound to 127.0.0.1, and is
stopped by its process id.
"""

import http.client
import os
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from phong_table.editor.app import MAX_SESSIONS, EditorPage
from phong_table.editor.state import EditorState, render_exact_frame, render_table_frame

RES = 16


@pytest.fixture
def page(tmp_path):
    from bokeh.document import Document

    opened = EditorState.default().save(tmp_path / "start.toml")
    page = EditorPage(opened, resolution=RES)
    page.attach(Document())
    yield page
    page._stop()


def test_points_that_are_not_finite_numbers_are_refused_and_later_edits_work(page):
    control = page.state.control_nm.tolist()
    before = page.state.points["k_s"].copy()
    for bad in (float("nan"), float("inf"), "abc", None, True):
        y = before.tolist()
        y[3] = bad
        page._on_points("k_s", "data", None, {"x": control, "y": y})
        assert page.error.startswith("k_s: point 3 is ")
        assert "\n" not in page.error
        assert np.array_equal(page.state.points["k_s"], before)
        assert page.sources["k_s"][0].data["y"] == before.tolist()  # the page's points put back
    page._on_points("k_s", "data", None, {"x": control, "y": before.tolist()[:-1]})
    assert "10 points sent, the curve has 11" in page.error
    version = page.version
    y = before.tolist()
    y[3] = 0.9
    page._on_points("k_s", "data", None, {"x": control, "y": y})
    assert page.state.points["k_s"][3] == 0.9
    assert page.version == version + 1


def test_bad_options_are_refused_and_put_back(page):
    version = page.version
    for widget, bad in (
        (page.entries, float("nan")),
        (page.entries, 3),
        (page.entries, 4.5),
        (page.placement, "<b>nope</b>"),
        (page.interp, "cubic"),
    ):
        widget.value = bad
        assert page.error, bad
        assert "\n" not in page.error
        assert (page.placement.value, page.interp.value, page.entries.value) == (
            "error",
            "monotone",
            200,
        )
    page.entries.value = 64
    assert page.version > version
    assert page._good_options == ("error", "monotone", 64)


def test_messages_are_shown_as_text_never_as_markup(page, tmp_path):
    from bokeh.models import Div

    divs = list(page.doc.select({"type": Div}))
    assert len(divs) >= 4
    assert all(div.render_as_text for div in divs)
    hostile = tmp_path / "<img src=x onerror=alert(1)>.toml"
    hostile.write_text("[material]\nk_d = 0.2\n")
    page.path_input.value = str(hostile)
    page._on_open()
    assert "<img src=x onerror=alert(1)>.toml" in page.error_div.text
    assert page.error_div.styles["color"] == "#b00"


def test_saves_stay_in_their_folder_and_overwrite_on_a_second_press(page, tmp_path):
    outside = tmp_path.parent / f"{tmp_path.name}-outside"
    outside.mkdir()
    (tmp_path / "link").symlink_to(outside)
    for name in ("../x.toml", str(outside / "x.toml"), "link/x.toml", "notes.txt", " "):
        page.path_input.value = name
        page._on_save()
        assert page.error_div.styles["color"] == "#b00", name
    assert list(outside.iterdir()) == []
    assert not (tmp_path / "notes.txt").exists()
    # A new name inside the folder (or a sub-folder) is written at once.
    (tmp_path / "sub").mkdir()
    page.path_input.value = "sub/new.toml"
    page._on_save()
    assert page.error.startswith("saved ")
    assert (tmp_path / "sub" / "new.toml").is_file()
    # An existing file: the first press asks, the second overwrites.
    existing = tmp_path / "start.toml"
    text = existing.read_text()
    page.state.set_point("k_d", 2, 0.9)
    page.path_input.value = "start.toml"
    page._on_save()
    assert "press save again to overwrite" in page.error
    assert existing.read_text() == text
    page._on_save()
    assert page.error.startswith("saved ")
    assert existing.read_text() != text
    # The question is asked again for the next save.
    page._on_save()
    assert "press save again" in page.error


def test_the_difference_image_is_in_the_layout_with_a_gain_from_the_image(page):
    toggle = page.doc.select_one({"name": "difference"})
    assert toggle is not None  # in the page, not only made
    model = page.state.model()
    exact = render_exact_frame(model, resolution=RES)
    table = render_table_frame(model, resolution=RES, entries=8, placement="uniform")
    page._show("exact", (page.version, model, exact))
    page._show("table", (page.version, model, table))
    title = page.diff_plot.title.text
    gain = float(title.split("× ")[1].split()[0])
    assert gain > 1.0
    image = page.image_sources["diff"].data["image"][0].view(np.uint8).reshape(RES, RES, 4)
    assert image[..., :3].max() >= 250  # the worst difference is shown bright, not near black
    toggle.active = False
    assert page.diff_plot.visible is False


def test_preset_menus_name_their_curve(page):
    from bokeh.models import Select

    titles = {
        s.name: s.title for s in page.doc.select({"type": Select}) if s.name.endswith("_preset")
    }
    assert sorted(titles) == ["k_d_preset", "k_s_preset", "light_preset", "n_preset"]
    assert len(set(titles.values())) == 4
    menu = page.doc.select_one({"name": "light_preset"})
    menu.value = "illuminant FL2"
    assert page.sources["light"][1].data["x"].size == 81  # FL2's own 5 nm samples


def test_at_most_max_sessions_pages_are_served_and_a_closed_one_frees_its_place(tmp_path):
    from bokeh.document import Document
    from bokeh.models import Div

    from phong_table.editor.app import _page_maker

    make = _page_maker(None, "far", RES, tmp_path)
    docs = [Document() for _ in range(MAX_SESSIONS + 2)]
    for doc in docs:
        make(doc)

    def refused(doc):
        roots = list(doc.roots)
        return len(roots) == 1 and isinstance(roots[0], Div) and "pages are open" in roots[0].text

    def workers():
        return sum(t.name == "editor-worker" and t.is_alive() for t in threading.enumerate())

    assert [refused(d) for d in docs] == [False] * MAX_SESSIONS + [True, True]
    running = workers()
    assert running >= 2 * MAX_SESSIONS
    for callback in list(docs[0].callbacks.session_destroyed_callbacks):
        callback(None)  # the first page's tab is closed: its threads end, its place is free
    end = time.monotonic() + 30
    while workers() > running - 2 and time.monotonic() < end:
        time.sleep(0.05)
    assert workers() == running - 2
    again = Document()
    make(again)
    assert not refused(again)
    for doc in [*docs[1:MAX_SESSIONS], again]:
        for callback in list(doc.callbacks.session_destroyed_callbacks):
            callback(None)


def _get(port, host, path="/"):
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    connection.request("GET", path, headers={"Host": host})
    response = connection.getresponse()
    body = response.read()
    connection.close()
    return response.status, response.getheader("Location") or "", body


def _threads(pid) -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("Threads:"):
            return int(line.split()[1])
    raise AssertionError("no thread count")


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="reads /proc for threads")
def test_the_server_serves_its_own_host_and_a_bounded_number_of_pages():
    from phong_table.editor.browser import editor_server

    idle = 2.0
    with editor_server(resolution=RES, idle_seconds=idle) as (url, process):
        port = int(url.rstrip("/").rsplit(":", 1)[1])
        assert port != 0  # --port 0: the port bound, announced
        base = _threads(process.pid)
        # Another Host (a page whose DNS name was re-bound to 127.0.0.1) is refused.
        status, location, _ = _get(port, f"evil.example:{port}")
        assert status == 302
        assert location.startswith("/host-refused")
        status, _, body = _get(port, f"evil.example:{port}", "/host-refused")
        assert status == 403
        assert b"127.0.0.1" in body
        assert _get(port, f"localhost:{port}")[0] == 200
        # More page loads than the server serves: its threads stay bounded (two per page).
        for _ in range(MAX_SESSIONS + 2):
            assert _get(port, f"127.0.0.1:{port}")[0] == 200
        grown = _threads(process.pid) - base
        assert grown <= 2 * MAX_SESSIONS
        # Pages whose browser never connected are closed, and their threads end.
        end = time.monotonic() + 30 * idle
        while _threads(process.pid) > base + 1 and time.monotonic() < end:
            time.sleep(0.25)
        assert _threads(process.pid) <= base + 1
        assert process.poll() is None
    assert not os.path.exists(f"/proc/{process.pid}/status") or process.poll() is not None


def test_a_save_folder_that_is_not_a_folder_is_refused_before_the_server_starts(tmp_path, capsys):
    from validation.cli import main

    (tmp_path / "file").write_text("x")
    for folder in (tmp_path / "missing", tmp_path / "file"):
        assert main(["phong", "edit", "--port", "0", "--save-dir", str(folder)]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1
        assert "--save-dir: not a folder" in err
