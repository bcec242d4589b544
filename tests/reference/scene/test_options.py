"""``[render.options]``: every key registered and checked where the scene is loaded."""

import subprocess
import sys

import pytest

import phong_table  # noqa: F401  (registers options.phong)
import shrm  # noqa: F401  (registers the environment, SHRM and polymer options)
from reference.errors import SpecrefError
from reference.scene.loader import loads_scene
from reference.scene.options import RENDER_OPTIONS

BAD = [
    ("shrm_tolerance = 0.01", "render.options: unknown key 'shrm_tolerance'; allowed: environment"),
    ("shrm_tol = nan", "render.options.shrm_tol: must be a number in (0, 1), got nan"),
    ('sphere_light_tol = "x"', "render.options.sphere_light_tol: must be a number in (0, 1)"),
    ("polymer_oracle_tol = 1.5", "render.options.polymer_oracle_tol: must be a number in (0, 1)"),
    ("polymer_fis_tol = 0", "render.options.polymer_fis_tol: must be a number in (0, 100), got 0"),
    ('polymer_fis_tol = "x"', "render.options.polymer_fis_tol: must be a number in (0, 100)"),
    ("environment_accuracy = -1", "environment_accuracy: must be a relative error in (0, 0.25]"),
    ("environment_accuracy = true", "environment_accuracy: must be a relative error"),
    ("environment_tol = 0", "render.options.environment_tol: must be a number in (0, 1), got 0"),
    ("environment_size = 100000", "environment_size: must be an integer in [4, 2048], got 100000"),
    ("environment_size = 64.0", "environment_size: must be an integer in [4, 2048], got 64.0"),
    ('environment = "brute"', "render.options.environment: unknown value 'brute'; allowed:"),
    ('phong = { method = "tabel" }', "phong: method: unknown value 'tabel'; allowed: exact, table"),
    ('phong = { method = "table", entries = 0 }', "phong: entries: table: entries: must be"),
    ('phong = { method = "table", entry = 64 }', "render.options.phong: unknown key 'entry'"),
    ("phong = 3", "render.options.phong: must be a table, got 3"),
    (
        'phong = { method = "table", entries = 100, segments = 30 }',
        "phong: table: segments: must divide entries = 100, got 30",
    ),
    ('upsampling = "jakob"', "render.options.upsampling: unknown value 'jakob'"),
]


@pytest.mark.parametrize(("line", "message"), BAD, ids=[line for line, _ in BAD])
def test_bad_options_are_refused_naming_file_and_key(line, message):
    with pytest.raises(SpecrefError) as caught:
        loads_scene(f"[render.options]\n{line}\n", "s.toml")
    text = str(caught.value)
    assert text.startswith("s.toml: render.options")
    assert message in text
    assert "\n" not in text


def test_good_options_come_back_checked():
    text = (
        '[render.options]\nshrm_tol = 0.01\nenvironment_size = 128\nenvironment = "sh"\n'
        'phong = { method = "table", entries = 64, placement = "uniform" }\n'
    )
    options = loads_scene(text).render.options
    assert options["shrm_tol"] == 0.01
    assert options["environment_size"] == 128
    assert options["phong"] == {"method": "table", "entries": 64, "placement": "uniform"}


def test_every_key_a_shader_reads_is_registered():
    """The keys read through ``ctx.options`` in the packages are the registry's keys."""
    import re
    from pathlib import Path

    root = Path(__file__).resolve().parents[3]
    read = set()
    for package in ("reference", "shrm", "phong_table", "impastor"):
        for path in (root / package).rglob("*.py"):
            text = path.read_text()
            read |= set(re.findall(r"ctx\.options(?:\.get\(|\[)\"([a-z_]+)\"", text))
    assert read, "found no option read: the pattern is out of date"
    assert read <= set(RENDER_OPTIONS.names()), read - set(RENDER_OPTIONS.names())


def test_the_cli_refuses_an_unknown_key_in_one_line(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text("[render]\nwidth = 4\nheight = 4\n[render.options]\nshrm_tolerance = 0.01\n")
    out = tmp_path / "o.png"
    run = subprocess.run(
        [sys.executable, "-m", "validation.cli", "render", str(scene), "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2
    assert run.stderr.count("\n") == 1
    assert "s.toml: render.options: unknown key 'shrm_tolerance'" in run.stderr
    assert not out.exists()
