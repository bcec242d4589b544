"""Every command that writes a file refuses an unwritable output in one line, with exit code 2.

Four ways an output cannot be written: the path is a folder; a part of its folder is a file; the
folder is on a read-only file system; the disk is full. The last two are real file systems (a
small tmpfs, mounted read-only or filled: the ``read_only_folder`` and ``full_folder`` fixtures of
conftest.py), which needs root; without it they are simulated.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path

import numpy as np
import pytest

from reference.data import data_path
from reference.errors import SpecrefError
from reference.files import output_error, write_text_atomic
from reference.images.formats import write_exr, write_png
from validation.cli import main

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = data_path("examples")


def _outputs(tmp_path: Path, kind: str, request) -> Path:
    """An output path that cannot be written, of the given kind (for "a folder": create it)."""
    if kind == "a folder":
        return tmp_path / "out"
    if kind == "a file in the path":
        (tmp_path / "blocker").write_text("x")
        return tmp_path / "blocker" / "out"
    folder = request.getfixturevalue("full_folder" if kind == "full disk" else "read_only_folder")
    return folder / "out"


KINDS = ("a folder", "a file in the path", "read-only", "full disk")
MESSAGES = {
    "a folder": "is a folder",
    "a file in the path": "is a file, not a folder",
    "read-only": "read-only file system",
    "full disk": "no space left",
}


def _spectral_exr(path, image):
    from reference.images.spectral import write_spectral_blocks

    blocks = [(0, image.astype(np.float32))]
    return write_spectral_blocks(Path(f"{path}.exr"), *image.shape[:2], [450, 550, 650], blocks)


def _spectral_tiff(path, image):
    from reference.images.spectral import write_spectral_blocks

    blocks = [(0, image.astype(np.float32))]
    return write_spectral_blocks(Path(f"{path}.tif"), *image.shape[:2], [450, 550, 650], blocks)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize(
    "writer",
    [write_png, write_exr, _spectral_exr, _spectral_tiff],
    ids=["png", "exr", "spectral-exr", "spectral-tiff"],
)
def test_image_writers_refuse_in_one_line(writer, kind, tmp_path, request):
    path = _outputs(tmp_path, kind, request)
    if kind == "a folder":
        path.mkdir()
        for suffix in (".exr", ".tif"):
            Path(f"{path}{suffix}").mkdir()
    image = np.random.default_rng(1).random((128, 128, 3))
    with pytest.raises(SpecrefError, match=MESSAGES[kind]) as caught:
        writer(path, image)
    assert str(path.name) in str(caught.value)
    assert "\n" not in str(caught.value)
    # No temporary file is left behind.
    if path.parent.is_dir():
        assert not [p for p in path.parent.iterdir() if p.name.startswith(f".{path.name}.")]


def test_output_error_passes_other_errors_through(tmp_path, monkeypatch):
    assert output_error("x", OSError(errno.EIO, "I/O error")) is None

    def failing_fsync(fd):
        raise OSError(errno.EIO, "I/O error")

    monkeypatch.setattr(os, "fsync", failing_fsync)
    with pytest.raises(OSError, match="I/O error"):
        write_text_atomic(tmp_path / "a.txt", "x")
    assert list(tmp_path.iterdir()) == []


def _commands(out: Path, tmp_path: Path) -> dict[str, list[str]]:
    env = tmp_path / "env.exr"
    if not env.exists():
        write_exr(env, np.random.default_rng(2).random((8, 16, 3)) + 0.1)
    material = tmp_path / "m.toml"
    material.write_text("[material]\nk_d = 0.2\nk_s = 0.5\nn = 3\n")
    scene = EXAMPLES / "phong-sphere.toml"
    sweep = tmp_path / "sweep.toml"
    sweep.write_text(
        'kind = "phong"\n[grid]\nmaterials = ["R1"]\nviews = ["near"]\n'
        'placements = ["error"]\ninterpolations = ["monotone"]\nentries = [25]\nresolution = 8\n'
    )
    return {
        "render -o": ["render", str(scene), "-o", f"{out}.png", "--width", "8"],
        "render --exr": [
            "render",
            str(scene),
            "-o",
            str(tmp_path / "ok.png"),
            "--exr",
            f"{out}.exr",
            "--width",
            "8",
        ],
        "sh project -o": ["sh", "project", str(env), "--order", "2", "-o", f"{out}.npz"],
        "sh prefilter --out": [
            "sh",
            "prefilter",
            str(env),
            "--kernel",
            "lambert",
            "--size",
            "4",
            "--out",
            f"{out}.exr",
        ],
        "brdf tabulate -o": [
            "brdf",
            "tabulate",
            "ggx",
            "--theta-step",
            "45",
            "--phi-step",
            "90",
            "-o",
            f"{out}.txt",
        ],
        "phong --json": [
            "phong",
            "--material",
            str(material),
            "--resolution",
            "8",
            "--repeats",
            "1",
            "--entries",
            "25",
            "--json",
            f"{out}.json",
        ],
        "equations -o": ["equations", "-o", f"{out}.md"],
        "polymer characterize -o": ["polymer", "characterize", "-o", f"{out}.csv"],
        "display calibrate -o": ["display", "calibrate", "--points", "4", "-o", f"{out}.cal"],
        "env fit -o": ["env", "fit", "-o", f"{out}.json"],
        "render --json": [
            "render",
            str(scene),
            "-o",
            str(tmp_path / "ok.png"),
            "--width",
            "8",
            "--json",
            f"{out}.json",
        ],
        "compare --json": ["compare", str(env), str(env), "--json", f"{out}.json"],
        "compare --diff": ["compare", str(env), str(env), "--diff", f"{out}.exr"],
        "sweep -o": ["sweep", str(sweep), "--scheduler", "serial", "-o", f"{out}.csv"],
        "shrm orbit -o": [
            "shrm",
            "orbit",
            "--quick",
            "--frames",
            "1",
            "--no-cache",
            "-o",
            str(out),
        ],
    }


COMMANDS = (
    "render -o",
    "render --exr",
    "sh project -o",
    "sh prefilter --out",
    "brdf tabulate -o",
    "phong --json",
    "equations -o",
    "polymer characterize -o",
    "display calibrate -o",
    "env fit -o",
    "render --json",
    "compare --json",
    "compare --diff",
    "sweep -o",
    "shrm orbit -o",
)


# shrm orbit -o names a folder, so an existing folder there is a valid output, not a case.
CASES = [(c, k) for c in COMMANDS for k in KINDS if (c, k) != ("shrm orbit -o", "a folder")]


@pytest.mark.slow
@pytest.mark.parametrize(("command", "kind"), CASES)
def test_commands_refuse_unwritable_outputs_in_one_line(command, kind, tmp_path, request, capsys):
    out = _outputs(tmp_path, kind, request)
    argv = _commands(out, tmp_path)[command]
    if kind == "a folder":
        # A folder stands where the output file would go.
        for arg in argv:
            if arg.startswith(str(out)):
                Path(arg).mkdir()
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert MESSAGES[kind] in lines[0], lines[0]


@pytest.mark.parametrize("kind", ["read-only", "full disk"])
def test_phong_refuses_its_json_output_before_the_work(
    kind, tmp_path, request, capsys, monkeypatch
):
    # the study is not run at all: on a cold kernel cache it ran 20 s and printed its progress
    # before the one-line refusal
    from validation.studies import phong_table1

    def must_not_run(*args, **kwargs):
        raise AssertionError("the study ran before the output was checked")

    monkeypatch.setattr(phong_table1, "run_material", must_not_run)
    argv = _commands(_outputs(tmp_path, kind, request), tmp_path)["phong --json"]
    assert main(argv) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    assert MESSAGES[kind] in lines[0], lines[0]


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        # brdf tabulate: a step that would allocate terabytes, and one that is not a divisor.
        (
            ["brdf", "tabulate", "ggx", "--theta-step", "1e-4", "-o", "{tmp}/t.txt"],
            "at most 753,571",
        ),
        (
            ["brdf", "tabulate", "ggx", "--phi-step", "inf", "-o", "{tmp}/t.txt"],
            "phi step: must divide 180 degrees, got inf",
        ),
        # phong: no timing from zero repetitions.
        (
            ["phong", "--material", "{tmp}/m.toml", "--resolution", "8", "--repeats", "0"],
            "--repeats",
        ),
        # shrm orbit: a missing environment the user named is not replaced by a built-in sky.
        (
            ["shrm", "orbit", "--env", "{tmp}/missing.hdr", "--quick", "-o", "{tmp}/o"],
            "missing.hdr: environment file not found (--env)",
        ),
        # sh prefilter: linear HDR data are not written under a PNG name.
        (
            ["sh", "prefilter", "{tmp}/env.exr", "--kernel", "lambert", "--out", "{tmp}/x.png"],
            "must end in .exr",
        ),
    ],
)
def test_hostile_arguments_are_refused_in_one_line(argv, message, tmp_path, capsys):
    # Source: docs/bad-input.md, the cases found with hostile input.
    (tmp_path / "m.toml").write_text("[material]\nk_d = 0.2\nk_s = 0.5\nn = 3\n")
    write_exr(tmp_path / "env.exr", np.random.default_rng(3).random((8, 16, 3)) + 0.1)
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert len(err.strip().splitlines()) == 1, err
    assert message in err
    assert not (tmp_path / "t.txt").exists()
    assert not (tmp_path / "x.png").exists()
    assert not (tmp_path / "o").exists()


def test_sprague_with_too_few_samples_is_refused():
    from reference.colour.spectra import GRID_41, make_spectrum, resample_spectrum

    three = make_spectrum([380.0, 580.0, 780.0], [0.1, 0.5, 0.2], "three")
    with pytest.raises(SpecrefError, match="three: sprague interpolation needs at least 6"):
        resample_spectrum(three, GRID_41, interpolation="sprague")
    uneven = make_spectrum([380, 400, 450, 500, 600, 700, 780], [0.1] * 7, "uneven")
    with pytest.raises(SpecrefError, match="unevenly spaced"):
        resample_spectrum(uneven, GRID_41, interpolation="sprague")


def test_commands_set_the_allocator_thresholds_streamed_ones_their_own(tmp_path, monkeypatch):
    # docs/scale-out.md: every command keeps NumPy's temporaries on the heap; the streamed ones
    # (env convert, env spectralize, sh project) map chunk-sized blocks on their own, set
    # explicitly so that thresholds inherited through the environment do not apply
    import numpy as np

    import reference.tasks
    from reference.images.formats import write_exr
    from validation.cli import main

    calls = []
    monkeypatch.setattr(
        reference.tasks, "set_malloc_trim", lambda *args: calls.append(args) or True
    )
    sky = write_exr(tmp_path / "sky.exr", np.ones((8, 16, 3), np.float32))
    assert main(["env", "convert", str(sky), str(tmp_path / "sky.zarr")]) == 0
    streamed = (reference.tasks.STREAMED_TRIM_BYTES, reference.tasks.STREAMED_MMAP_BYTES)
    assert calls == [streamed]
    assert reference.tasks.STREAMED_MMAP_BYTES < reference.tasks.WORKER_MMAP_BYTES
    assert main(["sweep", str(tmp_path / "missing.toml"), "--scheduler", "serial"]) == 2
    assert calls == [streamed, ()]
