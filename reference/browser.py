"""Headless Chromium, for the pages specref writes: the report's checks and the editor's screenshot.

Debian's ``chromium`` and ``chromium-driver`` (``apt install chromium chromium-driver``) are driven
either from the command line or through Selenium; nothing here is needed to render or to write a
page. The flags keep Chromium from reaching the network, which closed CI machines refuse.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile

from reference.errors import SpecrefError, require

__all__ = ["CHROMIUM_FLAGS", "INSTALL_HINT", "chromium_driver", "find_chromium"]


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


@contextlib.contextmanager
def chromium_driver(width: int = 1280, height: int = 900, page_load_timeout: float = 120):
    """A headless Chromium driven by Selenium and ``chromedriver`` (fresh profile, HOME set to it).

    Raises
    ------
    SpecrefError
        Chromium, chromedriver or Selenium missing (with how to install them).

    Examples
    --------
    >>> if find_chromium() and shutil.which("chromedriver"):
    ...     with chromium_driver(320, 200) as driver:
    ...         driver.get("data:text/html,<title>specref</title>")
    ...         title = driver.title
    ... else:
    ...     title = "specref"
    >>> title
    'specref'
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
