"""polar_sfp: monocular shape from polarization from NumPy.

The renderer, the reconstruction methods and the metrics of polar-sfp
(compiled, in ``polar_sfp._native``) and readers of public SfP dataset
layouts (``polar_sfp.datasets``). Frames and formulas are those of the
project's docs/conventions.md: camera x right, y up, z towards the camera;
polarizer angles and the AoP measured from image right, counter-clockwise.
"""

from ._native import (
    DatasetViews,
    Result,
    View,
    __version__,
    dataset,
    evaluate,
    frame_fit,
    import_angles,
    import_mosaic,
    methods,
    read_layout,
    read_view,
    reconstruct,
    render,
)
from .datasets import read_deepsfp, read_sfpuel, read_spw

__all__ = [
    "DatasetViews",
    "Result",
    "View",
    "__version__",
    "dataset",
    "evaluate",
    "frame_fit",
    "import_angles",
    "import_mosaic",
    "methods",
    "read_deepsfp",
    "read_layout",
    "read_sfpuel",
    "read_spw",
    "read_view",
    "reconstruct",
    "render",
]
