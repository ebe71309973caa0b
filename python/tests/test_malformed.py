"""Malformed input is a Python exception naming the problem, never a
panic or a crash of the interpreter: empty images, options that nest
without end, files the dataset readers cannot use (each error names the
file, as docs/python.md promises), and work too large for the memory."""

import os
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest

import polar_sfp as ps


@pytest.fixture(scope="module")
def view():
    return next(iter(ps.dataset("builtin", size=16, views=1, spp=1)))


@pytest.mark.parametrize("shape", [(4, 0, 5), (4, 5, 0), (4, 0, 0)])
def test_an_image_without_pixels_is_a_value_error(shape):
    with pytest.raises(ValueError, match=re.escape(f"shape {list(shape)} has no pixels")):
        ps.View(np.zeros(shape, np.float32))


def test_options_that_contain_themselves_or_nest_too_deep_are_value_errors(view):
    cycle = []
    cycle.append(cycle)
    with pytest.raises(ValueError, match="light.*contains itself"):
        ps.reconstruct(view, method="smith", light=cycle)
    table = {}
    table["a"] = table
    with pytest.raises(ValueError, match="contains itself"):
        ps.reconstruct(view, method="smith", light=table)
    deep = []
    for _ in range(200_000):
        deep = [deep]
    with pytest.raises(ValueError, match="nested deeper than"):
        ps.reconstruct(view, method="smith", light=deep)


def test_empty_dataset_arrays_are_value_errors_naming_the_file(tmp_path):
    np.save(tmp_path / "empty_polar.npy", np.zeros((0, 0, 4), np.float32))
    with pytest.raises(ValueError, match=r"empty_polar.*\(0, 0, 4\)"):
        ps.read_spw(tmp_path / "empty_polar.npy")
    scipy_io = pytest.importorskip("scipy.io", reason="scipy reads DeepSfP's .mat files")
    path = tmp_path / "empty.mat"
    scipy_io.savemat(path, {"images": np.zeros((0, 0, 4)), "mask": np.zeros((0, 0))})
    with pytest.raises(ValueError, match=r"empty\.mat.*\(0, 0, 4\)"):
        ps.read_deepsfp(path)


def test_malformed_dataset_files_name_the_file(tmp_path):
    text = tmp_path / "text_polar.npy"
    text.write_text("not an array")
    with pytest.raises(OSError, match="text_polar.npy"):
        ps.read_spw(text)
    archive = tmp_path / "archive_polar.npy"
    with open(archive, "wb") as f:
        np.savez(f, a=np.zeros((2, 2, 4)))
    with pytest.raises(OSError, match="archive_polar.npy"):
        ps.read_spw(archive)
    np.save(tmp_path / "mixed_polar.npy", np.zeros((4, 4, 4), np.float32))
    with pytest.raises(ValueError, match="mixed_polar.npy.*mask"):
        ps.read_spw(tmp_path / "mixed_polar.npy", mask=np.ones((3, 3), bool))
    layout = tmp_path / "layout"
    layout.mkdir()
    (layout / "layout.json").write_text("[1, 2")
    with pytest.raises(ValueError, match="layout.json"):
        ps.read_sfpuel(layout)
    (layout / "layout.json").write_text("[1, 2]")
    with pytest.raises(ValueError, match="layout.json"):
        ps.read_sfpuel(layout)

    scipy_io = pytest.importorskip("scipy.io", reason="scipy reads DeepSfP's .mat files")
    not_mat = tmp_path / "not.mat"
    not_mat.write_text("not a .mat file")
    with pytest.raises(OSError, match="not.mat"):
        ps.read_deepsfp(not_mat)
    mismatched = tmp_path / "mismatched.mat"
    scipy_io.savemat(mismatched, {
        "images": np.full((4, 4, 4), 0.5),
        "mask": np.ones((3, 3)),
        "normals_gt": np.zeros((4, 4, 3)),
    })
    with pytest.raises(ValueError, match="mismatched.mat.*mask"):
        ps.read_deepsfp(mismatched)
    words = tmp_path / "words.mat"
    scipy_io.savemat(words, {"images": np.full((4, 4, 4), 0.5), "mask": "abc"})
    with pytest.raises(ValueError, match="words.mat"):
        ps.read_deepsfp(words)


@pytest.mark.skipif(shutil.which("prlimit") is None, reason="prlimit (util-linux) is not installed")
def test_too_large_a_problem_for_the_address_space_is_a_memory_error():
    code = (
        "import numpy as np, polar_sfp as ps\n"
        "try:\n"
        "    ps.reconstruct(np.full((4, 3000, 3000), .5, np.float32), method='smith')\n"
        "except MemoryError as e:\n"
        "    print('MemoryError:', e)\n"
    )
    done = subprocess.run(
        ["prlimit", "--as=2000000000", sys.executable, "-c", code],
        capture_output=True, text=True, env={**os.environ, "RAYON_NUM_THREADS": "2"},
    )
    assert done.returncode == 0, done.stderr
    assert "MemoryError:" in done.stdout and "GB" in done.stdout, done.stdout
