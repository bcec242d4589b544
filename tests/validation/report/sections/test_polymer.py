import pytest

from shrm.polymer.hybrid import MIRROR_FACTORS
from validation.report.runner import REPORT_SECTIONS, SECTIONS, run_report
from validation.report.sections.polymer_held_out import MODELS


def test_polymer_section_follows_the_shrm_sections():
    # the polymer model shades from SHRMs: it comes right after them (the SHRM section and its
    # full-resolution measurements)
    names = [s.name for s in SECTIONS]
    assert names.index("shrm-fullres") == names.index("shrm") + 1
    assert names.index("polymer") == names.index("shrm-fullres") + 1
    assert REPORT_SECTIONS.lookup("polymer").title == "Herbert hybrid model"


@pytest.mark.slow
def test_report_polymer_section_quick(tmp_path):
    results = run_report(tmp_path, effort="quick", only=["polymer"], progress=False)
    section = results["sections"]["polymer"]
    # Fig. 2: three thicknesses (0.03", 0.06", 0.120"), 11 loads, over black and in transmission
    assert sorted(section["fig2"]) == ["0.762", "1.524", "3.048"]
    assert all(len(c["L_transmission"]) == 11 for c in section["fig2"].values())
    checks = [c for c in results["checks"] if c["section"] == "polymer"]
    held_out = [c for c in checks if "held-out chips" in c["name"]]
    design = [c for c in checks if c not in held_out]
    assert len(design) == 16
    assert all(c["passed"] for c in design), [c for c in design if not c["passed"]]
    # Held out: every shipped map, the object and rim targets of a real-time model. Herbert's
    # hybrid misses them under studio_small_03 (object mean about 2, rim above 3; far more on a
    # tinted chip, whose tint it multiplies in while the oracle takes a dye, erratum E115). The
    # layered model with its filtered importance sampling, its sample count from a tolerance
    # (erratum E118: more samples where small lamps' highlights are all a near-black chip shows),
    # meets both on every map and beats the same model with Karis's split sum on every map, over
    # the object and at the rim. One check per map states the oracle's own noise (two seeds).
    noise = [c for c in held_out if c["name"].startswith("the layered oracle's own noise")]
    assert len(noise) == 4
    assert all(0 <= c["measured"] < 1.0 for c in noise), noise
    assert len(held_out) == 3 * 2 * 4 + 4
    assert {c["basis"] for c in held_out} == {"held out"}

    def by_map(prefix, part):
        return {
            c["name"].split(", ")[-1].split(":")[0]: c
            for c in held_out
            if c["name"].startswith(prefix + " vs") and part in c["name"]
        }

    hybrid = by_map(MODELS["hybrid"], "object")
    assert not hybrid["studio_small_03_1k.hdr"]["passed"], hybrid
    for part in ("object", "rim"):
        fis, split = by_map(MODELS["layered"], part), by_map(MODELS["layered_split_sum"], part)
        assert all(fis[m]["measured"] < split[m]["measured"] for m in fis), (fis, split)
        assert all(fis[m]["passed"] for m in fis), fis
    rows = section["held_out"]["rows"]
    assert len(rows) == 3 * 4 * section["held_out"]["settings"]["chips"]
    # the layered model's sample count is its pilot's, stated per row: more under studio_small_03's
    # small lamps than under venice's sky (erratum E118)
    samples = section["held_out"]["samples"]
    assert min(samples["studio_small_03_1k.hdr"]["fis"]) > max(
        samples["venice_sunset_1k.hdr"]["fis"]
    )
    assert all(r["fis_samples"] >= 32 for r in rows if r["model"] == "layered")
    # where the layered model's error lies: with the oracle's specular term in its place, every
    # held-out chip under every map agrees with the oracle far within the targets (its body and
    # transmission are the oracle's terms from prefiltered maps), so what it misses is its specular
    swapped = [r for r in rows if r["model"] == "layered"]
    assert all(r["swap_mean"] < 0.25 and r["swap_rim"] < 0.5 for r in swapped), swapped
    assert all(r["swap_rim"] < 0.1 * r["rim"] for r in swapped if r["rim"] > 1.0), swapped
    names = (
        "fig1",
        "fig2",
        "chips",
        "terms-fresnel",
        "terms-cosine",
        "terms-none",
        "oracle-images",
    )
    # Fig. 1 rebuilt: the reference light's shift is 0 and the others' are stated
    assert section["fig1"]["delta_E00"]["D65"] == 0.0
    assert section["fig1"]["delta_E00"]["FL2"] > 0.0
    for name in (*names, "oracle-sweeps", "oracle-speed"):
        assert (tmp_path / "images" / f"polymer-{name}.png").is_file()
    # Erratum E34: the printed model returns more than a passive surface can at grazing views
    assert all(v["grazing"] > 1.0 for v in section["uniform_sky"].values())
    # The hybrid against the layered oracle: every sweep, every M_s, and the speed chart's points
    oracle = section["oracle"]
    assert sorted(oracle["sweeps"]) == ["gloss", "thickness_mm", "tio2_pct"]
    assert sorted(oracle["speed"]["hybrid"]) == sorted(MIRROR_FACTORS.names())
    assert len(oracle["failures"]) == 3 * len(MIRROR_FACTORS.names())
