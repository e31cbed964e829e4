"""Contact sheet and trajectory plot: files that open, with the expected layout."""

import numpy as np
import pytest
from PIL import Image

from nbv.viz.figures import (
    contact_sheet,
    plot_training_curves,
    plot_trajectory,
    training_curves,
    trajectory_figure,
)
from render.camera import UAVCamera
from render.dataset import DatasetWriter, read_dataset
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import load_scene


@pytest.fixture
def dataset(tmp_path):
    center = np.array([0, 0, 0.4])
    with DatasetWriter(tmp_path / "ds", UAVCamera(40, 30), {"center": center.tolist()}) as writer:
        for i in range(7):
            view = Viewpoint(2.0, i, 0.3)
            rgb = np.full((30, 40, 3), 30 * i, np.uint8)
            writer.add(rgb, np.ones((30, 40), np.float32), viewpoint_to_c2w(view, center), view)
    return read_dataset(tmp_path / "ds")


def test_contact_sheet_tiles_every_view(dataset, tmp_path):
    path = contact_sheet(dataset, tmp_path / "sheet.png", thumb_width=40)
    sheet = np.asarray(Image.open(path))
    assert sheet.shape == (2 * 30, 4 * 40, 3)  # 7 views at 4:3 make 4 columns, 2 rows
    # The last tile (view 6, value 180) sits at row 1, column 2; sample below its label.
    assert sheet[30 + 20, 2 * 40 + 20].tolist() == [180, 180, 180]


def test_trajectory_plot_is_written(dataset, tmp_path):
    mesh = load_scene("test_building").target_mesh()
    path = plot_trajectory(dataset.poses(), mesh, tmp_path / "t.png", "t")
    with Image.open(path) as img:
        assert img.size[0] > 800 and img.size[1] > 400


def test_the_trajectory_draws_the_flown_path_not_the_chords(dataset):
    mesh = load_scene("test_building").target_mesh()
    poses = dataset.poses()
    flown = np.stack([[2 * np.cos(a), 2 * np.sin(a), 0.5] for a in np.linspace(0, 3, 50)])
    top = trajectory_figure(poses, mesh, flown=flown).axes[1]
    drawn = {line.get_label(): np.column_stack(line.get_data()) for line in top.get_lines()}
    assert np.allclose(drawn["flown path"], flown[:, :2]) and np.allclose(drawn["start view"], flown[:1, :2])
    chords = trajectory_figure(poses, mesh).axes[1].get_lines()
    assert [np.column_stack(line.get_data()).tolist() for line in chords] == [poses[:, :2, 3].tolist()]


def test_training_curves_average_the_last_window(tmp_path):
    csv_path = tmp_path / "metrics.csv"
    csv_path.write_text("frames,updates,reward_mean,episode_return,episodes\n"
                        "10,0,1.0,,0\n20,10,2.0,5.0,1\n30,20,3.0,,0\n40,30,4.0,7.0,1\n")
    curves = training_curves(csv_path, window=20)  # each point: its own batch and the one before
    assert curves["reward"].tolist() == pytest.approx([1.0, 1.5, 2.5, 3.5])
    assert curves["return"][1:].tolist() == pytest.approx([5.0, 5.0, 7.0]) and np.isnan(curves["return"][0])
    assert curves["steps"][1:].tolist() == pytest.approx([20.0, 20.0, 20.0])
    png = plot_training_curves({"a": csv_path, "b": csv_path}, tmp_path / "curves.png", window=20)
    assert Image.open(png).size[0] > 500
