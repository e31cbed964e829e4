"""Registrability (`--min-matches`): verified matches between views of the textured box, the connectivity
repair of a kept set (hand-worked graphs, and `nbv refine` on the box arc), the planners' choice among
linked candidates, and the option's bad values."""

from __future__ import annotations

import json

import pytest
from synthetic_box import write_box_arc

from nbv.cli import main
from nbv.features.config import FeatureConfig
from nbv.features.sift import extract_features
from nbv.planning.config import PlanConfig, PlanSettings
from nbv.planning.linking import FlownLinks, pick_linked
from nbv.sfm.config import LinkSettings
from nbv.sfm.links import link_graph, verified_matches
from nbv.sfm.repair import Repair, repair_kept, repair_links
from render.dataset import read_dataset
from render.viewpoint import Viewpoint
from scenes.spec import SceneSpec

ARC = {"views": 6, "step_deg": 15.0, "size": (240, 180)}
"""Six views 15 degrees apart (as test_sfm.py). With OpenCV's SIFT (500 features a view, fast) neighbours
share 185 to 192 verified matches, views two or more apart at most 75 (measured), so K = 100 links
exactly the neighbours."""
SIFT = FeatureConfig(backend="opencv")
K = 100


@pytest.fixture(scope="module")
def arc(tmp_path_factory):
    return write_box_arc(tmp_path_factory.mktemp("box") / "arc", **ARC)


@pytest.fixture(scope="module")
def features(arc):
    dataset = read_dataset(arc)
    return dataset, extract_features([dataset.rgb(i) for i in range(len(dataset))], SIFT)


def test_neighbours_on_the_arc_are_linked_and_far_views_are_not(features):
    dataset, feats = features
    links = link_graph(feats, dataset.poses()[:, :3, 3], dataset.camera.K, neighbours=5)
    assert len(links) == 15  # every pair of six views
    linked = sorted(pair for pair, matches in links.items() if matches >= K)
    assert linked == [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5)]
    assert verified_matches(feats[0], feats[0], dataset.camera.K) == len(feats[0]) == 500  # with itself


def test_the_repair_adds_the_chain_between_the_arc_ends(features):
    dataset, feats = features
    repair, record = repair_kept(feats, dataset.poses()[:, :3, 3], dataset.camera.K, [0, 5],
                                 LinkSettings(min_matches=K, link_neighbours=5))
    assert repair == Repair(kept=[0, 1, 2, 3, 4, 5], added=[1, 2, 3, 4], unlinked=[])
    assert record["paper_kept"] == [0, 5] and record["pairs_matched"] == 15 and record["pairs_linked"] == 5


def test_the_repair_takes_the_fewest_views_and_joins_every_kept_view():
    # 0-1-4 is one added view, 0-2-3-4 two; then 4-5-6 (5 added) reaches 6; 0-6 is one match short.
    links = {(0, 1): 40, (1, 4): 35, (0, 2): 50, (2, 3): 45, (3, 4): 60, (4, 5): 30, (5, 6): 33, (0, 6): 29}
    assert repair_links([0, 4, 6], 8, links, 30) == Repair([0, 1, 4, 5, 6], added=[1, 5], unlinked=[])
    # a kept view with no link at all is kept, and reported unlinked
    assert repair_links([0, 4, 7], 8, links, 30) == Repair([0, 1, 4, 7], added=[1], unlinked=[7])
    # equal costs: the lowest-numbered view is reached first
    assert repair_links([0, 3], 4, {(0, 1): 9, (0, 2): 9, (1, 3): 9, (2, 3): 9}, 9).added == [1]
    # kept views linked through each other need nothing
    assert repair_links([0, 1, 2], 3, {(0, 1): 9, (1, 2): 9}, 9) == Repair([0, 1, 2], [], [])
    assert repair_links([], 3, {}, 9) == Repair([], [], [])


def test_nbv_refine_with_min_matches_adds_the_views_between_two_kept(arc, tmp_path, capsys):
    common = ["--ranges", "1", "--words", "100", "--feature-backend", "opencv", "--match-cosine", "0.8",
              "--cache-dir", str(tmp_path / "cache")]
    assert main(["refine", str(arc), "--out", str(tmp_path / "paper"), *common]) == 0
    paper = json.loads((tmp_path / "paper" / "refine.json").read_text())
    assert paper["kept"] == [0, 3] and "links" not in paper  # views 0 and 3 share about 10 matches
    args = ["--min-matches", str(K), "--link-neighbours", "5"]
    assert main(["refine", str(arc), "--out", str(tmp_path / "on"), *args, *common]) == 0
    assert "registrable (--min-matches 100): the paper's rule kept 2, 2 added to link them, 0 kept view(s) " \
           "unlinked" in capsys.readouterr().out
    doc = json.loads((tmp_path / "on" / "refine.json").read_text())
    assert doc["kept"] == [0, 1, 2, 3] and doc["kept_views"] == 4 and len(read_dataset(tmp_path / "on")) == 4
    links = doc["links"]
    assert (links["paper_kept"], links["added"], links["unlinked"]) == ([0, 3], [1, 2], [])
    assert links["min_matches"] == K


def test_planners_fly_the_best_linked_candidate():
    assert pick_linked([5.0, 9.0, 7.0], [40, 10, 30], 30) == 2
    assert pick_linked([5.0, 9.0, 9.0], [40, 30, 30], 30) == 1  # first on ties, as greedy
    assert pick_linked([5.0, 9.0, 7.0], [4, 10, 10], 30) == 1  # none linked: the most links


@pytest.mark.parametrize(("args", "message"), [
    (["--min-matches", "-1"], "min_matches must be >= 0"),
    (["--link-neighbours", "0"], "link_neighbours must be >= 1"),
])
def test_bad_link_settings_are_named(arc, tmp_path, capsys, args, message):
    assert main(["refine", str(arc), "--out", str(tmp_path / "out"), *args]) == 2
    assert message in capsys.readouterr().err


def test_min_matches_is_refused_for_a_planner_that_does_not_choose():
    settings = PlanSettings(links=LinkSettings(min_matches=20))
    with pytest.raises(ValueError, match=r"--min-matches applies to .*\(random, greedy, infogain\); 'orbit'"):
        PlanConfig(scene=SceneSpec(scene="test_building"), planner="orbit", out="x", settings=settings)
    PlanConfig(scene=SceneSpec(scene="test_building"), planner="greedy", out="x", settings=settings)


def test_a_candidate_is_matched_with_the_flown_views_and_a_flown_viewpoint_never_again(features):
    dataset, feats = features
    flown = FlownLinks(LinkSettings(min_matches=K, link_neighbours=1), dataset.camera.K)
    flown.add(Viewpoint(2.0, 0.0, 0.5), feats[0])
    flown.add(Viewpoint(2.0, 3.0, 0.5), feats[3])
    assert flown.matches(Viewpoint(2.0, 0.0, 0.5), feats[0]) == -1  # at a flown viewpoint
    # near the first flown view, so matched with it alone (link_neighbours 1)
    assert flown.matches(Viewpoint(2.0, 0.2, 0.5), feats[1]) == verified_matches(feats[1], feats[0],
                                                                                  dataset.camera.K) >= K
