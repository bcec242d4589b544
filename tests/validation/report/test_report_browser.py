"""The report in a real browser, as its readers open it.

Needs Debian's ``chromium`` and ``chromium-driver`` (``apt install chromium chromium-driver``;
``.ci/run`` installs them); skipped with that hint where they are missing.
"""

import shutil

import pytest

from reference.browser import INSTALL_HINT, find_chromium
from validation.report.browser import check_report_page
from validation.report.runner import PARTS, run_report
from validation.report.sections import impastor, phong, polymer_scene
from validation.report.sections.phong import PhongStudy

pytestmark = pytest.mark.skipif(
    find_chromium() is None or shutil.which("chromedriver") is None, reason=INSTALL_HINT
)


#: One section of each part, the cheap ones (about half a minute in all): the page's layout,
#: summary and links are the same code whatever the sections; each section's own blocks are
#: checked by its test.
SMALL_REPORT = ("spectral-core", "phong", "polymer-scene", "impastor")


#: The Phong section's tiny sizes (an 8² image, one material): the page, not the figures, is tested.
PHONG_TINY = PhongStudy(8, False, 1, (25,), ("R1",), ("near",), (10,), (50,), (10,), 64, True)
#: The polymer scene's bottle on a coarse mesh in a 16 × 20 frame.
POLYMER_SCENE_TINY = {"around": 16, "profile": 13, "width": 16, "height": 20}


@pytest.fixture(scope="module")
def quick_report(tmp_path_factory):
    # Every part's page on small sizes: the Phong and ImpastoR sections on their tiny settings
    out = tmp_path_factory.mktemp("report")
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(phong, "QUICK", PHONG_TINY)
        patch.setattr(impastor, "QUICK", impastor.TINY)
        patch.setitem(polymer_scene.SETTINGS, "quick", POLYMER_SCENE_TINY)
        results = run_report(out, "quick", only=list(SMALL_REPORT), progress=False, screenshot=True)
    return out, results


def test_the_small_report_has_a_section_of_every_part():
    for part in PARTS:
        assert {s.name for s in part.sections} & set(SMALL_REPORT), part.name


def test_quick_report_reads_in_a_browser(quick_report):
    out, _results = quick_report
    page = check_report_page(out / "index.html", width=1280)
    # Every picture loads, at least 256 CSS pixels wide.
    assert page["images"], "the report shows no images"
    broken = [i["src"] for i in page["images"] if not i["complete"] or i["natural"] <= 0]
    assert broken == []
    narrow = [(i["src"], i["shown"]) for i in page["images"] if i["shown"] < 256]
    assert narrow == []
    # Nothing overflows the page horizontally at 1280 px, and no figure is split over two lines
    assert page["scroll_width"] <= page["client_width"]
    assert page["split_cells"] == []
    # The summary is the first content, and every in-page link resolves.
    assert page["first_content"] == "summary"
    # The bar (the parts, the contents menu, the way up) is on the first screen and the last.
    assert page["contents_on_every_screen"]
    assert page["broken_links"] == []
    assert page["links"] >= 2 * len(SMALL_REPORT)
    # Each part of the summary states figures and links to its sections.
    html = (out / "index.html").read_text()
    summary = html[html.index("id='summary'") : html.index("<nav>")]
    for part in PARTS:
        block = summary[summary.index(f"id='summary-{part.name}'") :]
        block = block[: block.index("</div></div>")]
        shown = [s for s in part.sections if s.name in SMALL_REPORT]
        assert block.count("<li>") >= 1 + len(shown), part.name


def test_first_screen_screenshot_is_written(quick_report):
    from PIL import Image

    out, results = quick_report
    assert results["meta"]["screenshot"] == "written"
    with Image.open(out / "first-screen.png") as shot:
        assert shot.size == (1280, 900)
        # Not a blank page: the first screen has text and pictures (many distinct colours).
        assert len(shot.convert("RGB").getcolors(maxcolors=1 << 20) or []) > 50


def test_the_page_check_finds_a_figure_split_over_two_lines(tmp_path):
    # The check can fail: a narrow cell that may break anywhere splits "0.00672 / 7"; the report's
    # own cells (class n) do not
    page = tmp_path / "split.html"
    cell = "<td style='width:3em;max-width:3em;overflow-wrap:anywhere'>0.00672 / 7</td>"
    kept = "<td class='n' style='white-space:nowrap'>0.00672 / 7</td>"
    # and a bar that scrolls away with the page is found out
    bar = "<nav id='bar'>contents</nav>"
    tall = "<p style='height:2000px'>a long section</p>"
    page.write_text(f"{bar}<h1>t</h1><table style='width:6em'><tr>{cell}{kept}</tr></table>{tall}")
    found = check_report_page(page, width=400, height=300)
    assert found["split_cells"] == ["0.00672 / 7"]
    assert found["contents_on_every_screen"] is False
