"""transforms.json's `applied_transform`: written as the identity, absent accepted, anything else refused."""

from __future__ import annotations

import json

import numpy as np
import pytest

from render.camera import UAVCamera
from render.dataset import DatasetError, DatasetWriter, read_dataset
from render.viewpoint import Viewpoint, viewpoint_to_c2w


@pytest.fixture
def dataset(tmp_path):
    out = tmp_path / "ds"
    with DatasetWriter(out, UAVCamera(16, 12), {"scene": "synthetic"}) as writer:
        writer.add(np.zeros((12, 16, 3), np.uint8), np.ones((12, 16), np.float32),
                   viewpoint_to_c2w(Viewpoint(2.0, 0.5, 0.3), np.zeros(3)))
    return out


def edit(dataset, change) -> None:
    path = dataset / "transforms.json"
    doc = json.loads(path.read_text())
    change(doc)
    path.write_text(json.dumps(doc))


def test_written_as_the_identity(dataset):
    doc = json.loads((dataset / "transforms.json").read_text())
    assert doc["applied_transform"] == np.eye(4)[:3].tolist()
    assert len(read_dataset(dataset)) == 1


def test_files_written_before_it_are_read(dataset):
    edit(dataset, lambda doc: doc.pop("applied_transform"))
    assert len(read_dataset(dataset)) == 1


@pytest.mark.parametrize("value", [
    [[0, 1, 0, 0], [1, 0, 0, 0], [0, 0, -1, 0]],  # nerfstudio's COLMAP axis swap
    [[1, 0, 0, 0.5], [0, 1, 0, 0], [0, 0, 1, 0]],
    np.eye(4).tolist(),
    "identity",
    [[1, 0], [0, 1]],
])
def test_anything_else_is_refused_naming_file_and_field(dataset, value):
    edit(dataset, lambda doc: doc.update(applied_transform=value))
    with pytest.raises(DatasetError, match=r"transforms\.json: field applied_transform"):
        read_dataset(dataset)
