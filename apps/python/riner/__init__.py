"""riner: ring-artifact removal for CT by an implicit neural representation, on OpenCL.

    import numpy as np, riner
    geometry = riner.parallel_beam(np.linspace(0, np.pi, 181), columns=640, center=295.6)
    image, alpha, beta, summary, field = riner.reconstruct(sino, geometry, steps=12000)

Arrays are numpy arrays: a sinogram [views, columns] (2D) or a projection stack
[views, rows, columns] (3D), images [y, x] or volumes [z, y, x] in 1/mm. A geometry is the
scan contract of riner's docs/guide/scans.md (a dict, a JSON file, or a preset name);
parallel_beam() and divergent_beam() build one from tomopy/algotom-style arguments. Errors
raise riner.InputError (also a ValueError) for bad input, riner.OpenCLError for device
failures (both riner.Error, a RuntimeError), TypeError for arrays of the wrong kind; Ctrl-C
during training raises KeyboardInterrupt once training has stopped.
"""

import json
import numbers
import os
from typing import NamedTuple

from . import _riner
from ._riner import Error, InputError, OpenCLError

__all__ = [
    "Error", "InputError", "OpenCLError", "Reconstruction",
    "devices", "settings", "geometry", "parallel_beam", "divergent_beam",
    "reconstruct", "fbp", "destripe", "simulate", "center", "flat_field", "load_scan",
    "read_array", "write_array", "compare",
]
__version__ = "0.1.0"


def devices():
    """Every OpenCL device: its capabilities and the training plan riner would use on it."""
    return json.loads(_riner.devices_json())


def settings():
    """Every setting reconstruct() takes: name, type, allowed values, default, meaning."""
    return json.loads(_riner.settings_json())


def geometry(spec):
    """A validated geometry dict from a dict, a JSON file's path, or a preset name
    ("fan2d-paper", "cone3d-paper", "parallel3d")."""
    return json.loads(_geometry_json(spec))


def _geometry_json(spec):
    if isinstance(spec, dict):
        return _riner.geometry_json(json.dumps(spec), "geometry")
    if isinstance(spec, (str, os.PathLike)):
        path = os.fspath(spec)
        if os.path.exists(path):
            return _riner.load_geometry_json(path)
        if "/" not in path and not path.endswith(".json"):
            return _riner.preset_geometry_json(path)
        raise InputError(f"{path}: no such geometry file")
    raise TypeError(f"geometry must be a dict, a JSON file's path or a preset name "
                    f"(got {type(spec).__name__})")


def _image_grid(columns, pitch, magnification, rows, image_shape, voxel_size):
    if voxel_size is None:
        voxel_size = pitch / magnification
    if image_shape is None:
        image_shape = (columns, columns) if rows is None else (rows, columns, columns)
    return {"shape": [int(n) for n in image_shape], "voxel_mm": float(voxel_size)}


def _count(name, value):
    """A whole number >= 0 for `name`, or InputError (a negative one reached the C++ binding as a
    TypeError that printed the whole array)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 0:
        if isinstance(value, float) and value.is_integer() and value >= 0:
            return int(value)
        raise InputError(f"{name} must be a whole number >= 0 (got {value!r})")
    return int(value)


def _offset(columns, center):
    # center: the 0-based, fractional column the rotation axis projects to (tomopy's and
    # algotom's "center"); riner's offset_px is its distance from the detector's middle.
    if center is None:
        return 0.0
    try:
        return (columns - 1) / 2.0 - float(center)
    except (TypeError, ValueError):
        raise InputError(f'center must be the axis\'s column (a number) or "auto" (got {center!r})') from None


def _axis_offset(g, center):
    # The offset of a geometry dict's detector for the axis at column `center`.
    columns = g["detector"]["count"]
    return _offset(columns[0] if isinstance(columns, list) else columns, center)


def _set_offset(g, offset):
    # A 3D detector's offset is [u, v]: the axis moves u only.
    if isinstance(g["detector"]["offset_px"], list):
        g["detector"]["offset_px"][0] = offset
    else:
        g["detector"]["offset_px"] = offset


def _detector(columns, rows, pitch, center):
    offset = _offset(columns, center)
    if rows is None:
        return {"count": int(columns), "pitch_mm": float(pitch), "offset_px": offset}
    return {"count": [int(columns), int(rows)], "pitch_mm": [float(pitch), float(pitch)],
            "offset_px": [offset, 0.0]}


def parallel_beam(angles, columns, center=None, rows=None, pixel_size=1.0,
                  image_shape=None, voxel_size=None):
    """A parallel-beam geometry, tomopy-style: angles in radians (one per view), columns of
    the detector, center = the column the rotation axis projects to (0-based; default the
    middle), rows for a 3D stack, pixel_size in mm. The image defaults to columns x columns
    (x rows slices) of pixel_size."""
    detector = _detector(columns, rows, pixel_size, center)
    return geometry({
        "type": "parallel2d" if rows is None else "parallel3d",
        "detector": detector,
        "angles_rad": [float(a) for a in angles],
        "volume": _image_grid(columns, pixel_size, 1.0, rows, image_shape, voxel_size),
    })


def divergent_beam(angles, columns, source_origin, origin_detector, center=None, rows=None,
                   pixel_size=1.0, image_shape=None, voxel_size=None):
    """A fan-beam (2D) or, with rows, cone-beam (3D) geometry with a flat detector: distances
    in mm from the source to the rotation axis and from the axis to the detector. The image
    defaults to columns x columns of pixel_size / magnification."""
    magnification = (source_origin + origin_detector) / source_origin
    return geometry({
        "type": "fan2d" if rows is None else "cone3d",
        "detector": _detector(columns, rows, pixel_size, center),
        "source_origin_mm": float(source_origin),
        "origin_detector_mm": float(origin_detector),
        "angles_rad": [float(a) for a in angles],
        "volume": _image_grid(columns, pixel_size, magnification, rows, image_shape, voxel_size),
    })


def _array(value):
    import numpy
    return value if isinstance(value, numpy.ndarray) else numpy.asarray(value)


def _device(device):
    return "" if device is None else str(device)


def flat_field(projections, flat, dark=None, flat_after=None):
    """rho = -ln((I - D) / (F - D)) with F and D the per-pixel means of the flat and dark frames
    (one frame or a stack). A reading with no light (at or below the dark, or, given two or more
    dark frames, less than 3 times their noise above it: report's dark_noise and
    readings_in_dark_noise) becomes +inf, which reconstruct keeps as a bound where an object
    stopped the beam; other invalid readings become NaN. flat_after: flats taken after the scan
    (a drifting beam): each view's F is interpolated between the two series by its place in the
    scan. Returns (rho, report dict)."""
    rho, report = _riner.flat_field(_array(projections), _array(flat),
                                    None if dark is None else _array(dark),
                                    None if flat_after is None else _array(flat_after))
    return rho, json.loads(report)


def _scan(sino, geometry_spec, flat, dark, center_spec, flat_after=None):
    """The normalised measurement, the geometry JSON and what was done to get them."""
    notes = {"flat_field": None, "centre": None}
    if flat is not None:
        sino, notes["flat_field"] = flat_field(sino, flat, dark, flat_after)
    elif dark is not None:
        raise InputError("dark needs flat")
    elif flat_after is not None:
        raise InputError("flat_after needs flat")
    else:
        sino = _array(sino)
    geometry_json = _geometry_json(geometry_spec)
    if center_spec is not None:
        g = json.loads(geometry_json)
        if center_spec == "auto":
            notes["centre"] = json.loads(_riner.center(sino, geometry_json))
            offset = notes["centre"]["offset_px"]
        else:
            offset = _axis_offset(g, center_spec)
        _set_offset(g, offset)
        geometry_json = _riner.geometry_json(json.dumps(g), "geometry")
    return sino, geometry_json, notes


def center(sino, geometry, flat=None, dark=None, flat_after=None):
    """The centre of rotation a parallel-beam scan's own views point to (mirrored views half
    a turn apart): a dict with offset_px (riner's), axis_column (tomopy's center), spread_px,
    method, and half_acquisition (a full turn whose axis lies near one end of the detector)."""
    sino, geometry_json, _ = _scan(sino, geometry, flat, dark, None, flat_after)
    return json.loads(_riner.center(sino, geometry_json))


def fbp(sino, geometry, flat=None, dark=None, center=None, filter="ram-lak", device=None,
        engine="opencl", flat_after=None, fill_stopped_beam=False, return_report=False):
    """FBP (parallel, fan), FDK (cone) or slice-wise FBP (parallel 3D) of a scan, mu in 1/mm.
    center: the axis column, or "auto" to estimate it (parallel beam); flat_after: as
    flat_field's. Invalid readings are interpolated from their neighbours, but readings of +inf
    where the object stopped the beam (metal) read, beside a metal's edge, as the largest finite
    reading of nine views in ten (of their detector row), so the metal shows (a UserWarning says
    so); fill_stopped_beam=True
    interpolates them too. return_report=True returns (image, report): the dict `riner fbp
    --json` gives (non_finite_replaced, stopped_beam_readings, stopped_beam_floor, short_scan,
    parker_weighted, half_acquisition_overlap_mm, and flat_field and centre as reconstruct's
    summary has them)."""
    sino, geometry_json, notes = _scan(sino, geometry, flat, dark, center, flat_after)
    image, report = _riner.fbp(sino, geometry_json, filter, engine, _device(device),
                               bool(fill_stopped_beam))
    if not return_report:
        return image
    report = json.loads(report)
    report.update(notes)
    return image, report


def destripe(sino, geometry, flat=None, dark=None, center=None, method="all", size=0,
             large_size=0, snr=3.0, sigma=0.0, fit_order=2, levels=0, wavelet=9, device=None,
             engine="opencl", flat_after=None, rank_window=0):
    """Classical stripe removal on the sinogram, as `riner destripe`: method "normalise",
    "sorting", "filtering", "fitting", "wavelet" (Münch et al.'s wavelet-Fourier filter),
    "large", "dead" or "all" (Vo et al.'s combination); size and large_size 0 for the
    literature's 21 (5 in "all", after its large-stripe step) and 51; rank_window the sorting
    step's mean of its correction over that many ranks (0: a sixth of the views, 1: Vo's as
    published); sigma 0 for the method's
    own width, levels 0 for as many as fit (up to 4), wavelet the Daubechies order. Returns a
    dict: sino (the destriped measurement), stripes (each element's mean removed, rho;
    exp(-stripes) reads as alpha), dead_elements,
    large_stripe_elements, size, large_size, rank_window, sigma, wavelet_levels,
    non_finite_replaced.
    engine "opencl" runs every step as a kernel on device (None: the first GPU, else the first
    device), "reference" on the CPU twins. flat_after: as flat_field's."""
    sino, geometry_json, _ = _scan(sino, geometry, flat, dark, center, flat_after)
    return _riner.destripe(sino, geometry_json, method, _count("size", size),
                           _count("large_size", large_size), _count("rank_window", rank_window),
                           snr, sigma,
                           _count("fit_order", fit_order), _count("levels", levels),
                           _count("wavelet", wavelet), engine, _device(device))


def simulate(image=None, geometry="fan2d-paper", seed=0, photons=1e7, nonideal_fraction=0.75,
             alpha_min=0.75, alpha_max=1.25, dead=2, dead_rows=0, dead_columns=0,
             mu_unit="mm", mu_scale=0.1, projector="exact", device=None, engine="opencl",
             response_pattern="per-element", partial=0, partial_dead=0):
    """A ring-corrupted scan by the paper's protocol (METHOD.md §4) of `image` (on the
    geometry's grid; mu_unit "cm" for DeepLesion's 1/cm) or, when None, of the built-in
    Shepp-Logan phantom. response_pattern "rows-x-columns" (3D) draws alpha as row x column
    factors, as `riner simulate --response-pattern` does; partial and partial_dead make
    that many elements change their response or die part-way (partial rings; alpha is then
    per view), as `riner simulate --partial/--partial-dead` do. Returns a dict: sino,
    clean, alpha (0 = dead), ground_truth, geometry."""
    if mu_unit not in ("mm", "cm"):
        raise InputError(f"mu_unit must be mm or cm (got {mu_unit!r})")
    if image is not None:
        image = _array(image)
        if mu_unit == "cm":
            image = image * 0.1
    geometry_json = _geometry_json(geometry)
    out = _riner.simulate(image, geometry_json, mu_scale, _count("seed", seed), photons,
                          nonideal_fraction, alpha_min, alpha_max, _count("dead", dead),
                          _count("dead_rows", dead_rows), _count("dead_columns", dead_columns),
                          projector, engine, _device(device), response_pattern,
                          _count("partial", partial), _count("partial_dead", partial_dead))
    out["geometry"] = json.loads(geometry_json)
    return out


class _ReconstructionTuple(NamedTuple):
    image: object    # mu in 1/mm on the geometry's grid, rings corrected
    alpha: object    # the detector's estimated response per element ([columns] or [rows, columns])
    beta: object     # validity per element; < 0.5 marks a dead element
    summary: dict    # what `riner reconstruct` writes to summary.json
    field: object    # the trained field before the ring corrections


class Reconstruction(_ReconstructionTuple):
    """(image, alpha, beta, summary, field), and alpha_by_view: each view's response ([views,
    columns] or [views, rows, columns]) when some element changes or dies part-way through the
    scan (summary["changing_elements"]), else None. An attribute, not a sixth item, so that
    code unpacking five items keeps working."""

    def __new__(cls, image, alpha, beta, summary, field, alpha_by_view=None):
        self = super().__new__(cls, image, alpha, beta, summary, field)
        self.alpha_by_view = alpha_by_view
        return self


def _settings_list(kwargs):
    names = [s["name"] for s in settings()]
    pairs = []
    for key, value in kwargs.items():
        if key in names:
            name = key
        else:
            matches = [n for n in names if n.rsplit(".", 1)[-1] == key]
            if len(matches) != 1:
                hint = (f"it could be {', '.join(matches)}" if matches
                        else "riner.settings() lists them")
                raise InputError(f"unknown setting {key!r} ({hint}; pass settings={{name: value}})")
            name = matches[0]
        pairs.append((name, json.dumps(value)))
    return pairs


def reconstruct(sino, geometry, flat=None, dark=None, center=None, config=None, settings=None,
                progress=None, progress_every=200, quality=True, device=None, engine="opencl",
                flat_after=None, checkpoint=None, checkpoint_minutes=5.0, **short_settings):
    """Riner on a scan: returns Reconstruction(image, alpha, beta, summary, field), with
    .alpha_by_view (each view's response when some change part-way, else None).

    sino: the log-normalised measurement, or raw intensities when flat (and dark) are given;
    flat_after: flats taken after the scan (a drifting beam), as flat_field's.
    geometry: a dict, a JSON path or a preset name. center: the axis column, or "auto".
    config: a settings dict or JSON file as `riner reconstruct --config` takes; settings: a
    dict {"training.steps": 12000, ...}; keyword arguments name settings by their last part
    (steps=12000, seed=1, alpha_lr_scale=0.3); riner.settings() lists them.
    progress: called with a dict (step, total, loss, seconds) every progress_every steps;
    returning False stops training early. quality: the no-reference quality report against
    FBP in the summary. Ctrl-C stops training and raises KeyboardInterrupt.
    checkpoint: a file where training's state is saved every checkpoint_minutes minutes of
    training and where it stops early (Ctrl-C, the callback); when it exists, training goes on
    from it (the same scan, settings and device: the uninterrupted run's result to the bit), and
    it is removed once training has finished. The temporary files that a kill in the middle of
    a save left in its folder (their writer on this host ended) are removed first.
    """
    sino, geometry_json, notes = _scan(sino, geometry, flat, dark, center, flat_after)
    if config is None:
        config_json = ""
    elif isinstance(config, dict):
        config_json = json.dumps(config)
    else:
        try:
            with open(config, encoding="utf-8") as f:
                config_json = f.read()
        except OSError as e:
            raise InputError(f"{os.fspath(config)}: cannot read the settings file "
                             f"({e.strerror})") from None
    pairs = _settings_list(dict(settings or {}, **short_settings))
    image, alpha, beta, summary, field, alpha_by_view = _riner.reconstruct(
        sino, geometry_json, config_json, pairs, engine, _device(device), progress,
        int(progress_every), bool(quality), "" if checkpoint is None else os.fspath(checkpoint),
        float(checkpoint_minutes))
    summary = json.loads(summary)
    summary.update(notes)
    return Reconstruction(image, alpha, beta, summary, field, alpha_by_view)


def load_scan(path, geometry=None, flat=None, dark=None, row=None, center=None,
              flat_after=None):
    """A scan from files, as `riner reconstruct SCAN` reads it: a measurement (.npy, .nii, .tif,
    a TIFF folder or pattern, "file.h5:/dataset"), raw projections with flat (and dark) files,
    a Data Exchange / NXtomo file with its own flats and darks, or a scan JSON naming its
    files. geometry: a JSON path (default: geometry.json beside the scan); row: one detector
    row of a stack (a 2D slice); center: the axis's column, or "auto" to estimate it;
    flat_after: flats taken after the scan (each view's flat interpolated between the two).
    Beside a Data Exchange / NXtomo file, flat and dark replace the file's own and flat_after
    adds to them. Returns (sino, geometry dict, notes dict with flat_field, centre and
    geometry_doubts: a line each for what the readings say against the geometry, such as views
    that turn twice or half as far as the angles say)."""
    sino, geometry_json, notes = _riner.load_scan(
        os.fspath(path), "" if geometry is None else os.fspath(geometry),
        "" if flat is None else os.fspath(flat), "" if dark is None else os.fspath(dark),
        row, "auto" if center == "auto" else "",
        "" if flat_after is None else os.fspath(flat_after))
    g = json.loads(geometry_json)
    if center not in (None, "auto"):
        _set_offset(g, _axis_offset(g, center))
    return sino, g, json.loads(notes)


def read_array(path):
    """An array file (.npy, .nii, .tif, .raw with its sidecar, HDF5 "file.h5:/dataset", a TIFF
    folder or pattern) as float32."""
    array, _, _ = _riner.read_array(os.fspath(path))
    return array


def write_array(path, array, voxel_size=None):
    """Writes an array (format by extension), atomically; voxel_size per axis (mm) for NIfTI."""
    array = _array(array)
    _riner.write_array(os.fspath(path), array,
                       [] if voxel_size is None else [float(v) for v in voxel_size])


def compare(image, reference, mask=None):
    """PSNR (keys psnr and psnr_db, the CLI's), SSIM (scikit-image's definition), MAE, RMSE of
    image against reference, and
    edge_ratio (the image's gradient over the reference's strongest edges against the
    reference's: 1 as sharp, below 1 blurred); mask="circle" restricts them to the inscribed
    circle."""
    if mask not in (None, "circle"):
        raise InputError(f"mask must be None or 'circle' (got {mask!r})")
    return _riner.compare(_array(image), _array(reference), mask == "circle")
