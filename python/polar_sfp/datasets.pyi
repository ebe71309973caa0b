from os import PathLike
from typing import Optional, Union

import numpy.typing as npt

from ._native import View

StrPath = Union[str, "PathLike[str]"]

def read_deepsfp(path: StrPath) -> View: ...
def read_spw(
    polar_path: StrPath,
    normal_path: Optional[StrPath] = None,
    mask: Optional[npt.ArrayLike] = None,
) -> View: ...
def read_sfpuel(path: StrPath, name: Optional[str] = None) -> View: ...
