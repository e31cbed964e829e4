"""`nbv ablate`: levels change one setting, the summary is hand-checkable, `--quick` runs end to end."""

import csv
import json
import subprocess
import sys

import pytest
from PIL import Image

from nbv.experiments.ablate import QUICK, AblateConfig, units
from nbv.experiments.ablation_axes import AXES, REFERENCE, apply_level
from nbv.experiments.ablation_report import summary_rows
from render.settings import RenderSettings


def test_every_level_changes_only_its_own_settings():
    base = RenderSettings()
    for axis in AXES.values():
        assert sum(level.is_reference for level in axis.levels) == 1, axis.name
        for level in axis.levels:
            changed = apply_level(base, level)  # the settings' own checks accept every level
            differs = {f for f in ("spp", "denoiser", "resolution_scale", "pixel_filter", "max_depth",
                                   "texture_scale", "motion_blur_m", "lighting", "sensor")
                       if getattr(changed, f) != getattr(base, f)}
            touched = {path.split(".")[0] for path, _ in level.overrides}
            assert differs <= touched and (level.is_reference or differs), (axis.name, level.label)
    four = next(level for level in AXES["denoiser"].levels if level.label == "oidn, 4 spp")
    assert apply_level(base, four) == RenderSettings(spp=4, denoiser="oidn")
    jpeg50 = next(level for level in AXES["jpeg"].levels if level.label == "50")
    assert apply_level(base, jpeg50).sensor.jpeg_quality == 50


def test_units_measure_the_reference_once_per_building_and_seed():
    config = AblateConfig(axis=("spp", "jpeg"), scene=("a", "b"), seeds=(0, 1))
    names = [(u.scene, u.axis, u.level.label, u.seed) for u in units(config)]
    assert len(names) == 2 * 2 * (1 + 3 + 3)
    assert names[:4] == [("a", REFERENCE, REFERENCE, 0), ("a", "spp", "1", 0), ("a", "spp", "4", 0),
                         ("a", "spp", "64", 0)]
    assert AblateConfig().axes == tuple(AXES) and QUICK.scenes == ("test_building",)


def test_summary_is_mean_and_std_over_units_with_jaccard_against_the_reference():
    def doc(axis, level, seed, psnr, kept):
        return {"scene": "s", "axis": axis, "level": level, "seed": seed, "psnr_db": psnr, "kept": kept,
                "gt_coverage": 0.5}

    docs = [doc(REFERENCE, REFERENCE, 0, 30.0, [0, 1, 2]), doc(REFERENCE, REFERENCE, 1, 32.0, [0, 1]),
            doc("spp", "4", 0, 24.0, [0, 1, 3]), doc("spp", "4", 1, 26.0, [0, 1])]
    rows = {r["level"]: r for r in summary_rows(docs, ("spp",))}
    assert rows["16"]["reference"] and rows["16"]["psnr_db_mean"] == 31.0 and rows["16"]["psnr_db_std"] == 1.0
    assert rows["4"]["psnr_db_mean"] == 25.0 and rows["4"]["units"] == 2
    assert rows["4"]["jaccard_mean"] == pytest.approx((2 / 4 + 1.0) / 2)  # {0,1,3} vs {0,1,2}; equal sets
    assert rows["16"]["gt_coverage_mean"] == 50.0
    assert rows["1"]["units"] == 0 and rows["1"]["ssim_mean"] is None


def test_an_unknown_axis_is_refused_by_name():
    with pytest.raises(ValueError, match="unknown axis 'fog'"):
        AblateConfig(axis=("fog",))
    run = subprocess.run([sys.executable, "-m", "nbv.cli", "ablate", "--axis", "fog"], capture_output=True,
                         text=True)
    assert run.returncode == 2 and "fog" in run.stderr


SMALLER = ["--width", "64", "--height", "48", "--end-overlap", "0.1", "--side-overlap", "0.0",
           "--quality-views", "1", "--reference-spp", "64", "--greedy-views", "3", "--greedy-candidates", "2",
           "--metric-points", "3000"]
"""`--quick` made smaller still for the suite: every axis, level and stage, on fewer pixels, views (a 13-view
scan) and samples."""


@pytest.mark.slow
def test_quick_ablation_end_to_end(tmp_path):
    run = subprocess.run([sys.executable, "-m", "nbv.cli", "ablate", "--quick", "--out", str(tmp_path),
                          *SMALLER], capture_output=True, text=True, timeout=540)
    assert run.returncode == 0, run.stderr[-2000:]
    doc = json.loads((tmp_path / "ablations.json").read_text())
    rows = {(r["axis"], r["level"]): r for r in doc["rows"]}
    assert set(rows) == {(a.name, level.label) for a in AXES.values() for level in a.levels}
    with open(tmp_path / "ablations.csv") as handle:
        assert len(list(csv.DictReader(handle))) == len(rows)
    spp = [rows[("spp", label)]["psnr_db_mean"] for label in ("1", "4", "16", "64")]
    assert all(a < b for a, b in zip(spp, spp[1:])), spp  # more samples, closer to the high-spp reference
    assert all(r["jaccard_mean"] == 1.0 for r in doc["rows"] if r["reference"])
    lighting = [r for r in doc["rows"] if AXES[r["axis"]].lighting]
    assert all(r["greedy_coverage_mean"] is not None for r in lighting)
    spp_levels = [r for r in doc["rows"] if r["axis"] == "spp" and not r["reference"]]
    assert all(r["greedy_coverage_mean"] is None for r in spp_levels)
    for name in ("quality_vs_time.png", "crops.png", *(f"axis_{a}.png" for a in AXES)):
        with Image.open(tmp_path / name) as image:
            assert image.size[0] > 300
    readme = (tmp_path / "README.md").read_text()
    assert all(f"**{a}**" in readme for a in AXES) and "nbv ablate --quick" in readme
