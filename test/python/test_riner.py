# The Python module against the CLI and against known answers; its error cases each raise the
# stated exception. Run by ctest (label python) with the build's package on PYTHONPATH.
import json
import os
import re
import signal
import subprocess
import threading
import warnings

import numpy as np
import pytest

import riner


def small_fan():
    angles = np.linspace(0, 2 * np.pi, 120, endpoint=False)
    return riner.divergent_beam(angles, columns=96, source_origin=150.0, origin_detector=150.0,
                                image_shape=(64, 64), voxel_size=1.0)


@pytest.fixture(scope="module")
def fan_scan():
    g = small_fan()
    return riner.simulate(None, g, seed=3), g


def test_devices_lists_the_opencl_devices_with_their_plans():
    devices = riner.devices()
    assert len(devices) >= 1
    assert {"index", "name", "platform", "type", "training_plan"} <= set(devices[0])


def test_settings_are_the_cli_table():
    names = {s["name"] for s in riner.settings()}
    assert {"training.steps", "training.seed", "training.alpha_lr_scale"} <= names


def test_parallel_beam_puts_the_axis_at_center():
    g = riner.parallel_beam(np.linspace(0, np.pi, 181), columns=640, center=295.6)
    assert g["type"] == "parallel2d"
    assert g["detector"]["offset_px"] == pytest.approx(23.9)  # tooth's geometry.json
    assert g["volume"] == {"shape": [640, 640], "voxel_mm": 1.0}
    g3 = riner.parallel_beam([0.0, 1.0], columns=8, rows=4, center=3.5)
    assert g3["type"] == "parallel3d" and g3["volume"]["shape"] == [4, 8, 8]
    assert g3["detector"]["offset_px"] == [0.0, 0.0]


def test_a_stack_of_rows_beside_a_2d_geometry_is_a_slice_per_row():
    # As the CLI reads tooth.h5 beside its 2D geometry.json; one row is that row's 2D scan.
    g = riner.parallel_beam(np.linspace(0, np.pi, 60, endpoint=False), columns=48, center=23.5)
    rng = np.random.default_rng(3)
    rows = rng.uniform(0.0, 0.1, size=(60, 2, 48)).astype(np.float32)
    both = riner.fbp(rows, g)
    assert both.shape == (2, 48, 48)
    first = riner.fbp(np.ascontiguousarray(rows[:, 0, :]), g)
    assert np.allclose(both[0], first, atol=1e-6)
    one = riner.fbp(np.ascontiguousarray(rows[:, :1, :]), g)
    assert one.shape == (48, 48)
    assert np.array_equal(one, first)


def test_geometry_from_preset_file_and_dict(tmp_path):
    preset = riner.geometry("fan2d-paper")
    path = tmp_path / "g.json"
    path.write_text(json.dumps(preset))
    assert riner.geometry(path) == preset
    assert riner.geometry(str(path)) == riner.geometry(dict(preset))


@pytest.mark.parametrize("change, message", [
    ({"type": "fan9d"}, "type"),
    ({"detector": {"count": 96, "pitch_mm": -2.0}}, "detector.pitch_mm must be > 0"),
    ({"source_origin_mm": 0.0}, "source_origin_mm"),
])
def test_bad_geometry_raises_input_error(change, message):
    g = dict(small_fan(), **change)
    with pytest.raises(riner.InputError, match=message):
        riner.geometry(g)
    with pytest.raises(ValueError):  # InputError is a ValueError too
        riner.geometry(g)


def test_geometry_of_the_wrong_kind_raises_type_error():
    with pytest.raises(TypeError, match="geometry must be"):
        riner.geometry(42)
    with pytest.raises(riner.InputError, match="preset"):
        riner.geometry("fan2d-nonsense")


def test_simulate_matches_the_cli_bit_for_bit(cli, tmp_path):
    sim = riner.simulate(None, "fan2d-paper", seed=5)
    subprocess.run([cli, "simulate", "--geometry", "fan2d-paper", "--seed", "5", "--out",
                    str(tmp_path), "--quiet"], check=True)
    assert np.array_equal(sim["sino"], riner.read_array(tmp_path / "sino.npy"))
    assert np.array_equal(sim["alpha"], riner.read_array(tmp_path / "alpha.npy"))
    assert (sim["alpha"] == 0).sum() == 2


def test_simulate_partial_rings_matches_the_cli(cli, tmp_path):
    sim = riner.simulate(None, "fan2d-paper", seed=2, partial=3, partial_dead=1)
    subprocess.run([cli, "simulate", "--geometry", "fan2d-paper", "--seed", "2", "--partial", "3",
                    "--partial-dead", "1", "--out", str(tmp_path), "--quiet"], check=True)
    assert sim["alpha"].shape == (360, 500)
    assert np.array_equal(sim["alpha"], riner.read_array(tmp_path / "alpha.npy"))
    assert np.array_equal(sim["sino"], riner.read_array(tmp_path / "sino.npy"))
    changing = [e for e in range(500) if np.any(np.diff(sim["alpha"][:, e]))]
    assert len(changing) == 4


def test_reconstruct_returns_each_views_response_when_some_change_part_way():
    sim = riner.simulate(None, "fan2d-paper", seed=2, partial=3, partial_dead=1)
    r = riner.reconstruct(sim["sino"], "fan2d-paper", steps=20, quality=False)
    found = {c["element"] for c in r.summary["changing_elements"]}
    truth = {e for e in range(500) if np.any(np.diff(sim["alpha"][:, e]))}
    assert found and found <= truth
    assert r.alpha_by_view.shape == (360, 500) and r.alpha_by_view.dtype == np.float32
    for e in found:  # a changing element's response steps where the simulation's does
        assert np.any(np.diff(r.alpha_by_view[:, e]))


def test_fbp_matches_the_cli(cli, tmp_path, fan_scan):
    sim, g = fan_scan
    riner.write_array(tmp_path / "sino.npy", sim["sino"])
    (tmp_path / "geometry.json").write_text(json.dumps(g))
    subprocess.run([cli, "fbp", str(tmp_path / "sino.npy"), "--out", str(tmp_path / "fbp.npy"),
                    "--quiet"], check=True)
    assert np.array_equal(riner.fbp(sim["sino"], g), riner.read_array(tmp_path / "fbp.npy"))


def test_destripe_matches_the_cli(cli, tmp_path, fan_scan):
    sim, g = fan_scan
    riner.write_array(tmp_path / "sino.npy", sim["sino"])
    (tmp_path / "geometry.json").write_text(json.dumps(g))
    subprocess.run([cli, "destripe", str(tmp_path / "sino.npy"), "--method", "sorting",
                    "--out", str(tmp_path / "clean"), "--quiet"], check=True)
    out = riner.destripe(sim["sino"], g, method="sorting")
    assert np.array_equal(out["sino"], riner.read_array(tmp_path / "clean" / "sino.npy"))
    assert np.array_equal(out["stripes"], riner.read_array(tmp_path / "clean" / "stripes.npy"))
    assert out["size"] == 13  # the literature's 21, at most an eighth of 96 columns
    views = sim["sino"].shape[0]
    assert out["rank_window"] == (views // 6) | 1
    subprocess.run([cli, "destripe", str(tmp_path / "sino.npy"), "--method", "sorting",
                    "--rank-window", "1", "--out", str(tmp_path / "published"), "--quiet"],
                   check=True)
    published = riner.destripe(sim["sino"], g, method="sorting", rank_window=1)
    assert published["rank_window"] == 1
    assert np.array_equal(published["sino"],
                          riner.read_array(tmp_path / "published" / "sino.npy"))
    assert not np.array_equal(published["sino"], out["sino"])
    wavelet = riner.destripe(sim["sino"], g, method="wavelet", levels=3, wavelet=5)
    assert wavelet["sino"].shape == sim["sino"].shape and wavelet["wavelet_levels"] == 3
    assert wavelet["sigma"] == 1.0  # the method's own width
    # The CPU twins give the kernels' result to float precision.
    twin = riner.destripe(sim["sino"], g, method="wavelet", levels=3, wavelet=5,
                          engine="reference")
    assert np.max(np.abs(twin["sino"] - wavelet["sino"])) < 1e-4
    with pytest.raises(riner.InputError, match="a destripe method is"):
        riner.destripe(sim["sino"], g, method="wavelets")


def test_arrays_come_out_as_float32_without_a_copy(tmp_path, fan_scan):
    sim, g = fan_scan
    image = riner.fbp(sim["sino"], g)
    assert image.dtype == np.float32 and image.shape == (64, 64)
    assert not image.flags.owndata and image.flags.c_contiguous  # riner's buffer, handed over
    # Other real dtypes and layouts are converted: the same numbers give the same image.
    assert np.array_equal(riner.fbp(sim["sino"].astype(np.float64), g), image)
    assert np.array_equal(riner.fbp(np.asfortranarray(sim["sino"]), g), image)


def test_a_rows_x_columns_detector_matches_the_cli_and_trains_as_factors(cli, tmp_path):
    g = {"type": "cone3d", "detector": {"count": [40, 24], "pitch_mm": [2.0, 2.0]},
         "source_origin_mm": 300, "origin_detector_mm": 300,
         "angles": {"count": 36, "range_rad": 2 * np.pi},
         "volume": {"shape": [12, 32, 32], "voxel_mm": 1.0}}
    sim = riner.simulate(None, g, seed=2, response_pattern="rows-x-columns")
    (tmp_path / "g.json").write_text(json.dumps(g))
    subprocess.run([cli, "simulate", "--geometry", str(tmp_path / "g.json"), "--seed", "2",
                    "--response-pattern", "rows-x-columns", "--out", str(tmp_path / "sim"),
                    "--quiet"], check=True)
    assert np.array_equal(sim["alpha"], riner.read_array(tmp_path / "sim" / "alpha.npy"))
    r = riner.reconstruct(sim["sino"], g, steps=20, alpha_model="rows-x-columns", quality=False)
    assert r.summary["alpha_model"]["model"] == "rows-x-columns"
    a = r.alpha.astype(np.float64)
    assert a[2, 3] * a[20, 37] == pytest.approx(a[2, 37] * a[20, 3], rel=1e-4)
    with pytest.raises(riner.InputError, match="response_pattern must be"):
        riner.simulate(None, g, response_pattern="diagonal")


def test_reconstruct_returns_image_alpha_beta_summary(fan_scan):
    sim, g = fan_scan
    r = riner.reconstruct(sim["sino"], g, steps=300, seed=1)
    image, alpha, beta, summary, field = r
    assert image.shape == (64, 64) and field.shape == (64, 64)
    assert r.alpha_by_view is None  # no element changes part-way
    assert alpha.shape == (96,) and beta.shape == (96,)
    assert summary["steps"] == 300
    # The two dead elements of the simulation are reported dead.
    assert set(np.flatnonzero(sim["alpha"] == 0)) <= set(summary["dead_elements"])
    # ... and so are beta (below 0.5) and alpha (0), as the CLI writes them.
    assert np.all(beta[summary["dead_elements"]] < 0.5)
    assert np.all(alpha[summary["dead_elements"]] == 0)
    assert summary["quality"]["ring_index"] < summary["quality"]["fbp_ring_index"]
    fbp = riner.compare(riner.fbp(sim["sino"], g), sim["ground_truth"])["psnr"]
    metrics = riner.compare(image, sim["ground_truth"])
    assert metrics["psnr"] > fbp
    assert metrics["psnr_db"] == metrics["psnr"]  # the CLI's compare --json key too


def test_the_gil_is_released_while_training(fan_scan):
    sim, g = fan_scan
    done = threading.Event()
    ticks = 0

    def train():
        riner.reconstruct(sim["sino"], g, steps=600, quality=False)
        done.set()

    worker = threading.Thread(target=train)
    worker.start()
    while not done.is_set():
        ticks += 1
    worker.join()
    assert ticks > 10000  # this thread kept running Python while the other trained


def test_progress_callback_sees_every_report_and_can_stop_training(fan_scan):
    sim, g = fan_scan
    seen = []
    r = riner.reconstruct(sim["sino"], g, steps=500, quality=False, progress_every=100,
                          progress=lambda p: seen.append((p["step"], p["total"])))
    assert seen == [(100, 500), (200, 500), (300, 500), (400, 500), (500, 500)]
    r = riner.reconstruct(sim["sino"], g, steps=500, quality=False, progress_every=100,
                          progress=lambda p: p["step"] < 200)
    assert r.summary["steps"] == 200


def test_an_exception_in_the_callback_aborts_training(fan_scan):
    sim, g = fan_scan

    def fail(progress):
        raise ArithmeticError(f"stop at {progress['step']}")

    with pytest.raises(ArithmeticError, match="stop at 50"):
        riner.reconstruct(sim["sino"], g, steps=500, progress=fail, progress_every=50)


def test_a_run_stopped_goes_on_from_its_checkpoint_to_the_same_result(fan_scan, tmp_path):
    sim, g = fan_scan
    whole = riner.reconstruct(sim["sino"], g, steps=500, quality=False)
    checkpoint = tmp_path / "run.checkpoint"

    def fail(progress):
        if progress["step"] == 300:
            raise ArithmeticError("killed")

    # No periodic checkpoint within the run: the one saved where the callback stops it.
    with pytest.raises(ArithmeticError, match="killed"):
        riner.reconstruct(sim["sino"], g, steps=500, quality=False, progress=fail,
                          progress_every=50, checkpoint=checkpoint)
    assert checkpoint.exists()
    # A SIGKILL while saving leaves the half-written file; an ended writer's goes on resuming,
    # a running one's (this process's) stays.
    ended = subprocess.Popen(["true"])
    ended.wait()
    dead = tmp_path / ("run.checkpoint" + riner._riner.temporary_marker(ended.pid) + "1.0")
    live = tmp_path / ("run.checkpoint" + riner._riner.temporary_marker(os.getpid()) + "1.0")
    dead.write_bytes(b"half")
    live.write_bytes(b"half")
    with pytest.raises(riner.InputError, match="a checkpoint of other settings"):
        riner.reconstruct(sim["sino"], g, steps=400, quality=False, checkpoint=checkpoint)
    resumed = riner.reconstruct(sim["sino"], g, steps=500, quality=False, checkpoint=checkpoint)
    assert resumed.summary["steps"] == 500
    assert resumed.summary["resumed_at_step"] == 300  # where the callback stopped it
    np.testing.assert_array_equal(resumed.image, whole.image)
    np.testing.assert_array_equal(resumed.alpha, whole.alpha)
    assert not checkpoint.exists()  # training finished: the result stands for it
    assert not dead.exists() and live.exists()
    with pytest.raises(riner.InputError, match="checkpoint_minutes must be"):
        riner.reconstruct(sim["sino"], g, steps=50, checkpoint=checkpoint, checkpoint_minutes=0)


def test_ctrl_c_cancels_training_cleanly(fan_scan):
    sim, g = fan_scan
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        riner.reconstruct(sim["sino"], g, steps=10_000_000)
    timer.join()
    # Nothing is left in a bad state: the next run works.
    assert riner.reconstruct(sim["sino"], g, steps=50, quality=False).summary["steps"] == 50


@pytest.mark.parametrize("sino, error, message", [
    (lambda s: s.astype(np.complex64), TypeError, "must hold real numbers"),
    (lambda s: s.astype(bool), TypeError, "must hold real numbers"),
    (lambda s: "a sinogram", TypeError, "must hold real numbers"),
    (lambda s: s[:, :90], riner.InputError, r"shape \[120, 90\]"),
    (lambda s: s[None], riner.InputError, "shape"),
    (lambda s: np.full_like(s, np.nan), riner.InputError, "finite"),
])
def test_bad_measurements_raise(fan_scan, sino, error, message):
    sim, g = fan_scan
    with pytest.raises(error, match=message):
        riner.reconstruct(sino(sim["sino"]), g, steps=10)


@pytest.mark.parametrize("kwargs, message", [
    ({"stepz": 3}, "unknown setting 'stepz'"),
    ({"steps": -3}, "training.steps must be in"),
    ({"settings": {"training.sampler": "sideways"}}, "training.sampler"),
    ({"device": "no such device anywhere"}, "no such device"),
    ({"steps": 0}, "training.steps is 0 and there is no warm start"),
    ({"learning_rate": float("nan")}, r'training.learning_rate must be a number \(got "NaN"\)'),
    # Each an InputError with one line (were FileNotFoundError, and "config: config:").
    ({"config": "/nonexistent/settings.json"}, "cannot read the settings file"),
    ({"config": {"training": {"steps": "x"}}}, "^config: training.steps must be an integer"),
])
def test_bad_settings_raise(fan_scan, kwargs, message):
    sim, g = fan_scan
    with pytest.raises(riner.Error, match=message):
        riner.reconstruct(sim["sino"], g, **kwargs)


def test_missing_and_corrupt_files_raise_input_error(tmp_path):
    with pytest.raises(riner.InputError, match="missing.npy"):
        riner.read_array(tmp_path / "missing.npy")
    (tmp_path / "bad.npy").write_bytes(b"\x93NUMPY garbage")
    with pytest.raises(riner.InputError, match="bad.npy"):
        riner.read_array(tmp_path / "bad.npy")


def test_flat_field_and_center_on_raw_parallel_projections():
    angles = np.linspace(0, np.pi, 121)  # 180 degrees with the endpoint view
    g = riner.parallel_beam(angles, columns=80, center=41.5, image_shape=(64, 64))
    sim = riner.simulate(None, g, seed=2, photons=0, dead=0, nonideal_fraction=0)
    flat = np.full((2, 80), 1000.0)
    dark = np.full((80,), 100.0)
    raw = dark + (flat[0] - dark) * np.exp(-sim["sino"])
    rho, report = riner.flat_field(raw, flat, dark)
    assert report["flat_frames"] == 2 and report["dark_frames"] == 1
    assert np.allclose(rho, sim["sino"], atol=1e-4)
    found = riner.center(raw, g, flat=flat, dark=dark)
    assert found["axis_column"] == pytest.approx(41.5, abs=0.1)
    assert found["offset_px"] == pytest.approx(g["detector"]["offset_px"], abs=0.1)


def test_flat_field_takes_light_within_the_dark_noise_for_none():
    # Two dark frames 100 +- 4 (a noise of 4 * sqrt(2) = 5.66 counts): light of 10 over the dark is
    # within 3 sigma sqrt(1 + 1/2) = 20.8 of it, light of 30 is not, under a beam of 10^4 (over
    # e^4 times 20.8: a beam a metal stops).
    dark = np.stack([np.full(50, 96.0), np.full(50, 104.0)])
    dark[:, ::2] = dark[::-1, ::2]  # the noise differs between pixels: no frame-wide offset
    flat = np.full(50, 10100.0)
    raw = np.full((2, 50), 600.0)
    raw[0, 5], raw[1, 5] = 110.0, 130.0
    rho, report = riner.flat_field(raw, flat, dark)
    assert rho[0, 5] == np.inf and rho[1, 5] == pytest.approx(-np.log(0.003), rel=1e-5)
    assert report["dark_noise"] == pytest.approx(4 * np.sqrt(2), rel=1e-5)
    assert report["readings_in_dark_noise"] == 1 and report["invalid_readings"] == 1
    # One dark frame says nothing of its noise: the light of 10 is a reading.
    rho, report = riner.flat_field(raw, flat, dark.mean(axis=0))
    assert np.isfinite(rho[0, 5]) and report["dark_noise"] == 0


def test_messages_name_python_keywords_not_cli_options(fan_scan):
    # The library words its hints as the CLI's options; Python's errors and notes name the
    # keyword that does the same.
    sim, g = fan_scan
    with pytest.raises(riner.Error, match=r"^device=no such device anywhere: .*riner\.devices\(\)"):
        riner.reconstruct(sim["sino"], g, device="no such device anywhere")
    counts = 1e6 * np.exp(-sim["sino"])
    with pytest.raises(riner.InputError, match=r"give their flat field \(flat= and dark=\)") as e:
        riner.fbp(counts, g)
    assert "--" not in str(e.value)
    angles = np.linspace(0, np.pi, 121)
    flat_readings = np.zeros((121, 80))
    with pytest.raises(riner.InputError, match="pass the axis's column with center=$"):
        riner.center(flat_readings, riner.parallel_beam(angles, columns=80))


def test_a_small_cone_beam_volume():
    angles = np.linspace(0, 2 * np.pi, 60, endpoint=False)
    g = riner.divergent_beam(angles, columns=40, rows=24, source_origin=100.0,
                             origin_detector=100.0, image_shape=(16, 32, 32), voxel_size=1.0)
    sim = riner.simulate(None, g, seed=1)
    r = riner.reconstruct(sim["sino"], g, steps=100, seed=1)
    assert r.image.shape == (16, 32, 32)
    assert r.alpha.shape == (24, 40) and r.beta.shape == (24, 40)


def test_deeplesion_slice_reconstructs_to_the_clis_psnr(cli, shared, tmp_path):
    # The same scan, seed and settings through the CLI and through Python (300 steps here; the
    # closing measurement at the defaults is in docs/history/RESULTS.md).
    truth = riner.read_array(shared / "deeplesion" / "slice_0.nii") * 0.1  # 1/cm -> 1/mm
    sim = riner.simulate(truth, "fan2d-paper", seed=0)
    riner.write_array(tmp_path / "sino.npy", sim["sino"])
    (tmp_path / "geometry.json").write_text(json.dumps(sim["geometry"]))
    subprocess.run([cli, "reconstruct", str(tmp_path / "sino.npy"), "--steps", "300", "--seed",
                    "7", "--format", "npy", "--out", str(tmp_path / "cli"), "--quiet"],
                   check=True)
    cli_image = riner.read_array(tmp_path / "cli" / "image.npy")
    r = riner.reconstruct(sim["sino"], "fan2d-paper", steps=300, seed=7)
    cli_psnr = riner.compare(cli_image, truth)["psnr"]
    py_psnr = riner.compare(r.image, truth)["psnr"]
    assert py_psnr == pytest.approx(cli_psnr, abs=0.01)
    assert np.abs(r.image - cli_image).max() < 1e-4
    assert np.array_equal(r.alpha, riner.read_array(tmp_path / "cli" / "alpha.npy"))


def test_load_scan_reads_a_tomography_file_and_finds_its_centre(shared):
    sino, g, notes = riner.load_scan(shared / "tooth" / "tooth.h5", row=0, center="auto")
    assert notes["flat_field"]["flat_frames"] == 10 and notes["flat_field"]["dark_frames"] == 10
    assert np.allclose(sino, riner.read_array(shared / "tooth" / "sino_row0.npy"), atol=1e-5,
                       equal_nan=True)
    assert notes["centre"]["offset_px"] == pytest.approx(23.9, abs=1.0)  # geometry.json: 23.9
    assert g["detector"]["offset_px"] == notes["centre"]["offset_px"]
    # The axis's column, as reconstruct takes it (it was refused: "None or 'auto' here").
    _, g, _ = riner.load_scan(shared / "tooth" / "tooth.h5", row=0, center=296.0)
    assert g["detector"]["offset_px"] == pytest.approx((640 - 1) / 2 - 296.0)


def test_load_scan_reads_a_scan_json_naming_raw_files(tmp_path):
    g = riner.parallel_beam(np.linspace(0, np.pi, 31), columns=40, image_shape=(32, 32))
    sim = riner.simulate(None, g, seed=4, photons=0, dead=0)
    flat = np.full((40,), 5000.0, dtype=np.float32)
    riner.write_array(tmp_path / "raw.npy", flat * np.exp(-sim["sino"]))
    riner.write_array(tmp_path / "flat.npy", flat)
    (tmp_path / "scan.json").write_text(json.dumps(
        dict(g, files={"projections": "raw.npy", "flat": "flat.npy"})))
    sino, geometry, notes = riner.load_scan(tmp_path / "scan.json")
    assert np.allclose(sino, sim["sino"], atol=1e-4, equal_nan=True)
    assert geometry == g and notes["flat_field"]["dark_frames"] == 0
    with pytest.raises(riner.InputError, match="give no flat, dark or geometry"):
        riner.load_scan(tmp_path / "scan.json", flat=tmp_path / "flat.npy")
    with pytest.raises(riner.InputError, match="nothing.npy"):
        riner.load_scan(tmp_path / "nothing.npy", geometry=tmp_path / "scan.json")


def test_load_scan_interpolates_flats_before_and_after_a_drifting_beam(tmp_path):
    g = riner.parallel_beam(np.linspace(0, np.pi, 41), columns=40, image_shape=(32, 32))
    sim = riner.simulate(None, g, seed=4, photons=0, dead=0)
    views = sim["sino"].shape[0]
    drop = 0.08 * (np.arange(views)[:, None] + 0.5) / views  # 8% less light by the end
    before = np.full((40,), 5000.0, dtype=np.float32)
    after = (before * 0.92).astype(np.float32)
    raw = before * (1 - drop) * np.exp(-sim["sino"])
    riner.write_array(tmp_path / "raw.npy", raw.astype(np.float32))
    riner.write_array(tmp_path / "before.npy", before)
    riner.write_array(tmp_path / "after.npy", after)
    for name in ("geometry.json", "scan.json"):
        (tmp_path / name).write_text(json.dumps(g))
    sino, _, notes = riner.load_scan(tmp_path / "raw.npy", flat=tmp_path / "before.npy",
                                     flat_after=tmp_path / "after.npy")
    assert np.allclose(sino, sim["sino"], atol=1e-4, equal_nan=True)
    assert notes["flat_field"]["flat_series"] == 2 and not notes["flat_field"]["air_drifts"]
    _, _, stale = riner.load_scan(tmp_path / "raw.npy", flat=tmp_path / "before.npy")
    assert stale["flat_field"]["air_drifts"]
    # The same through a scan JSON's files.
    (tmp_path / "scan.json").write_text(json.dumps(dict(
        g, files={"projections": "raw.npy", "flat": "before.npy", "flat_after": "after.npy"})))
    sino_json, _, _ = riner.load_scan(tmp_path / "scan.json")
    assert np.array_equal(sino_json, sino, equal_nan=True)
    with pytest.raises(riner.InputError, match="flats after the scan need the flats before"):
        riner.load_scan(tmp_path / "raw.npy", flat_after=tmp_path / "after.npy")
    # And from arrays: flat_field, fbp and reconstruct take the second series as flat_after.
    rho, report = riner.flat_field(raw, before, flat_after=after)
    assert np.array_equal(rho, sino, equal_nan=True) and report["flat_series"] == 2
    assert np.array_equal(riner.fbp(raw, g, flat=before, flat_after=after), riner.fbp(sino, g))
    r = riner.reconstruct(raw, g, flat=before, flat_after=after, steps=5, quality=False)
    assert r.summary["flat_field"]["flat_series"] == 2
    with pytest.raises(riner.InputError, match="flat_after needs flat"):
        riner.fbp(raw, g, flat_after=after)


def test_a_file_read_in_the_session_can_be_written_back(tmp_path):
    # Read, edit, write back: a read guards its file during that call only (the CLI's
    # "refusing to overwrite an input file" is for one run reading and writing).
    a = np.arange(12, dtype=np.float32).reshape(3, 4)
    riner.write_array(tmp_path / "p.npy", a)
    b = riner.read_array(tmp_path / "p.npy")
    riner.write_array(tmp_path / "p.npy", b + 1)
    assert np.array_equal(riner.read_array(tmp_path / "p.npy"), a + 1)


def test_the_librarys_warnings_and_the_centre_check_reach_python():
    # Before: simulate's starved-photons warning was the CLI's alone, and reconstruct neither
    # warned of a geometry whose axis the scan contradicts nor kept the check in its summary.
    g = riner.parallel_beam(np.linspace(0, np.pi, 91), columns=96, center=47.5 + 6.0)
    with pytest.warns(UserWarning, match="fewer than 10 photons"):
        riner.simulate(None, g, mu_scale=30.0)
    sim = riner.simulate(None, g, seed=1)
    wrong = json.loads(json.dumps(g))
    wrong["detector"]["offset_px"] = 0.0
    with pytest.warns(UserWarning, match="puts the rotation axis at offset"):
        r = riner.reconstruct(sim["sino"], wrong, steps=20, quality=False)
    assert r.summary["centre_check"]["offset_px"] == pytest.approx(g["detector"]["offset_px"], abs=0.5)


def test_fbp_shows_a_beam_the_metal_stopped_and_says_so():
    # A 3/mm disc on the axis of a water disc stops the beam: FBP reads those readings as the
    # scan's largest finite reading (the metal shows), and says so; fill_stopped_beam=True
    # interpolates them from their neighbours (it hardly shows); without metal nothing is said.
    g = riner.parallel_beam(np.linspace(0, np.pi, 90, endpoint=False), columns=70,
                            image_shape=(64, 64))
    y, x = np.mgrid[:64, :64] - 31.5
    body = np.where(x * x + y * y < 28 * 28, 0.02, 0.0).astype(np.float32)
    metal = np.where(x * x + y * y < 4.5 * 4.5, 3.0, body).astype(np.float32)
    with pytest.warns(UserWarning, match="fewer than 10 photons"):
        sino = riner.simulate(metal, g, seed=3)["sino"]
    # In Python's words: the keyword, not the command line's option.
    with pytest.warns(UserWarning, match=r"look like a beam the object stopped.*reads them.*"
                      r"fill_stopped_beam=True interpolates them.*riner\.reconstruct trains"):
        shown = riner.fbp(sino, g)
    with pytest.warns(UserWarning, match="fills them from their neighbours"):
        filled, report = riner.fbp(sino, g, fill_stopped_beam=True, return_report=True)
    assert report["stopped_beam_readings"] > 100 and report["stopped_beam_floor"] == 0
    assert report["non_finite_replaced"] >= report["stopped_beam_readings"]
    assert report["flat_field"] is None and report["centre"] is None
    inside = metal > 1
    # 1.86 and 1.04 (the truth 3.0)
    assert shown[inside].mean() > 1.5 and shown[inside].mean() > 1.5 * filled[inside].mean()
    plain = riner.simulate(body, g, seed=3)["sino"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        riner.fbp(plain, g)


def test_a_360_degree_scan_under_180_degrees_of_angles_is_doubted_in_python():
    # The same lines as the command line's: fbp and reconstruct warn and keep them, center
    # raises; under the scan's own angles nothing is said.
    full = riner.parallel_beam(np.linspace(0, 2 * np.pi, 180, endpoint=False), columns=120,
                               center=59.5 + 2.5, image_shape=(96, 96))
    half = riner.parallel_beam(np.linspace(0, np.pi, 180, endpoint=False), columns=120,
                               center=59.5 + 2.5, image_shape=(96, 96))
    sino = riner.simulate(None, full, seed=3)["sino"]
    doubt = "the views cover a full turn (360 degrees), the geometry's angles 179.0 degrees"
    with pytest.warns(UserWarning, match=re.escape(doubt)):
        riner.fbp(sino, half)
    with pytest.warns(UserWarning, match="the views cover a full turn"):
        r = riner.reconstruct(sino, half, steps=20, quality=False)
    assert len(r.summary["geometry_doubts"]) == 1
    assert r.summary["geometry_doubts"][0].startswith(doubt)
    with pytest.raises(riner.InputError, match="no centre: the views cover a full turn"):
        riner.center(sino, half)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        riner.fbp(sino, full)
        riner.destripe(sino, full)
        assert riner.reconstruct(sino, full, steps=20, quality=False).summary["geometry_doubts"] == []
    assert not [w for w in said if "the views cover" in str(w.message)]
    with pytest.warns(UserWarning, match="the views cover a full turn"):
        riner.destripe(sino, half)


def test_bad_arguments_raise_input_error_with_one_line(fan_scan):
    sim, g = fan_scan
    # A negative count reached the binding as a TypeError printing the whole array.
    with pytest.raises(riner.InputError, match=r"^size must be a whole number >= 0 \(got -3\)$"):
        riner.destripe(sim["sino"], g, size=-3)
    with pytest.raises(riner.InputError, match="center must be the axis's column"):
        riner.fbp(sim["sino"], riner.parallel_beam(np.linspace(0, np.pi, 10), columns=8),
                  center="abc")
