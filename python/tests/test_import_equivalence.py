"""Python's imports write the view folder `sfp import` writes, byte for byte,
and warn what it warns: both run the same library import, with a dark
frame, a flat field, the automatic mask and the vertical angle frame."""

import struct
import subprocess
import warnings
import zlib

import numpy as np
import pytest

import polar_sfp as ps

from conftest import sfp_binary


def write_png(path, codes):
    """A 16-bit grayscale PNG of `codes` (uint16 (H, W))."""
    h, w = codes.shape
    rows = b"".join(b"\0" + codes[y].astype(">u2").tobytes() for y in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", w, h, 16, 0, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")
    )
    return str(path)


@pytest.fixture(scope="module")
def capture(sfp, tmp_path_factory):
    """An analytic sphere (64²) seen by a sensor with an offset and an
    uneven response, as four images and as a 128² mosaic (90° 45° over
    135° 0°), with its dark frame and flat field."""
    folder = tmp_path_factory.mktemp("capture")
    sfp("analytic", "--shape", "sphere", "--size", 64, "--out", folder / "sphere")
    images = ps.read_view(folder / "sphere").images
    rng = np.random.default_rng(7)
    h, w = images.shape[1:]
    dark = rng.integers(200, 260, (2 * h, 2 * w))
    y, x = np.mgrid[0 : 2 * h, 0 : 2 * w]
    response = 0.8 + 0.3 * np.exp(-((x - w) ** 2 + (y - h) ** 2) / (2.0 * (w / 2) ** 2))
    scene = np.zeros((2 * h, 2 * w))
    for (dy, dx), k in {(0, 0): 2, (0, 1): 1, (1, 0): 3, (1, 1): 0}.items():
        scene[dy::2, dx::2] = images[k] * 40000
    raw = np.clip(np.round(dark + response * scene), 0, 65534).astype(np.uint16)
    flat = np.round(dark + response * 30000).astype(np.uint16)
    files = {
        "raw": write_png(folder / "raw.png", raw),
        "dark": write_png(folder / "dark.png", dark.astype(np.uint16)),
        "flat": write_png(folder / "flat.png", flat),
        "half_dark": write_png(folder / "half_dark.png", dark[0::2, 0::2].astype(np.uint16)),
        "half_flat": write_png(folder / "half_flat.png", flat[0::2, 0::2]),
    }
    # The four images in the labels of the vertical, clockwise frame: the
    # project's 0° is its 90°.
    for label, k in {"p0": 2, "p45": 1, "p90": 0, "p135": 3}.items():
        codes = np.round(dark[0::2, 0::2] + response[0::2, 0::2] * images[k] * 40000).astype(np.uint16)
        files[label] = write_png(folder / f"{label}.png", codes)
    return folder, files


def cli(*args):
    done = subprocess.run([sfp_binary(), *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return [line.removeprefix("warning: ") for line in done.stderr.splitlines()]


def assert_same_folders(a, b):
    files = sorted(p.relative_to(a) for p in a.rglob("*") if p.is_file())
    assert files == sorted(p.relative_to(b) for p in b.rglob("*") if p.is_file())
    assert any(f.name == "meta.json" for f in files) and any(f.name == "mask.png" for f in files)
    for f in files:
        assert (a / f).read_bytes() == (b / f).read_bytes(), f"{f} differs"


def python_import(call, *args, **options):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        view = call(*args, **options)
    return view, [str(w.message) for w in caught if issubclass(w.category, UserWarning)]


def test_a_mosaic_imports_as_the_cli_imports_it(capture, tmp_path):
    _, f = capture
    cli_out, py_out = str(tmp_path / "cli"), str(tmp_path / "py")
    said = cli(
        "import", "--mosaic", f["raw"], "--pattern", "0,45,135,90", "--angles-from", "vertical-cw",
        "--dark", f["dark"], "--flat", f["flat"], "--auto-mask", "--out", cli_out,
    )  # fmt: skip
    view, warned = python_import(
        ps.import_mosaic, f["raw"], pattern="0,45,135,90", angles_from="vertical-cw",
        dark=f["dark"], flat=f["flat"], auto_mask=True, out=py_out,
    )  # fmt: skip
    assert_same_folders(tmp_path / "cli", tmp_path / "py")
    assert warned == [w.replace(cli_out, py_out) for w in said]
    assert view.meta["capture"]["dark"] == f["dark"] and "auto_mask" in view.meta
    np.testing.assert_array_equal(view.images, ps.read_view(py_out).images)


def test_four_images_import_as_the_cli_imports_them(capture, tmp_path):
    _, f = capture
    angles = [f["p0"], f["p45"], f["p90"], f["p135"]]
    said = cli(
        "import", "--angles", *angles, "--angles-from", "vertical-cw", "--dark", f["half_dark"],
        "--flat", f["half_flat"], "--auto-mask", "--out", tmp_path / "cli",
    )  # fmt: skip
    _, warned = python_import(
        ps.import_angles, *angles, angles_from="vertical-cw", dark=f["half_dark"],
        flat=f["half_flat"], auto_mask=True, out=tmp_path / "py",
    )  # fmt: skip
    assert_same_folders(tmp_path / "cli", tmp_path / "py")
    assert warned == [w.replace(str(tmp_path / "cli"), str(tmp_path / "py")) for w in said]


def test_mask_choices_are_one_of_three(capture):
    _, f = capture
    with pytest.raises(ValueError, match="one of mask, window and auto_mask"):
        ps.import_mosaic(f["raw"], window=(0.1, 0.9), auto_mask=True)
    with pytest.raises(ValueError, match="angles_from"):
        ps.import_mosaic(f["raw"], angles_from="clockwise")
