"""Type stubs of the compiled module (python/src)."""

from os import PathLike
from typing import Any, Dict, Iterator, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
StrPath = Union[str, "PathLike[str]"]

class View:
    """One polarization view; arrays are read-only.

    images: float32 (4, H, W) behind polarizers at 0°, 45°, 90°, 135° (from
    image right, counter-clockwise), in units of the sensor's full scale;
    mask: bool (H, W) or None; normals: float32 (H, W, 3) ground truth in
    the camera frame (x right, y up, z towards the camera) or None; meta:
    the view's meta.json.
    """

    def __init__(
        self,
        images: ArrayLike,
        mask: Optional[ArrayLike] = None,
        normals: Optional[ArrayLike] = None,
        meta: Optional[Dict[str, Any]] = None,
    ) -> None: ...
    @property
    def images(self) -> npt.NDArray[np.float32]: ...
    @property
    def mask(self) -> Optional[npt.NDArray[np.bool_]]: ...
    @property
    def normals(self) -> Optional[npt.NDArray[np.float32]]: ...
    @property
    def meta(self) -> Dict[str, Any]: ...
    def stokes(self) -> npt.NDArray[np.float32]:
        """float32 (3, H, W): s0, s1, s2."""
    def dop(self) -> npt.NDArray[np.float32]:
        """float32 (H, W): degree of linear polarization in [0, 1]."""
    def aop(self) -> npt.NDArray[np.float32]:
        """float32 (H, W): angle of polarization in [0, π), radians."""

class Result:
    """A reconstruction: normals float32 (H, W, 3), height float32 (H, W)
    with NaN outside the mask, info (what run.json holds), metrics (the
    figures of metrics.json when the view has ground truth, else None)."""

    @property
    def normals(self) -> npt.NDArray[np.float32]: ...
    @property
    def height(self) -> npt.NDArray[np.float32]: ...
    @property
    def info(self) -> Dict[str, Any]: ...
    @property
    def metrics(self) -> Optional[Dict[str, float]]: ...

class DatasetViews:
    """The views of a dataset preset, rendered as they are asked for."""

    def __iter__(self) -> Iterator[View]: ...
    def __next__(self) -> View: ...
    def __len__(self) -> int: ...

def read_view(path: StrPath) -> View:
    """A view folder; OSError names the file that could not be read."""

def read_layout(path: StrPath, name: Optional[str] = None) -> View:
    """One view of the per-angle layout `sfp export` writes."""

Codes = Union[ArrayLike, StrPath]

def import_angles(
    i0: Codes,
    i45: Codes,
    i90: Codes,
    i135: Codes,
    mask: Optional[Union[ArrayLike, StrPath]] = None,
    sensor_bits: Optional[int] = None,
    window: Optional[Tuple[float, float]] = None,
    auto_mask: bool = False,
    dark: Optional[Codes] = None,
    flat: Optional[Codes] = None,
    angles_from: str = "horizontal-ccw",
    out: Optional[StrPath] = None,
) -> View:
    """Four polarizer images (uint8/uint16 (H, W) arrays or PNG paths)
    labelled 0°, 45°, 90°, 135° in the frame `angles_from`
    ("horizontal-ccw" or "vertical-cw"), imported as `sfp import --angles`
    imports them: one of `mask`, `window` (low, high) and `auto_mask`;
    `dark` and `flat` frames; `out` writes the view folder. Warnings are
    UserWarnings."""

def import_mosaic(
    raw: Codes,
    pattern: str = "90,45,135,0",
    demosaic: str = "superpixel",
    mask: Optional[Union[ArrayLike, StrPath]] = None,
    sensor_bits: Optional[int] = None,
    window: Optional[Tuple[float, float]] = None,
    auto_mask: bool = False,
    dark: Optional[Codes] = None,
    flat: Optional[Codes] = None,
    angles_from: str = "horizontal-ccw",
    out: Optional[StrPath] = None,
) -> View:
    """A division-of-focal-plane raw frame (uint8/uint16 (H, W) array or PNG
    path), imported as `sfp import --mosaic` imports it; the options are
    `import_angles`'."""

def reconstruct(
    view_or_images: Union[View, ArrayLike],
    mask: Optional[ArrayLike] = None,
    method: str = "smsfp",
    **options: Any,
) -> Result:
    """Normals and height by `method` with its options by name (see
    methods()); unknown methods and options raise ValueError. What the
    method found the data leave undetermined (info["warnings"]) is raised
    as a UserWarning each."""

def methods() -> Dict[str, Dict[str, Any]]:
    """Every method: display, paper, ablations, options {name: {default, doc}}."""

def evaluate(normals: ArrayLike, gt: ArrayLike, mask: ArrayLike) -> Dict[str, float]:
    """mae_deg, rmse_deg, median_deg, acc_11_25, acc_22_5, acc_30, pixels, missing."""

def render(
    scene: StrPath,
    spp: Optional[int] = None,
    seed: Optional[int] = None,
    size: Optional[Union[int, Tuple[int, int]]] = None,
) -> View:
    """Path-traces a scene file (a path) or TOML text."""

def dataset(
    preset: str,
    size: Optional[int] = None,
    views: Optional[int] = None,
    seed: Optional[int] = None,
    spp: Optional[int] = None,
    svbrdf: bool = False,
    textured: bool = False,
) -> DatasetViews:
    """The views of a preset (builtin, a, b or a .toml file), lazily rendered."""
