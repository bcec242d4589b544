"""The report's HTML and Markdown renderings (``index.html``, ``docs/results.md``).

Both follow the same order, written for a reader rather than a test log (the HTML page also has
a bar on every screen, :func:`_html_bar`: the summary, each part, a contents menu and the way back
to the top; each section has its own "↑ top"):

1. provenance (commit, date, mode, cores, run time);
2. the summary: one block per part (each paper, and the shared core) with a hero image, the
   headline figures beside their anchors, and how many targets hold, linking to the sections;
3. the sections, each with its own targets folded (``<details>``), the failing ones shown open
   and marked;
4. every target in one table, at the end.

Images narrower than :data:`MIN_WIDTH` are enlarged by a whole factor without smoothing
(``image-rendering: pixelated``), their true size in the caption; a click opens the file.
"""

from __future__ import annotations

import html
import math

import numpy as np

from validation.report.types import (
    CHECK_BASES,
    Image,
    ReportPart,
    ReportSection,
    SectionResult,
    Table,
    Text,
)

__all__ = ["MIN_WIDTH", "render_html", "render_markdown", "shown_size"]

#: Narrowest width (CSS pixels) at which the page shows an image.
MIN_WIDTH = 256

#: Widest width at which the page shows an image (the text column).
MAX_WIDTH = 1060


#: A text cell this short that holds a digit is a figure ("0.00672 / 7"): kept on one line.
FIGURE_CHARS = 24


def _td(value, fmt: str) -> str:
    """A table cell: class ``n`` (never wrapped) for a number or a short text holding one."""
    text = _cell(value, fmt)
    figure = not isinstance(value, str) or (
        len(text) <= FIGURE_CHARS and any(c.isdigit() for c in text)
    )
    return f"<td class='n'>{html.escape(text)}</td>" if figure else f"<td>{html.escape(text)}</td>"


def _cell(value, fmt: str) -> str:
    if value is None:  # not measured (e.g. a figure an older benchmark file lacks)
        return "—"
    if isinstance(value, float | np.floating):
        return fmt.format(float(value)) if math.isfinite(value) else "—"
    return str(value)


def shown_size(width: int, height: int) -> tuple[int, int, int]:
    """The whole enlargement factor and the size at which the page shows an image.

    Examples
    --------
    >>> shown_size(48, 48), shown_size(98, 48), shown_size(600, 400), shown_size(0, 0)
    ((6, 288, 288), (3, 294, 144), (1, 600, 400), (1, 0, 0))
    """
    factor = math.ceil(MIN_WIDTH / width) if 0 < width < MIN_WIDTH else 1
    return factor, width * factor, height * factor


def _caption(block: Image) -> str:
    """The caption, with the true size when the page enlarges the image."""
    factor, _, _ = shown_size(block.width, block.height)
    if factor == 1:
        return block.caption
    size = f"true size {block.width}×{block.height} px, shown ×{factor}"
    return f"{block.caption} ({size})" if block.caption else f"({size})"


_CSS = " ".join(
    [
        "body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;",
        "line-height:1.45;color:#222} p,li,figcaption{overflow-wrap:anywhere}",
        # a figure never splits across lines (td.n: a number, or a short text holding one; a wide
        # table scrolls in its .scroll box); other cells wrap at spaces only
        "td{overflow-wrap:normal} td.n{white-space:nowrap}",
        ".scroll{overflow-x:auto;max-width:100%}",
        "table{border-collapse:collapse;margin:.6em 0 1.4em}",
        "td,th{border:1px solid #ccc;padding:.25em .6em;text-align:right;",
        "font-variant-numeric:tabular-nums}",
        "th{background:#f3f3f3} td:first-child,th:first-child{text-align:left}",
        "caption{caption-side:top;text-align:left;font-weight:600;padding:.3em 0}",
        "figure{display:inline-block;margin:.5em 1em .5em 0;vertical-align:top;max-width:100%}",
        "figcaption{font-size:.9em;color:#444;max-width:640px}",
        "img{max-width:100%;height:auto} img.pixelated{image-rendering:pixelated}",
        "code{background:#f5f5f5;padding:0 .2em} .meta{color:#555;font-size:.9em}",
        ".part{border:1px solid #ddd;border-radius:6px;padding:.6em 1em;margin:.8em 0;",
        "display:flex;gap:1.2em;align-items:flex-start} .part img{max-width:300px}",
        ".part h3{margin:.1em 0 .3em} .part ul{margin:.3em 0;padding-left:1.2em}",
        ".anchor{color:#666} .fail{color:#a00;font-weight:600} .ok{color:#060}",
        ".banner{margin:2.2em 0 0;padding:.3em .6em;background:#eef2f7;font-weight:600}",
        "details{margin:.4em 0 1em} summary{cursor:pointer}",
        # the bar: on every screen, the parts, the contents (a menu) and the way back up
        ".bar{position:sticky;top:0;z-index:10;background:#fff;border-bottom:1px solid #ddd;",
        "padding:.35em 0;display:flex;flex-wrap:wrap;gap:.3em 1em;align-items:baseline;",
        "font-size:.92em} .bar details{margin:0;position:relative}",
        ".bar details ul{position:absolute;left:0;top:1.6em;background:#fff;border:1px solid #ccc;",
        "border-radius:4px;padding:.4em 1em .4em 1.6em;margin:0;max-height:70vh;overflow-y:auto;",
        "width:max-content;max-width:90vw;box-shadow:0 2px 8px rgba(0,0,0,.15)}",
        "section{scroll-margin-top:2.6em} .banner,#top{scroll-margin-top:2.6em}",
        "a.up{float:right;margin-top:1.6em;font-size:.85em;color:#666}",
    ]
)


def _html_text(text: str) -> str:
    pieces = html.escape(text).split("`")
    return "".join(p if i % 2 == 0 else f"<code>{p}</code>" for i, p in enumerate(pieces))


def _html_image(block: Image, css_class: str = "") -> str:
    esc = html.escape
    factor, width, height = shown_size(block.width, block.height)
    size = f" width='{width}' height='{height}'" if width else ""
    classes = " ".join(c for c in (css_class, "pixelated" if factor > 1 else "") if c)
    klass = f" class='{classes}'" if classes else ""
    return (
        f"<a href='{esc(block.path)}'><img src='{esc(block.path)}'{size}{klass} "
        f"alt='{esc(block.caption)}'></a>"
    )


def _html_checks(rows, with_section: bool) -> str:
    esc = html.escape
    head = "<th>section</th>" if with_section else ""
    out = [
        f"<div class='scroll'><table><tr>{head}<th>check</th><th>target</th><th>measured</th>"
        "<th>measured on</th><th>holds</th></tr>"
    ]
    for section, c in rows:
        mark = "<span class='ok'>yes</span>" if c.passed else "<span class='fail'>NO</span>"
        first = f"<td>{esc(section.title)}</td>" if with_section else ""
        out.append(
            f"<tr>{first}<td>{esc(c.name)}</td>{_td(c.target, '{}')}"
            f"{_td(c.measured, '{:.4g}')}<td>{esc(_basis(c))}</td>"
            f"<td>{mark}</td></tr>"
        )
    out.append("</table></div>")
    return "".join(out)


def _basis(check) -> str:
    """What a check is measured on, as its table shows it (``CHECK_BASES``)."""
    return check.basis or "not stated"


def _count(checks) -> str:
    """How many targets hold; then, once any states its basis, the count per basis."""
    failed = sum(not c.passed for c in checks)
    text = f"{len(checks) - failed} of {len(checks)} targets hold"
    text += f"; {failed} do not" if failed else ""
    if not any(c.basis for c in checks):
        return text
    parts = []
    for basis in (*CHECK_BASES, ""):
        group = [c for c in checks if c.basis == basis]
        if group:
            held = sum(c.passed for c in group)
            parts.append(f"{basis or 'not stated'} {held} of {len(group)}")
    return f"{text} (measured on {', '.join(parts)})"


def _first_image(results: list[SectionResult], sections: list[ReportSection]) -> Image | None:
    """The part's hero: a section's named hero image, else the first image of the part."""
    for section, result in zip(sections, results, strict=True):
        for block in result.blocks:
            if (
                isinstance(block, Image)
                and section.hero
                and block.path.endswith(f"{section.name}-{section.hero}.png")
            ):
                return block
    for result in results:
        for block in result.blocks:
            if isinstance(block, Image):
                return block
    return None


def _part_results(part: ReportPart, done) -> tuple[list, list]:
    by_name = {s.name: (s, r) for s, r in done}
    pairs = [by_name[s.name] for s in part.sections if s.name in by_name]
    return [s for s, _ in pairs], [r for _, r in pairs]


def _html_summary(parts: list[ReportPart], done) -> list[str]:
    esc = html.escape
    checks = [c for _, r in done for c in r.checks]
    out = [
        "<section id='summary'><h2>Summary</h2>",
        f"<p>{_count(checks)} (<a href='#targets'>all targets</a>).</p>",
    ]
    for part in parts:
        sections, results = _part_results(part, done)
        if not sections:
            continue
        out.append(f"<div class='part' id='summary-{esc(part.name)}'>")
        hero = _first_image(results, sections)
        if hero is not None:
            out.append(f"<div>{_html_image(hero)}</div>")
        out.append(f"<div><h3>{esc(part.title)}</h3><p>{esc(part.about)}</p><ul>")
        for result in results:
            for line in result.headlines:
                anchor = f" <span class='anchor'>({esc(line.anchor)})</span>" if line.anchor else ""
                out.append(f"<li>{_html_text(line.text)}{anchor}</li>")
        out.append("</ul><ul>")
        for section, result in zip(sections, results, strict=True):
            state = ""
            if result.checks:
                failed = any(not c.passed for c in result.checks)
                klass = "fail" if failed else "ok"
                state = f": <span class='{klass}'>{_count(result.checks)}</span>"
            out.append(f"<li><a href='#{esc(section.name)}'>{esc(section.title)}</a>{state}</li>")
        out.append("</ul></div></div>")
    out.append("</section>")
    return out


def _html_blocks(blocks) -> list[str]:
    esc = html.escape
    out = []
    for block in blocks:
        if isinstance(block, Text):
            out.append(f"<p>{_html_text(block.text)}</p>")
        elif isinstance(block, Table):
            out.append(f"<div class='scroll'><table><caption>{esc(block.caption)}</caption><tr>")
            out.extend(f"<th>{esc(str(c))}</th>" for c in block.columns)
            out.append("</tr>")
            for row in block.rows:
                cells = "".join(_td(v, block.fmt) for v in row)
                out.append(f"<tr>{cells}</tr>")
            out.append("</table></div>")
        elif isinstance(block, Image):
            out.append(
                f"<figure>{_html_image(block)}<figcaption>{esc(_caption(block))}"
                "</figcaption></figure>"
            )
    return out


def _html_section(section: ReportSection, result: SectionResult) -> list[str]:
    esc = html.escape
    up = "<a class='up' href='#top'>↑ top</a>"
    out = [f"<section id='{esc(section.name)}'>{up}<h2>{esc(section.title)}</h2>"]
    failed = [(section, c) for c in result.checks if not c.passed]
    if failed:
        out.append("<p class='fail'>Targets that do not hold:</p>")
        out.append(_html_checks(failed, with_section=False))
    if result.checks:
        out.append(
            f"<details><summary>Targets: {_count(result.checks)}</summary>"
            + _html_checks([(section, c) for c in result.checks], with_section=False)
            + "</details>"
        )
    out.extend(_html_blocks(result.blocks))
    settings = "quick" if result.quick else "full"
    out.append(
        f"<p class='meta'>Section time {result.seconds:.1f} s ({settings} settings).</p></section>"
    )
    return out


def _html_bar(parts: list[ReportPart], sections, pending) -> str:
    """The bar at the top of every screen: the summary, each part, a contents menu, the top.

    Examples
    --------
    >>> s, t = ReportSection("s", "S"), ReportSection("t", "T")
    >>> parts = [ReportPart("a", "Part A", "", (s,)), ReportPart("b", "Part B", "", (t,))]
    >>> bar = _html_bar(parts, [(s, None)], [t])
    >>> "href='#part-a'" in bar, "href='#part-b'" in bar, "Contents (2 sections)" in bar
    (True, False, True)
    """
    esc = html.escape
    listed = [s for s, _ in sections] + list(pending)
    items = "".join(f"<li><a href='#{esc(s.name)}'>{esc(s.title)}</a></li>" for s in listed)
    links = ["<a href='#top'>↑ top</a>", "<a href='#summary'>Summary</a>"]
    if len(parts) > 1:  # the parts with a section on the page (each has its banner)
        done = {s.name for s, _ in sections}
        shown = [p for p in parts if any(s.name in done for s in p.sections)]
        links += [f"<a href='#part-{esc(p.name)}'>{esc(p.title)}</a>" for p in shown]
    links.append("<a href='#targets'>All targets</a>")
    menu = (
        f"<details><summary>Contents ({len(listed)} sections)</summary><ul>{items}"
        "<li><a href='#targets'>All targets</a></li></ul></details>"
    )
    return f"<nav class='bar' id='bar'>{menu}{' '.join(links)}</nav>"


def _html_pending(pending) -> list[str]:
    """The sections a run has not reached yet: a heading each, saying so."""
    esc = html.escape
    return [
        f"<section id='{esc(s.name)}' class='pending'><h2>{esc(s.title)}</h2>"
        "<p class='meta'>Still to come: this run has not reached this section yet.</p></section>"
        for s in pending
    ]


def _meta_line(meta: dict) -> str:
    keys = ("commit", "date", "mode", "cores", "total_seconds", "python", "machine", "benchmarks")
    names = {"total_seconds": "run time (s)"}
    return ", ".join(f"{names.get(k, k)}: {meta[k]}" for k in keys if k in meta)


def render_html(title: str, meta: dict, sections, parts=None, pending=()) -> str:
    """The report as one HTML page: provenance, summary, the sections, then every target.

    Parameters
    ----------
    title : str
        Page title.
    meta : dict
        Provenance (commit, date, mode, cores, run time, ...).
    sections : list of (ReportSection, SectionResult)
        The sections that ran, in order.
    parts : list of ReportPart, optional
        The summary's parts; default one part holding every section.
    pending : sequence of ReportSection
        Sections still to come (a run in progress): listed as such in the contents and the page.

    Examples
    --------
    >>> from validation.report.types import Check
    >>> section = ReportSection("demo", "Demo")
    >>> page = render_html("t", {"mode": "quick"}, [(section, SectionResult(
    ...     [Text("a `b`")], {}, [Check("x", "<= 1", 0.5, True)]))])
    >>> "<code>b</code>" in page, "1 of 1 targets hold" in page
    (True, True)
    >>> page.index("id='summary'") < page.index("id='demo'") < page.index("id='targets'")
    True
    >>> "Still to come" in render_html("t", {}, [], pending=[ReportSection("later", "Later")])
    True
    """
    esc = html.escape
    if parts is None:
        parts = [ReportPart("all", title, "", tuple(s for s, _ in sections))]
    parts_html = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        "<meta name='viewport' content='width=device-width, initial-scale=1'>",
        f"<title>{esc(title)}</title>",
        f"<style>{_CSS}</style></head><body>",
        _html_bar(parts, sections, pending),
        f"<h1 id='top'>{esc(title)}</h1>",
        f"<p class='meta' id='provenance'>{esc(_meta_line(meta))}</p>",
    ]
    parts_html += _html_summary(parts, sections)
    parts_html.append("<nav><h2>Contents</h2><ul>")
    for section, result in sections:
        parts_html.append(
            f"<li><a href='#{esc(section.name)}'>{esc(section.title)}</a> "
            f"<span class='meta'>({result.seconds:.1f} s)</span></li>"
        )
    for section in pending:
        parts_html.append(
            f"<li><a href='#{esc(section.name)}'>{esc(section.title)}</a> "
            "<span class='meta'>(still to come)</span></li>"
        )
    parts_html.append("<li><a href='#targets'>All targets</a></li></ul></nav>")
    by_name = {s.name: (s, r) for s, r in sections}
    for part in parts:
        members = [by_name[s.name] for s in part.sections if s.name in by_name]
        if not members:
            continue
        if len(parts) > 1:
            parts_html.append(
                f"<div class='banner' id='part-{esc(part.name)}'>{esc(part.title)}</div>"
            )
        for section, result in members:
            parts_html += _html_section(section, result)
    parts_html += _html_pending(pending)
    checks = [(s, c) for s, r in sections for c in r.checks]
    count = _count([c for _, c in checks])
    count += f" so far ({len(pending)} sections still to come)" if pending else ""
    parts_html.append(f"<section id='targets'><h2>All targets</h2><p>{count}.</p>")
    if checks:
        parts_html.append(_html_checks(checks, with_section=True))
    parts_html.append("</section></body></html>")
    return "\n".join(parts_html)


def _md_checks(rows, with_section: bool) -> list[str]:
    head = "| section " if with_section else ""
    lines = [
        f"{head}| check | target | measured | measured on | holds |",
        "|---" * (5 + with_section) + "|",
    ]
    for section, c in rows:
        first = f"| {section.title} " if with_section else ""
        holds = "yes" if c.passed else "**NO**"
        measured = _cell(c.measured, "{:.4g}")
        lines.append(f"{first}| {c.name} | {c.target} | {measured} | {_basis(c)} | {holds} |")
    return lines


def _md_image(block: Image, prefix: str) -> str:
    _, width, _ = shown_size(block.width, block.height)
    path = f"{prefix}{block.path}"
    if width and width != block.width:
        alt = html.escape(block.caption)
        return (
            f"<a href='{path}'><img src='{path}' width='{width}' alt='{alt}' "
            "style='image-rendering:pixelated'></a>"
        )
    return f"![{block.caption}]({path})"


def _md_summary(parts, sections, prefix: str) -> list[str]:
    checks = [c for _, r in sections for c in r.checks]
    lines = ["## Summary", "", f"{_count(checks)} ([all targets](#all-targets)).", ""]
    for part in parts:
        members, results = _part_results(part, sections)
        if not members:
            continue
        lines += [f"### {part.title}", "", part.about, ""]
        hero = _first_image(results, members)
        if hero is not None:
            lines += [_md_image(hero, prefix), ""]
        for result in results:
            for line in result.headlines:
                lines.append(f"- {line.text}" + (f" ({line.anchor})" if line.anchor else ""))
        for section, result in zip(members, results, strict=True):
            state = f": {_count(result.checks)}" if result.checks else ""
            lines.append(f"- [{section.title}](#{_md_anchor(section.title)}){state}")
        lines.append("")
    return lines


def _md_anchor(title: str) -> str:
    """GitHub's heading anchor: lower case, punctuation dropped, spaces as hyphens."""
    kept = "".join(c for c in title.lower() if c.isalnum() or c in " -_")
    return kept.replace(" ", "-")


def _md_blocks(blocks, prefix: str) -> list[str]:
    lines = []
    for block in blocks:
        if isinstance(block, Text):
            lines += [block.text, ""]
        elif isinstance(block, Table):
            if block.caption:
                lines += [f"**{block.caption}**", ""]
            lines.append("| " + " | ".join(str(c) for c in block.columns) + " |")
            lines.append("|" + "---|" * len(block.columns))
            for row in block.rows:
                lines.append("| " + " | ".join(_cell(v, block.fmt) for v in row) + " |")
            lines.append("")
        elif isinstance(block, Image):
            lines += [_md_image(block, prefix), "", f"*{_caption(block)}*", ""]
    return lines


def render_markdown(title: str, meta: dict, sections, image_prefix: str, parts=None) -> str:
    """The report as Markdown (``docs/results.md``), in the HTML page's order.

    Image links start with ``image_prefix`` (the path from the Markdown file to the report).

    Examples
    --------
    >>> section = ReportSection("demo", "Demo")
    >>> text = render_markdown("t", {}, [(section, SectionResult([Image("images/a.png", "A")]))],
    ...                        "results/")
    >>> "![A](results/images/a.png)" in text, text.index("## Summary") < text.index("## Demo")
    (True, True)
    """
    if parts is None:
        parts = [ReportPart("all", title, "", tuple(s for s, _ in sections))]
    lines = [
        f"# {title}",
        "",
        "<!-- Generated by `specref report`; do not edit by hand. -->",
        "",
        _meta_line(meta),
        "",
    ]
    lines += _md_summary(parts, sections, image_prefix)
    for section, result in sections:
        lines += [f"## {section.title}", ""]
        failed = [(section, c) for c in result.checks if not c.passed]
        if failed:
            lines += ["**Targets that do not hold:**", "", *_md_checks(failed, False), ""]
        if result.checks:
            rows = [(section, c) for c in result.checks]
            lines += [f"<details><summary>Targets: {_count(result.checks)}</summary>", ""]
            lines += [*_md_checks(rows, False), "", "</details>", ""]
        lines += _md_blocks(result.blocks, image_prefix)
    checks = [(s, c) for s, r in sections for c in r.checks]
    lines += ["## All targets", "", f"{_count([c for _, c in checks])}.", ""]
    if checks:
        lines += [*_md_checks(checks, True), ""]
    return "\n".join(lines)
