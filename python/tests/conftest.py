"""Shared fixtures: the `sfp` binary and small views it writes.

The binary is $SFP_BIN, or target/release/sfp of this checkout (built by
`cargo test --workspace --release` or `cargo build --release`). Tests that
compare with it fail when $SFP_BIN names a missing file and skip, saying
so, when neither exists.
"""

import os
import subprocess
from pathlib import Path

import pytest

import polar_sfp as ps

REPO = Path(__file__).resolve().parents[2]


def sfp_binary():
    given = os.environ.get("SFP_BIN")
    if given:
        assert Path(given).is_file(), f"SFP_BIN={given} does not exist"
        return given
    built = REPO / "target" / "release" / "sfp"
    if built.is_file():
        return str(built)
    pytest.skip("no sfp binary: set SFP_BIN or run cargo build --release --bin sfp")


@pytest.fixture(scope="session")
def sfp():
    binary = sfp_binary()

    def run(*args):
        done = subprocess.run([binary, *map(str, args)], capture_output=True, text=True)
        assert done.returncode == 0, f"sfp {' '.join(map(str, args))}: {done.stderr}"
        return done.stdout

    return run


@pytest.fixture(scope="session")
def blobs(sfp, tmp_path_factory):
    """The analytic blobs view of `sfp analytic --shape blobs` (64²)."""
    path = tmp_path_factory.mktemp("views") / "blobs"
    sfp("analytic", "--shape", "blobs", "--size", 64, "--out", path)
    return path


@pytest.fixture(scope="session")
def builtin(sfp, tmp_path_factory):
    """A path-traced built-in view of `sfp dataset builtin` (64², 4 spp)."""
    out = tmp_path_factory.mktemp("views") / "builtin"
    sfp("dataset", "builtin", "--out", out, "--views", 1, "--size", 64, "--spp", 4)
    return sorted(p for p in out.iterdir() if (p / "meta.json").is_file())[0]


@pytest.fixture(scope="session")
def rendered():
    """A path-traced built-in view rendered in memory (no binary needed)."""
    return next(iter(ps.dataset("builtin", size=48, views=1, spp=4)))
