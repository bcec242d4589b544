"""The material editor in a real browser (errata E28, E29): headless Chromium through Selenium.

Needs Debian's ``chromium`` and ``chromium-driver`` (``apt install chromium chromium-driver``;
``.ci/run`` installs them) and ``selenium`` (a test extra); skipped with that hint where missing.
The control point is dragged with the mouse (Selenium pointer actions at the pixel the plot's own
scales give); a second edit goes through the page's JS model (the ``data`` of the curve's
``ColumnDataSource``, which ``PointDrawTool`` writes). The buttons are clicked as a user clicks.
"""

import shutil
import subprocess
import sys

import numpy as np
import pytest

from phong_table.editor.state import EditorState
from phong_table.materialfile import load_material_file
from reference.browser import INSTALL_HINT, find_chromium

selenium = pytest.importorskip("selenium", reason="pip install selenium (a test extra)")
pytestmark = pytest.mark.skipif(
    find_chromium() is None or shutil.which("chromedriver") is None, reason=INSTALL_HINT
)


_INJECTED_JS = """
function images(root) {
    let count = root.querySelectorAll('img').length;
    for (const el of root.querySelectorAll('*')) {
        if (el.shadowRoot) { count += images(el.shadowRoot); }
    }
    return count;
}
return [window.injected !== undefined, images(document)];
"""


def test_an_edit_in_the_browser_renders_and_saves(tmp_path):
    from phong_table.editor.browser import (
        click_button,
        drag_control_point,
        editor_driver,
        editor_server,
        image_checksum,
        page_value,
        rms_shown,
        set_control_point,
        set_widget,
        wait_for,
    )

    start = EditorState.default()
    opened = start.save(tmp_path / "start.toml")
    with editor_server(opened) as (url, process), editor_driver() as driver:
        assert url.startswith("http://127.0.0.1:")
        driver.get(url)
        rms0 = wait_for(driver, rms_shown, 120, "the first RMS")
        frame0, image0 = page_value(driver, "frame"), image_checksum(driver)
        # A mouse drag of the k_s point at 500 nm: the table image and then the exact one change.
        drag_control_point(driver, "k_s", 3, 0.95)
        wait_for(driver, lambda d: page_value(d, "frame") != frame0, 30, "the edited frame")
        dragged = page_value(driver, "k_s_points", "data")["y"][3]
        assert dragged == pytest.approx(0.95, abs=0.02)  # one pixel of the plot is ~0.005
        wait_for(driver, lambda d: image_checksum(d) != image0, 30, "the new image")
        rms1 = wait_for(driver, lambda d: rms_shown(d) != rms0 and rms_shown(d), 30, "new RMS")
        # One edit through the page's JS model (its latency is a benchmark's, not this test's).
        frame1, image1 = page_value(driver, "frame"), image_checksum(driver)
        set_control_point(driver, "n", 0, 3000.0)
        wait_for(driver, lambda d: image_checksum(d) != image1, 30, "the image of the n edit")
        assert page_value(driver, "frame") != frame1
        rms2 = wait_for(
            driver,
            lambda d: rms_shown(d) not in (None, rms1) and rms_shown(d),
            30,
            "the n edit's RMS",
        )
        figures = " -> ".join(text.split()[1] for text in (rms0, rms1, rms2))
        print(f"\nRMS {figures}")  # noqa: T201
        # Save to a new file through the page's path field and its "save" button.
        saved = tmp_path / "saved.toml"
        set_widget(driver, "path", "value", str(saved))
        click_button(driver, "save")
        wait_for(driver, lambda d: saved.is_file(), 30, "the saved file")
        wait_for(driver, lambda d: "saved" in page_value(d, "error"), 30, "the saved message")
        # A file that fails to parse, named as markup: the one-line error on the page, shown as
        # text (no element made, no script run); saving does not touch the file.
        bad = tmp_path / "<img src=x onerror=window.injected=1>.toml"
        bad.write_text("[material]\nk_d = 0.2\n")
        set_widget(driver, "path", "value", str(bad))
        click_button(driver, "open")
        wait_for(driver, lambda d: "<img" in (page_value(d, "error") or ""), 30, "error")
        message = page_value(driver, "error")
        assert "k_s" in message
        assert "\n" not in message
        assert driver.execute_script(_INJECTED_JS) == [False, 0]
        click_button(driver, "save")
        wait_for(driver, lambda d: "not overwritten" in page_value(d, "error"), 30, "refusal")
        assert bad.read_text() == "[material]\nk_d = 0.2\n"
        # The difference image's toggle is on the page and hides the image.
        assert page_value(driver, "diff_plot", "visible") is True
        click_button(driver, "difference image")
        wait_for(driver, lambda d: page_value(d, "diff_plot", "visible") is False, 30, "hidden")
        assert process.poll() is None
    # The saved file holds the edit and `specref phong --material` accepts it.
    model = load_material_file(saved)
    wl = model.grid.wavelengths_nm.tolist()
    assert model.material.k_s[wl.index(500.0)] == pytest.approx(dragged)
    assert model.material.n[0] == pytest.approx(3000.0)
    np.testing.assert_allclose(model.material.k_d, start.curve("k_d"))
    command = [sys.executable, "-m", "validation.cli", "phong", "--material", str(saved)]
    command += ["--resolution", "24", "--repeats", "1", "--entries", "32"]
    run = subprocess.run(
        command,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert run.returncode == 0, run.stderr
