"""The report in a real browser: a screenshot of the first screen, and the page's own checks.

Both use Debian's headless Chromium (``apt install chromium chromium-driver``); nothing here is
needed to write the report. :func:`screenshot_first_screen` drives the ``chromium`` command line;
:func:`check_report_page` drives it through Selenium and ``chromedriver`` and reads, from the page
as the browser laid it out:

- every ``<img>``: loaded, with a natural width above zero;
- the page's width against the window (no horizontal overflow at 1280 px);
- the first content block after the title and provenance (the summary);
- every in-page link (``href="#..."``): an element with that id exists.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

from reference.errors import SpecrefError, require
from reference.images import atomic_path

__all__ = ["CHROMIUM_FLAGS", "INSTALL_HINT", "find_chromium", "screenshot_first_screen"]

#: How to install what this module needs on Debian.
INSTALL_HINT = (
    "install Debian's chromium and chromium-driver (apt install chromium chromium-driver)"
)

#: Headless flags: no GPU, no sandbox (CI runs as root), and no background network traffic,
#: which a closed network refuses.
CHROMIUM_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
)


def find_chromium() -> str | None:
    """The Chromium executable on ``PATH`` (``chromium``, ``chromium-browser``), or None.

    Examples
    --------
    >>> find_chromium() in (None, shutil.which("chromium"), shutil.which("chromium-browser"))
    True
    """
    for name in ("chromium", "chromium-browser"):
        path = shutil.which(name)
        if path:
            return path
    return None


def screenshot_first_screen(page, out, width: int = 1280, height: int = 900) -> str:
    """Write a PNG of the first ``width × height`` CSS pixels of an HTML page, atomically.

    Parameters
    ----------
    page : str or Path
        The HTML file.
    out : str or Path
        The PNG to write.

    Returns
    -------
    str
        ``"written"``, or why not (Chromium missing or failing), for ``results.json``.

    Examples
    --------
    >>> with tempfile.TemporaryDirectory() as d:
    ...     page = Path(d) / "index.html"
    ...     _ = page.write_text("<h1>specref</h1>")
    ...     status = screenshot_first_screen(page, Path(d) / "shot.png", 320, 200)
    >>> status == "written" or status.startswith("not written")
    True
    """
    chromium = find_chromium()
    if chromium is None:
        return f"not written: {INSTALL_HINT}"
    url = Path(page).resolve().as_uri()
    with tempfile.TemporaryDirectory() as profile, atomic_path(out, suffix=".png") as tmp:
        command = [
            chromium,
            *CHROMIUM_FLAGS,
            f"--user-data-dir={profile}",
            f"--window-size={width},{height}",
            f"--screenshot={tmp}",
            url,
        ]
        try:
            done = subprocess.run(command, capture_output=True, timeout=120, check=False)
        except (OSError, subprocess.SubprocessError) as exc:
            return f"not written: chromium failed ({exc})"
        if done.returncode != 0 or not Path(tmp).is_file() or Path(tmp).stat().st_size == 0:
            tail = done.stderr.decode(errors="replace").strip().splitlines()[-1:] or [""]
            raise SpecrefError(f"{out}: chromium could not take the screenshot: {tail[0]}")
    return "written"


_PAGE_CHECKS_JS = """
const images = Array.from(document.images).map(i => ({
    src: i.getAttribute('src'), complete: i.complete, natural: i.naturalWidth, shown: i.width}));
const links = Array.from(document.querySelectorAll('a[href^="#"]'))
    .map(a => a.getAttribute('href'));
const broken = links.filter(h => !document.getElementById(decodeURIComponent(h.slice(1))));
const title = document.querySelector('h1');
let first = title ? title.nextElementSibling : null;
while (first && first.id === 'provenance') { first = first.nextElementSibling; }
return {images: images, links: links.length, broken_links: broken,
        scroll_width: document.documentElement.scrollWidth,
        client_width: document.documentElement.clientWidth,
        first_content: first ? first.id : null};
"""


@contextlib.contextmanager
def chromium_driver(width: int = 1280, height: int = 900, page_load_timeout: float = 120):
    """A headless Chromium driven by Selenium and ``chromedriver`` (fresh profile, HOME set to it).

    Raises
    ------
    SpecrefError
        Chromium, chromedriver or Selenium missing (with how to install them).
    """
    chromium = find_chromium()
    driver_path = shutil.which("chromedriver")
    require(chromium is not None and driver_path is not None, f"headless Chromium: {INSTALL_HINT}")
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError as exc:  # pragma: no cover - selenium is a test extra
        raise SpecrefError(f"headless Chromium: pip install selenium ({exc})") from exc
    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for flag in CHROMIUM_FLAGS:
        options.add_argument(flag)
    with tempfile.TemporaryDirectory() as profile:
        options.add_argument(f"--user-data-dir={profile}")
        options.add_argument(f"--window-size={width},{height}")
        service = Service(executable_path=driver_path, env={**os.environ, "HOME": profile})
        driver = webdriver.Chrome(options=options, service=service)
        try:
            driver.set_page_load_timeout(page_load_timeout)
            yield driver
        finally:
            driver.quit()


def check_report_page(page, width: int = 1280, height: int = 900) -> dict:
    """Open an HTML report in headless Chromium and return what the checks need.

    Returns
    -------
    dict
        ``images`` (``src``, ``complete``, ``natural`` and ``shown`` widths), ``links`` (the
        number of in-page links), ``broken_links``, ``scroll_width`` and ``client_width`` (CSS
        pixels), ``first_content`` (the id of the first block after the title and provenance).

    Raises
    ------
    SpecrefError
        Chromium, chromedriver or Selenium missing (with how to install them).
    """
    with chromium_driver(width, height) as driver:
        driver.get(Path(page).resolve().as_uri())
        driver.execute_async_script(
            "const done = arguments[arguments.length - 1];"
            "Promise.all(Array.from(document.images).map(i => i.decode().catch(() => null)))"
            ".then(() => done(true));"
        )
        return driver.execute_script(_PAGE_CHECKS_JS)
