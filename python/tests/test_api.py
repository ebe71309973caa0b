"""The API on its own: views, listing, metrics, rendering, imports."""

import warnings

import numpy as np
import pytest

import polar_sfp as ps
from conftest import REPO



def test_methods_list_every_option_with_its_default():
    listed = ps.methods()
    assert sorted(listed) == ["atkinson", "mahmoud", "smith", "smsfp", "yu2017"]
    assert listed["smsfp"]["options"]["eta"]["default"] == 1.15
    assert listed["smith"]["options"]["lambda"]["default"] == 0.1
    assert "parg" in listed["smsfp"]["ablations"]
    for name, entry in listed.items():
        for option, spec in entry["options"].items():
            # Every listed option is accepted by name at its default.
            assert set(spec) == {"default", "doc"}, (name, option)
    view = next(iter(ps.dataset("builtin", size=32, views=1, spp=2)))
    options = {k: v["default"] for k, v in listed["smith"]["options"].items()}
    result = ps.reconstruct(view, method="smith", **options)
    assert {k: result.info["config"][k] for k in options} == options


def test_view_polarimetry_follows_conventions(rendered):
    i0, i45, i90, i135 = rendered.images.astype(np.float64)
    s = rendered.stokes()
    assert s.shape == (3,) + rendered.images.shape[1:]
    np.testing.assert_allclose(s[1], i0 - i90, atol=1e-6)
    np.testing.assert_allclose(s[2], i45 - i135, atol=1e-6)
    inside = rendered.mask & (s[0] > 1e-3)
    dop = np.hypot(s[1], s[2])[inside] / s[0][inside]
    np.testing.assert_allclose(rendered.dop()[inside], np.clip(dop, 0, 1), atol=1e-5)
    aop = rendered.aop()
    assert aop.min() >= 0 and aop.max() < np.pi
    with pytest.raises(ValueError):
        rendered.images[0, 0, 0] = 1.0  # read-only


def test_evaluate_gives_the_metrics_keys(rendered):
    m = ps.evaluate(rendered.normals, rendered.normals, rendered.mask)
    assert set(m) == {"mae_deg", "rmse_deg", "median_deg", "acc_11_25", "acc_22_5",
                      "acc_30", "pixels", "missing"}
    assert m["mae_deg"] < 0.1 and m["pixels"] == rendered.mask.sum()
    flipped = rendered.normals * np.array([-1, -1, 1], dtype=np.float32)
    assert ps.evaluate(flipped, rendered.normals, rendered.mask)["mae_deg"] > 1.0


def test_render_from_a_file_and_from_text_agree():
    scene = REPO / "scenes" / "examples" / "sphere.toml"
    from_file = ps.render(scene, size=24, spp=2)
    from_text = ps.render(scene.read_text(), size=24, spp=2)
    np.testing.assert_array_equal(from_file.images, from_text.images)
    assert from_file.normals is not None and from_file.mask.any()
    wide = ps.render(scene, size=(32, 16), spp=1)
    assert wide.images.shape == (4, 16, 32)


def test_dataset_yields_its_views_lazily():
    views = ps.dataset("builtin", size=16, views=2, spp=1)
    n = len(views)
    seen = [v.meta["name"] for v in views]
    assert len(seen) == n and n >= 2 and seen[0].endswith("_0")
    assert list(views) == []  # consumed


def test_imports_of_codes_match_the_images(rendered):
    codes = np.round(rendered.images * 65535).astype(np.uint16)
    view = ps.import_angles(*codes, mask=rendered.mask)
    np.testing.assert_array_equal(view.images, rendered.images)
    np.testing.assert_array_equal(view.mask, rendered.mask & (codes < 65535).all(axis=0))
    assert "pattern_check" in view.meta
    # A mosaic of 2×2 cells 90° 45° over 135° 0° (the default pattern).
    i0, i45, i90, i135 = codes
    h, w = i0.shape
    raw = np.zeros((2 * h, 2 * w), dtype=np.uint16)
    raw[0::2, 0::2], raw[0::2, 1::2], raw[1::2, 0::2], raw[1::2, 1::2] = i90, i45, i135, i0
    mosaic = ps.import_mosaic(raw, mask=rendered.mask)
    np.testing.assert_array_equal(mosaic.images, view.images)
    eight = ps.import_angles(*(codes >> 8).astype(np.uint8))
    assert eight.images.max() <= 1.0 and eight.mask is None or eight.mask.any()


def test_what_the_data_leave_undetermined_is_a_warning(sfp, tmp_path):
    # η 3.2 lies beyond SMSfP's search range: the search runs into its top
    # and says so; at 1.5 it says nothing.
    for eta, warned in [(3.2, True), (1.5, False)]:
        folder = tmp_path / f"sphere_{eta}"
        sfp("analytic", "--size", 64, "--eta", eta, "--out", folder)
        view = ps.read_view(folder)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = ps.reconstruct(view, method="smsfp")
        said = [str(w.message) for w in caught if issubclass(w.category, UserWarning)]
        assert said == result.info.get("warnings", []), (eta, said)
        assert bool(said) == warned and all("refractive index" in s for s in said), (eta, said)
