"""The paper's figures and Table 1 (validation.studies.phong_figures; ``phong table1 --images``)."""

import numpy as np
import pytest
from PIL import Image as PILImage

from phong_table.scenes import SCENES
from validation.cli import main
from validation.report import ReportContext
from validation.studies import phong_figures, phong_table1
from validation.studies.phong import view_state
from validation.studies.phong_figures import (
    PAPER_TABLE1,
    TABLE1_METHODS,
    fig3_cosine_powers,
    fig4_nodes,
    fig567_scene,
    table1_blocks,
    table_image,
)


@pytest.fixture(scope="module")
def r1(tmp_path_factory):
    ctx = ReportContext(tmp_path_factory.mktemp("fig"), quick=True, section="phong")
    model = SCENES.lookup("R1").build()
    states = {v: view_state(model, v, 16, compiled=False) for v in ("far", "near")}
    return ctx, states


def _size(ctx, image):
    # the record's size is the PNG's, and the file is where the record says
    with PILImage.open(ctx.out_dir / image.path) as png:
        return png.size


def test_figure_functions_write_pngs_of_the_recorded_size(r1):
    ctx, states = r1
    images = [fig3_cosine_powers(ctx), fig4_nodes(ctx, states["far"], 12, 3)]
    images += fig567_scene(ctx, "R1", states, 32)
    assert len(images) == 2 + 1 + 2 * 2
    for image in images:
        assert _size(ctx, image) == (image.width, image.height)
        assert image.width > 300
        assert image.height > 150
    assert "n = 2000" in images[0].caption
    names = sorted(p.name for p in (ctx.out_dir / "images").iterdir())
    assert "phong-fig567-R1-near-error.png" in names


def test_table_image_is_the_exact_render_and_error_table_agrees(r1):
    _, states = r1
    state = states["near"]
    exact = table_image(state, None, None, 200)
    mask = state.geometry.gbuffer.mask
    assert exact.shape == (16, 16, 3)
    np.testing.assert_array_equal(exact[mask], state.exact)
    assert np.all(exact[~mask] == 0)
    got = table_image(state, "error", "monotone", 200)
    assert np.max(np.abs(got - exact)) < 1e-4


def test_table1_blocks_in_the_paper_layout(r1):
    _, states = r1
    ours, printed, note = table1_blocks({("R1", v): s for v, s in states.items()}, 64, 1, True)
    assert len(ours.rows) == 2 * len(TABLE1_METHODS)
    exact = [r for r in ours.rows if r[2] == "exact"]
    assert [r[5] for r in exact] == [1.0, 1.0]
    rms = {(r[1], r[2]): r[3] for r in ours.rows}
    # the t-parabola on importance nodes is far worse than error + monotone (Erratum E19)
    assert rms[("far", "error + monotone")] < rms[("far", "importance p=m + parabolic")]
    # the printed ratios: (b)/(a) of R1 is 0.382 / 3.658
    assert [r[2] for r in printed.rows] == list("abcdef")
    assert printed.rows[1][4] == pytest.approx(0.382 / 3.658)
    assert printed.rows[5][3] == PAPER_TABLE1["R1"][5][0] == 2.053
    assert "E24" in note.text
    assert "quick mode" in ours.caption


@pytest.mark.slow
def test_table1_images_via_cli(tmp_path, monkeypatch, capsys):
    # small and uncompiled (the NumPy references): the test checks the files, not the kernels
    def tiny(resolution, entries, repeats, progress=False, scheduler=None):
        model = SCENES.lookup("R1").build()
        variants = [("error", "monotone", entries, None)]
        rows, _ = phong_table1.material_rows(model, "far", variants, resolution, 1, compiled=False)
        return {"rows": rows, "targets": []}

    def numpy_state(model, view, resolution, compiled=True):
        return view_state(model, view, resolution, False)

    monkeypatch.setattr(phong_table1, "run_table1", tiny)
    monkeypatch.setattr(phong_figures, "view_state", numpy_state)
    args = ["phong", "table1", "--resolution", "12", "--entries", "16", "--repeats", "1"]
    assert main([*args, "--images", str(tmp_path / "figs")]) == 0
    names = sorted(p.name for p in (tmp_path / "figs" / "images").iterdir())
    assert len(names) == 2 + 1 + 1 + 3 * 5
    assert "phong-fig2-R3-far.png" in names
    assert "phong-fig3-cosine-powers.png" in names
    assert "wrote 19 figures" in capsys.readouterr().out


def test_table1_images_into_a_file_is_refused(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["phong", "table1", "--images", str(blocker)]) == 2
    assert "Traceback" not in capsys.readouterr().err


def test_images_without_table1_is_refused(tmp_path, capsys):
    args = ["phong", "--material", str(tmp_path / "m.toml"), "--images", str(tmp_path)]
    assert main(args) == 2
    assert "--images goes with table1" in capsys.readouterr().err
