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
