"""Bad input raises a Python exception naming the problem."""

import numpy as np
import pytest

import polar_sfp as ps


@pytest.fixture(scope="module")
def view():
    return next(iter(ps.dataset("builtin", size=16, views=1, spp=1)))


def test_bad_arrays_are_value_errors(view):
    with pytest.raises(ValueError, match="images"):
        ps.View(np.zeros((3, 8, 8)))
    with pytest.raises(ValueError, match="images"):
        ps.View(np.zeros((4, 8)))
    with pytest.raises(ValueError, match="mask"):
        ps.View(view.images, mask=np.ones((3, 3), bool))
    with pytest.raises(ValueError, match="normals"):
        ps.View(view.images, normals=np.zeros((16, 16, 2)))
    with pytest.raises(ValueError, match="images"):
        ps.View([["not", "numbers"]])
    with pytest.raises(ValueError, match="mask"):
        ps.reconstruct(np.full((4, 8, 8), np.nan, np.float32))
    with pytest.raises(ValueError, match="light"):
        ps.reconstruct(np.zeros((4, 8, 8), np.float32))
    with pytest.raises(ValueError, match="mask"):
        ps.reconstruct(view, view.mask)
    with pytest.raises(ValueError, match="size mismatch"):
        ps.evaluate(np.zeros((4, 4, 3)), np.zeros((5, 4, 3)), np.ones((4, 4), bool))
    with pytest.raises(ValueError, match="uint8 or uint16"):
        ps.import_angles(*view.images)
    with pytest.raises(ValueError, match="demosaic"):
        ps.import_mosaic(np.zeros((8, 8), np.uint16), demosaic="nearest")


def test_unknown_methods_and_options_are_refused(view):
    with pytest.raises(ValueError, match="nope"):
        ps.reconstruct(view, method="nope")
    with pytest.raises(ValueError, match="lambda"):
        ps.reconstruct(view, method="atkinson", **{"lambda": 0.5})
    with pytest.raises(ValueError, match="eta"):
        ps.reconstruct(view, method="smith", eta="high")
    with pytest.raises(ValueError, match="option eta"):
        ps.reconstruct(view, method="smith", lambda_=1, eta="high")
    with pytest.raises(ValueError, match="finite"):
        ps.reconstruct(view, method="smith", eta=float("nan"))
    with pytest.raises(ValueError, match="tau_stepp"):
        ps.reconstruct(view, method="smsfp", parg_params={"tau_stepp": 0.3})


def test_files_are_os_errors(tmp_path):
    with pytest.raises(OSError, match="missing"):
        ps.read_view(tmp_path / "missing")
    (tmp_path / "bad" / "input").mkdir(parents=True)
    (tmp_path / "bad" / "input" / "pol_000.png").write_bytes(b"not a png")
    with pytest.raises(OSError, match="pol_0"):
        ps.read_view(tmp_path / "bad")
    with pytest.raises(OSError):
        ps.render(tmp_path / "no-scene.toml")
    with pytest.raises(ValueError):
        ps.render("[camera]\nwidth = 'wide'\n")
    with pytest.raises(ValueError, match="preset"):
        ps.dataset("no-such-preset")
