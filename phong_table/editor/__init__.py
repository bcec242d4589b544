"""Wang, Chern & Lee's WYSIWYG spectral material editor (§1, §5, Wang et al.), ``phong edit``.

- :mod:`~phong_table.editor.state` — the editor's state, table and exact renders, save/open and the
  latest-only worker (no UI dependency).
- :mod:`~phong_table.editor.app` — the Bokeh page; Bokeh is imported only when the page is served.
- :mod:`~phong_table.editor.browser` — headless Chromium for the page's screenshot and browser test.
"""
