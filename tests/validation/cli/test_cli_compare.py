"""``specref compare``: summary line, JSON, and one-line errors with exit code 2."""

from __future__ import annotations

import json

import numpy as np

from reference.images.formats import write_exr
from validation.cli import main

WHITE = np.array([0.95047, 1.0, 1.08883])


def test_compare_prints_a_summary_and_json(tmp_path, capsys):
    B = np.broadcast_to(WHITE, (2, 3, 3)).copy()
    a = write_exr(tmp_path / "a.exr", 1.05 * B, ["X", "Y", "Z"])
    b = write_exr(tmp_path / "b.exr", B, ["X", "Y", "Z"])
    assert main(["compare", str(a), str(b), "--diff", str(tmp_path / "d.exr")]) == 0
    assert capsys.readouterr().out.startswith("6 lit pixels: relative error of Y mean 0.05")
    assert (tmp_path / "d.exr").is_file()
    assert main(["compare", str(a), str(b), "--json", "-"]) == 0
    assert json.loads(capsys.readouterr().out)["relative_error_Y"]["max"] > 0.049


def test_compare_errors_exit_2_with_one_line(tmp_path, capsys):
    B = np.broadcast_to(WHITE, (2, 3, 3)).copy()
    b = write_exr(tmp_path / "b.exr", B, ["X", "Y", "Z"])
    small = write_exr(tmp_path / "s.exr", B[:1], ["X", "Y", "Z"])
    cases = {
        "size": ([str(small), str(b)], "size 3×1 differs"),
        "missing": ([str(tmp_path / "none.exr"), str(b)], "none.exr: file not found"),
        "diff suffix": ([str(b), str(b), "--diff", "d.png"], "--diff: must end in .exr"),
    }
    for args, message in cases.values():
        assert main(["compare", *args]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1
        assert message in err[0]
