"""Each public-dataset reader round-trips its convention: files written in
the dataset's own format (by the test, from a rendered view) read back as
the view, and the written files obey the dataset's own relation between
AoP and normals (DeepSfP's prior: azimuth = AoP, diffuse)."""

import json
import os

import numpy as np
import pytest

import polar_sfp as ps


def image_frame(view):
    """A view's images (H, W, 4) and normals (H, W, 3) in the image frame
    of DeepSfP and SPW: y down the rows, angles clockwise as displayed."""
    i0, i45, i90, i135 = view.images
    images = np.stack([i0, i135, i90, i45], axis=-1)  # their 45° is our 135°
    normals = view.normals * np.array([1, -1, 1], dtype=np.float32)
    return images, normals


def assert_their_aop_follows_their_normals(images, normals, mask):
    """DeepSfP's prior: φ = ½ atan2(I45 − I135, I0 − I90) is the normal's
    azimuth atan2(n_y, n_x) mod π on a diffuse object."""
    s1 = images[..., 0] - images[..., 2]
    s2 = images[..., 1] - images[..., 3]
    phi = 0.5 * np.arctan2(s2, s1)
    azimuth = np.arctan2(normals[..., 1], normals[..., 0])
    polarized = mask & (np.hypot(s1, s2) > 0.02 * images.sum(-1).max() / 2)
    agreement = np.cos(2 * (phi - azimuth))[polarized].mean()
    assert agreement > 0.9, agreement


def assert_same_view(read, view, normals_atol=0.0):
    np.testing.assert_allclose(read.images, view.images, atol=1e-7)
    np.testing.assert_array_equal(read.mask, view.mask)
    np.testing.assert_allclose(read.normals, view.normals, atol=normals_atol)


def test_deepsfp_mat_round_trips(rendered, tmp_path):
    scipy_io = pytest.importorskip("scipy.io", reason="scipy reads DeepSfP's .mat files")
    images, normals = image_frame(rendered)
    assert_their_aop_follows_their_normals(images, normals, rendered.mask)
    path = tmp_path / "object_f.mat"
    scipy_io.savemat(path, {
        "images": images.astype(np.float64),
        "mask": rendered.mask.astype(np.uint8),
        "normals_gt": normals.astype(np.float64),
    })
    read = ps.read_deepsfp(path)
    assert_same_view(read, rendered)
    assert read.meta["format"] == "deepsfp"
    with pytest.raises(ValueError, match="images"):
        scipy_io.savemat(tmp_path / "bad.mat", {"images": images[..., :3], "mask": 1})
        ps.read_deepsfp(tmp_path / "bad.mat")


def test_spw_npy_round_trips(rendered, tmp_path):
    images, normals = image_frame(rendered)
    np.save(tmp_path / "scene_polar.npy", images)
    np.save(tmp_path / "scene_normal.npy", normals)
    read = ps.read_spw(tmp_path / "scene_polar.npy")
    assert_same_view(read, rendered)
    read = ps.read_spw(tmp_path / "scene_polar.npy", mask=rendered.mask)
    assert_same_view(read, rendered)
    np.save(tmp_path / "wrong_polar.npy", images[..., :3])
    with pytest.raises(ValueError, match="wrong_polar"):
        ps.read_spw(tmp_path / "wrong_polar.npy")


def test_sfpuel_layout_of_sfp_export_round_trips(sfp, builtin, tmp_path):
    layout = tmp_path / "layout"
    sfp("export", builtin, "--out", layout, "--name", "obj")
    view = ps.read_view(builtin)
    read = ps.read_sfpuel(layout)
    # Normals pass through 16-bit PNGs: (n + 1) / 2 · 65535.
    assert_same_view(read, view, normals_atol=1e-4)
    sidecar = layout / "layout.json"
    meta = json.loads(sidecar.read_text())
    meta["axes"] = "x right, y down, z away from the camera"
    sidecar.write_text(json.dumps(meta))
    with pytest.raises(ValueError, match="axes"):
        ps.read_sfpuel(layout)



def test_sfpuel_axes_convert_the_normals_and_a_misfit_is_warned(sfp, builtin, tmp_path):
    """``axes`` names the frame of the layout's normals: our normals read as
    y-down ones come out with y negated, and the warning says they fit the
    other y sense along the mask's outline."""
    layout = tmp_path / "layout"
    sfp("export", builtin, "--out", layout, "--name", "obj")
    view = ps.read_view(builtin)
    with pytest.warns(UserWarning, match="--axes ours"):
        read = ps.read_sfpuel(layout, axes="image")
    flipped = view.normals * np.array([1, -1, 1], dtype=np.float32)
    np.testing.assert_allclose(read.normals, flipped, atol=1e-4)
    with pytest.raises(ValueError, match="axes"):
        ps.read_sfpuel(layout, axes="dx")


def test_spw_normals_stored_y_up_are_warned_about(rendered, tmp_path):
    """The SPW and DeepSfP readers assume the image frame (y down); normals
    stored y up show along the mask's outline, and the reader says so."""
    images, normals = image_frame(rendered)
    np.save(tmp_path / "up_polar.npy", images)
    np.save(tmp_path / "up_normal.npy", rendered.normals)  # y up: not theirs
    with pytest.warns(UserWarning, match="only with y negated"):
        ps.read_spw(tmp_path / "up_polar.npy")
    np.save(tmp_path / "down_normal.npy", normals)
    np.save(tmp_path / "down_polar.npy", images)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ps.read_spw(tmp_path / "down_polar.npy")
    ours, flipped = ps.frame_fit(rendered.normals, rendered.mask)
    assert ours > 0.8 and flipped < 0.3, (ours, flipped)


def test_a_colour_sfpuel_folder_reads_as_its_colour_view(sfp, tmp_path):
    """A third-party-style SfPUEL folder of a colour render (RGB 8-bit
    polarizer PNGs, 16-bit normals, no layout.json) reads as the view it
    came from, colour kept; normals read in the other y sense draw the
    warning naming the frame that fits."""
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    with open(os.path.join(repo, "scenes", "examples", "sphere.toml"), encoding="utf-8") as f:
        text = f.read()
    for old, new in [("width = 128", "width = 40"), ("height = 128", "height = 40"),
                     ("max_depth = 1", "max_depth = 1\ncolour = true"),
                     ("eta = 1.5", "eta = 1.5, tint = [1.0, 0.6, 0.25]"),
                     ("bits = 16", "bits = 8")]:
        text = text.replace(old, new)
    scene = tmp_path / "colour.toml"
    scene.write_text(text)
    view_dir, layout = tmp_path / "view", tmp_path / "sfpuel"
    sfp("render", scene, "--out", view_dir)
    sfp("export", view_dir, "--out", layout, "--name", "v")
    (layout / "layout.json").unlink()
    (layout / "normal" / "v.npy").unlink()
    view = ps.read_view(view_dir)
    read = ps.read_sfpuel(layout)
    assert view.colour is not None and read.colour.shape == (4, 3, 40, 40)
    np.testing.assert_array_equal(read.colour, view.colour)
    assert_same_view(read, view, normals_atol=1e-4)
    lum = np.einsum("c,kchw->khw", [0.2126, 0.7152, 0.0722], read.colour)
    np.testing.assert_allclose(read.images, lum, atol=0.5 / 255 + 1e-6)
    # What the methods read stays grey: (4, H, W).
    assert read.images.shape == (4, 40, 40)
    # Read as y-down normals, they draw the warning naming the frame that fits.
    with pytest.warns(UserWarning, match="--axes ours"):
        ps.read_sfpuel(layout, axes="image")
