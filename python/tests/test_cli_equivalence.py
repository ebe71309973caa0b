"""Python's reconstruct gives `sfp reconstruct`'s normals, for every method,
on the analytic blobs and on a path-traced built-in view."""

import json

import numpy as np
import pytest

import polar_sfp as ps

TOLERANCE = 1e-5


def cli_result(sfp, view, method, out):
    result = out / f"result-{method}"
    sfp("reconstruct", view, "--method", method, "--out", result)
    export = out / f"export-{method}"
    sfp("export", result, "--out", export)
    run = json.loads((result / "run.json").read_text())
    metrics = json.loads((result / "metrics.json").read_text())
    return np.load(export / "normals.npy"), np.load(export / "height.npy"), run, metrics


@pytest.mark.parametrize("which", ["blobs", "builtin"])
@pytest.mark.parametrize("method", sorted(ps.methods()))
def test_normals_equal_the_cli(which, method, request, sfp, tmp_path):
    path = request.getfixturevalue(which)
    normals, height, run, metrics = cli_result(sfp, path, method, tmp_path)
    view = ps.read_view(path)
    for result in (
        ps.reconstruct(view, method=method),
        ps.reconstruct(view.images, view.mask, method=method),
    ):
        diff = np.abs(result.normals - normals).max()
        print(f"{which} {method}: max |Δn| = {diff:.2e}")
        assert diff <= TOLERANCE, f"{which} {method}: normals differ by {diff}"
        assert np.array_equal(np.isnan(result.height), np.isnan(height))
        assert result.info["config"] == run["config"]
        assert result.info["method"] == method
    from_view = ps.reconstruct(view, method=method)
    assert from_view.info["view"]["input_hash"] == run["view"]["input_hash"]
    assert from_view.metrics == pytest.approx(metrics)


@pytest.fixture(scope="session")
def glossy(sfp, tmp_path_factory):
    """A path-traced built-in view with the paper's material model (a
    specular lobe, so `gt/specular_stokes.exr` scores a labelling)."""
    out = tmp_path_factory.mktemp("views") / "glossy"
    sfp("dataset", "builtin", "--out", out, "--views", 1, "--size", 48, "--spp", 4, "--svbrdf")
    return sorted(p for p in out.iterdir() if (p / "meta.json").is_file())[0]


@pytest.mark.parametrize("method", sorted(ps.methods()))
def test_metrics_equal_metrics_json_with_a_specular_labelling(method, glossy, sfp, tmp_path):
    result = tmp_path / method
    sfp("reconstruct", glossy, "--method", method, "--set", "specular=auto", "--out", result)
    metrics = json.loads((result / "metrics.json").read_text())
    assert "specular" in metrics, "the view scores a specular labelling"
    ours = ps.reconstruct(ps.read_view(glossy), method=method, specular="auto").metrics
    assert_same(ours, metrics, method)


def assert_same(ours, theirs, where):
    """Equal key for key, numbers within rounding, at every depth."""
    if isinstance(theirs, dict):
        assert isinstance(ours, dict) and sorted(ours) == sorted(theirs), where
        for key in theirs:
            assert_same(ours[key], theirs[key], f"{where}.{key}")
    else:
        assert ours == pytest.approx(theirs), where


def test_the_default_method_is_the_same(blobs, sfp, tmp_path):
    sfp("reconstruct", blobs, "--out", tmp_path / "default")
    run = json.loads((tmp_path / "default" / "run.json").read_text())
    default = ps.reconstruct(ps.read_view(blobs))
    assert run["config"]["method"] == default.info["config"]["method"] == "smsfp"
