"""Readers of public shape-from-polarization dataset layouts.

Each reader returns a :class:`polar_sfp.View` in the project's convention
(docs/conventions.md §1): images (4, H, W) behind polarizers at 0°, 45°,
90°, 135° measured from image right **counter-clockwise** (towards image
up), normals in the camera frame x right, **y up**, z towards the camera,
zero outside the object.

DeepSfP (Ba et al., ECCV 2020) and SPW / sfp-wild (Lei et al., CVPR 2022)
store their arrays in the image's own frame: x right, **y down the rows**,
z towards the camera, polarizer angles measured from image right towards
the rows below (clockwise as displayed). That frame is ours mirrored
through the x axis, so the readers negate ``n_y`` and swap the 45° and
135° images (an angle ϑ there is −ϑ ≡ 180° − ϑ here); the writers in the
tests do the inverse. SPW trains on DeepSfP's data unconverted beside its
own, which is why both share one convention. The SfPUEL layout written by
``sfp export`` is already in ours and says so in its ``layout.json``.
"""

import contextlib
import json
import os
import warnings

import numpy as np

from ._native import View, frame_fit, read_layout

#: The axis statement of ``sfp export``'s layout.json (core/src/export.rs).
_OUR_AXES_PREFIX = "camera frame: x right, y up, z towards the camera"


def _from_image_frame(images_hwc, normals_hwc):
    """Images (H, W, 4) and normals (H, W, 3) in the image frame (y down,
    angles clockwise as displayed) as our (4, H, W) images and normals."""
    images = np.moveaxis(np.asarray(images_hwc, dtype=np.float32), -1, 0)
    images = images[[0, 3, 2, 1]]  # 0°, 45°, 90°, 135° there = 0°, 135°, 90°, 45° here
    normals = None
    if normals_hwc is not None:
        normals = np.array(normals_hwc, dtype=np.float32)
        normals[..., 1] *= -1.0
    return images, normals


def _warn_if_y_reversed(normals, mask, path, layout):
    """Warns when the normals, converted from ``layout``'s image frame, point
    out of the mask along its outline only with y negated (``frame_fit``):
    the file is then in another frame than this reader assumes."""
    if normals is None or mask is None:
        return
    fit = frame_fit(normals, mask)
    if fit is not None and fit[1] > fit[0] + 0.5:
        warnings.warn(
            f"{path}: the normals point out of the mask along its outline only with y "
            f"negated (mean cosine {fit[1]:.2f}, {fit[0]:.2f} as read): this reader "
            f"assumes {layout}'s image frame (y down); the file seems to store y up",
            UserWarning,
            stacklevel=3,
        )


@contextlib.contextmanager
def _naming(path):
    """Errors raised while reading ``path`` name it, as docs/python.md
    promises: a file the system cannot read stays an ``OSError``; content a
    reader cannot use (arrays of the wrong shape or type) is a
    ``ValueError``, whatever the library underneath raised."""
    path = os.fspath(path)
    try:
        yield
    except ImportError:
        raise
    except Exception as e:
        if str(e).startswith(path):
            raise
        kind = OSError if isinstance(e, OSError) else ValueError
        raise kind(f"{path}: {type(e).__name__}: {e}") from e


def _load_npy(path):
    """The array of one ``.npy`` file (no pickles); a file that is not one
    is an ``OSError`` naming it."""
    try:
        array = np.load(os.fspath(path), allow_pickle=False)
    except Exception as e:
        raise OSError(f"{os.fspath(path)}: not a readable .npy file: {e}") from e
    if not isinstance(array, np.ndarray):
        raise OSError(f"{os.fspath(path)}: not a .npy file holding one array")
    return array


def _check_hwc(array, channels, name, path):
    array = np.asarray(array)
    if array.ndim != 3 or array.shape[-1] != channels or 0 in array.shape:
        raise ValueError(f"{path}: {name} has shape {array.shape}, expected (H, W, {channels})")


def read_deepsfp(path):
    """One DeepSfP ``.mat`` file: ``images`` (H, W, 4) at 0°, 45°, 90°, 135°,
    ``mask`` (H, W), ``normals_gt`` (H, W, 3), in the image frame (see the
    module doc), converted to ours. Needs scipy (``pip install scipy``)."""
    try:
        from scipy.io import loadmat
    except ImportError as e:  # scipy is optional: only .mat files need it
        raise ImportError("reading DeepSfP .mat files needs scipy: pip install scipy") from e
    try:
        data = loadmat(os.fspath(path))
    except Exception as e:  # scipy's MatReadError and others name no file
        raise OSError(f"{path}: not a readable .mat file: {e}") from e
    with _naming(path):
        for key in ("images", "mask"):
            if key not in data:
                raise ValueError(f"{path}: no `{key}` in the .mat file")
        _check_hwc(data["images"], 4, "images", path)
        normals = data.get("normals_gt")
        if normals is not None:
            _check_hwc(normals, 3, "normals_gt", path)
        images, normals = _from_image_frame(data["images"], normals)
        mask = np.asarray(data["mask"]) > 0
        if mask.shape != images.shape[1:]:
            raise ValueError(f"mask has shape {mask.shape}, images {images.shape[1:]}")
        if normals is not None:
            normals[~mask] = 0.0
        _warn_if_y_reversed(normals, mask, path, "DeepSfP")
        meta = {"source": os.fspath(path), "format": "deepsfp"}
        return View(images, mask=mask, normals=normals, meta=meta)


def read_spw(polar_path, normal_path=None, mask=None):
    """One SPW (sfp-wild) sample: ``*_polar.npy`` (H, W, 4) images at 0°,
    45°, 90°, 135° and, when given or found beside it, ``*_normal.npy``
    (H, W, 3), in the image frame (see the module doc), converted to ours.
    ``mask`` is an optional bool (H, W) array; without one the object is
    the pixels with a ground-truth normal, else every pixel."""
    polar_path = os.fspath(polar_path)
    if normal_path is None and polar_path.endswith("_polar.npy"):
        candidate = polar_path[: -len("_polar.npy")] + "_normal.npy"
        normal_path = candidate if os.path.isfile(candidate) else None
    polar = _load_npy(polar_path)
    _check_hwc(polar, 4, "the polarizer images", polar_path)
    normals = None
    if normal_path is not None:
        normals = _load_npy(normal_path)
        _check_hwc(normals, 3, "the normals", normal_path)
        if normals.shape[:2] != polar.shape[:2]:
            raise ValueError(
                f"{normal_path}: normals are {normals.shape[:2]}, images {polar.shape[:2]}"
            )
    with _naming(polar_path):
        images, normals = _from_image_frame(polar, normals)
        if mask is None and normals is not None:
            mask = np.any(normals != 0.0, axis=-1)
        _warn_if_y_reversed(normals, mask, polar_path, "SPW")
        meta = {"source": polar_path, "format": "spw"}
        return View(images, mask=mask, normals=normals, meta=meta)


def read_sfpuel(path, name=None, axes="ours"):
    """One view of the SfPUEL per-angle layout (``pol000/ pol045/ pol090/
    pol135/ mask/ normal/``, one PNG per view) as ``sfp export VIEW --out
    LAYOUT`` writes it, or as SfPUEL publishes its data (RGB PNGs and no
    ``layout.json``; RGB images make a colour view, whose ``colour`` holds
    R, G, B per polarizer and whose ``images`` are their Rec. 709
    luminance, what the methods read): in our convention,
    which a ``layout.json``, when there is one, states and this reader
    checks. ``name`` picks a view when the layout holds several; ``axes``
    names the frame of its normals (``ours``, ``image``: y down,
    ``opencv``: y down and z into the scene), and a warning says when the
    normals fit the other y sense along the mask's outline."""
    sidecar = os.path.join(os.fspath(path), "layout.json")
    if os.path.isfile(sidecar):
        with _naming(sidecar), open(sidecar, encoding="utf-8") as f:
            layout = json.load(f)
            stated = layout.get("axes", "") if isinstance(layout, dict) else None
            if not isinstance(stated, str):
                raise ValueError("not a layout.json object with an `axes` string")
        if not stated.startswith(_OUR_AXES_PREFIX):
            raise ValueError(f"{sidecar}: axes {stated!r} are not the project's ({_OUR_AXES_PREFIX})")
    return read_layout(path, name, axes)
