"""`nbv scan`, `nbv scene` and `nbv demo` run end to end; bad input exits 2 naming the fault."""

import json

import pytest

from nbv.cli import main
from render.dataset import read_dataset


def test_scan_circle_writes_a_readable_dataset(tmp_path):
    out = tmp_path / "ds"
    assert main(["scan", "test_building", "circle", "--views", "4", "--elevation-deg", "20",
                 "--width", "48", "--height", "36", "--spp", "2", "--out", str(out)]) == 0
    ds = read_dataset(out)
    assert len(ds) == 4 and ds.camera.width == 48
    assert ds.meta["scene"] == "test_building"
    assert ds.meta["plan"] == {"name": "circle", "radius": 2.0, "elevation_deg": 20.0, "views": 4,
                               "end_overlap": 0.85}
    assert [round(f.viewpoint.elevation, 6) for f in ds.frames] == [round(0.349066, 6)] * 4


def test_scan_takes_every_render_setting_as_a_flag_and_records_it(tmp_path):
    out = tmp_path / "ds"
    assert main(["scan", "test_building", "circle", "--views", "2", "--width", "32",
                 "--height", "24", "--spp", "2", "--pixel-filter", "tent", "--resolution-scale", "1.5",
                 "--texture-scale", "0.5", "--motion-blur-m", "0.02", "--motion-blur-frames", "2",
                 "--sky-model", "sunsky", "--light-mode", "overcast", "--sun-elevation-deg", "30",
                 "--sun-azimuth-deg", "100", "--turbidity", "4", "--exposure-stops", "0.5",
                 "--shot-noise", "0.001", "--read-noise", "0.002", "--jpeg-quality", "70",
                 "--out", str(out)]) == 0
    doc = json.loads((out / "transforms.json").read_text())
    assert (doc["w"], doc["h"]) == (48, 36)
    render = doc["nbv"]["render"]
    assert (render["pixel_filter"], render["resolution_scale"], render["texture_scale"]) == ("tent", 1.5, 0.5)
    assert (render["motion_blur_m"], render["motion_blur_frames"]) == (0.02, 2)
    assert render["lighting"] == {"sky_model": "sunsky", "light_mode": "overcast", "sun_elevation_deg": 30.0,
                                  "sun_azimuth_deg": 100.0, "turbidity": 4.0}
    assert render["sensor"] == {"exposure_stops": 0.5, "shot_noise": 0.001, "read_noise": 0.002,
                                "jpeg_quality": 70}
    assert read_dataset(out).render_settings.sensor.jpeg_quality == 70


def test_scan_plans_are_subcommands_with_their_own_flags(tmp_path):
    from nbv.cli.parse import parse
    from render.scan import CirclePlan, HemispherePlan, ScanConfig

    out = ["--out", str(tmp_path / "ds")]
    assert parse(ScanConfig, ["test_building", *out], "nbv scan").plan == HemispherePlan()
    high = parse(ScanConfig, ["test_building", "hemisphere", "--min-elevation-deg", "40", *out], "nbv scan")
    assert high.plan == HemispherePlan(min_elevation_deg=40.0)
    low = parse(ScanConfig, ["test_building", *out, "circle", "--elevation-deg", "5", "--width", "64"],
                "nbv scan")
    assert low.plan == CirclePlan(elevation_deg=5.0) and low.camera.width == 64  # options after the plan too
    assert min(v.elevation for v in high.viewpoints()) > 0.69 and len(low.viewpoints()) == 24


def test_scene_list_and_export(tmp_path, capsys):
    assert main(["scene", "list"]) == 0
    assert "test_building" in capsys.readouterr().out.split()
    assert main(["scene", "export", "test_building", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "mesh.ply").stat().st_size > 0


@pytest.mark.parametrize("args, message", [
    (["no_such_scene"], "unknown scene"),
    (["test_building", "--width", "0"], "width"),
    (["test_building", "--focal-mm", "-3"], "focal_mm"),
    (["test_building", "circle", "--views", "0"], "views"),
    (["test_building", "circle", "--radius", "0.5"], "radius must lie in"),
    (["test_building", "hemisphere", "--min-elevation-deg", "60", "--max-elevation-deg", "30"],
     "need -90 < min_elevation_deg <= max_elevation_deg <= 90"),
    (["test_building", "--jpeg-quality", "0"], "jpeg_quality must be in 1..100, got 0"),
    (["test_building", "--resolution-scale", "0"], "resolution_scale"),
    (["test_building", "--texture-scale", "2"], "texture_scale"),
    (["test_building", "--motion-blur-frames", "1"], "motion_blur_frames"),
    (["test_building", "--sun-elevation-deg", "-5"], "sun_elevation_deg"),
    (["test_building", "--turbidity", "20"], "turbidity"),
    (["test_building", "--shot-noise", "nan"], "shot_noise"),
    (["test_building", "--exposure-stops", "inf"], "exposure_stops"),
])
def test_bad_scan_input_exits_2_with_a_message(tmp_path, capsys, args, message):
    assert main(["scan", *args, "--out", str(tmp_path / "ds")]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "ds").exists()
