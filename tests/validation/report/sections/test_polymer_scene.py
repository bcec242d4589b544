import numpy as np
import pytest

from reference.geometry.mesh import mesh_from_obj
from validation.report.runner import REPORT_SECTIONS, SECTIONS, run_report
from validation.report.sections import polymer_scene
from validation.report.sections.polymer_scene import bottle_obj, bottle_profile


def test_polymer_scene_section_follows_polymer():
    names = [s.name for s in SECTIONS]
    assert names.index("polymer-scene") == names.index("polymer") + 1
    assert REPORT_SECTIONS.lookup("polymer-scene").title == "Polymer scenes"


def test_full_bottle_has_100k_triangles_in_three_groups(tmp_path):
    s = polymer_scene.SETTINGS["full"]
    # Source: the construction: two triangles per quad between profile rings, a fan per disc
    expected = 2 * s["around"] * (s["profile"] - 1) + 2 * s["around"]
    assert expected >= polymer_scene.TRIANGLES_TARGET
    _, _, group = bottle_profile(s["profile"])
    assert sorted(set(group.tolist())) == [0, 1, 2]
    path = tmp_path / "b.obj"
    assert bottle_obj(path, 16, 13) == 2 * 16 * 12 + 2 * 16


def test_bottle_is_closed_and_faces_outwards(tmp_path):
    path = tmp_path / "b.obj"
    bottle_obj(path, 24, 21)
    mesh = mesh_from_obj(path, groups={"body": 0, "band": 1, "cap": 2})
    a, b, c = (mesh.vertices[mesh.faces[:, k]] for k in range(3))
    cross = np.cross(b - a, c - a)
    # Source: the divergence theorem: a closed, outward-wound surface encloses a positive volume
    # (sum of signed tetrahedra from the origin), and every edge is shared by exactly two faces
    volume = np.einsum("ij,ij->i", a, cross).sum() / 6.0
    assert volume > 0
    edges = np.sort(
        np.concatenate([mesh.faces[:, [0, 1]], mesh.faces[:, [1, 2]], mesh.faces[:, [2, 0]]]),
        axis=1,
    )
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert (counts == 2).all()
    # The shading normals agree with the winding (outwards) on every face
    normal = mesh.normals[mesh.faces].mean(axis=1)
    assert (np.einsum("ij,ij->i", normal, cross) > 0).all()


@pytest.mark.slow
def test_report_polymer_scene_section_tiny(tmp_path, monkeypatch):
    monkeypatch.setitem(
        polymer_scene.SETTINGS, "quick", {"around": 16, "profile": 13, "width": 16, "height": 20}
    )
    results = run_report(tmp_path, effort="quick", only=["polymer-scene"], progress=False)
    section = results["sections"]["polymer-scene"]
    assert section["groups"] == ["body", "band", "cap"]
    assert section["maps"] == {"lambert": 1, "normalized-phong": 2, "polymer-effect": 1}
    checks = [c for c in results["checks"] if c["section"] == "polymer-scene"]
    assert len(checks) == 3
    assert all(c["passed"] for c in checks), [c for c in checks if not c["passed"]]
    assert (tmp_path / "images" / "polymer-scene-bottle.png").is_file()
