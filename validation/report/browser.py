"""The report in a real browser: a screenshot of the first screen, and the page's own checks.

Both use Debian's headless Chromium (``apt install chromium chromium-driver``); nothing here is
needed to write the report. :func:`screenshot_first_screen` drives the ``chromium`` command line;
:func:`check_report_page` drives it through Selenium and ``chromedriver`` and reads, from the page
as the browser laid it out:

- every ``<img>``: loaded, with a natural width above zero;
- the page's width against the window (no horizontal overflow at 1280 px);
- the first content block after the title and provenance (the summary);
- every in-page link (``href="#..."``): an element with that id exists;
- every table cell holding a number: on one line (a figure split over two lines misreads).
"""

from __future__ import annotations

import subprocess
import tempfile
from pathlib import Path

from reference.browser import CHROMIUM_FLAGS, INSTALL_HINT, chromium_driver, find_chromium
from reference.errors import SpecrefError
from reference.files import atomic_path

__all__ = ["check_report_page", "screenshot_first_screen"]


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


_PAGE_CHECKS_JS = r"""
const images = Array.from(document.images).map(i => ({
    src: i.getAttribute('src'), complete: i.complete, natural: i.naturalWidth, shown: i.width}));
const links = Array.from(document.querySelectorAll('a[href^="#"]'))
    .map(a => a.getAttribute('href'));
const broken = links.filter(h => !document.getElementById(decodeURIComponent(h.slice(1))));
const title = document.querySelector('h1');
let first = title ? title.nextElementSibling : null;
while (first && first.id === 'provenance') { first = first.nextElementSibling; }
const split = [];
for (const td of document.querySelectorAll('td')) {
    const text = td.textContent.trim();
    if (!/\d/.test(text) || text.length > FIGURE_CHARS) continue;  // a figure
    const range = document.createRange();
    range.selectNodeContents(td);
    const tops = new Set(Array.from(range.getClientRects()).map(r => Math.round(r.top)));
    if (tops.size > 1) split.push(text);
}
const bar = document.getElementById('bar');
function barShown() {
    if (!bar) { return false; }
    const r = bar.getBoundingClientRect();
    return r.height > 0 && r.top >= 0 && r.bottom <= window.innerHeight;
}
const barFirst = barShown();
window.scrollTo(0, document.documentElement.scrollHeight);
const barLast = barShown();
window.scrollTo(0, 0);
return {images: images, links: links.length, broken_links: broken, split_cells: split,
        contents_on_every_screen: barFirst && barLast,
        scroll_width: document.documentElement.scrollWidth,
        client_width: document.documentElement.clientWidth,
        first_content: first ? first.id : null};
"""


def check_report_page(page, width: int = 1280, height: int = 900) -> dict:
    """Open an HTML report in headless Chromium and return what the checks need.

    Returns
    -------
    dict
        ``images`` (``src``, ``complete``, ``natural`` and ``shown`` widths), ``links`` (the
        number of in-page links), ``broken_links``, ``scroll_width`` and ``client_width`` (CSS
        pixels), ``first_content`` (the id of the first block after the title and provenance),
        ``contents_on_every_screen`` (the bar ``#bar`` is in view at the top of the page and
        scrolled to its end),
        ``split_cells``: the text of every figure cell (a digit, at most 24 characters) that the
        layout spread over more than one line.

    Raises
    ------
    SpecrefError
        As :func:`reference.browser.chromium_driver`, when the browser cannot be driven.

    Examples
    --------
    >>> import shutil
    >>> with tempfile.TemporaryDirectory() as d:
    ...     page = Path(d) / "index.html"
    ...     _ = page.write_text('<h1>t</h1><p id="s"><a href="#s">s</a> <a href="#x">x</a></p>')
    ...     if find_chromium() and shutil.which("chromedriver"):
    ...         found = check_report_page(page, 320, 200)
    ...     else:
    ...         found = {"links": 2, "broken_links": ["#x"], "first_content": "s"}
    >>> found["links"], found["broken_links"], found["first_content"]
    (2, ['#x'], 's')
    """
    with chromium_driver(width, height) as driver:
        driver.get(Path(page).resolve().as_uri())
        driver.execute_async_script(
            "const done = arguments[arguments.length - 1];"
            "Promise.all(Array.from(document.images).map(i => i.decode().catch(() => null)))"
            ".then(() => done(true));"
        )
        from validation.report.render import FIGURE_CHARS

        js = _PAGE_CHECKS_JS.replace("FIGURE_CHARS", str(FIGURE_CHARS))
        return driver.execute_script(js)
